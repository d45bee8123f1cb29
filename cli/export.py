"""`designer export fmu|modelica|mjcf|urdf`: a joint for simulators from numbers, a design or a suggestion."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from designer.errors import DesignerError

from .common import console, print_json, progress

export_app = typer.Typer(
    help="Export a joint: FMU (FMI 2/3), Modelica package, MJCF or URDF snippet.", no_args_is_help=True
)

Floats = Annotated[list[float] | None, typer.Option(show_default=False)]  # noqa: UP007 (typer needs Optional)
Number = Annotated[float | None, typer.Option(show_default=False)]  # noqa: UP007


def _joint(
    axis, k, c, m, density, length, width, height, layer, raster, from_, candidate, name, allow_extrapolation
):
    """The joint from exactly one source: --k/--c numbers, a design (six factors) or --from."""
    from designer.joint import from_one_source

    design = {
        "density": density,
        "length": length,
        "width": width,
        "height": height,
        "layer": layer,
        "raster": raster,
    }
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
    return from_one_source(
        coefficients=coefficients,
        design=design or None,
        suggestion=from_,
        candidate=candidate,
        axes=None if coefficients else axis or (None if from_ else ["x"]),
        name=name,
        allow_extrapolation=allow_extrapolation,
    )


def _print_joint(joint, what: str, path: Path) -> None:
    from designer import units

    console.print(f"wrote {what} [bold]{path}[/bold] for joint '{joint.name}'")
    for a, ac in joint.axes.items():
        si = ac.si()
        mass = "" if si["m"] is None else f", m = {si['m']:.4g} {units.si_unit('m', a)}"
        console.print(
            f"  {a}: k = {si['k']:.4g} {units.si_unit('k', a)}, c = {si['c']:.4g} "
            f"{units.si_unit('c', a)}{mass}  ({ac.origin})"
        )


JOINT_HELP = "rig units: --k N/mm (N.mm/rad), --c N.s/mm (N.mm.s/rad), --m kg (kg.m^2)"


def register(app: typer.Typer) -> None:
    """Add the `export` command group to the app."""

    @export_app.command("fmu")
    def fmu(
        output: Annotated[Path, typer.Option("-o", "--output", help="the .fmu file to write")] = Path(
            "joint.fmu"
        ),
        fmi: Annotated[int, typer.Option("--fmi", help="FMI version, 2 or 3")] = 2,
        interface: Annotated[str, typer.Option(help="force (element) or body")] = "force",
        source_only: Annotated[bool, typer.Option("--source-only", help="no binary: sources/ only")] = False,
        axis: Annotated[
            list[str] | None, typer.Option(help="x y z theta phi psi; repeat for several")
        ] = None,  # noqa: UP007
        k: Floats = None,
        c: Floats = None,
        m: Floats = None,
        density: Number = None,
        length: Number = None,
        width: Number = None,
        height: Number = None,
        layer: Number = None,
        raster: Number = None,
        from_: Annotated[
            Path | None, typer.Option("--from", help="output of designer suggest --json")
        ] = None,  # noqa: UP007
        candidate: Annotated[int, typer.Option(help="candidate in --from, 1 = best")] = 1,
        name: Annotated[str, typer.Option(help="joint (model) name")] = "FlexJoint",
        allow_extrapolation: Annotated[
            bool, typer.Option(help="accept a design outside the tested ranges")
        ] = False,
        json_out: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
    ) -> None:
        """Write the joint as an FMU (Co-Simulation and Model Exchange), SI units, provenance inside.

        The joint comes from --k/--c [--m] (rig units, repeat with --axis for several axes), from the six
        print settings via the surrogate, or from --from suggestion.json. The body interface needs a mass.

        Example: designer export fmu --k 0.8 --c 2e-3 --m 0.01 --interface body --fmi 3 -o joint.fmu
        """
        from designer.export.fmu import export_fmu

        joint = _joint(
            axis,
            k,
            c,
            m,
            density,
            length,
            width,
            height,
            layer,
            raster,
            from_,
            candidate,
            name,
            allow_extrapolation,
        )
        with progress("exporting FMU (compiling on first use)") as tick:
            path = export_fmu(joint, output, fmi, interface, source_only, progress=tick)
        if json_out:
            print_json(
                {
                    "path": str(path),
                    "fmi_version": fmi,
                    "interface": interface,
                    "source_only": source_only,
                    "joint": joint.to_dict(),
                }
            )
            return
        _print_joint(joint, f"FMI {fmi} FMU ({interface} interface)", path)
        if source_only:
            console.print(
                "  no binary: build it from sources/ with 'python -m fmpy compile " + str(path) + "'"
            )

    def snippet(fmt: str, suffix: str, title: str):
        def command(
            output: Annotated[Path, typer.Option("-o", "--output", help="the file to write")] = Path(
                f"joint{suffix}"
            ),
            axis: Annotated[
                list[str] | None, typer.Option(help="x y z theta phi psi; repeat for several")
            ] = None,  # noqa: UP007
            k: Floats = None,
            c: Floats = None,
            m: Floats = None,
            density: Number = None,
            length: Number = None,
            width: Number = None,
            height: Number = None,
            layer: Number = None,
            raster: Number = None,
            from_: Annotated[
                Path | None, typer.Option("--from", help="output of designer suggest --json")
            ] = None,  # noqa: UP007
            candidate: Annotated[int, typer.Option(help="candidate in --from, 1 = best")] = 1,
            name: Annotated[str, typer.Option(help="joint (model) name")] = "FlexJoint",
            allow_extrapolation: Annotated[
                bool, typer.Option(help="accept a design outside the ranges")
            ] = False,
            json_out: Annotated[bool, typer.Option("--json", help="print the result as JSON")] = False,
        ) -> None:
            joint = _joint(
                axis,
                k,
                c,
                m,
                density,
                length,
                width,
                height,
                layer,
                raster,
                from_,
                candidate,
                name,
                allow_extrapolation,
            )
            if fmt == "modelica":
                from designer.export.modelica import export_modelica

                path = export_modelica(joint, output)
            else:
                from designer.export.robot import export_robot

                path = export_robot(joint, output, fmt)
            if json_out:
                print_json({"path": str(path), "format": fmt, "joint": joint.to_dict()})
                return
            _print_joint(joint, title, path)

        command.__doc__ = (
            f"Write the joint as {title}, SI units, provenance in a comment.\n\n"
            f"The joint comes from --k/--c [--m] ({JOINT_HELP}), the six print settings, or --from.\n\n"
            f"Example: designer export {fmt} --k 0.8 --c 2e-3 --m 0.01 -o joint{suffix}"
        )
        export_app.command(fmt)(command)

    snippet("modelica", ".mo", "a Modelica package (MSL SpringDamper, Mass/Inertia)")
    snippet("mjcf", ".xml", "an MJCF model (joint stiffness, damping, armature)")
    snippet("urdf", ".urdf", "a URDF chain (dynamics damping; URDF has no stiffness)")
    app.add_typer(export_app, name="export")
