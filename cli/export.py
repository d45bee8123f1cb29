"""`designer export fmu|modelica|mjcf|urdf|sdf|usd|ssp`: a joint for simulators.

The joint comes from numbers, a design or a suggestion.
"""

from __future__ import annotations

import inspect
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Annotated, Any

import typer
from rich.markup import escape

from designer.errors import DesignerError

from .common import (
    SurrogateOpt,
    Typer,
    console,
    err_console,
    finishing,
    flag_message,
    load_surrogate,
    print_json,
    progress,
)

export_app = Typer(
    help="Export a joint: FMU (FMI 2/3), Modelica, MJCF, URDF, SDF, USD or SSP.", no_args_is_help=True
)


def _floats(text: str) -> Any:
    """A repeatable coefficient option (one value per --axis), rig units, with its help."""
    return Annotated[list[float] | None, typer.Option(show_default=False, help=text)]  # noqa: UP007


def _number(text: str) -> Any:
    """A print-setting option with its help (the study's units and tested range)."""
    return Annotated[float | None, typer.Option(show_default=False, help=text)]  # noqa: UP007


K = _floats("stiffness k per --axis: N/mm (N.mm/rad rotational)")
C = _floats("damping c per --axis: N.s/mm (N.mm.s/rad rotational)")
M = _floats("moving mass m per --axis: kg (kg.m^2 rotational)")
DENSITY = _number("infill density, % (20-100): predict k and c from the print settings")
LENGTH = _number("length, mm (18-30)")
WIDTH = _number("width, mm (2-7)")
HEIGHT = _number("height, mm (4-14)")
LAYER = _number("layer thickness, mm (0.12, 0.16 or 0.2)")
RASTER = _number("raster angle, deg (0 or 45)")


def _joint(axis, k, c, m, design, from_, candidate, name, allow_extrapolation, surrogate=None):
    """The joint from exactly one source: --k/--c numbers, a design (the six factors given, None where
    not; predicted by --surrogate or the shipped surrogate) or --from."""
    from designer.joint import from_one_source

    design = {n: v for n, v in design.items() if v is not None}
    coefficients = None
    if k or c or m:
        axes = axis or ["x"]
        if len(k or []) != len(axes) or len(c or []) != len(axes) or len(m or []) not in (0, len(axes)):
            raise DesignerError(
                f"{len(axes)} axis/axes but {len(k or [])} --k, {len(c or [])} --c and {len(m or [])} --m",
                "give one --k and one --c per --axis (and one --m per axis, or none), in the same order",
            )
        if len(set(axes)) != len(axes):
            raise DesignerError(f"an axis is given twice in --axis {' '.join(axes)}", "give each --axis once")
        coefficients = {a: {"k": k[i], "c": c[i]} | ({"m": m[i]} if m else {}) for i, a in enumerate(axes)}
    sources = [n for n, v in (("--k/--c", coefficients), ("a design", design), ("--from", from_)) if v]
    if len(sources) != 1:
        raise DesignerError(
            "give the joint one way: " + ("none given" if not sources else f"got {' and '.join(sources)}"),
            "use --k and --c (rig units, N/mm and N.s/mm), or the six print settings --density ... --raster, "
            "or --from suggestion.json",
        )
    if surrogate is not None and not design:
        raise DesignerError(
            "--surrogate predicts a joint from a design, and none is given",
            "give the six print settings --density ... --raster with it, or leave --surrogate out: "
            "--k/--c are the joint's own numbers, --from carries its suggestion's predictions",
        )
    return from_one_source(
        coefficients=coefficients,
        design=design or None,
        suggestion=from_,
        candidate=candidate,
        axes=None if coefficients else axis or (None if from_ else ["x"]),
        name=name,
        allow_extrapolation=allow_extrapolation,
        surrogate=None if surrogate is None else load_surrogate(surrogate),
    )


def _print_joint(joint, what: str, path: Path) -> None:
    from designer import units

    console.print(
        f"wrote {what} [bold]{escape(str(path))}[/bold] for joint '{escape(joint.name)}'", markup=True
    )
    for a, ac in joint.axes.items():
        si = ac.si()
        mass = "" if si["m"] is None else f", m = {si['m']:.4g} {units.si_unit('m', a)}"
        console.print(
            f"  {a}: k = {si['k']:.4g} {units.si_unit('k', a)}, c = {si['c']:.4g} "
            f"{units.si_unit('c', a)}{mass}  ({ac.origin})"
        )


