"""Export joints as an SSP archive (System Structure and Parameterization 1.0) and read SSV files.

The archive holds `SystemStructure.ssd`: one FMI 2 co-simulation FMU component per joint (body
interface by default: input load, outputs deflection, velocity, acceleration), its connectors exposed
on the system as `<joint>_<variable>` and wired to them; per joint `resources/<joint>.fmu` and the SSV
`resources/<joint>.ssv` the SSD binds, with the joint's m, c, k in SI units declared with their base
units; and alternative parameter sets (for example a suggestion's candidates) as
`resources/<joint>.<set>.ssv` for a tool to bind instead. Element names and namespaces follow the SSP
1.0 standard and its normative XML schemas (as shipped with FMPy, which validates them on reading).

Parameter names inside an SSV are the FMU's own (`theta.k`), relative to the component it is bound to.
"""

from __future__ import annotations

import zipfile
from collections.abc import Mapping, Sequence
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .. import units
from ..errors import DesignerError, check_type
from ..files import atomic_path, check_suffix, temporary_folder
from ..joint import Joint, check_joint
from . import fmu
from .robot import with_masses

JOINTS_FIX = "give a Joint (Joint.from_coefficients, from_design, from_suggestion) or a list of Joints"

NS = {
    "ssd": "http://ssp-standard.org/SSP1/SystemStructureDescription",
    "ssc": "http://ssp-standard.org/SSP1/SystemStructureCommon",
    "ssv": "http://ssp-standard.org/SSP1/SystemStructureParameterValues",
}
_XMLNS = " ".join(f'xmlns:{p}="{u}"' for p, u in NS.items())
#: the joint coefficients an SSV carries, per axis
SSV_QUANTITIES = ("m", "c", "k")
#: the FMU parameters whose units read_ssv checks, and the quantity each is
_CHECKED = {"m": "m", "c": "c", "k": "k", "offset": "r"}


def _units(names: set[str]) -> list[str]:
    """`ssc:Unit` elements with their SI base-unit exponents (the FMU's table)."""
    lines = []
    for u in sorted(names):
        exps = fmu.BASE_UNITS[u]
        base = " ".join(f'{k}="{exps[k]}"' for k in fmu.BASE_ORDER if k in exps)
        lines.append(f"    <ssc:Unit name={quoteattr(u)}><ssc:BaseUnit {base}/></ssc:Unit>")
    return lines


def ssv_text(joint: Joint, name: str) -> str:
    """An SSV parameter set: m, c, k of every axis of `joint` in SI, named as the FMU's parameters."""
    params, used = [], set()
    for a, ac in joint.axes.items():
        si = ac.si()
        for q in SSV_QUANTITIES:
            if si[q] is None:
                continue
            unit = units.si_unit(q, a)
            used.add(unit)
            params.append(
                f'    <ssv:Parameter name="{a}.{q}"><ssv:Real value="{si[q]!r}" unit={quoteattr(unit)}/>'
                "</ssv:Parameter>"
            )
    return "\n".join(
        [
            '<?xml version="1.0" encoding="UTF-8"?>',
            f'<ssv:ParameterSet {_XMLNS} version="1.0" name={quoteattr(name)}>',
            "  <ssv:Parameters>",
            *params,
            "  </ssv:Parameters>",
            "  <ssv:Units>",
            *_units(used),
            "  </ssv:Units>",
            "</ssv:ParameterSet>",
            "",
        ]
    )


def _connectors(joint: Joint, interface: str, pad: str) -> tuple[list[str], list[tuple[str, str]], set[str]]:
    """The FMU's inputs, outputs and parameters as SSD connectors; (name, kind) of the wired ones; units."""
    lines, wired, used = [], [], set()
    for v in fmu.variables(joint, interface):
        if v.causality not in ("input", "output", "parameter"):
            continue
        unit = v.unit if v.unit in fmu.BASE_UNITS else None  # an undefined unit is left out
        if unit is not None:
            used.add(unit)
        typ = v.type.connector(unit)
        lines.append(f'{pad}<ssd:Connector name="{v.name}" kind="{v.causality}">{typ}</ssd:Connector>')
        if v.causality != "parameter":
            wired.append((v.name, v.causality, typ))
    return lines, wired, used


