"""A 3MF plate holding every print of a batch, each object with its own slicer settings.

The 3D model (meshes, names, placement on the bed) is written by lib3mf, the 3MF Consortium's
reference implementation: it writes the core specification and its reader checks what it wrote. The
slicers' own settings are not part of the 3MF specification; each slicer keeps them in a file of
its own inside the package, which lib3mf carries as attachments:

- PrusaSlicer: `Metadata/Slic3r_PE.config` (the plate's options, one `; key = value` per line) and
  `Metadata/Slic3r_PE_model.config` (XML: per object its options and its volume's triangles);
- OrcaSlicer and Bambu Studio: `Metadata/model_settings.config` (XML: per object its options) and
  `Metadata/project_settings.config` (JSON: the plate's options).

Each object's id in those files is its resource id in the 3D model, as the slicers match them.
"""

from __future__ import annotations

import contextlib
import json
import locale
import xml.etree.ElementTree as ET
from collections.abc import Iterator, Sequence
from pathlib import Path
from typing import Any

from ..errors import DesignerError
from . import settings
from .specimen import Specimen

#: the relationship type the slicers' configuration files are attached with (the slicers find them
#: by path; a 3MF reader keeps attachments of the types it is told to read)
RELATIONSHIP = "http://schemas.slic3r.org/3mf/2017/06/config"
SPACING_MM = 10.0
PRUSA_PLATE = "/Metadata/Slic3r_PE.config"
PRUSA_OBJECTS = "/Metadata/Slic3r_PE_model.config"
ORCA_OBJECTS = "/Metadata/model_settings.config"
ORCA_PLATE = "/Metadata/project_settings.config"


