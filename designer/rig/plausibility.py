"""Whether an identified axis is in the rig's units: its scale against what the tool knows.

A load logged in kN under the schema's N column (or a position in m under its mm column) fits as
well as a right one (R2 1.0000) and gives k and c 1000x off; nothing in the fit itself can tell.
What can is the scale, against three references:
- the rig: the peak motion and load any rig for printed joints logs (`RIG_RANGES`). A column's
  peak outside them gets a warning naming the unit that would bring it inside (small joints and
  large rigs exist, so this alone refuses nothing);
- the study (the x axis): every specimen of the bundled table has k_x in a range; a k_x more than
  `SCALE_LIMIT` times outside it is refused;
- the specimen (the x axis, its factors in the sidecar): the shipped surrogate's prediction for it
  (its 95 % interval spans about x1.5 either side); a k_x more than `SCALE_LIMIT` times off it is
  refused.
The refusal names the likely unit: the mislabelled column whose factor is nearest the ratio (x1000:
a load in kN, a position in m), preferring the column whose peak is itself outside the rig's range.
"""

from __future__ import annotations

import functools
import math

from .. import units
from .logs import LOAD, UNITS

#: the peak |value| a rig for printed joints logs, per unit: (smallest, largest)
RIG_RANGES: dict[str, tuple[float, float]] = {
    "mm": (0.01, 1000.0),
    "rad": (1e-3, 2 * math.pi),
    "N": (0.01, 1e4),
    "N.mm": (0.05, 1e7),
}
#: per unit of the schema, the units a column is likely to be logged in instead, each with the
#: factor its numbers are off by (logged = true x factor)
MISLABELS: dict[str, tuple[tuple[str, float], ...]] = {
    "mm": (("m", 1e-3), ("um", 1e3)),
    "rad": (("deg", 180 / math.pi), ("mrad", 1e3)),
    "N": (("kN", 1e-3), ("mN", 1e3)),
    "N.mm": (("N.m", 1e-3),),
}
#: k more than this many times off its reference is refused as a unit error
SCALE_LIMIT = 30.0


def _out_of_range(unit: str, peak: float) -> str | None:
    """'below' or 'above' the rig's range for `unit`, or None when the peak lies inside it."""
    lo, hi = RIG_RANGES[unit]
    return "below" if peak < lo else "above" if peak > hi else None


def range_warnings(axis: str, r_peak: float, f_peak: float) -> list[str]:
    """A sentence per column of the axis whose peak lies outside what a rig logs, with the unit
    that would bring it inside."""
    out = []
    for col, peak in ((axis, r_peak), (LOAD[axis], f_peak)):
        unit = UNITS[col]
        side = _out_of_range(unit, peak)
        if side is None:
            continue
        lo, hi = RIG_RANGES[unit]
        fits = [name for name, factor in MISLABELS[unit] if _out_of_range(unit, peak / factor) is None]
        guess = f": is it in {' or '.join(fits)}, not {unit}?" if fits else ": check its unit and scale"
        out.append(
            f"the peak of {col}, {peak:.3g} {unit}, is {side} what a rig for printed joints logs "
            f"({lo:g} to {hi:g} {unit}){guess}"
        )
    return out


@functools.lru_cache(maxsize=1)
def _study_k_range() -> tuple[float, float]:
    """The bundled study table's lowest and highest k_x (N/mm)."""
    from ..study.data import load_table

    k = load_table()["k_x"]
    return float(k.min()), float(k.max())


@functools.lru_cache(maxsize=1)
def _surrogate():
    """The shipped surrogate (read once per process: a fit's scale check needs only its k_x)."""
    from ..model.surrogate import Surrogate

    return Surrogate.load()


def _reference(axis: str, k: float, factors: dict[str, float] | None) -> tuple[float, str] | None:
    """k over the reference for this axis (1 inside a range), and the reference in words; None when
    the tool knows no k for the axis."""
    if axis != "x":
        return None
    if factors is not None:
        pred = _surrogate().predict(factors, responses=["k_x"], allow_extrapolation=True)["k_x"]
        value, low, high = (float(getattr(pred, q).ravel()[0]) for q in ("value", "low", "high"))
        return k / value, (
            f"what the shipped surrogate predicts for this specimen ({value:.3g} N/mm, 95 % interval "
            f"{low:.3g} to {high:.3g})"
        )
    lo, hi = _study_k_range()
    span = f"the study's printed specimens span {lo:.3g} to {hi:.3g} N/mm"
    if k < lo:
        return k / lo, f"the lowest k_x of any printed specimen ({span})"
    return (k / hi if k > hi else 1.0), f"the highest k_x of any printed specimen ({span})"


def _likely_units(axis: str, ratio: float, r_peak: float, f_peak: float) -> str:
    """The mislabelled column(s) whose factor is nearest k's `ratio` to its reference, in words:
    among them those whose peak is outside the rig's range and inside it once converted, if any."""
    options = []  # (distance in decades, evidence, words)
    for col, peak, sign in ((axis, r_peak, -1), (LOAD[axis], f_peak, 1)):
        unit = UNITS[col]
        for name, factor in MISLABELS[unit]:
            effect = factor**sign  # k's factor: the load's own, the position's inverse
            distance = abs(math.log10(ratio / effect))
            if distance < math.log10(SCALE_LIMIT):
                evidence = (
                    _out_of_range(unit, peak) is not None and _out_of_range(unit, peak / factor) is None
                )
                times = f"x{effect:.4g}" if effect >= 1 else f"/{1 / effect:.4g}"
                options.append((distance, evidence, f"{col} in {name} under its {unit} column ({times})"))
    if not options:
        return "no unit factor explains it: check each column's unit and the sensors' calibration factors"
    pool = [o for o in options if o[1]] or options  # a column whose own peak says so comes first
    nearest = min(o[0] for o in pool)
    return "likely " + ", or ".join(o[2] for o in pool if o[0] <= nearest + 0.25)


def scale_failure(
    axis: str, k: float, r_peak: float, f_peak: float, factors: dict[str, float] | None
) -> str | None:
    """Why this axis's k cannot be in the rig's units (naming the likely unit), or None when it can."""
    ref = _reference(axis, k, factors)
    if ref is None:
        return None
    ratio, where = ref
    if 1 / SCALE_LIMIT <= ratio <= SCALE_LIMIT:
        return None
    ku = units.rig_unit("k", axis)
    size = f"{ratio:.3g} times" if ratio > 1 else f"1/{1 / ratio:.3g} of"
    seen = range_warnings(axis, r_peak, f_peak)
    return (
        f"implausible scale, a unit error: k = {k:.3g} {ku} is {size} {where}; "
        f"{_likely_units(axis, ratio, r_peak, f_peak)}"
        + (f" ({'; '.join(seen)})" if seen else "")
        + "; c is off by the same factor. Convert the column and identify again"
    )
