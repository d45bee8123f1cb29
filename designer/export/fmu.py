"""Export a Joint as an FMU (FMI 2.0 or 3.0, Co-Simulation and Model Exchange in one archive).

The binary is generic (see `build`); an export writes modelDescription.xml, the start values the binary
reads at instantiation (resources/start_values.txt), the provenance (resources/joint.json) and the C
sources, and zips them with fixed timestamps and order so that the same joint gives the same bytes.
"""

from __future__ import annotations

import hashlib
import json
import math
import uuid
import zipfile
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from xml.sax.saxutils import quoteattr

from .. import __version__, units
from ..errors import DesignerError
from ..files import atomic_path, check_suffix
from ..joint import AxisCoefficients, Joint, check_joint
from . import build
from .layout import layout

INTERFACES = ("force", "body")
FMI_VERSIONS = (2, 3)
GENERATOR = f"flexjoint designer {__version__}"
ZIP_DATE = (1980, 1, 1, 0, 0, 0)
_TOKEN = "@TOKEN@"


# SI units and their base-unit exponents, for UnitDefinitions
BASE_UNITS: dict[str, dict[str, int]] = {
    "s": {"s": 1},
    "m": {"m": 1},
    "rad": {"rad": 1},
    "m/s": {"m": 1, "s": -1},
    "rad/s": {"rad": 1, "s": -1},
    "m/s^2": {"m": 1, "s": -2},
    "rad/s^2": {"rad": 1, "s": -2},
    "N": {"kg": 1, "m": 1, "s": -2},
    "N.m": {"kg": 1, "m": 2, "s": -2},
    "N/m": {"kg": 1, "s": -2},
    "N.m/rad": {"kg": 1, "m": 2, "s": -2, "rad": -1},
    "N.s/m": {"kg": 1, "s": -1},
    "N.m.s/rad": {"kg": 1, "m": 2, "s": -1, "rad": -1},
    "kg": {"kg": 1},
    "kg.m^2": {"kg": 1, "m": 2},
}
BASE_ORDER = ("kg", "m", "s", "A", "K", "mol", "cd", "rad")


def value_reference(axis: str, field: str) -> int:
    """The fixed value reference of `axis.field` in every FlexJoint FMU (fmus/FlexJoint/config.h)."""
    return layout().value_reference(axis, field)


@dataclass(frozen=True)
class ValueType:
    """A variable's type as each format names it and writes its values: `fmi2` (the ScalarVariable's
    element), `fmi3` (the variable's element), `ssc` (SSP's connector type), `text` (a value as the
    model description and the binary's start values write it)."""

    fmi2: str
    fmi3: str
    ssc: str
    text: Callable[[float | bool], str]

    def connector(self, unit: str | None) -> str:
        """The SSP connector type, `<ssc:Real unit="N.m"/>` (`unit` None: none declared)."""
        return f"<ssc:{self.ssc}/>" if unit is None else f"<ssc:{self.ssc} unit={quoteattr(unit)}/>"


REAL = ValueType("Real", "Float64", "Real", lambda v: repr(float(v)))
BOOLEAN = ValueType("Boolean", "Boolean", "Boolean", lambda v: "true" if v else "false")


@dataclass(frozen=True)
class Variable:
    """One model variable as both FMI versions declare it (a Boolean has no unit and no derivative)."""

    name: str
    vr: int
    type: ValueType
    causality: str
    variability: str
    description: str
    start: float | bool | None = None
    unit: str | None = None
    initial: str | None = None
    derivative_of: str | None = None  # name of the state this variable is the derivative of
    depends_on: tuple[str, ...] | None = None  # for Outputs and derivatives: inputs and states
    parameters: tuple[str, ...] = ()  # the tunable parameters it depends on (FMI 3 dependencies)


