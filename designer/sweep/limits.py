"""Task limits and objectives on the per-joint co-simulation metrics ("overshoot<=5%", "settling_time")."""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from ..errors import DesignerError

#: short metric name -> (column suffix of designer.cosim.metrics.joint_metrics, unit)
METRICS: dict[str, tuple[str, str]] = {
    "tracking_rms": ("tracking_rms_rad", "rad"),
    "peak_deflection": ("peak_deflection_rad", "rad"),
    "energy_dissipated": ("energy_dissipated_J", "J"),
    "overshoot": ("overshoot_pct", "%"),
    "settling_time": ("settling_time_s", "s"),
}
#: metrics defined only for a joint whose motor reference is a step
STEP_METRICS = ("overshoot_pct", "settling_time_s")
_LIMIT = re.compile(r"^\s*([a-z_]+)\s*(<=|>=)\s*([-+0-9.eE]+)\s*([a-zA-Z%]*)\s*$")


def metric(name: str) -> str:
    """The metric column suffix of a short or full metric name; a DesignerError for unknown names."""
    for short, (column, _) in METRICS.items():
        if name in (short, column):
            return column
    raise DesignerError(f"unknown metric '{name}'", f"use one of: {', '.join(METRICS)}")


def applies(column: str, reference: object) -> bool:
    """Whether a metric is defined for a joint with this motor reference (step metrics need a step)."""
    from ..cosim.references import Step

    return column not in STEP_METRICS or isinstance(reference, Step)


def unit(column: str) -> str:
    """The unit of a metric column suffix."""
    return next(u for c, u in METRICS.values() if c == column)


@dataclass(frozen=True)
class Limit:
    """A task limit on one metric, met by a case when every joint's value satisfies it."""

    metric: str  # column suffix, e.g. "overshoot_pct"
    op: str  # "<=" or ">="
    value: float

    def met(self, value: float | None) -> bool:
        """Whether one joint's value meets the limit; a missing value (never settled) does not."""
        if value is None or not math.isfinite(value):
            return False
        return value <= self.value if self.op == "<=" else value >= self.value

    def excess(self, value: float | None) -> float:
        """How far a value lies beyond the limit, in the metric's unit (0 when met, inf when missing)."""
        if value is None or not math.isfinite(value):
            return math.inf
        return max(value - self.value, 0.0) if self.op == "<=" else max(self.value - value, 0.0)

    def __str__(self) -> str:
        return f"{self.metric} {self.op} {self.value:g} {unit(self.metric)}"


def parse_limit(text: str) -> Limit:
    """A limit from text such as "overshoot<=5%" or "settling_time <= 0.3 s" (units optional).

    Raises:
        DesignerError: the text is not NAME<=VALUE or NAME>=VALUE, the metric is unknown, or the
            unit is not the metric's.
    """
    m = _LIMIT.match(str(text))
    if not m:
        raise DesignerError(f"limit {text!r} is not NAME<=VALUE or NAME>=VALUE", 'e.g. "overshoot<=5%"')
    name, op, value, given_unit = m.groups()
    column = metric(name)
    expected = unit(column)
    if given_unit and given_unit != expected:
        raise DesignerError(
            f"limit {text!r}: {name} is in {expected}, not {given_unit}", f"write it in {expected}"
        )
    try:
        number = float(value)
    except ValueError:
        raise DesignerError(f"limit {text!r}: {value!r} is not a number", 'e.g. "overshoot<=5%"') from None
    if not math.isfinite(number):
        raise DesignerError(f"limit {text!r} is not finite", "give a finite number")
    return Limit(column, op, number)
