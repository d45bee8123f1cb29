"""`designer fit`, `designer predict` and `designer suggest`: the surrogate and inverse design."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer
from rich.markup import escape

from designer.errors import DesignerError

from .common import (
    AxisOpt,
    DataOpt,
    FixOpt,
    JsonOpt,
    SurrogateOpt,
    ToleranceOpt,
    answer,
    console,
    finishing,
    load_surrogate,
    output_option,
    parse_fix,
    parse_goal,
    pi_text,
    print_json,
    progress,
    tolerance_fraction,
)


def fit(
    data: DataOpt = None,
    out: Annotated[Path | None, output_option("where to write the surrogate JSON")] = None,
    as_json: JsonOpt = False,
) -> None:
    """Fit the response surfaces (form and ridge penalty chosen by leave-one-out) and save them.

    Accuracy is reported by nested leave-one-out: the whole selection repeated without each run.
    Without --data, fits the bundled 44-run study table; without -o, writes nothing and reports.

    Example: designer fit --data my_runs.csv -o my_surrogate.json
    """
    from designer.files import check_output
    from designer.model.surrogate import Surrogate
    from designer.study.data import load_table

    if out is not None:
        check_output(out, suffixes=[".json"])
    table = load_table(data)
    with progress("fitting (nested leave-one-out)", enabled=not as_json) as bar:
        sur = Surrogate().fit(table, progress=bar)
    finishing()
    if out is not None:
        sur.save(out)
    report = sur.report() | {"out": str(out) if out else None}
    if as_json:
        print_json(report)
        return
    _print_fit(report, len(table))
    console.print(f"surrogate id {sur.id}" + (f", written to {out}" if out else " (not saved: give -o FILE)"))


def _print_fit(report: dict, n_runs: int) -> None:
    from rich.table import Table

    tab = Table(title=f"Nested leave-one-out accuracy on {n_runs} runs (form chosen again without each run)")
    for col in ("response", "form", "Q2", "RMSE", "MAPE", "PI95 coverage", "verdict"):
        tab.add_column(col)
    for r, m in report["responses"].items():
        nested = m["loo_nested"]
        tab.add_row(
            r,
            m["form"],
            f"{nested['q2']:.2f}",
            f"{nested['rmse']:.2g} {m['unit']}",
            f"{nested['mape']:.0f} %",
            f"{100 * nested['coverage95']:.0f} %",
            "partly predictable" if m["predictable"] else "unpredictable (mean)",
        )
    console.print(tab)
    for r, m in report["responses"].items():
        for d in m["influence"]:
            console.print(
                f"- {r}: run {d['run']} ({100 * d['press_share']:.0f} % of the LOO squared error): "
                f"without it the procedure {'keeps' if d['form'] == m['form'] else 'picks'} the "
                f"{d['form']} form (its LOO Q2 {d['q2']:.2f}, {d['delta_q2']:+.2f})"
            )
        lof = m["lack_of_fit"]
        if lof and lof["p_value"] is not None:
            console.print(
                f"- {r}: lack of fit against {lof['df_pure_error']:g} dof of pure error from "
                f"{lof['replicated_designs']} replicated design(s): "
                f"F = {lof['f']:.3g}, p = {lof['p_value']:.2g}"
            )


def predict(
    density: Annotated[float | None, typer.Option(help="infill density, % (20-100)")] = None,
    length: Annotated[float | None, typer.Option(help="length, mm (18-30)")] = None,
    width: Annotated[float | None, typer.Option(help="width, mm (2-7)")] = None,
    height: Annotated[float | None, typer.Option(help="height, mm (4-14)")] = None,
    layer: Annotated[float | None, typer.Option(help="layer thickness, mm (0.12, 0.16 or 0.2)")] = None,
    raster: Annotated[float | None, typer.Option(help="raster angle, deg (0 or 45)")] = None,
    axis: AxisOpt = "x",
    allow_extrapolation: Annotated[
        bool, typer.Option(help="accept continuous factors outside the tested ranges")
    ] = False,
    surrogate: SurrogateOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Predict k and c of one design with 95 % prediction intervals and how predictable each is.

    Example: designer predict --density 60 --length 24 --width 4.5 --height 9 --layer 0.16 --raster 0
    """
    from designer import units
    from designer.design.suggestions import predictability
    from designer.study import space

    params = space.check_design(
        dict(density=density, length=length, width=width, height=height, layer=layer, raster=raster),
        allow_extrapolation,
    )
    sur = load_surrogate(surrogate)
    units.check_axis(axis)
    preds = sur.predict(params, responses=[f"k_{axis}", f"c_{axis}"], allow_extrapolation=allow_extrapolation)
    info = predictability(sur, axis)
    predicted = {
        q: preds[f"{q}_{axis}"].at(0).to_dict()
        | {
            "unit": units.rig_unit(q, axis),
            "loo_q2": info[q]["q2"],
            "predictable": info[q]["predictable"],
        }
        for q in ("k", "c")
    }
    notes = space.printability_notes(params)
    extrapolated = space.extrapolated(params)
    for name in extrapolated:
        f = space.BY_NAME[name]
        notes.append(
            f"{name} = {params[name]:g} {f.unit} is outside the tested range {f.describe_range()}: "
            "the prediction is an extrapolation"
        )
    if as_json:
        print_json(
            {
                "axis": axis,
                "params": params,
                "predicted": predicted,
                "extrapolated": extrapolated,
                "notes": notes,
                "surrogate_id": sur.id,
            }
        )
        return
    for q in ("k", "c"):
        p = predicted[q]
        console.print(
            f"{q}_{axis} = {pi_text(p)} {p['unit']}  (value [95 % PI]; nested LOO Q2 = {p['loo_q2']:.2f})"
        )
        if not p["predictable"]:
            console.print(f"  [yellow]{escape(info[q]['statement'])}[/yellow]", markup=True)
    for note in notes:
        console.print(f"note: {note}")