def _pi_text(ac: AxisCoefficients, quantity: str) -> str:
    """The 95 % PI of a predicted coefficient in SI, for the variable's description."""
    pred, axis = ac.predicted.get(quantity), ac.axis
    if pred is None:
        return ""
    lo, hi = (units.to_si(quantity, axis, v) for v in (pred.low, pred.high))
    return f", 95 % PI {lo:.4g} to {hi:.4g} {units.si_unit(quantity, axis)}"


def _var(axis: str, field: str, *args, **kw) -> Variable:
    """The variable `axis.field` with its fixed value reference."""
    return Variable(f"{axis}.{field}", value_reference(axis, field), *args, **kw)


def _parameter_variables(a: str, ac: AxisCoefficients) -> list[Variable]:
    """The tunable parameters of axis `a`: m (if known), c, k, offset, enabled."""
    si = ac.si()
    rot = units.is_rotational(a)
    out: list[Variable] = []

    def var(field: str, *args, **kw) -> Variable:
        return _var(a, field, *args, **kw)

    what = {
        "m": f"{'inertia' if rot else 'mass'} on {a}; {ac.origin}",
        "c": f"damping on {a}; {ac.origin}" + _pi_text(ac, "c"),
        "k": f"stiffness on {a}; {ac.origin}" + _pi_text(ac, "k"),
    }
    for q, text in what.items():
        if si[q] is not None:
            out.append(var(q, REAL, "parameter", "tunable", text, si[q], units.si_unit(q, a)))
    r = units.si_unit("r", a)
    out.append(var("offset", REAL, "parameter", "tunable", f"rest position on {a}", 0.0, r))
    out.append(var("enabled", BOOLEAN, "parameter", "tunable", f"spring-damper on {a} active", True))
    return out


def _io_variables(a: str, interface: str) -> list[Variable]:
    """Inputs, outputs and states of axis `a` for the force or the body interface."""
    r, f = units.si_unit("r", a), units.si_unit("F", a)
    rot = units.is_rotational(a)
    what = "torque" if rot else "force"
    out: list[Variable] = []

    def var(field: str, *args, **kw) -> Variable:
        return _var(a, field, *args, **kw)

    if interface == "force":
        out.append(
            var(
                "s",
                REAL,
                "input",
                "continuous",
                f"relative {'angle' if rot else 'displacement'}",
                0.0,
                r,
            )
        )
        out.append(var("v", REAL, "input", "continuous", "relative velocity", 0.0, f"{r}/s"))
        out.append(
            var(
                "f",
                REAL,
                "output",
                "continuous",
                f"{what} of the joint, -(k (s - offset) + c v)",
                unit=f,
                depends_on=(f"{a}.s", f"{a}.v"),
                parameters=(f"{a}.c", f"{a}.k", f"{a}.offset", f"{a}.enabled"),
            )
        )
    else:
        out.append(
            var(
                "s",
                REAL,
                "output",
                "continuous",
                f"{'angle' if rot else 'displacement'} (state)",
                0.0,
                r,
                "exact",
                depends_on=(f"{a}.s",),
            )
        )
        out.append(
            var(
                "v",
                REAL,
                "output",
                "continuous",
                "velocity (state), der(s)",
                0.0,
                f"{r}/s",
                "exact",
                derivative_of=f"{a}.s",
                depends_on=(f"{a}.v",),
            )
        )
        out.append(var("f", REAL, "input", "continuous", f"load {what} on the body", 0.0, f))
        out.append(
            var(
                "a",
                REAL,
                "output",
                "continuous",
                "acceleration, der(v)",
                unit=f"{r}/s^2",
                derivative_of=f"{a}.v",
                depends_on=(f"{a}.s", f"{a}.v", f"{a}.f"),
                parameters=(f"{a}.m", f"{a}.c", f"{a}.k", f"{a}.offset", f"{a}.enabled"),
            )
        )
    return out