#: the ends of a connection between a component's connector and its system connector, by causality
SYSTEM_ENDS = {
    "input": 'startConnector="{joint}_{var}" endElement="{joint}" endConnector="{var}"',
    "output": 'startElement="{joint}" startConnector="{var}" endConnector="{joint}_{var}"',
}


def ssd_text(joints: list[Joint], interface: str, *, system_connectors: bool = False) -> str:
    """The SSD: one component per joint, bound to its SSV; with `system_connectors`, its inputs and
    outputs also exposed on the system as `<joint>_<variable>`.

    (Not `<joint>.<variable>`: fmpy.ssp names results by dotted path, where that would clash with the
    component's own connector.) A connection to a system connector has no startElement or endElement,
    as the standard allows, and libcosim refuses such an SSD ("No such node (<xmlattr>.endElement)"):
    hence off by default.
    """
    outer, elements, connections, used = [], [], [], set()
    for j in joints:
        inner, wired, u = _connectors(j, interface, "          ")
        used |= u
        for var, causality, typ in wired if system_connectors else ():
            connector = f'name="{j.name}_{var}" kind="{causality}"'
            outer.append(f"      <ssd:Connector {connector}>{typ}</ssd:Connector>")
            ends = SYSTEM_ENDS[causality].format(joint=j.name, var=var)
            connections.append(f"      <ssd:Connection {ends}/>")
        elements += [
            f'      <ssd:Component name="{j.name}" type="application/x-fmu-sharedlibrary" '
            f'source="resources/{j.name}.fmu">',
            "        <ssd:Connectors>",
            *inner,
            "        </ssd:Connectors>",
            "        <ssd:ParameterBindings>",
            f'          <ssd:ParameterBinding type="application/x-ssp-parameter-set" '
            f'source="resources/{j.name}.ssv"/>',
            "        </ssd:ParameterBindings>",
            "      </ssd:Component>",
        ]
    return "\n".join(
        [
            '<?xml version="1.0" encoding="UTF-8"?>',
            f'<ssd:SystemStructureDescription {_XMLNS} version="1.0" name="flexjoints">',
            '  <ssd:System name="flexjoints">',
            *(["    <ssd:Connectors>", *outer, "    </ssd:Connectors>"] if outer else []),
            "    <ssd:Elements>",
            *elements,
            "    </ssd:Elements>",
            *(["    <ssd:Connections>", *connections, "    </ssd:Connections>"] if connections else []),
            "  </ssd:System>",
            "  <ssd:Units>",
            *_units(used),
            "  </ssd:Units>",
            "</ssd:SystemStructureDescription>",
            "",
        ]
    )


