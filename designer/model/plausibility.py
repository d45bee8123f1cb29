"""Measured coefficients that no printer can give: a unit slip caught before it calibrates.

A k typed in N/m (the SI value an export prints) is 1000 times the N/mm the tables use, and a rig
whose load channel logs kN gives a k 1000 times too small. Calibration would take either for a
printer factor of about 1000 (or 1/1000), far outside its prior (0.55-1.8 at 95 %), and carry it
into every prediction. Each measured value is compared with the study's prediction at its design:
beyond `MARGIN` times the widest a printer could plausibly give (the study's 95 % interval times the
prior's factor range), the value is refused, naming the likely unit, unless accepted deliberately.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING, Any

import numpy as np

from .. import units
from ..errors import DesignerError
from ..study import space
from .correction import PRINTER_SD

if TYPE_CHECKING:
    from .surrogate import Surrogate

#: how far beyond the plausible band (study PI x prior factor range) a value is still accepted
MARGIN = 10.0
#: the prior printer factor's 95 % range, as calibration states it
FACTOR_RANGE = (math.exp(-1.96 * PRINTER_SD), math.exp(1.96 * PRINTER_SD))
#: a slip of a thousand (N/m vs N/mm, kN vs N) is named when the ratio is within this factor of it
SLIP_TOLERANCE = 8.0


def unit_slip(quantity: str, axis: str, ratio: float, *, logged: bool = True) -> tuple[str, float] | None:
    """The unit mistake that a value `ratio` times the expected one suggests: (its cause in words,
    the multiplier that corrects the value), or None.

    A value in SI typed where the rig's unit is expected is `units.to_si`'s factor times too large
    (N/m for N/mm: 1000; N.m/rad for N.mm/rad: 1/1000). With `logged` (a value identified from a
    rig log) a load channel logged in kN also gives 1/1000.
    """
    unit, si = units.rig_unit(quantity, axis), units.si_unit(quantity, axis)
    factor = units.to_si(quantity, axis, 1.0)
    for sign in (1, -1):
        if abs(math.log10(ratio) - 3 * sign) >= math.log10(SLIP_TOLERANCE):
            continue
        causes = [f"a value in {si} rather than {unit}"] if math.log10(factor) == 3 * sign else []
        if logged and sign < 0:
            causes.append("a load logged in kN rather than N")
        if causes:
            return " or ".join(causes), 10.0 ** (-3 * sign)
    return None


def likely_slip(quantity: str, axis: str, ratio: float, *, logged: bool = True) -> str:
    """`unit_slip` in words, e.g. 'x1000: a value in N/m rather than N/mm? divide by 1000', or ''."""
    slip = unit_slip(quantity, axis, ratio, logged=logged)
    if slip is None:
        return ""
    cause, multiplier = slip
    return f"x{'1000' if multiplier < 1 else '1/1000'}: {cause}? " + (
        "divide by 1000" if multiplier < 1 else "multiply by 1000"
    )


def check_measured(surrogate: Surrogate, table: Any, *, accept_implausible: bool = False) -> None:
    """Raise for the first measured value whose implied printer factor no printer can have.

    Args:
        surrogate: the study surrogate (or one calibrated from it: its prior is used).
        table: the user's runs as `load_table` gives them (the six factors, c_<axis>, k_<axis>).
        accept_implausible: take such values as they are.

    Raises:
        DesignerError: naming the row, the value, the study's prediction there and the likely unit.
    """
    if accept_implausible or table is None or len(table) == 0:
        return
    prior = surrogate.prior if surrogate.calibration else surrogate
    # stiffness first: the response a printer factor is best known for
    responses = sorted((r for r in prior.responses if r in table.columns), key=lambda r: r[0] != "k")
    if not responses:
        return
    designs = table[list(space.FACTOR_NAMES)]
    predicted = prior.predict(designs, responses=responses, allow_extrapolation=True)
    low_f, high_f = FACTOR_RANGE
    for r in responses:
        q, axis = r.split("_", 1)
        p = predicted[r]
        measured = table[r].to_numpy(dtype=float)
        low = np.maximum(np.asarray(p.low, dtype=float), 1e-3 * np.asarray(p.value, dtype=float))
        band_low, band_high = low * low_f / MARGIN, np.asarray(p.high, dtype=float) * high_f * MARGIN
        bad = np.flatnonzero(np.isfinite(measured) & ((measured > band_high) | (measured < band_low)))
        if not bad.size:
            continue
        i = int(bad[0])
        unit = units.rig_unit(q, axis)
        ratio = measured[i] / float(p.value[i])
        pi = f"{float(p.value[i]):.3g} [{float(p.low[i]):.3g}, {float(p.high[i]):.3g}] {unit}"
        where = f"print {table['print'].iloc[i]}" if "print" in table.columns else f"row {i + 1}"
        raise DesignerError(
            f"runs: {r} of {where} is {measured[i]:.4g} {unit}, {ratio:.3g} times the study's "
            f"prediction there ({pi}): "
            f"a printer factor far outside its prior ({low_f:.2f}-{high_f:.2f} at 95 %)",
            f"{likely_slip(q, axis, ratio) or 'check its unit and the identification of that run'}; "
            "if the value is right, pass accept_implausible=True",
        )
