"""Check of identification in closed loop: the virtual rig's logs give back the coefficients."""

from __future__ import annotations

import pandas as pd

from ..units import rig_unit
from .checks import CheckResult, Context

#: coefficient sets of the closed loop (rig units): the bundled table's lowest, middle and highest
#: k_x, and the example joint's theta axis
IDENTIFY_SETS: tuple[tuple[str, dict[str, float]], ...] = (
    ("x", {"k": 0.246, "c": 4.91e-4, "m": 1e-3}),
    ("x", {"k": 0.8, "c": 2e-3, "m": 1e-3}),
    ("x", {"k": 2.09, "c": 4.52e-3, "m": 1e-3}),
    ("theta", {"k": 330.0, "c": 0.83, "m": 2e-6}),
)
IDENTIFY_SECONDS = 60.0
IDENTIFY_TOLERANCE_PCT = 1.0


def check_identification(ctx: Context) -> CheckResult:
    """The virtual rig's log (1 % force noise, dropouts), identified, gives back k and c within 1 %."""
    from ..plots.checks import plot_identification
    from ..plots.common import save_figure
    from ..rig.identify import identify
    from ..rig.logs import validate_frame
    from ..rig.simulate import simulate

    rows = []
    for i, (axis, coef) in enumerate(IDENTIFY_SETS):
        log = simulate({axis: coef}, duration=IDENTIFY_SECONDS, noise=0.01, dropouts=0.001, seed=i)
        fit = identify(validate_frame(log, source="virtual rig"))[0].axes[axis]
        k_err, c_err = 100 * (fit.k / coef["k"] - 1), 100 * (fit.c / coef["c"] - 1)
        rows.append(
            {
                "set": f"{axis}: k {coef['k']:g}, c {coef['c']:g}",
                "k true": f"{coef['k']:g} {rig_unit('k', axis)}",
                "k identified": fit.k,
                "k error %": k_err,
                "c true": f"{coef['c']:g} {rig_unit('c', axis)}",
                "c identified": fit.c,
                "c error %": c_err,
                "R2": fit.r2,
                "within": max(abs(k_err), abs(c_err)) <= IDENTIFY_TOLERANCE_PCT,
            }
        )
    table = pd.DataFrame(rows)
    fig = save_figure(
        plot_identification(table, tolerance_pct=IDENTIFY_TOLERANCE_PCT), ctx.figures / "identification.png"
    )
    worst = table[["k error %", "c error %"]].abs().max()
    summary = (
        f"{int(table.within.sum())} of {len(table)} sets within {IDENTIFY_TOLERANCE_PCT:g} % on "
        f"{IDENTIFY_SECONDS:g} s logs; worst k error {worst['k error %']:.2g} %, worst c error "
        f"{worst['c error %']:.2g} %"
    )
    return CheckResult("Identification closed loop", bool(table.within.all()), summary, table, [fig])