def export_ssp(
    joints: Joint | Sequence[Joint],
    path: str | Path,
    *,
    alternatives: Mapping[str, Mapping[str, Joint]] | None = None,
    interface: str = "body",
    system_connectors: bool = False,
) -> Path:
    """Write an SSP archive at `path` (.ssp): the SSD, per joint an FMI 2 FMU and an SSV, alternatives.

    Args:
        joints: one joint or several (distinct names); each is a component `<name>` whose FMU
            (`resources/<name>.fmu`) carries its numbers as start values and whose SSV
            (`resources/<name>.ssv`) the SSD binds.
        alternatives: per joint name, named alternative parameter sets (e.g. a suggestion's candidates,
            `{"FlexJoint": {"candidate_1": joint1, ...}}`) with that joint's axes, written as
            `resources/<name>.<set>.ssv` for a tool to bind instead.
        interface: "body" (load in, motion out; needs masses, from geometry when a design) or "force".
        system_connectors: also expose each component's inputs and outputs on the system, wired by
            connections without startElement/endElement (SSP allows them; fmpy.ssp's `input=` drives
            them; libcosim cannot load them).

    Raises:
        DesignerError: a wrong suffix, repeated joint names, an alternative for no joint or with other
            axes, or a missing mass.
    """
    path = check_suffix(path, (".ssp",), what="an SSP")
    why = "the body interface needs a mass (or use interface='force')"
    if not isinstance(joints, Joint):
        check_type(joints, (list, tuple), "joints", expected="a Joint or a list of them", fix=JOINTS_FIX)
        for i, j in enumerate(joints):
            check_joint(j, f"joints[{i}]")
    joints = [joints] if isinstance(joints, Joint) else list(joints)
    if interface == "body":
        joints = [with_masses(j, why) for j in joints]
    by_name = {j.name: j for j in joints}
    if len(by_name) != len(joints):
        raise DesignerError("joints= has two joints of the same name", "give each joint its own name")
    entries = {f"resources/{j.name}.ssv": ssv_text(j, j.name).encode() for j in joints}
    for name, sets in (alternatives or {}).items():
        for set_name, other in sets.items():
            if (
                name not in by_name
                or not set_name.isidentifier()
                or list(other.axes) != list(by_name[name].axes)
            ):
                raise DesignerError(
                    f"alternatives[{name!r}][{set_name!r}] is not a parameter set of a joint given",
                    "key it by one of the joints' names, name it as an identifier, keep the joint's axes",
                )
            other = with_masses(other, why) if interface == "body" else other
            entries[f"resources/{name}.{set_name}.ssv"] = ssv_text(other, set_name).encode()
    entries["SystemStructure.ssd"] = ssd_text(joints, interface, system_connectors=system_connectors).encode()
    for j in joints:
        entries[f"resources/{j.name}.fmu"] = _fmu_bytes(j, interface)
    with atomic_path(path) as tmp, zipfile.ZipFile(tmp, "w", zipfile.ZIP_DEFLATED) as z:
        for name in sorted(entries):  # fixed dates: the same joints give the same bytes
            z.writestr(zipfile.ZipInfo(name, date_time=fmu.ZIP_DATE), entries[name], zipfile.ZIP_DEFLATED)
    return path


def candidate_sets(suggestion, *, axes: list[str] | None = None, name: str = "FlexJoint") -> dict[str, Joint]:
    """Every candidate of a suggestion (object or saved JSON) as a parameter set `candidate_<i>`.

    Raises:
        DesignerError: the suggestion cannot be read or has no candidates.
    """
    from ..design.candidates import Suggestion

    if not isinstance(suggestion, Suggestion):
        suggestion = Suggestion.load(suggestion)
    if not suggestion.candidates:
        raise DesignerError("the suggestion has no candidates", "run suggest with reachable targets")
    return {
        f"candidate_{i}": Joint.from_suggestion(suggestion, candidate=i, axes=axes, name=name)
        for i in range(1, len(suggestion.candidates) + 1)
    }


def _fmu_bytes(joint: Joint, interface: str) -> bytes:
    """The joint's FMI 2 FMU as bytes, written through `fmu.export_fmu` into a temporary folder."""
    with temporary_folder("designer-ssp-") as tmp:
        out = Path(tmp) / f"{joint.name}.fmu"
        fmu.export_fmu(joint, out, fmi_version=2, interface=interface)
        return out.read_bytes()


def read_ssv(path: str | Path) -> dict[str, float]:
    """The Real parameters of an SSV file, converted to SI: {"theta.k": 0.05, ...}.

    Units are read from each parameter's `unit` and the file's unit definitions; a joint's m, c, k and
    offset are converted to SI by their unit's factor and offset, and a unit whose base-unit exponents
    are not the quantity's is refused rather than guessed. The keys match the FMU's parameter
    names, so the result can serve as a co-simulation scenario's `parameters` overrides.

    Raises:
        DesignerError: the file is missing or not an SSV, or a unit is not the quantity's SI unit.
    """
    import xml.etree.ElementTree as ET

    path = Path(path)
    try:
        root = ET.parse(path).getroot()
    except (OSError, ET.ParseError) as exc:
        raise DesignerError(f"path={str(path)!r} cannot be read as XML: {exc}", "give an SSV file") from None
    if root.tag != f"{{{NS['ssv']}}}ParameterSet":
        raise DesignerError(f"path={str(path)!r} is not an SSV parameter set", "give an .ssv file")
    return _ssv_values(root, path)


