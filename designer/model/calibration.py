"""Calibration of the study's surrogate to a user's printer from the user's own runs: the public calls.

`calibrate` updates the study surrogate by the user's measured runs, `new_printer` is the study as a
prior for a printer not measured yet, `with_runs` adds runs the design loop imagines, and `report`
says what a calibration found. The model behind them (printer factor, local correction) is in
`designer.model.correction`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..errors import DesignerError
from ..files import format_bytes
from ..study import space
from . import plausibility
from .calibration_record import CalibrationRecord
from .correction import (
    PRINTER_SD,
    CalibratedSurface,
    calibrated,
    check_printer_sd,
    evidence,
    runs_table,
    settings_of,
)
from .prediction import ResponseSurface
from .surrogate import Surrogate

#: the most runs `calibrate` takes: 2000 take about 4 s and 0.45 GB on a 2-core machine
MAX_RUNS = 2000
#: peak bytes per pair of runs (the correlation's coded differences and the covariance, measured:
#: 4000 runs peaked at 1.2 GB)
MEMORY_PER_RUN_PAIR = 75


def new_printer(surrogate: Surrogate, *, printer_sd: float = PRINTER_SD) -> Surrogate:
    """The study surrogate as a prior for a printer not measured yet: every response carries the
    printer factor's uncertainty, and the local correction the study's own runs observe (no run of
    the user's). What a user's first print should expect; `calibrate` with runs continues from it."""
    if surrogate.calibration is not None:
        return surrogate
    models = {
        r: CalibratedSurface.from_base(
            base,
            *evidence(surrogate, r, {n: np.zeros(0) for n in space.FACTOR_NAMES}, np.zeros(0)),
            settings_of(surrogate, r),
            printer_sd,
        )
        for r, base in surrogate.models.items()
    }
    columns = {c: np.zeros(0) for c in [*space.FACTOR_NAMES, *surrogate.responses]}
    return Surrogate(
        models=models,
        table_hash=surrogate.table_hash,
        training=surrogate.training,
        prior=surrogate,
        calibration=CalibrationRecord(columns, printer_sd),
    )


def calibrate(
    surrogate: Surrogate, runs: Any, *, printer_sd: float = PRINTER_SD, accept_implausible: bool = False
) -> Surrogate:
    """The study surrogate updated by a user's measured runs: a printer factor and a local correction.

    Args:
        surrogate: the prior, usually the shipped study surrogate (`Surrogate.load()`); a surrogate
            that is already calibrated is recalibrated from its own prior with all runs.
        runs: the user's runs, a coefficient table (path or DataFrame: the six factors and any of
            the surrogate's responses, e.g. k_x and c_x; designer identify's output) with 0 or more
            rows. Responses missing from the table stay as in the prior.
        printer_sd: prior standard deviation of log(printer factor).
        accept_implausible: take measured values whose implied printer factor lies far outside its
            prior (a unit slip, refused by default) as they are.

    Returns:
        A new `Surrogate` whose responses are `CalibratedSurface`s; with no run, `surrogate` itself.

    Raises:
        DesignerError: a malformed table, a factor outside what can be printed, no response of the
            surrogate's axis in the table, a non-positive coefficient, a value no printer can give
            (`designer.model.plausibility`), printer_sd <= 0, or more than MAX_RUNS runs (with the
            ones already calibrated).
    """
    if not isinstance(surrogate, Surrogate) or not surrogate.models:
        raise DesignerError(
            f"surrogate={type(surrogate).__name__} is not a fitted Surrogate",
            "give Surrogate.load() or a fitted Surrogate",
        )
    check_printer_sd(printer_sd)
    prior = surrogate.prior if surrogate.calibration else surrogate
    table = runs_table(runs, prior)
    plausibility.check_measured(prior, table, accept_implausible=accept_implausible)
    if prior is not surrogate and surrogate.calibration.n_runs:
        import pandas as pd

        table = pd.concat([surrogate.calibration["table"], table], ignore_index=True)
    if len(table) > MAX_RUNS:
        raise DesignerError(
            f"runs has {len(table)} rows; a calibration takes at most {MAX_RUNS} (its time grows as "
            f"the cube of the runs and its memory as the square: {MAX_RUNS} take a few seconds, "
            f"{len(table)} would need about {format_bytes(MEMORY_PER_RUN_PAIR * len(table) ** 2)})",
            "average repeated prints of one design into one row, or fit a surrogate to your own runs "
            "with designer fit",
        )
    return calibrated(prior, table, printer_sd)


def with_runs(surrogate: Surrogate, rows: list[dict[str, float]]) -> Surrogate:
    """`surrogate` calibrated on its own runs plus `rows`, runs the tool itself imagines (the six
    factors and responses by their canonical names, printable), without a user table's checks: the
    design loop recalibrates on each imagined measurement, where those checks (and a table's
    bookkeeping) would cost most of its time."""
    if not rows:
        return surrogate
    names = list(dict.fromkeys(c for row in rows for c in row))
    new = {c: np.array([row.get(c, np.nan) for row in rows], dtype=float) for c in names}
    if surrogate.calibration is None:
        return calibrated(surrogate, new, PRINTER_SD)
    old = surrogate.calibration["columns"]
    n_old = len(old[space.FACTOR_NAMES[0]])
    both = {
        c: np.concatenate(
            [
                old[c] if c in old else np.full(n_old, np.nan),
                new[c] if c in new else np.full(len(rows), np.nan),
            ]
        )
        for c in dict.fromkeys([*old, *new])
    }
    return calibrated(surrogate.prior, both, surrogate.calibration["printer_sd"])


def _user_loo(model: CalibratedSurface) -> dict[str, float] | None:
    """Each of the user's runs predicted by the surrogate calibrated on the others (the prior and
    its settings come from the study, so nothing is refitted on the user's runs): median absolute
    error (%) and the share inside the 95 % interval."""
    if model.own.sum() < 2:
        return None
    held = model.own_loo()
    y = model.observed[model.own > 0]
    errors = np.abs(held.value - y) / y
    inside = (held.low <= y) & (y <= held.high)
    return {"n": len(y), "mape": 100 * float(np.median(errors)), "coverage95": float(np.mean(inside))}


def _statement(m: ResponseSurface, calibrated: ResponseSurface) -> str:
    if not isinstance(calibrated, CalibratedSurface):
        return "no measured value: the study's prediction"
    if m.predictable:
        return (
            f"{m.response}: the study's {m.form} form through your printer's departure (its factor, "
            "width and height offsets, infill, layer and raster adhesion, and a smooth rest), corrected "
            f"near the designs you and the study printed (correlation length {calibrated.length:g} of a "
            "factor's half-range); far from your prints the interval keeps what they leave open"
        )
    return (
        f"{m.response} is not predictable from the six factors (the study's nested Q2 "
        f"{m.accuracy.get('q2', float('nan')):.2f}): your runs set its level for your printer and pin it "
        "down at the designs you printed; elsewhere its interval stays wide"
    )


def report(surrogate: Surrogate) -> dict[str, Any]:
    """What a calibration found, as plain data: per response the user's run count, the printer
    factor with its 95 % interval, what the runs say of each mechanism of the printer's departure
    (`designer.model.mechanisms`: posterior value and 95 % interval beside the prior sd), and the
    nested leave-one-out over the user's runs.

    Raises:
        DesignerError: `surrogate` is not calibrated.
    """
    if surrogate.calibration is None:
        raise DesignerError("surrogate is not calibrated", "give the result of designer.calibrate(...)")
    out: dict[str, Any] = {
        "surrogate_id": surrogate.id,
        "prior_id": surrogate.prior.id,
        "n_runs": surrogate.calibration.n_runs,
        "n_study_runs": len(surrogate.prior.training["run"]),
        "printer_sd": surrogate.calibration["printer_sd"],
        "responses": {},
    }
    for r, m in surrogate.models.items():
        base = surrogate.prior.model(r)
        cal = isinstance(m, CalibratedSurface)
        out["responses"][r] = {
            "unit": m.unit,
            "n_runs": int(m.own.sum()) if cal else 0,
            "printer_factor": m.printer_factor().to_dict() if cal else None,
            "mechanisms": m.mechanisms() if cal else None,
            "settings": m.settings() if cal else None,
            "loo_user": _user_loo(m) if cal else None,
            "predictable": base.predictable,
            "statement": _statement(base, m),
        }
    return out
