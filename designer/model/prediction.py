"""A prediction with its 95 % interval, and one response's fitted surface that makes them."""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Any

import casadi as ca
import numpy as np

from .. import units
from ..errors import DesignerError
from ..study import space
from . import stored
from .forms import CasadiOps, columns, design_matrix
from .ridge import Fit, fit_arrays, interval


@dataclass(frozen=True)
class Prediction:
    """Predicted values and their 95 % prediction interval (`low`, `high`), in rig units.

    Arrays of shape (n,) for n designs, or floats for one design (`at(i)`). The one shape of a
    prediction everywhere: surrogate, suggest, joint provenance, exports and JSON (`to_dict`).
    """

    value: Any
    low: Any
    high: Any

    def at(self, i: int) -> Prediction:
        """The prediction for design `i` as floats."""
        return Prediction(float(self.value[i]), float(self.low[i]), float(self.high[i]))

    def scaled(self, factor: float) -> Prediction:
        """The same prediction in other units: every bound times `factor` (> 0)."""
        return Prediction(self.value * factor, self.low * factor, self.high * factor)

    def text(self, unit: str = "") -> str:
        """One design's prediction for people, '1.27 [0.81, 2] N/mm': the value to three significant
        digits, the bounds to two, written out below a million ('300 [210, 430] N.mm/rad', not
        '2.1e+02')."""
        return f"{_digits(self.value, 3)} [{_digits(self.low, 2)}, {_digits(self.high, 2)}]" + (
            f" {unit}" if unit else ""
        )

    def to_dict(self) -> dict[str, Any]:
        """{"value", "low", "high"}: floats, or lists for several designs."""

        def plain(v: Any) -> Any:
            return np.asarray(v, dtype=float).tolist()

        return {"value": plain(self.value), "low": plain(self.low), "high": plain(self.high)}

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, where: str = "prediction") -> Prediction:
        """Read back `to_dict` output; raise DesignerError when a key is missing or not a number."""
        try:
            values = [d[k] for k in ("value", "low", "high")]
            if all(np.ndim(v) == 0 for v in values):
                return cls(*(float(v) for v in values))
            return cls(*(np.asarray(v, dtype=float) for v in values))
        except (KeyError, TypeError, ValueError) as exc:
            raise DesignerError(
                f"{where} is not a prediction ({exc})", 'expected {"value": .., "low": .., "high": ..}'
            ) from None