def variables(joint: Joint, interface: str) -> list[Variable]:
    """Every model variable of the joint: time, then per declared axis its parameters and I/O."""
    out = [Variable("time", 0, REAL, "independent", "continuous", "simulation time", unit="s")]
    for a in units.AXES:
        if a in joint.axes:
            out += _parameter_variables(a, joint.axes[a]) + _io_variables(a, interface)
    return out


def _start(v: Variable) -> str:
    if v.start is None:
        return ""
    return f' start="{v.type.text(v.start)}"'


def _unit_definitions(variables: list[Variable]) -> list[str]:
    lines = ["  <UnitDefinitions>"]
    for u in sorted({v.unit for v in variables if v.unit}):
        base = " ".join(f'{k}="{BASE_UNITS[u][k]}"' for k in BASE_ORDER if k in BASE_UNITS[u])
        lines += [f"    <Unit name={quoteattr(u)}>", f"      <BaseUnit {base}/>", "    </Unit>"]
    return lines + ["  </UnitDefinitions>"]


def _log_categories() -> list[str]:
    """The categories the runtime logs in (runtime/instance.c setLogCategory)."""
    return [
        "  <LogCategories>",
        '    <Category name="logEvents" description="life-cycle events"/>',
        '    <Category name="logStatusDiscard" description="calls answered with Discard"/>',
        '    <Category name="logStatusError" description="errors"/>',
        "  </LogCategories>",
    ]


def _default_experiment(joint: Joint, interface: str) -> str:
    """A run long enough to settle and a step resolving the fastest axis (body), else 1 s at 1 ms."""
    stop, step = 1.0, 1e-3
    if interface == "body":
        settle, period = [], []
        for ac in joint.axes.values():
            si = ac.si()
            wn = math.sqrt(si["k"] / si["m"])
            decay = si["c"] / (2 * si["m"])
            settle.append(8.0 / decay if decay > 0 else 20 * 2 * math.pi / wn)
            period.append(2 * math.pi / wn)
        stop = float(f"{max(settle):.1g}")
        step = float(f"{min(period) / 100:.1g}")
    return f'  <DefaultExperiment startTime="0.0" stopTime="{REAL.text(stop)}" stepSize="{REAL.text(step)}"/>'


def _description(joint: Joint, interface: str) -> str:
    prov = joint.provenance
    parts = [f"3D-printed TPU flexible joint '{joint.name}', {interface} interface"]
    if "params" in prov:
        parts.append("print settings " + ", ".join(f"{k} {v:g}" for k, v in prov["params"].items()))
    if "surrogate" in prov:
        parts.append(f"surrogate {prov['surrogate']}")
    parts.append("coefficients " + str(prov.get("source", "entered by hand")))
    return "; ".join(parts) + " (details in resources/joint.json)"


