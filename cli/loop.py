"""`designer calibrate` and `designer next`: the design loop with the user's own printer and prints."""

from __future__ import annotations

from pathlib import Path
from typing import Annotated

import typer

from .common import (
    AcceptImplausibleOpt,
    AxisOpt,
    FixOpt,
    JsonOpt,
    SurrogateOpt,
    ToleranceOpt,
    answer,
    console,
    design_text,
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

#: the calibrate report's significant digits for a factor and its interval
_FACTOR = "{:.2f}"


def calibrate(
    runs: Annotated[
        Path,
        typer.Argument(help="your measured runs: a coefficient table (CSV or Parquet), e.g. identify's"),
    ],
    out: Annotated[Path | None, output_option("where to write the calibrated surrogate JSON")] = None,
    surrogate: SurrogateOpt = None,
    accept_implausible: AcceptImplausibleOpt = False,
    as_json: JsonOpt = False,
) -> None:
    """Calibrate the study's surrogate to your printer with your own measured runs.

    The study's surrogate is the prior; your runs estimate how your printer departs from the study's
    (a factor per response with its 95 % interval, width and height offsets, infill, layer and raster
    adhesion: those your runs pin down are printed) and a local correction that is strong near the
    designs you printed and fades away from them. The result is a surrogate file every --surrogate
    option accepts. The report gives a leave-one-out over your runs (each predicted from the others;
    nothing is refitted, the settings come from the study). The runs table designer print writes is
    read as filled: prints not measured yet are left out. A k or c whose implied printer factor lies
    far outside its prior (a value in N/m, a load in kN) is refused, naming the likely unit, unless
    --accept-implausible.

    Example: designer calibrate my_runs.csv -o mine.json
    """
    from designer.files import check_output
    from designer.model.calibration import calibrate as run_calibrate
    from designer.model.calibration import report
    from designer.model.plausibility import check_measured
    from designer.printing.runs import measured, settings_and_coefficients

    if out is not None:
        check_output(out, suffixes=[".json"])
    table, notes = measured(runs, source=runs.name)
    prior = load_surrogate(surrogate)
    check_measured(prior, table, accept_implausible=accept_implausible)  # names each print by its id
    calibrated = run_calibrate(prior, table[settings_and_coefficients(table)], accept_implausible=True)
    finishing()
    if out is not None:
        calibrated.save(out)
    data = report(calibrated) | {"out": str(out) if out else None, "notes": notes}
    if as_json:
        print_json(data)
        return
    _print_calibration(data)
    for note in notes:
        console.print(f"- {note}")
    console.print(
        f"surrogate id {calibrated.id}" + (f", written to {out}" if out else " (not saved: give -o FILE)")
    )


def _print_calibration(data: dict) -> None:
    console.print(f"{data['n_runs']} run(s) of yours on top of the study's {data['n_study_runs']}")
    for r, m in data["responses"].items():
        if m["n_runs"] == 0:
            console.print(f"- {r}: no measured value in your runs: the study's prediction, unchanged")
            continue
        f = m["printer_factor"]
        line = (
            f"- {r}: printer factor {_FACTOR.format(f['value'])} "
            f"[{_FACTOR.format(f['low'])}, {_FACTOR.format(f['high'])}] (95 %) from {m['n_runs']} run(s)"
        )
        nested = m["loo_user"]
        if nested:
            line += (
                f"; each of your runs predicted from the others: median error {nested['mape']:.0f} %, "
                f"{100 * nested['coverage95']:.0f} % inside the 95 % PI"
            )
        console.print(line)
        pinned = _pinned(m["mechanisms"])
        if pinned:
            console.print(f"  what your prints say of the printer: {pinned}")
        console.print(f"  {m['statement']}")


#: how each mechanism reads in the calibrate report (value formats with units)
_MECHANISM_TEXT = {
    "width_offset": ("width offset", "{:+.2f} mm"),
    "height_offset": ("height offset", "{:+.2f} mm"),
    "infill": ("infill exponent change", "{:+.2f}"),
    "layer": ("layer adhesion", "{:+.2f} per 0.04 mm"),
    "raster": ("raster", "{:+.2f}"),
    "layer_raster": ("layer x raster", "{:+.2f}"),
}


def _pinned(mechanisms: dict) -> str:
    """The mechanisms the runs narrowed to under 70 % of their prior sd, as 'name value [low, high]'."""
    parts = []
    for name, (label, fmt) in _MECHANISM_TEXT.items():
        m = mechanisms[name]
        if (m["high"] - m["low"]) / (2 * 1.96) < 0.7 * m["prior_sd"]:
            parts.append(
                f"{label} {fmt.format(m['value'])} [{fmt.format(m['low'])}, {fmt.format(m['high'])}]"
            )
    return "; ".join(parts)


def next_(
    k: Annotated[str | None, typer.Option("--k", help="stiffness target (N/mm; N.mm/rad rotational)")] = None,
    c: Annotated[
        str | None, typer.Option("--c", help="damping goal: a target (N.s/mm; N.mm.s/rad), min or max")
    ] = None,
    axis: AxisOpt = "x",
    fix: FixOpt = None,
    n: Annotated[int, typer.Option("--n", help="how many designs to print now (1-10)")] = 3,
    tolerance: ToleranceOpt = 10.0,
    stop: Annotated[
        float,
        typer.Option("--stop", help="print the recommendation once it lands with this probability (0-1)"),
    ] = 0.9,
    surrogate: SurrogateOpt = None,
    as_json: JsonOpt = False,
) -> None:
    """The designs to print and measure next so that the recommendation lands on your target.

    The first print is design #1, the one most likely to land now; each further one (--n) is chosen
    for how much measuring it raises the chance that the best design afterwards lands within
    --tolerance of the targets (a knowledge gradient), among printable designs near the target. When
    design #1 already lands with probability --stop or more, it says to print it and proposes
    nothing else. Exit 1 when the target is out of reach
    (the reason is printed, no print is proposed), 2 on bad input.

    Example: designer next --k 0.8 --n 3 --surrogate mine.json
    """
    from designer.design.next_prints import next_prints

    with progress("choosing the next prints", enabled=not as_json) as bar:
        result = next_prints(
            load_surrogate(surrogate),
            k=parse_goal(k, "--k"),
            c=parse_goal(c, "--c"),
            axis=axis,
            fixed=parse_fix(fix),
            n=n,
            tolerance=tolerance_fraction(tolerance),
            stop=stop,
            progress=bar,
        )
    answer(result.to_dict(), as_json, _print_next)


def _print_next(data: dict) -> None:
    from designer.units import rig_unit

    def both(predicted: dict) -> str:  # k and c with their units on the goals' axis
        return ", ".join(f"{q} {pi_text(predicted[q], rig_unit(q, data['axis']))}" for q in ("k", "c"))

    rec = data["recommendation"]
    console.print(f"Design #1 now: {design_text(rec['params'])}")
    console.print(
        f"  {both(rec['predicted'])}; "
        f"lands within +-{100 * data['tolerance']:g} % with probability {data['p_now']:.2f}"
    )
    for i, p in enumerate(data["prints"], 1):
        mark = " (design #1 itself)" if p["recommended"] else ""
        console.print(f"Print {i}{mark}: {design_text(p['params'])}")
        console.print(f"  predicted {both(p['predicted'])}; {p['reason']}")
    for s in data["statements"]:
        console.print(f"- {s}")


def register(app: typer.Typer) -> None:
    app.command()(calibrate)
    app.command("next")(next_)