Platforms = Annotated[
    str | None,  # noqa: UP007
    typer.Option(
        help="binaries for: all, host, or a comma list of x86_64-linux, aarch64-linux, "
        "x86_64-windows, x86_64-darwin, aarch64-darwin (default: all)"
    ),
]

JOINT_HELP = "rig units: --k N/mm (N.mm/rad), --c N.s/mm (N.mm.s/rad), --m kg (kg.m^2)"


def _snippet(
    fmt: str, suffix: str, title: str, write: Callable[..., object], example: str, extra: tuple = ()
) -> None:
    """Add `export FMT`: the joint options, `extra` options (inspect.Parameters) passed to `write`.

    `write(joint, output, (suggestion path, candidate) or None, **extra)` writes and returns the
    path or a result with `advice`.
    """

    def command(
        output: Annotated[Path, typer.Option("-o", "--output", help="the file to write")] = Path(
            f"joint{suffix}"
        ),
        axis: Annotated[
            list[str] | None, typer.Option(help="x y z theta phi psi; repeat for several")
        ] = None,  # noqa: UP007
        k: K = None,
        c: C = None,
        m: M = None,
        density: DENSITY = None,
        length: LENGTH = None,
        width: WIDTH = None,
        height: HEIGHT = None,
        layer: LAYER = None,
        raster: RASTER = None,
        from_: Annotated[
            Path | None, typer.Option("--from", help="output of designer suggest --json")
        ] = None,  # noqa: UP007
        candidate: Annotated[int, typer.Option(help="candidate in --from, 1 = best")] = 1,
        name: Annotated[str, typer.Option(help="joint (model) name")] = "FlexJoint",
        allow_extrapolation: Annotated[bool, typer.Option(help="accept a design outside the ranges")] = False,
        surrogate: SurrogateOpt = None,
        json_out: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
        **options,
    ) -> None:
        from designer.files import check_output

        check_output(output)  # folder, writability, space; the writer checks its suffix
        design = {"density": density, "length": length, "width": width, "height": height}
        design |= {"layer": layer, "raster": raster}
        joint = _joint(axis, k, c, m, design, from_, candidate, name, allow_extrapolation, surrogate)
        result = write(joint, output, (from_, candidate) if from_ else None, **options)
        finishing()
        advice = getattr(result, "advice", {})
        if json_out:
            written = result.to_dict() if hasattr(result, "to_dict") else {"path": str(result)}
            print_json({"format": fmt, "joint": joint.to_dict()} | written)
            return
        _print_joint(joint, title.format(**options), output)
        for n, a in advice.items():
            console.print(f"  {n}: {a.text()}")
        for line in getattr(result, "notes", ()):
            console.print(f"  {flag_message(line)}")

    command.__doc__ = (
        f"Write the joint as {title.format(fmi='2|3', interface='force|body')}, SI units, "
        "provenance inside.\n\n"
        f"The joint comes from --k/--c [--m] ({JOINT_HELP}), the six print settings, or --from.\n\n"
        f"Example: {example}"
    )
    signature = inspect.signature(command, eval_str=True)  # typer reads a __signature__ as it is
    params = [p for p in signature.parameters.values() if p.kind is not p.VAR_KEYWORD]
    command.__signature__ = signature.replace(parameters=[*params, *extra])
    export_app.command(fmt)(command)


def register(app: typer.Typer) -> None:
    """Add the `export` command group to the app."""
    _formats(_snippet)
    app.add_typer(export_app, name="export")


#: where the joint came from when it is a suggestion's candidate: (suggestion file, candidate), else None
Source = tuple[Path, int] | None  # noqa: UP007

if TYPE_CHECKING:
    from designer.joint import Joint


def _option(name: str, annotation: object, default: object) -> inspect.Parameter:
    """A keyword-only typer option for `_snippet`'s `extra`."""
    return inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=annotation)


INTO = _option(
    "into",
    Annotated[Path | None, typer.Option(help="the robot file to copy with --joint made flexible")],  # noqa: UP007
    None,
)
ROBOT_JOINT = _option("joint_name", Annotated[str | None, typer.Option("--joint", help="robot joint")], None)
REST = _option(
    "rest",
    Annotated[
        float | None,  # noqa: UP007
        typer.Option(help="spring rest position, rad or m (the joint's qpos; --into: default the host's)"),
    ],
    None,
)
AXIS_PICK = _option(
    "axis_pick", Annotated[str | None, typer.Option("--use-axis", help="joint axis to use")], None
)


