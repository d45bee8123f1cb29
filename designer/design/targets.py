"""Goals on k and c: a target value, min or max, their desirability, and the chance of meeting one.

The engineering standard of response optimisers (Minitab Response Optimizer, JMP Profiler): per
response a goal with Derringer-Suich desirability bounds, weight and importance.
"""

from __future__ import annotations

import math
import sys
import threading
from dataclasses import dataclass
from typing import Any

import numpy as np

from .. import units
from ..errors import DesignerError, number_argument
from ..model.prediction import Prediction
from ..model.surrogate import Surrogate

#: default tolerance around a target within which a printed joint counts as meeting it
TOLERANCE = 0.10
#: weight of the (normalised) squared PI width in the objective: a tie-breaker only
#: which way each kind of goal prefers a response to go
SENSE = {"target": 0.0, "min": -1.0, "max": 1.0}
#: the thread importing the t distribution's module ahead of its first use (`prefetch_t_distribution`)
_PREFETCH: list[threading.Thread] = []


def prefetch_t_distribution() -> None:
    """Start importing scipy's `special` (the t distribution of P) in a background thread, once.

    Its import is about 0.15-0.2 s of Python (its array-API layer clones numpy's namespace, which
    loads numpy's f2py, testing and ma; it rewrites its functions' docstrings), about as long as
    `import casadi` itself, while P is needed only after IPOPT has searched. CasADi releases the
    interpreter lock while it builds and runs IPOPT, so on a second core the import is done by the
    time `probability_between` asks for it (Python's import lock makes that call wait for the
    thread otherwise). The same functions are imported: P does not change. Not a daemon thread: the
    interpreter's exit waits for the import rather than stopping it halfway.
    """
    if "scipy.special" in sys.modules or _PREFETCH:
        return
    thread = threading.Thread(target=_import_t_distribution, name="prefetch scipy.special")
    _PREFETCH.append(thread)
    thread.start()


def _import_t_distribution() -> None:
    try:
        import scipy.special  # noqa: F401
    except Exception:  # noqa: BLE001 - the caller's own import raises it where it is needed
        pass


def probability_within(
    prediction: Prediction, target: float, tolerance: float, dof: float, *, log: bool = True
) -> float:
    """Probability that a printed joint's response lies within +-tolerance (relative) of `target`.

    The surrogate's predictive distribution is a Student t in its fit space g(y) (g = log for the
    power law, `log=True`; the identity otherwise): g(Y) = mu + s T_dof, whose 95 % interval is the
    prediction's (low, high) = g^-1(mu -+ t95 s), t95 the 0.975 quantile of t with `dof`. So
    mu = g(value), s = (g(high) - g(low)) / (2 t95), and

        P = F_dof((g(target (1 + tolerance)) - mu) / s) - F_dof((g(target (1 - tolerance)) - mu) / s)

    with F_dof the t CDF (scipy's `stdtr`; t95 from `stdtrit`) and the lower term 0 when
    target (1 - tolerance) <= 0 under the log. `dof` is the fitted surface's `dof`
    in the surrogate JSON; `value`, `low` and `high` are the prediction's, in rig units. Returns a
    float in [0, 1].
    """
    return probability_between(prediction, target * (1 - tolerance), target * (1 + tolerance), dof, log=log)


def probability_between(
    prediction: Prediction, low: float, high: float, dof: float, *, log: bool = True
) -> float:
    """Probability that a printed joint's response lies between two limits (spec limits, `low` < `high`,
    rig units): `probability_within`'s predictive Student t in the fit space, with the lower term 0
    when `low` <= 0 under the log. The profiler page's asymmetric goals use the same formula."""
    from scipy.special import stdtr, stdtrit  # numbers, not CasADi symbols: no need in the graph

    g = math.log if log else (lambda v: v)
    t95 = float(stdtrit(dof, 0.975))
    mu = g(float(prediction.value))
    s = (g(float(prediction.high)) - g(float(prediction.low))) / (2 * t95)
    upper = float(stdtr(dof, (g(high) - mu) / s))
    lower = 0.0 if (log and low <= 0) else float(stdtr(dof, (g(low) - mu) / s))
    return max(0.0, min(1.0, upper - lower))


