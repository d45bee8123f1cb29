"""`designer fit`, `designer predict` and `designer suggest`: the surrogate and inverse design."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from designer.errors import DesignerError

from .common import console, print_json

AxisOpt = Annotated[str, typer.Option("--axis", help="Axis: x y z theta phi psi.")]
SurrogateOpt = Annotated[
    Path | None,
    typer.Option("--surrogate", help="Surrogate JSON from `designer fit` (default: the shipped one)."),
]
JsonOpt = Annotated[bool, typer.Option("--json", help="Print machine-readable JSON only.")]


def _load(path: Path | None):
    from designer.surrogate import Surrogate

    return Surrogate.load() if path is None else Surrogate.load(path)


def _parse_fix(items: list[str]) -> dict[str, float]:
    fixed = {}
    for item in items:
        name, sep, value = item.partition("=")
        if not sep:
            raise DesignerError(
                f"--fix '{item}' is not NAME=VALUE", "write it as, for example, --fix width=4.5"
            )
        try:
            fixed[name.strip()] = float(value)
        except ValueError:
            raise DesignerError(
                f"--fix '{item}': '{value}' is not a number", "write --fix width=4.5"
            ) from None
    return fixed


def _pi(p: dict) -> str:
    """A prediction's to_dict() as 'value [low, high]'."""
    return f"{p['value']:.4g} [{p['low']:.3g}, {p['high']:.3g}]"


def fit(
    data: Annotated[Path | None, typer.Option("--data", help="Coefficient table (CSV/Parquet).")] = None,
    out: Annotated[
        Path | None, typer.Option("--out", "-o", help="Where to write the surrogate JSON.")
    ] = None,
    as_json: JsonOpt = False,
) -> None:
    """Fit the response surfaces (form and ridge penalty chosen by leave-one-out) and save them.

    Without --data, fits the bundled 44-run study table; without --out, writes nothing and reports.

    Example: designer fit --data my_runs.csv -o my_surrogate.json
    """
    from designer.data import load_table
    from designer.surrogate import Surrogate

    table = load_table(data)
    sur = Surrogate().fit(table)
    if out is not None:
        sur.save(out)
    report = {
        "surrogate_id": sur.id,
        "table_hash": sur.table_hash,
        "n_runs": len(table),
        "out": str(out) if out else None,
        "responses": {
            r: {
                "form": m.form,
                "unit": m.unit,
                "alpha": m.alpha,
                "loo": m.loo,
                "predictable": m.predictable,
                "candidates": m.candidates,
            }
            for r, m in sur.models.items()
        },
    }
    if as_json:
        print_json(report)
        return
    from rich.table import Table

    tab = Table(title=f"Leave-one-out accuracy on {len(table)} runs (form chosen per response)")
    for col in ("response", "form", "Q2", "RMSE", "MAPE", "PI95 coverage", "verdict"):
        tab.add_column(col)
    for r, m in sur.models.items():
        verdict = "partly predictable" if m.predictable else "unpredictable (mean)"
        tab.add_row(
            r,
            m.form,
            f"{m.loo['q2']:.3f}",
            f"{m.loo['rmse']:.3g} {m.unit}",
            f"{m.loo['mape']:.1f} %",
            f"{100 * m.loo['coverage95']:.0f} %",
            verdict,
        )
    console.print(tab)
    console.print(f"surrogate id {sur.id}" + (f", written to {out}" if out else " (not saved: give -o FILE)"))