def _mjcf(joint: Joint, output: Path, _from: Source, *, axis_pick: str | None, **options):
    """MJCF standalone or --into a robot; the CLI's --use-axis is the writer's `axis`."""
    from designer.export.mjcf import export_mjcf

    return export_mjcf(joint, output, axis=axis_pick, **options)


def _usd(joint: Joint, output: Path, _from: Source, *, axis_pick: str | None, **options):
    """USD standalone or --into a robot (a layer over it); the CLI's --use-axis is the writer's `axis`."""
    from designer.export.usd import export_usd

    return export_usd(joint, output, axis=axis_pick, **options)


def package_paths(items: list[str] | None) -> dict[str, Path]:
    """`--package-path NAME=DIR` options as {NAME: DIR}.

    Raises:
        DesignerError: an item without NAME=DIR.
    """
    out = {}
    for item in items or []:
        name, sep, folder = item.partition("=")
        if not (sep and name.strip() and folder.strip()):
            raise DesignerError(
                f"--package-path {item!r} is not NAME=DIR",
                "give the package's name and its folder, e.g. --package-path example-robot-data=/opt/erd",
            )
        out[name.strip()] = Path(folder.strip())
    return out


def _urdf(
    joint: Joint,
    output: Path,
    _from: Source,
    *,
    axis_pick: str | None,
    package_path: list[str] | None,
    **options,
):
    """URDF standalone or --into a robot; the CLI's --use-axis is the writer's `axis`."""
    from designer.export.urdf import export_urdf

    return export_urdf(joint, output, axis=axis_pick, package_paths=package_paths(package_path), **options)


def _sdf(joint: Joint, output: Path, _from: Source):
    from designer.export.urdf import export_sdf

    return export_sdf(joint, output)


@dataclass(frozen=True)
class _FmuWritten:
    """What `export fmu` wrote: for --json and the lines printed under the joint."""

    path: Path
    fmi_version: int
    interface: str
    source_only: bool
    platforms: list[str]

    def to_dict(self) -> dict:
        return {
            "path": str(self.path),
            "fmi_version": self.fmi_version,
            "interface": self.interface,
            "source_only": self.source_only,
            "platforms": self.platforms,
        }

    @property
    def notes(self) -> list[str]:
        if self.source_only:
            return [f"no binary: build it from sources/ with 'python -m fmpy compile {self.path}'"]
        return ["binaries: " + ", ".join(self.platforms)]


def _fmu(
    joint: Joint,
    output: Path,
    _from: Source,
    *,
    fmi: int,
    interface: str,
    source_only: bool,
    platforms: str | None,
    build_binaries: bool,
) -> _FmuWritten:
    """The FMU (co-simulation and model exchange) with the shipped binaries for the chosen platforms,
    compiled instead when the C sources were edited or --build asks."""
    from designer.export import build
    from designer.export.fmu import FMI_VERSIONS, export_fmu

    platforms = platforms or "all"
    checked = not source_only and fmi in FMI_VERSIONS  # export_fmu reports a bad --fmi
    compiling = build.needs_compiling(fmi, platforms, rebuild=build_binaries) if checked else []
    if compiling:
        why = "--build" if build_binaries else "the C sources differ from the shipped binaries'"
        err_console.print(
            f"compiling the FMU binary for {', '.join(compiling)} ({why}); "
            "a first Windows build takes minutes"
        )
    with progress("exporting FMU") as tick:
        path = export_fmu(
            joint,
            output,
            fmi_version=fmi,
            interface=interface,
            source_only=source_only,
            progress=tick,
            platforms=platforms,
            rebuild=build_binaries,
        )
    built = [] if source_only else build.resolve_platforms(platforms)
    return _FmuWritten(path, fmi, interface, source_only, built)


FMU_OPTIONS = (
    _option("fmi", Annotated[int, typer.Option("--fmi", help="FMI version, 2 or 3")], 2),
    _option("interface", Annotated[str, typer.Option(help="force (element) or body")], "force"),
    _option(
        "source_only", Annotated[bool, typer.Option("--source-only", help="no binary: sources/ only")], False
    ),
    _option("platforms", Platforms, None),
    _option(
        "build_binaries",
        Annotated[
            bool,
            typer.Option(
                "--build",
                help="compile the binaries (Zig, the build extra) instead of copying the shipped ones",
            ),
        ],
        False,
    ),
)