def suggest(
    k: Annotated[
        str | None,
        typer.Option("--k", help="stiffness goal: a target (N/mm; N.mm/rad on rotational axes), min or max"),
    ] = None,
    c: Annotated[
        str | None,
        typer.Option(
            "--c", help="damping goal: a target (N.s/mm; N.mm.s/rad on rotational axes), min or max"
        ),
    ] = None,
    axis: AxisOpt = "x",
    fix: FixOpt = None,
    top: Annotated[int, typer.Option("--top", help="how many distinct candidates")] = 5,
    tolerance: ToleranceOpt = 10.0,
    importance_k: Annotated[float, typer.Option("--importance-k", help="importance of the k goal")] = 1.0,
    importance_c: Annotated[float, typer.Option("--importance-c", help="importance of the c goal")] = 1.0,
    weight_k: Annotated[float, typer.Option("--weight-k", help="desirability shape exponent of k")] = 1.0,
    weight_c: Annotated[float, typer.Option("--weight-c", help="desirability shape exponent of c")] = 1.0,
    k_low: Annotated[
        float | None, typer.Option(help="lower desirability bound of k (default: measured min)")
    ] = None,
    k_high: Annotated[
        float | None, typer.Option(help="upper desirability bound of k (default: measured max)")
    ] = None,
    c_low: Annotated[
        float | None, typer.Option(help="lower desirability bound of c (default: measured min)")
    ] = None,
    c_high: Annotated[
        float | None, typer.Option(help="upper desirability bound of c (default: measured max)")
    ] = None,
    allow_extrapolation: Annotated[
        bool,
        typer.Option(help="search half a range beyond the tested ranges, within printable limits (flagged)"),
    ] = False,
    surrogate: SurrogateOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Suggest printable settings for goals on k and c, ranked by the chance of meeting them.

    Each goal is a target value, min or max. Candidates are ranked by the probability that a
    printed joint lands within --tolerance of the targets, then by composite desirability D (over
    the predictable responses). Exit 1 when no design's prediction reaches a target within the
    tolerance (the output is still printed, with the nearest designs), 2 on bad input.

    Example: designer suggest --k 0.8 --c 2e-3 --fix raster=0 --top 3
    """
    from designer.design.suggestions import suggest as run_suggest

    _positive(importance_k=importance_k, importance_c=importance_c, weight_k=weight_k, weight_c=weight_c)
    result = run_suggest(
        load_surrogate(surrogate),
        k=parse_goal(k, "--k"),
        c=parse_goal(c, "--c"),
        axis=axis,
        fixed=parse_fix(fix),
        top=top,
        importance={"k": importance_k, "c": importance_c},
        bounds={"k": (k_low, k_high), "c": (c_low, c_high)},
        weight={"k": weight_k, "c": weight_c},
        tolerance=tolerance_fraction(tolerance),
        allow_extrapolation=allow_extrapolation,
    )
    answer(result.to_dict(), as_json, _print_suggestion)


def _positive(**values: float) -> None:
    """Refuse a non-positive importance or weight, naming its flag."""
    for name, v in values.items():
        if not v > 0:
            flag = "--" + name.replace("_", "-")
            raise DesignerError(f"{flag} {v:g} must be positive", f"give e.g. {flag} 1")


def _cell(cand: dict, name: str) -> str:
    """A factor's value in the table: 'any' where it has no effect, '*' where extrapolated."""
    if name in cand["any"]:
        return "any"
    return f"{cand['params'][name]:g}" + ("*" if name in cand["extrapolated"] else "")


def _print_suggestion(data: dict) -> None:
    from rich import box
    from rich.table import Table

    u = data["units"]
    goals = ", ".join(
        f"{q} = {v:g} {u[q]}" if isinstance(v, float) else f"{q} {v}"
        for q, v in data["targets"].items()
        if v is not None
    )
    band = f"+-{100 * data['tolerance']:.0f} %"
    tab = Table(
        title=f"Designs for {goals} on axis {data['axis']}",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        collapse_padding=True,
    )
    for col in ("#", "density\n%", "length\nmm", "width\nmm", "height\nmm", "layer\nmm", "raster\ndeg"):
        tab.add_column(col, justify="right", no_wrap=True)
    for q in ("k", "c"):
        tab.add_column(f"{q} {u[q]}\n[95 % PI]", justify="right", no_wrap=True)
    tab.add_column(f"P\n{band}", justify="right", no_wrap=True)
    tab.add_column("D", justify="right", no_wrap=True)
    for i, cand in enumerate(data["candidates"], 1):
        names = ("density", "length", "width", "height", "layer", "raster")
        tab.add_row(
            str(i),
            *[_cell(cand, n) for n in names],
            *[pi_text(cand["predicted"][q]) for q in ("k", "c")],
            "-" if cand["p_within"] is None else f"{cand['p_within']:.2f}",
            "-" if cand["desirability"] is None else f"{cand['desirability']:.2f}",
        )
    console.print(tab)
    console.print(
        f"P: probability that a printed joint meets the predictable targets "
        f"within {band}; D: composite desirability of the predictable responses (1 = every goal met); "
        "any: no effect at this geometry (predicted as solid); *: outside the tested range (extrapolated)"
    )
    style = "green" if data["reachable"] else "bold red"
    for s in data["statements"]:
        console.print(f"[{style}]-[/{style}] {escape(s)}", markup=True)
    for q, info in data["predictability"].items():
        if data["targets"][q] is None or info["predictable"]:
            console.print(f"- {info['statement']}")
    for i, cand in enumerate(data["candidates"], 1):
        for note in cand["notes"]:
            console.print(f"- candidate {i}: {note}")
    console.print(
        "Printability: density rounded to 1 %, geometry to 0.01 mm, layer and raster at the study's levels; "
        "walls 0.8 mm, nozzle 0.4 mm, so width and height at least 2.0 mm."
    )


def register(app: typer.Typer) -> None:
    app.command()(fit)
    app.command()(predict)
    app.command()(suggest)
