"""A layer over the user's USD robot, and what it changes.

The layer has the robot's file as its only sublayer (by its path relative to the layer's folder, so the
two move together) and the robot's stage metadata (USD reads stage metadata from the root layer only:
without it the robot's metersPerUnit, upAxis and defaultPrim would be lost). The robot's file is
opened, never written. Before the layer replaces the output, usd-core composes it from beside the output
and `stage_changes` compares it with the robot prim by prim, attribute by attribute (values, time
samples, metadata, relationship targets, applied schemas).
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path

from ..files import atomic_path

#: root-layer fields the layer does not copy from the robot's: its own sublayers and its description
OWN_FIELDS = {"subLayers", "subLayerOffsets", "documentation", "comment", "primChildren"}


def over_layer(host_stage, host_path: Path, suffix: str):
    """An anonymous layer (format of `suffix`) over the robot, with its metadata, and a stage on it whose
    edit target is that layer: (layer, stage). Drop the stage before `write_over`."""
    from pxr import Sdf, Usd

    source = host_stage.GetRootLayer()
    layer = Sdf.Layer.CreateAnonymous(suffix)
    for key in source.pseudoRoot.ListInfoKeys():
        if key not in OWN_FIELDS:
            layer.pseudoRoot.SetInfo(key, source.pseudoRoot.GetInfo(key))
    layer.subLayerPaths.append(str(host_path.absolute()))
    return layer, Usd.Stage.Open(layer)


def write_over(layer, host_path: Path, path: Path, check: Callable[[object], None]) -> None:
    """Point the layer's sublayer at the robot relative to `path`'s folder, write it beside `path`,
    compose it there with usd-core, run `check(stage)`, then rename it to `path`."""
    from pxr import Usd

    try:
        relative = Path(os.path.relpath(host_path.absolute(), path.absolute().parent)).as_posix()
    except ValueError:  # another drive (Windows): the absolute path
        relative = str(host_path.absolute())
    layer.subLayerPaths[0] = relative
    with atomic_path(path) as tmp:
        if not layer.Export(str(tmp)):
            raise RuntimeError(f"usd-core could not write {tmp}")
        check(Usd.Stage.Open(str(tmp)))


def _same(a: object, b: object) -> bool:
    """Equal values, NaN equal to NaN (arrays of floats compare by their text)."""
    return a == b or repr(a) == repr(b)


def _prim_changes(before, after, skip: set[str]) -> list[str]:
    """What differs between two prims: metadata, attributes (value, time samples, metadata) and
    relationship targets, leaving out attributes named in `skip`."""
    changed = []
    meta_a, meta_b = before.GetAllMetadata(), after.GetAllMetadata()
    if "apiSchemas" in skip:  # the joint: its schemas may only gain the drive's and PhysX's
        gained = set(after.GetAppliedSchemas()) - set(before.GetAppliedSchemas())
        lost = set(before.GetAppliedSchemas()) - set(after.GetAppliedSchemas())
        if lost or not gained <= {
            s for s in after.GetAppliedSchemas() if s.startswith(("PhysicsDriveAPI", "Physx"))
        }:
            changed.append("apiSchemas")
        meta_a.pop("apiSchemas", None), meta_b.pop("apiSchemas", None)
    if not _same(meta_a, meta_b):
        changed.append("metadata")
    names_a = {a.GetName() for a in before.GetAttributes()} - skip
    # on the joint, a schema the edit applies brings its attributes' fallbacks, unauthored
    names_b = {
        a.GetName() for a in after.GetAttributes() if not skip or a.IsAuthored() or a.GetName() in names_a
    } - skip
    changed += sorted(names_a ^ names_b)
    for name in sorted(names_a & names_b):
        x, y = before.GetAttribute(name), after.GetAttribute(name)
        samples = x.GetTimeSamples()
        if not (
            _same(x.GetAllMetadata(), y.GetAllMetadata())
            and _same(x.Get(), y.Get())
            and _same(samples, y.GetTimeSamples())
            and all(_same(x.Get(t), y.Get(t)) for t in samples)
        ):
            changed.append(name)
    rels_a = {r.GetName(): r.GetTargets() for r in before.GetRelationships()}
    rels_b = {r.GetName(): r.GetTargets() for r in after.GetRelationships()}
    rels = (set(rels_a) | set(rels_b)) - skip
    changed += [name for name in sorted(rels) if rels_a.get(name) != rels_b.get(name)]
    return changed


def stage_changes(before, after, edited: dict, added: frozenset = frozenset()) -> list[str]:
    """Every difference between the robot's stage and the layered one ("prim: what"), leaving out, per
    prim path in `edited`, the attributes named there (and the drive and PhysX schemas they need), and
    the prims at the `added` paths."""
    from pxr import Usd

    changes = []
    keys = set(before.GetRootLayer().pseudoRoot.ListInfoKeys()) - OWN_FIELDS
    changes += [
        f"stage metadata {k}" for k in sorted(keys) if not _same(before.GetMetadata(k), after.GetMetadata(k))
    ]
    every = Usd.TraverseInstanceProxies(Usd.PrimAllPrimsPredicate)  # instanced content too
    paths_a = [p.GetPath() for p in Usd.PrimRange.Stage(before, every)]
    paths_b = [p.GetPath() for p in Usd.PrimRange.Stage(after, every) if p.GetPath() not in added]
    if paths_a != paths_b:
        return [*changes, "prims: " + ", ".join(str(p) for p in set(paths_a) ^ set(paths_b))]
    for p in paths_a:
        skip = edited[p] | {"apiSchemas"} if p in edited else set()
        changes += [
            f"{p}: {what}" for what in _prim_changes(before.GetPrimAtPath(p), after.GetPrimAtPath(p), skip)
        ]
    return changes