def _ssp(joint: Joint, output: Path, suggestion: Source, *, interface: str, system_connectors: bool) -> Path:
    """The SSP archive; from a suggestion, every candidate becomes an SSV parameter set."""
    from designer.export.ssp import candidate_sets, export_ssp

    sets = None
    if suggestion is not None:
        sets = {joint.name: candidate_sets(suggestion[0], axes=list(joint.axes), name=joint.name)}
    return export_ssp(
        joint, output, alternatives=sets, interface=interface, system_connectors=system_connectors
    )


OUTSIDE_RANGE = _option(
    "allow_outside_range",
    Annotated[bool, typer.Option(help="accept a --rest outside the robot joint's range")],
    False,
)
PACKAGE_PATH = _option(
    "package_path",
    Annotated[
        list[str] | None,  # noqa: UP007
        typer.Option(
            "--package-path",
            help="NAME=DIR: the folder of a package the robot's package://NAME/ file names use (repeat)",
        ),
    ],
    None,
)
#: the options of `export mjcf` beyond the joint's: where it goes in a robot and how
MJCF_OPTIONS = (
    INTO,
    ROBOT_JOINT,
    REST,
    AXIS_PICK,
    _option("form", Annotated[str, typer.Option(help="parallel or series (motor -> flexure)")], "parallel"),
    _option("motor_inertia", Annotated[float | None, typer.Option(help="series: SI")], None),  # noqa: UP007
    _option("motor_bandwidth", Annotated[float | None, typer.Option(help="series: servo Hz")], None),  # noqa: UP007
    OUTSIDE_RANGE,
)
#: the options of `export ssp` beyond the joint's
SSP_OPTIONS = (
    _option("interface", Annotated[str, typer.Option(help="body (load in) or force")], "body"),
    _option(
        "system_connectors",
        Annotated[
            bool,
            typer.Option(
                "--system-connectors",
                help="also wire each joint's inputs and outputs to the system's connectors (for "
                "fmpy.ssp; libcosim cannot load such connections)",
            ),
        ],
        False,
    ),
)


def _formats(snippet: Callable[..., None]) -> None:
    """The robot and Modelica sub-commands of `export`, each with its own options."""
    from designer.export.modelica import export_modelica

    snippet(
        "fmu",
        ".fmu",
        "an FMI {fmi} FMU ({interface} interface; co-simulation and model exchange)",
        _fmu,
        "designer export fmu --k 0.8 --c 2e-3 --m 0.01 --interface body --fmi 3 -o joint.fmu",
        FMU_OPTIONS,
    )
    snippet(
        "modelica",
        ".mo",
        "a Modelica package (MSL SpringDamper, Mass/Inertia)",
        lambda joint, output, _from, msl: export_modelica(joint, output, msl=msl),
        "designer export modelica --k 0.8 --c 2e-3 --m 0.01 --msl 3.2.3 -o joint.mo",
        (_option("msl", Annotated[str, typer.Option(help="MSL version: 4.0.0 or 3.2.3")], "4.0.0"),),
    )
    snippet(
        "mjcf",
        ".xml",
        "an MJCF model (joint stiffness, damping; real link inertia)",
        _mjcf,
        "designer export mjcf --k 50 --c 0.5 --m 1e-5 --axis theta --into robot.xml --joint elbow "
        "-o robot_flex.xml",
        MJCF_OPTIONS,
    )
    snippet(
        "urdf",
        ".urdf",
        "a URDF chain (damping; spring in a <gazebo reference> extension)",
        _urdf,
        "designer export urdf --k 50 --c 0.5 --m 1e-5 --axis theta -o joint.urdf",
        (INTO, ROBOT_JOINT, REST, AXIS_PICK, OUTSIDE_RANGE, PACKAGE_PATH),
    )
    snippet(
        "usd",
        ".usda",
        "an OpenUSD joint (UsdPhysics drive: stiffness, damping, targetPosition; PhysX armature)",
        _usd,
        "designer export usd --k 50 --c 0.5 --m 1e-5 --axis theta --into robot.usda --joint elbow "
        "-o robot_flex.usda",
        MJCF_OPTIONS,
    )
    snippet(
        "sdf",
        ".sdf",
        "an SDFormat model (spring_stiffness, spring_reference, damping)",
        _sdf,
        "designer export sdf --k 50 --c 0.5 --m 1e-5 --axis theta -o joint.sdf",
    )
    snippet(
        "ssp",
        ".ssp",
        "an SSP archive (SSD, FMI 2 FMU, SSV parameter sets in SI; --from: one set per candidate)",
        _ssp,
        "designer export ssp --from suggestion.json -o joint.ssp",
        SSP_OPTIONS,
    )