def _ssv_values(root, path: Path) -> dict[str, float]:
    """The Real parameters of a parsed SSV, joint parameters converted to SI by their units."""
    declared = {}
    for u in root.iterfind("ssv:Units/ssc:Unit", NS):
        base = u.find("ssc:BaseUnit", NS)
        declared[u.get("name")] = {k: float(v) for k, v in (base.attrib if base is not None else {}).items()}
    out = {}
    for p in root.iterfind("ssv:Parameters/ssv:Parameter", NS):
        real = p.find("ssv:Real", NS)
        if real is None:
            continue
        name, unit = p.get("name"), real.get("unit")
        out[name] = _si_value(name, float(real.get("value")), unit, declared.get(unit), path)
    return out


def _si_value(name: str, value: float, unit: str | None, base: dict | None, path: Path) -> float:
    """`value` of joint parameter `name` ("axis.field") in SI, converted by its unit's factor and offset.

    SSP units are SI base-unit exponents with SI = factor * value + offset. A unit that is not
    declared must be the SI unit itself; one whose exponents are not the quantity's is refused.
    """
    axis, _, field = name.rpartition(".")
    if axis not in units.AXES or field not in _CHECKED or unit is None:
        return value
    si = units.si_unit(_CHECKED[field], axis)
    want = {k: float(v) for k, v in fmu.BASE_UNITS[si].items()}
    exps = dict(base) if base is not None else (want if unit == si else None)
    factor, offset = (exps.pop("factor", 1.0), exps.pop("offset", 0.0)) if exps is not None else (1.0, 0.0)
    if exps != want:
        raise DesignerError(
            f"parameter {name} in {path} has unit {unit!r}, not a unit of {si}",
            f"give {name} in {si}, or declare {unit!r} with the base units of {si} in the file",
        )
    return factor * value + offset


def bound_parameters(path: str | Path) -> dict[str, float]:
    """The parameter values an SSP's SSD binds to its components, by hierarchical name.

    Every component-level `ParameterBinding` with a `source` is read from the archive (or the folder)
    and its names made hierarchical as SSP 1.0 resolves them: the binding's `prefix` and the
    component's name before each name in the SSV (`FlexJoint.x.k`). A joint's m, c, k and offset
    are converted to SI by their declared units (as `read_ssv`). This is what `fmpy.ssp.simulate_ssp(path,
    parameter_set=...)` needs, as fmpy applies only the set it is given and not the SSD's bindings;
    `fmpy_parameter_set` wraps it.

    Raises:
        DesignerError: the archive or a bound SSV cannot be read.
    """
    import xml.etree.ElementTree as ET

    path = Path(path)
    try:
        if path.is_dir():
            read = lambda name: (path / name).read_bytes()  # noqa: E731
        else:
            archive = zipfile.ZipFile(path)
            read = archive.read
        ssd = ET.fromstring(read("SystemStructure.ssd"))
        out = {}
        for component in ssd.iterfind("ssd:System/ssd:Elements/ssd:Component", NS):
            for binding in component.iterfind("ssd:ParameterBindings/ssd:ParameterBinding", NS):
                if binding.get("source") is None:
                    continue
                ssv = ET.fromstring(read(binding.get("source")))
                prefix = f"{component.get('name')}.{binding.get('prefix', '')}"
                values = _ssv_values(ssv, path / binding.get("source"))
                out.update({prefix + name: value for name, value in values.items()})
        return out
    except (OSError, KeyError, zipfile.BadZipFile, ET.ParseError) as exc:
        raise DesignerError(
            f"path={str(path)!r} cannot be read as an SSP: {exc}", "give an .ssp archive"
        ) from None


def fmpy_parameter_set(path: str | Path):
    """`bound_parameters(path)` as an `fmpy.ssp.ssd.ParameterSet` for `fmpy.ssp.simulate_ssp`."""
    from fmpy.ssp.ssd import Parameter, ParameterSet

    ps = ParameterSet(name="bound")
    for name, value in bound_parameters(path).items():
        ps.parameters.append(Parameter(name=name, type="Real", value=value))
    return ps