@dataclass(frozen=True)
class Target:
    """A goal on one response: a target value, or min or max, with Derringer-Suich bounds.

    `low`, `high`: where the desirability reaches 0 (and 1 for min/max); `weight`: the shape
    exponent (1 linear, > 1 insists on closeness); `importance`: its share in the composite.
    """

    quantity: str  # "k" or "c"
    value: float | None  # the target for kind "target", None for min and max
    low: float
    high: float
    importance: float = 1.0
    kind: str = "target"
    weight: float = 1.0

    @property
    def has_value(self) -> bool:
        """Whether the goal is a target value (not min or max), the only kind met within a tolerance."""
        return self.value is not None

    @property
    def goal(self) -> float | str:
        """The goal as a user gives it: the target value, or "min" or "max"."""
        return self.kind if self.value is None else self.value

    @property
    def sense(self) -> float:
        """+1 where a larger value is better (max), -1 where a smaller is (min), 0 for a target value."""
        return SENSE[self.kind]

    def desirability(self, y: float) -> float:
        """Derringer-Suich desirability of a predicted value: 1 at the goal, 0 at or past a bound."""
        if self.value is None:  # min or max: a ramp across the bounds, rising towards the better side
            gain = (y - self.low) if self.sense > 0 else (self.high - y)
            return float(np.clip(gain / (self.high - self.low), 0, 1) ** self.weight)
        if y <= self.low or y >= self.high:
            return 0.0
        side = (
            (y - self.low) / (self.value - self.low)
            if y <= self.value
            else (self.high - y) / (self.high - self.value)
        )
        return float(side**self.weight)

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "value": self.value,
            "low": self.low,
            "high": self.high,
            "weight": self.weight,
            "importance": self.importance,
        }


def make_target(
    surrogate: Surrogate,
    quantity: str,
    axis: str,
    goal: float | str,
    importance: float = 1.0,
    low: float | None = None,
    high: float | None = None,
    weight: float = 1.0,
) -> Target:
    """A goal (a number, "min" or "max") with bounds defaulting to the measured range of the response.

    A target outside that range widens the violated bound to half (or 1.5 times) the target, so
    the ranking still works; `suggest` states that the target lies outside what the data supports.
    """
    unit = units.rig_unit(quantity, axis)
    for name, v in (("importance", importance), ("weight", weight)):
        if not np.isfinite(v) or v <= 0:
            raise DesignerError(
                f"{name} of {quantity} = {v:g} must be positive", f"give {name}={{'{quantity}': 1.0}}"
            )
    obs_lo, obs_hi = surrogate.model(f"{quantity}_{axis}").observed_range
    if isinstance(goal, str):
        kind = goal.strip().lower()
        if kind not in ("min", "max"):
            raise DesignerError(
                f"goal {quantity}={goal!r} is not a number, 'min' or 'max'",
                f"give {quantity}=0.8 or {quantity}='max'",
            )
        value = None
        lo, hi = (obs_lo if low is None else low), (obs_hi if high is None else high)
    else:
        kind, value = "target", number_argument(goal, quantity)
        if not np.isfinite(value):
            raise DesignerError(
                f"target {quantity} = {value:g} is not a finite number",
                f"give a value in {unit}, e.g. {np.sqrt(obs_lo * obs_hi):.3g} (mid measured range)",
            )
        if value <= 0:
            raise DesignerError(f"target {quantity} = {value:g} {unit} must be positive", "give a value > 0")
        if value > 1e6 * obs_hi:  # the desirability scale (bounds squared) would overflow
            raise DesignerError(
                f"target {quantity} = {value:g} {unit} is over a million times the largest measured, "
                f"{obs_hi:.3g} {unit}",
                "give a target near the data's range",
            )
        lo = min(obs_lo, 0.5 * value) if low is None else low
        hi = max(obs_hi, 1.5 * value) if high is None else high
    if not (lo < hi and (value is None or lo < value < hi)):
        raise DesignerError(
            f"the {quantity} bounds {lo:g} to {hi:g} {unit} do not enclose the goal {value or kind}",
            "give a lower bound below the upper (and the target between them)",
        )
    return Target(quantity, value, float(lo), float(hi), float(importance), kind, float(weight))