def _fmi2_description(joint: Joint, interface: str, variables: list[Variable]) -> str:
    # FMI 2 makes "time" implicit and forbids a start on an explicit independent variable, which the
    # FMI Library in libcosim then reports as a missing start (its issue #21): leave it out
    variables = [v for v in variables if v.causality != "independent"]
    index = {v.name: i + 1 for i, v in enumerate(variables)}
    sources = "\n".join(f'      <File name="{Path(p).name}"/>' for p in build.c_sources(2))
    lay = layout()
    caps = (
        f'canGetAndSetFMUstate="{lay.flag("CAN_GET_AND_SET_FMU_STATE")}" '
        f'canSerializeFMUstate="{lay.flag("CAN_SERIALIZE_FMU_STATE")}" '
        f'providesDirectionalDerivative="{lay.flag("PROVIDES_DIRECTIONAL_DERIVATIVES")}" '
        'canNotUseMemoryManagementFunctions="true"'
    )
    not_needed = "false" if lay.capabilities["NEEDS_COMPLETED_INTEGRATOR_STEP"] else "true"
    variable_step = lay.flag("CAN_HANDLE_VARIABLE_COMMUNICATION_STEP_SIZE")
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<fmiModelDescription fmiVersion="2.0" modelName={quoteattr(joint.name)} guid="{_TOKEN}"',
        f"  description={quoteattr(_description(joint, interface))}",
        f'  generationTool="{GENERATOR}" variableNamingConvention="structured" '
        f'numberOfEventIndicators="{lay.capabilities["N_EVENT_INDICATORS"]}">',
        f'  <ModelExchange modelIdentifier="{lay.model_identifier}" {caps} '
        f'completedIntegratorStepNotNeeded="{not_needed}">',
        f"    <SourceFiles>\n{sources}\n    </SourceFiles>",
        "  </ModelExchange>",
        f'  <CoSimulation modelIdentifier="{lay.model_identifier}" {caps} '
        f'canHandleVariableCommunicationStepSize="{variable_step}">',
        f"    <SourceFiles>\n{sources}\n    </SourceFiles>",
        "  </CoSimulation>",
        *_unit_definitions(variables),
        *_log_categories(),
        _default_experiment(joint, interface),
        "  <ModelVariables>",
    ]
    for i, v in enumerate(variables, 1):
        attrs = [
            f"name={quoteattr(v.name)}",
            f'valueReference="{v.vr}"',
            f"description={quoteattr(v.description)}",
            f'causality="{v.causality}"',
            f'variability="{v.variability}"',
        ]
        if v.initial:
            attrs.append(f'initial="{v.initial}"')
        inner = [_start(v).strip()] if v.start is not None else []
        if v.unit:
            inner.insert(0, f"unit={quoteattr(v.unit)}")
        if v.derivative_of:
            inner.append(f'derivative="{index[v.derivative_of]}"')
        lines.append(f"    <!-- index {i} -->")
        lines.append(f"    <ScalarVariable {' '.join(attrs)}>")
        lines.append(f"      <{v.type.fmi2} {' '.join(inner)}/>".replace(" />", "/>"))
        lines.append("    </ScalarVariable>")
    lines += ["  </ModelVariables>", "  <ModelStructure>"]

    def unknown(v: Variable, deps: bool = True) -> str:
        d = (
            f' dependencies="{" ".join(str(index[n]) for n in v.depends_on)}"'
            if deps and v.depends_on
            else ""
        )
        return f'      <Unknown index="{index[v.name]}"{d}/>'

    outputs = [v for v in variables if v.causality == "output"]
    derivatives = [v for v in variables if v.derivative_of]
    initial = [v for v in variables if v.causality == "output" and v.initial is None]
    for tag, group, deps in (
        ("Outputs", outputs, True),
        ("Derivatives", derivatives, True),
        ("InitialUnknowns", initial, False),
    ):
        if group:
            lines += [f"    <{tag}>", *(unknown(v, deps) for v in group), f"    </{tag}>"]
    lines += ["  </ModelStructure>", "</fmiModelDescription>", ""]
    return "\n".join(lines)