def predict(
    density: Annotated[float | None, typer.Option(help="Infill density, % (20-100).")] = None,
    length: Annotated[float | None, typer.Option(help="Length l, mm (18-30).")] = None,
    width: Annotated[float | None, typer.Option(help="Width b, mm (2-7).")] = None,
    height: Annotated[float | None, typer.Option(help="Height h, mm (4-14).")] = None,
    layer: Annotated[float | None, typer.Option(help="Layer thickness, mm (0.12, 0.16 or 0.2).")] = None,
    raster: Annotated[float | None, typer.Option(help="Raster angle, deg (0 or 45).")] = None,
    axis: AxisOpt = "x",
    allow_extrapolation: Annotated[
        bool, typer.Option(help="Accept continuous factors outside the tested ranges.")
    ] = False,
    surrogate: SurrogateOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Predict k and c of one design with 95 % prediction intervals and how predictable each is.

    Example: designer predict --density 60 --length 24 --width 4.5 --height 9 --layer 0.16 --raster 0
    """
    from designer import space, units
    from designer.suggest import predictability

    params = space.check_design(
        dict(density=density, length=length, width=width, height=height, layer=layer, raster=raster),
        allow_extrapolation,
    )
    sur = _load(surrogate)
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
    if as_json:
        print_json(
            {"axis": axis, "params": params, "predicted": predicted, "notes": notes, "surrogate_id": sur.id}
        )
        return
    for q in ("k", "c"):
        p = predicted[q]
        console.print(f"{q}_{axis} = {_pi(p)} {p['unit']}  (value [95 % PI]; LOO Q2 = {p['loo_q2']:.2f})")
        if not p["predictable"]:
            console.print(f"  [yellow]{info[q]['statement']}[/yellow]")
    for note in notes:
        console.print(f"note: {note}")


def suggest(
    k: Annotated[
        float | None, typer.Option("--k", help="Target stiffness (N/mm; N.mm/rad on rotational axes).")
    ] = None,
    c: Annotated[
        float | None, typer.Option("--c", help="Target damping (N.s/mm; N.mm.s/rad on rotational axes).")
    ] = None,
    axis: AxisOpt = "x",
    fix: Annotated[
        list[str] | None, typer.Option("--fix", help="Hold a factor, e.g. --fix width=4.5 (repeatable).")
    ] = None,
    top: Annotated[int, typer.Option("--top", help="How many distinct candidates.")] = 5,
    importance_k: Annotated[float, typer.Option("--importance-k", help="Importance of the k target.")] = 1.0,
    importance_c: Annotated[float, typer.Option("--importance-c", help="Importance of the c target.")] = 1.0,
    k_low: Annotated[
        float | None, typer.Option(help="Lower desirability bound of k (default: data minimum).")
    ] = None,
    k_high: Annotated[
        float | None, typer.Option(help="Upper desirability bound of k (default: data maximum).")
    ] = None,
    c_low: Annotated[
        float | None, typer.Option(help="Lower desirability bound of c (default: data minimum).")
    ] = None,
    c_high: Annotated[
        float | None, typer.Option(help="Upper desirability bound of c (default: data maximum).")
    ] = None,
    allow_extrapolation: Annotated[
        bool, typer.Option(help="Search half a range beyond the tested ranges (flagged as extrapolated).")
    ] = False,
    surrogate: SurrogateOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """Suggest printable settings whose predicted k and c hit the targets, ranked by desirability.

    Either target may be omitted. Each candidate comes with predicted values, 95 % prediction
    intervals and its composite desirability; targets the data cannot reach or predict are said so.

    Example: designer suggest --k 0.8 --c 2e-3 --fix raster=0 --top 3
    """
    from designer.suggest import suggest as run_suggest

    result = run_suggest(
        _load(surrogate),
        k=k,
        c=c,
        axis=axis,
        fixed=_parse_fix(fix or []),
        top=top,
        importance={"k": importance_k, "c": importance_c},
        bounds={"k": (k_low, k_high), "c": (c_low, c_high)},
        allow_extrapolation=allow_extrapolation,
    )
    data = result.to_dict()
    if as_json:
        print_json(data)
        return
    _print_suggestion(data)


def _print_suggestion(data: dict) -> None:
    from rich import box
    from rich.table import Table

    u = data["units"]
    goals = ", ".join(f"{q} = {v:g} {u[q]}" for q, v in data["targets"].items() if v is not None)
    # an unpredictable response has the same prediction everywhere: stated below, not repeated per row
    shown = [q for q in ("k", "c") if data["predictability"][q]["predictable"]] or ["k", "c"]
    tab = Table(
        title=f"Designs for {goals} on axis {data['axis']}",
        box=box.SIMPLE_HEAD,
        pad_edge=False,
        collapse_padding=True,
    )
    for col in ("#", "infill\n%", "l\nmm", "b\nmm", "h\nmm", "layer\nmm", "raster\ndeg"):
        tab.add_column(col, justify="right", no_wrap=True)
    for q in shown:
        tab.add_column(f"{q} {u[q]}\n[95 % PI]", justify="right", no_wrap=True)
    tab.add_column("D", justify="right", no_wrap=True)
    for i, cand in enumerate(data["candidates"], 1):
        p, pr = cand["params"], cand["predicted"]
        tab.add_row(
            str(i),
            f"{p['density']:g}",
            f"{p['length']:g}",
            f"{p['width']:g}",
            f"{p['height']:g}",
            f"{p['layer']:g}",
            f"{p['raster']:g}",
            *[_pi(pr[q]) for q in shown],
            f"{cand['desirability']:.3f}",
        )
    console.print(tab)
    console.print("l, b, h: length, width, height; D: composite desirability (1 = every target met)")
    style = "green" if data["reachable"] else "bold red"
    for s in data["statements"]:
        console.print(f"[{style}]-[/{style}] {s}")
    for q, info in data["predictability"].items():
        if data["targets"][q] is None or info["predictable"]:
            console.print(f"- {info['statement']}")
    for i, cand in enumerate(data["candidates"], 1):
        for note in cand["notes"]:
            console.print(f"- candidate {i}: {note}")
    console.print(
        "Printability: infill rounded to 1 %, geometry to 0.01 mm, layer and raster at the study's levels; "
        "walls 0.8 mm, nozzle 0.4 mm."
    )


def register(app: typer.Typer) -> None:
    app.command()(fit)
    app.command()(predict)
    app.command()(suggest)