def layout(prints: Sequence[Specimen], bed: float = settings.BED_MM) -> list[tuple[float, float]]:
    """Where each print's mesh origin goes on the bed (mm): columns of prints side by side across
    their blocks, SPACING_MM apart, the whole centred on the bed.

    Raises:
        DesignerError: the prints do not fit on the bed.
    """
    sizes = [p.mesh.extents for p in prints]
    pitch_y = max(s[1] for s in sizes) + SPACING_MM
    pitch_x = max(s[0] for s in sizes) + SPACING_MM
    per_column = max(int((bed + SPACING_MM) // pitch_y), 1)
    columns = -(-len(prints) // per_column)
    rows = min(len(prints), per_column)
    width, depth = columns * pitch_x - SPACING_MM, rows * pitch_y - SPACING_MM
    if width > bed or depth > bed:
        raise DesignerError(
            f"{len(prints)} prints need {width:.0f} x {depth:.0f} mm, more than the {bed:g} mm bed",
            "print the batch on two plates (fewer designs per call)",
        )
    x0, y0 = (bed - width) / 2, (bed - depth) / 2
    return [(x0 + (i // per_column) * pitch_x, y0 + (i % per_column) * pitch_y) for i in range(len(prints))]


def _prusa_objects(prints: Sequence[Specimen], ids: Sequence[int]) -> bytes:
    root = ET.Element("config")
    for p, rid in zip(prints, ids, strict=True):
        obj = ET.SubElement(root, "object", id=str(rid), instances_count="1")
        ET.SubElement(obj, "metadata", type="object", key="name", value=p.print_id)
        for key, value in settings.prusa_object(p.params).items():
            ET.SubElement(obj, "metadata", type="object", key=key, value=value)
        volume = ET.SubElement(obj, "volume", firstid="0", lastid=str(len(p.mesh.faces) - 1))
        ET.SubElement(volume, "metadata", type="volume", key="name", value=p.print_id)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True)


def _orca_objects(prints: Sequence[Specimen], ids: Sequence[int]) -> bytes:
    root = ET.Element("config")
    for p, rid in zip(prints, ids, strict=True):
        obj = ET.SubElement(root, "object", id=str(rid))
        ET.SubElement(obj, "metadata", key="name", value=p.print_id)
        ET.SubElement(obj, "metadata", key="extruder", value="1")
        for key, value in settings.orca_object(p.params).items():
            ET.SubElement(obj, "metadata", key=key, value=value)
        part = ET.SubElement(obj, "part", id="1", subtype="normal_part")
        ET.SubElement(part, "metadata", key="name", value=p.print_id)
    return ET.tostring(root, encoding="utf-8", xml_declaration=True)


def _prusa_plate(first: Specimen) -> bytes:
    lines = ["; plate settings written by flexjoint designer (PrusaSlicer option names)"]
    lines += [f"; {key} = {value}" for key, value in sorted(settings.prusa_plate_of(first.params).items())]
    return ("\n".join(lines) + "\n").encode()


@contextlib.contextmanager
def locale_kept() -> Iterator[None]:
    """Restore the process's locale after the block: lib3mf's writer sets the C locale (for its
    decimal points) and leaves it so, which turns Python's default text encoding into ASCII."""
    saved = locale.setlocale(locale.LC_ALL)
    try:
        yield
    finally:
        locale.setlocale(locale.LC_ALL, saved)


def write_plate(prints: Sequence[Specimen], path: str | Path) -> Path:
    """Write `prints` as one 3MF plate (atomically) and return its path.

    Raises:
        DesignerError: no print, two prints with one id, or a plate the bed cannot hold.
    """
    from ..files import atomic_path

    if not prints:
        raise DesignerError("prints=[] holds no print", "give at least one Specimen")
    names = [p.print_id for p in prints]
    if len(set(names)) < len(names):
        raise DesignerError(f"two prints share an id among {names}", "give every print its own id")
    with locale_kept(), atomic_path(path) as tmp:
        _model(prints).QueryWriter("3mf").WriteToFile(str(tmp))
    return Path(path)


def _model(prints: Sequence[Specimen]) -> Any:
    """The lib3mf model of the plate: meshes, build items, metadata and the slicers' configs."""
    import lib3mf
    import numpy as np

    names = [p.print_id for p in prints]
    wrapper = lib3mf.get_wrapper()
    model = wrapper.CreateModel()
    model.SetUnit(lib3mf.ModelUnit.MilliMeter)
    ids = []
    for p, (x, y) in zip(prints, layout(prints), strict=True):
        obj = model.AddMeshObject()
        obj.SetName(p.print_id)
        obj.SetPartNumber(p.print_id)
        vertices = [_position(lib3mf, v) for v in np.asarray(p.mesh.vertices, dtype=float)]
        triangles = [_triangle(lib3mf, f) for f in np.asarray(p.mesh.faces)]
        obj.SetGeometry(vertices, triangles)
        transform = wrapper.GetTranslationTransform(float(x), float(y), 0.0)
        model.AddBuildItem(obj, transform)
        ids.append(obj.GetModelResourceID())
    meta = model.GetMetaDataGroup()
    meta.AddMetaData("", "Application", "flexjoint designer", "xs:string", False)
    meta.AddMetaData("", "Title", "TPU joint specimens " + ", ".join(names), "xs:string", False)
    parts = {
        PRUSA_PLATE: _prusa_plate(prints[0]),
        PRUSA_OBJECTS: _prusa_objects(prints, ids),
        ORCA_OBJECTS: _orca_objects(prints, ids),
        ORCA_PLATE: json.dumps(settings.orca_plate(prints[0].params), indent=2).encode(),
    }
    for uri, data in parts.items():
        model.AddAttachment(uri, RELATIONSHIP).ReadFromBuffer(bytearray(data))
    return model


def _position(lib3mf, v) -> object:
    out = lib3mf.Position()
    out.Coordinates[0], out.Coordinates[1], out.Coordinates[2] = (float(c) for c in v)
    return out


def _triangle(lib3mf, f) -> object:
    out = lib3mf.Triangle()
    out.Indices[0], out.Indices[1], out.Indices[2] = (int(i) for i in f)
    return out