def _fmi3_description(joint: Joint, interface: str, variables: list[Variable]) -> str:
    vr = {v.name: v.vr for v in variables}
    lay = layout()
    caps = (
        f'canGetAndSetFMUState="{lay.flag("CAN_GET_AND_SET_FMU_STATE")}" '
        f'canSerializeFMUState="{lay.flag("CAN_SERIALIZE_FMU_STATE")}" '
        f'providesDirectionalDerivatives="{lay.flag("PROVIDES_DIRECTIONAL_DERIVATIVES")}" '
        f'providesAdjointDerivatives="{lay.flag("PROVIDES_ADJOINT_DERIVATIVES")}"'
    )
    lines = [
        '<?xml version="1.0" encoding="UTF-8"?>',
        f'<fmiModelDescription fmiVersion="3.0" modelName={quoteattr(joint.name)}',
        f'  instantiationToken="{_TOKEN}"',
        f"  description={quoteattr(_description(joint, interface))}",
        f'  generationTool="{GENERATOR}" variableNamingConvention="structured">',
        f'  <ModelExchange modelIdentifier="{lay.model_identifier}" {caps} '
        f'needsCompletedIntegratorStep="{lay.flag("NEEDS_COMPLETED_INTEGRATOR_STEP")}"/>',
        f'  <CoSimulation modelIdentifier="{lay.model_identifier}" {caps} '
        f'canHandleVariableCommunicationStepSize="{lay.flag("CAN_HANDLE_VARIABLE_COMMUNICATION_STEP_SIZE")}" '
        f'hasEventMode="{lay.flag("HAS_EVENT_MODE")}"/>',
        *_unit_definitions(variables),
        *_log_categories(),
        _default_experiment(joint, interface),
        "  <ModelVariables>",
    ]
    for v in variables:
        attrs = [
            f"name={quoteattr(v.name)}",
            f'valueReference="{v.vr}"',
            f"description={quoteattr(v.description)}",
            f'causality="{v.causality}"',
            f'variability="{v.variability}"',
        ]
        if v.initial:
            attrs.append(f'initial="{v.initial}"')
        if v.start is not None:
            attrs.append(_start(v).strip())
        if v.unit:
            attrs.append(f"unit={quoteattr(v.unit)}")
        if v.derivative_of:
            attrs.append(f'derivative="{vr[v.derivative_of]}"')
        lines.append(f"    <{v.type.fmi3} {' '.join(attrs)}/>")
    lines += ["  </ModelVariables>", "  <ModelStructure>"]

    def unknown(tag: str, v: Variable, deps: bool = True) -> str:
        # FMI 3 dependencies include the tunable parameters an unknown depends on (leaving them out
        # would declare those partial derivatives identically zero)
        known = sorted(vr[n] for n in (*(v.depends_on or ()), *v.parameters) if n in vr)
        d = f' dependencies="{" ".join(map(str, known))}"' if deps and v.depends_on else ""
        return f'    <{tag} valueReference="{v.vr}"{d}/>'

    lines += [unknown("Output", v) for v in variables if v.causality == "output"]
    lines += [unknown("ContinuousStateDerivative", v) for v in variables if v.derivative_of]
    lines += [
        unknown("InitialUnknown", v, False)
        for v in variables
        if v.causality == "output" and v.initial is None
    ]
    lines += ["  </ModelStructure>", "</fmiModelDescription>", ""]
    return "\n".join(lines)


def _build_description() -> str:
    files = "\n".join(f'        <SourceFile name="{Path(p).name}"/>' for p in build.c_sources(3))
    return "\n".join(
        [
            '<?xml version="1.0" encoding="UTF-8"?>',
            '<fmiBuildDescription fmiVersion="3.0">',
            f'  <BuildConfiguration modelIdentifier="{layout().model_identifier}">',
            '    <SourceFileSet language="C99">',
            files,
            "    </SourceFileSet>",
            '    <Library name="m"/>',
            "  </BuildConfiguration>",
            "</fmiBuildDescription>",
            "",
        ]
    )


def _start_values(joint: Joint, interface: str, variables: list[Variable]) -> str:
    lines = [
        "# FlexJoint start values, read by the FMU binary when it is instantiated (SI units)",
        f"token {_TOKEN}",
        f"interface {interface}",
        *(f"axis {a}" for a in units.AXES if a in joint.axes),
    ]
    for v in variables:
        if v.start is None or v.causality == "independent":
            continue
        lines.append(f"{v.name} {v.type.text(v.start)}")
    return "\n".join(lines) + "\n"


def _check(joint: Joint, fmi_version: int, interface: str) -> None:
    if isinstance(fmi_version, bool) or not isinstance(fmi_version, int) or fmi_version not in FMI_VERSIONS:
        raise DesignerError(f"fmi_version={fmi_version!r} is not supported", "use fmi_version=2 or 3")
    if not isinstance(interface, str) or interface not in INTERFACES:
        raise DesignerError(f"interface={interface!r} is not an interface", "use interface='force' or 'body'")
    if interface == "body":
        missing = [a for a, ac in joint.axes.items() if ac.m is None]
        if missing:
            raise DesignerError(
                f"the body interface needs a mass, and axis {', '.join(missing)} has none",
                "give each axis an m in kg (kg.m^2 for a rotational axis), or build the joint with "
                "Joint.from_design so its mass follows from its geometry",
            )