@dataclass
class ResponseSurface:
    """One response's fitted form: coefficients, ridge penalty, and what its intervals need."""

    response: str
    form: str = "mean"
    alpha: float = 0.0
    coef: np.ndarray = field(default_factory=lambda: np.zeros(1))
    #: A^-1 Z'Z A^-1 with A = Z'Z + alpha P: the coefficients' covariance divided by sigma^2
    vcov: np.ndarray = field(default_factory=lambda: np.ones((1, 1)))
    sigma: float = 0.0
    dof: float = 0.0
    t95: float = 0.0
    loo: dict[str, float] = field(default_factory=dict)
    loo_predictions: Prediction | None = None
    candidates: dict[str, dict[str, float]] = field(default_factory=dict)
    observed_range: tuple[float, float] = (0.0, 0.0)
    #: nested LOO metrics: the whole selection repeated without each run (the honest accuracy)
    loo_nested: dict[str, float] = field(default_factory=dict)
    nested_predictions: Prediction | None = None
    #: runs whose removal changes the chosen form or moves its LOO Q2 by more than 0.05
    influence: list[dict[str, Any]] = field(default_factory=list)
    #: pure-error / lack-of-fit test when the table has replicated designs, else None
    lack_of_fit: dict[str, Any] | None = None

    @property
    def transform(self) -> str:
        return "log" if self.form == "powerlaw" else "none"

    @property
    def quantity(self) -> str:
        return self.response.split("_", 1)[0]

    @property
    def axis(self) -> str:
        return self.response.split("_", 1)[1]

    @property
    def unit(self) -> str:
        return units.rig_unit(self.quantity, self.axis)

    @property
    def fitted(self) -> bool:
        """Whether fit (or loading) gave this surface a residual scale and dof."""
        return self.dof > 0

    @property
    def predictable(self) -> bool:
        """Whether a form other than the mean is chosen and beats the mean under (nested) LOO."""
        return self.form != "mean" and self.accuracy.get("q2", 0.0) > 0.0

    @property
    def accuracy(self) -> dict[str, float]:
        """The honest accuracy figures: nested LOO when computed, else the chosen form's own LOO."""
        return self.loo_nested or self.loo

    def features(self, X: Any) -> np.ndarray:
        return design_matrix(self.form, X)

    def fit(self, X: Any, y: np.ndarray) -> ResponseSurface:
        """Fit this form; the ridge penalty is chosen by closed-form LOO on the given rows."""
        y = np.asarray(y, dtype=float)
        return self.set_fit(fit_arrays(self.form, self.features(X), y), y)

    def set_fit(self, f: Fit, y: np.ndarray) -> ResponseSurface:
        """Take the coefficients and interval terms of a fit to the runs `y`."""
        self.alpha, self.coef, self.vcov = f.alpha, f.coef, f.vcov
        self.sigma, self.dof, self.t95 = f.sigma, f.dof, f.t95
        self.observed_range = (float(np.min(y)), float(np.max(y)))
        return self

    def predict(self, X: Any) -> Prediction:
        """Value and 95 % PI at the designs X (mapping or DataFrame of factor columns, shape (n,))."""
        if not self.fitted:
            raise DesignerError(
                f"the surface of {self.response} is not fitted", "call fit(X, y) first, or load a surrogate"
            )
        Z = self.features(X)
        return Prediction(*interval(Z, self.coef, self.vcov, self.sigma, self.t95, self.transform == "log"))

    def casadi_function(self) -> ca.Function:
        """value, lo, hi of the 95 % PI as a CasADi function of the six factors (factor order)."""
        x = ca.SX.sym("x", len(space.FACTOR_NAMES))
        xs = {n: x[i] for i, n in enumerate(space.FACTOR_NAMES)}
        z = ca.vertcat(1, *columns(self.form, xs, CasadiOps))
        mean = ca.dot(z, ca.DM(self.coef))
        half = self.t95 * self.sigma * ca.sqrt(1 + ca.bilin(ca.DM(self.vcov), z, z))
        out = [mean, mean - half, mean + half]
        if self.transform == "log":
            out = [ca.exp(e) for e in out]
        return ca.Function(self.response, [x], out, ["x"], ["value", "lo", "hi"])

    def to_dict(self) -> dict[str, Any]:
        return {
            "form": self.form,
            "transform": self.transform,
            "unit": self.unit,
            "alpha": self.alpha,
            "coef": self.coef.tolist(),
            "vcov": self.vcov.tolist(),
            "sigma": self.sigma,
            "dof": self.dof,
            "t95": self.t95,
            "observed_range": list(self.observed_range),
            "loo": self.loo,
            "loo_nested": self.loo_nested,
            "loo_predictions": None if self.loo_predictions is None else self.loo_predictions.to_dict(),
            "nested_predictions": None
            if self.nested_predictions is None
            else self.nested_predictions.to_dict(),
            "influence": self.influence,
            "lack_of_fit": self.lack_of_fit,
            "candidates": self.candidates,
        }

    @classmethod
    def from_dict(cls, response: str, d: Mapping[str, Any], n_runs: int | None = None) -> ResponseSurface:
        """Read back `to_dict` output (a surrogate file's response), every value and shape checked
        (`designer.model.stored`); `n_runs` is the training runs' count the file's report indexes.

        Raises:
            DesignerError: naming the key and what it holds, with the fix (refit).
        """
        values = stored.surface_values(response, d)
        stored.report_values(response, d, n_runs)

        def predictions(key: str, required: bool = False) -> Prediction | None:
            if d.get(key) is None:
                if required:
                    raise stored.bad(f"response {response}", f"has no '{key}'")
                return None
            p = Prediction.from_dict(d[key], where=f"surrogate response {response} {key}")
            if n_runs is not None and np.shape(p.value) != (n_runs,):
                raise stored.bad(
                    f"response {response} {key}", f"has shape {np.shape(p.value)}, not ({n_runs},)"
                )
            return p

        return cls(
            response=response,
            loo=dict(d.get("loo") or {}),
            loo_predictions=predictions("loo_predictions", required=True),
            candidates=dict(d.get("candidates") or {}),
            loo_nested=dict(d.get("loo_nested") or {}),
            nested_predictions=predictions("nested_predictions"),
            influence=list(d.get("influence") or []),
            lack_of_fit=d.get("lack_of_fit"),
            **values,
        )


def _digits(v: float, n: int) -> str:
    """`v` rounded to `n` significant digits, in `g` format (an exponent only beyond 1e6 or 1e-4)."""
    return f"{float(f'{v:.{n}g}'):g}"