def archive_entries(
    joint: Joint,
    fmi_version: int = 2,
    interface: str = "force",
    source_only: bool = False,
    platforms: str | Sequence[str] = "all",
    rebuild: bool = False,
) -> dict[str, bytes]:
    """The files of the FMU archive, by name in the archive; binaries for `platforms` (see
    `build.resolve_platforms`: "all", "host" or FMI 3 platform tuples) unless `source_only`, the
    shipped ones unless the sources changed or `rebuild` (see `build.build_binary`)."""
    _check(joint, fmi_version, interface)
    model_variables = variables(joint, interface)
    describe = _fmi2_description if fmi_version == 2 else _fmi3_description
    description = describe(joint, interface, model_variables)
    start = _start_values(joint, interface, model_variables)
    provenance = {
        "generator": GENERATOR,
        "fmi_version": f"{fmi_version}.0",
        "interface": interface,
        "joint": joint.to_dict(),
        "value_references": {v.name: v.vr for v in model_variables},
    }
    info = json.dumps(provenance, indent=2, sort_keys=True, default=str) + "\n"
    digest = hashlib.sha256("\0".join((description, start, info)).encode()).digest()
    token = "{" + str(uuid.UUID(bytes=digest[:16], version=5)) + "}"
    entries = {
        "modelDescription.xml": description.replace(_TOKEN, token).encode(),
        "resources/start_values.txt": start.replace(_TOKEN, token).encode(),
        "resources/joint.json": info.encode(),
    }
    root = build.source_dir()
    for rel in build.source_files(fmi_version):
        entries[f"sources/{Path(rel).name}"] = (root / rel).read_bytes()
    if fmi_version == 3:
        entries["sources/buildDescription.xml"] = _build_description().encode()
    if not source_only:
        for platform in build.resolve_platforms(platforms):
            folder, name = build.platform_folder(fmi_version, platform), build.library_name(platform)
            entries[f"binaries/{folder}/{name}"] = build.build_binary(
                fmi_version, platform, rebuild=rebuild
            ).read_bytes()
    return entries


def export_fmu(
    joint: Joint,
    path: str | Path,
    fmi_version: int = 2,
    interface: str = "force",
    source_only: bool = False,
    progress: Callable[[float], None] | None = None,
    platforms: str | Sequence[str] = "all",
    rebuild: bool = False,
) -> Path:
    """Write `joint` as an FMU at `path` (atomically); the same joint always gives the same bytes.

    `platforms`: "all" (the default: linux, windows and macOS on x86_64 and aarch64 as build.PLATFORMS
    lists), "host" (this machine) or a list of FMI 3 platform tuples. The package ships these binaries
    prebuilt; they are compiled only when the C sources were edited or `rebuild` is set (the host's
    with the system C compiler, the others with the `build` extra's Zig; build.needs_compiling says
    which will be).

    Raises:
        DesignerError: bad arguments, or a binary that cannot be built.
    """
    path = check_suffix(path, (".fmu",), what="an FMU")
    check_joint(joint)
    entries = archive_entries(joint, fmi_version, interface, source_only, platforms, rebuild)
    if progress:
        progress(0.5)
    with atomic_path(path) as tmp, zipfile.ZipFile(tmp, "w") as z:
        for name in sorted(entries):
            info = zipfile.ZipInfo(name, date_time=ZIP_DATE)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = (0o755 if name.startswith("binaries/") else 0o644) << 16
            info.create_system = 3
            z.writestr(info, entries[name])
    if progress:
        progress(1.0)
    return path
