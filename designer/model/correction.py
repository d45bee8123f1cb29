"""Calibration of the study's surrogate to a user's printer from the user's own runs.

The study printed on one printer with one spool; another printer's joints differ by a factor (the
filament's modulus and the machine's extrusion) and, near any one design, by what the study's
response surface gets wrong there. Per response, in log space:

    log y_user(x) = mu0(x) + b + g(x) + e

- ``mu0(x)``: the study surrogate's prediction (its log), the prior mean;
- ``b ~ N(0, tau^2)``: the printer/material factor exp(b), shared by every design (tau = 0.3: a
  factor between 0.55 and 1.8 at 95 %);
- ``g ~ GP(0, s_g(x) s_g(x') rho(x, x'))``: the study model's local error, a Matern 5/2
  correlation over the coded factors whose length scale is the longest the study's own nested
  leave-one-out residuals do not reject (`fit_length`), and whose size is the study's predictive spread
  ``s_g(x)^2 = s0(x)^2 - sigma_n^2`` times an amplitude that makes it as large as those residuals
  show the model errs at a design it did not see (`fit_amplitude`: 1.06 for k; 2.46 for c, whose log
  spread the study's raw-space interval understates);
- ``e ~ N(0, sigma_n^2)``: print-to-print scatter, from the study's replicated runs (pure error),
  never below 2.5 %.

The correction is observed at the study's own runs too: each one's residual from the study's
prediction is the model's error g there (plus print scatter), on the study's printer (no factor b).
So near a design the study measured, one print of the user's pins both the printer factor and the
local error; near the user's runs the prediction converges to their measurements; far from every run
it is the study's, times the estimated printer factor, with the study's interval widened by the
factor's uncertainty. With no run of the user's, `calibrate` returns the study surrogate itself.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, fields, replace
from typing import Any, Protocol, TypeVar

import casadi as ca
import numpy as np

from ..errors import DesignerError, number_argument
from ..study import space
from . import mechanisms
from .calibration_record import CalibrationRecord
from .forms import as_printed
from .memo import array_key, memo_of
from .prediction import Prediction, ResponseSurface


class Study(Protocol):
    """What the correction reads of a study surrogate (`designer.model.surrogate.Surrogate`, which
    imports this module to load a calibrated file: so the correction names no class of it)."""

    models: dict[str, ResponseSurface]
    training: dict[str, list[float]]

    @property
    def responses(self) -> list[str]: ...


S = TypeVar("S", bound=Study)

#: prior standard deviation of log(printer factor): filaments of one grade and printers differ
PRINTER_SD = 0.3
#: the largest prior sd accepted: log-factor sd 3 already allows factors of e^±6 (x/÷ 400)
MAX_PRINTER_SD = 3.0
#: the smallest print-to-print scatter assumed (relative, log space)
MIN_NOISE = 0.025
#: length scales tried for the local correction (coded factor units, each factor spans [-1, 1])
LENGTHS = (0.25, 0.35, 0.5, 0.7, 1.0, 1.4, 2.0, 3.0)
#: log-likelihood drop that still counts as "not rejected" (about a 95 % profile interval)
LIKELIHOOD_DROP = 2.0
#: added to a squared distance before its square root (see `matern52`)
MATERN_FLOOR = 1e-24
#: the largest size of the local correction, as a multiple of the study's predictive spread
MAX_AMPLITUDE = 4.0
#: sd (log space) of a printer's own smooth departure from the study beyond the mechanism terms: the
#: study's runs are evidence of what every printer shares, not exact at their designs for yours
LOCAL_SD = 0.06


def coded(X: Mapping[str, Any]) -> np.ndarray:
    """(n, 6) coordinates of the local correction: every factor coded to [-1, 1] over its range.

    Where the walls fill the section the infill has no effect, so such designs are coded at 100 %.
    """
    cols = {n: np.atleast_1d(np.asarray(X[n], dtype=float)) for n in space.FACTOR_NAMES}
    core = np.minimum(cols["width"], cols["height"]) - 2 * space.WALL_MM
    cols["density"] = np.where(core > space.NOZZLE_MM + 1e-9, cols["density"], 100.0)
    return np.column_stack(
        [(cols[f.name] - (f.low + f.high) / 2) / ((f.high - f.low) / 2) for f in space.FACTORS]
    )


def _coded_symbolic(x: Any) -> list[Any]:
    """`coded` for one design as CasADi expressions (factor order)."""
    out = []
    for i, f in enumerate(space.FACTORS):
        xi = x[i]
        if f.name == "density":
            core = ca.fmin(x[space.FACTOR_NAMES.index("width")], x[space.FACTOR_NAMES.index("height")])
            xi = ca.if_else(core - 2 * space.WALL_MM > space.NOZZLE_MM + 1e-9, xi, 100.0)
        out.append((xi - (f.low + f.high) / 2) / ((f.high - f.low) / 2))
    return out


def _log_moments(base: ResponseSurface, X: Any) -> tuple[np.ndarray, np.ndarray]:
    """The study surface's predictive mean and scale in log space at designs X.

    For a raw-space form the log-normal with the same median and upper 95 % bound stands in.
    """
    p = base.predict(X)
    mu = np.log(np.asarray(p.value, dtype=float))
    s = (np.log(np.asarray(p.high, dtype=float)) - mu) / base.t95
    return mu, s


def noise_of(base: ResponseSurface) -> float:
    """Print-to-print scatter (log space) from the study's replicated runs, at least MIN_NOISE."""
    lof = base.lack_of_fit or {}
    if lof.get("df_pure_error"):
        sd = np.sqrt(lof["ss_pure_error"] / lof["df_pure_error"])
        mean = np.mean(base.observed_range)
        return float(max(sd / mean, MIN_NOISE))
    return MIN_NOISE


def _local_sd(s0: np.ndarray, noise: float) -> np.ndarray:
    """The local correction's prior sd at amplitude 1: the study's predictive spread less the print
    scatter (at least half the spread)."""
    return np.sqrt(np.maximum(s0**2 - noise**2, 0.25 * s0**2))


def matern52(d2: Any, length: float) -> Any:
    """Matern 5/2 correlation at squared coded distance d2 (numpy array or CasADi expression).

    Twice differentiable but not infinitely smooth: near a run it decorrelates faster than a
    squared exponential of the same length, which over-trusts a print at designs around it. The
    tiny floor keeps the square root's derivative finite at a run itself (IPOPT starts there); it
    changes the correlation by less than 1e-11.
    """
    exp = ca.exp if isinstance(d2, ca.SX | ca.MX) else np.exp
    r = 5.0**0.5 * (d2 + MATERN_FLOOR) ** 0.5 / length
    return (1.0 + r + r * r / 3.0) * exp(-r)


def _correlation(A: np.ndarray, B: np.ndarray, length: float) -> np.ndarray:
    return matern52(np.sum((A[:, None, :] - B[None, :, :]) ** 2, axis=2), length)


def fit_length(base: ResponseSurface, X: Mapping[str, Any], y: np.ndarray, noise: float) -> float:
    """Length scale of the model's local error, from the study's own residuals.

    The residuals are the nested leave-one-out ones where the surrogate carries them (each run
    predicted by a model that never saw it), else the selected form's own leave-one-out ones. The
    study's runs lie at least one coded unit apart, so its likelihood cannot tell length scales below
    that spacing apart: the longest length scale the residuals do not reject (log-likelihood within
    LIKELIHOOD_DROP of the best) is taken, the smoothest correction the data allows.
    """
    held = base.nested_predictions or base.loo_predictions
    if held is None:
        return LENGTHS[0]
    r = np.log(y) - np.log(np.asarray(held.value, dtype=float))
    printed = as_printed(dict(X))  # as the evidence and fit_amplitude see the runs
    _, s0 = _log_moments(base, printed)
    sg = _local_sd(s0, noise)
    Z = coded(printed)
    ll = []
    for length in LENGTHS:
        K = np.outer(sg, sg) * _correlation(Z, Z, length) + noise**2 * np.eye(len(r))
        L = np.linalg.cholesky(K)
        a = np.linalg.solve(L, r)
        ll.append(-0.5 * a @ a - np.sum(np.log(np.diag(L))))
    return max(length for length, v in zip(LENGTHS, ll, strict=True) if v >= max(ll) - LIKELIHOOD_DROP)


def fit_amplitude(base: ResponseSurface, X: Mapping[str, Any], y: np.ndarray, noise: float) -> float:
    """The local correction's size, as a multiple of the study's predictive spread: the smallest (at
    least 1, at most MAX_AMPLITUDE) at which the study's held-out residuals (nested leave-one-out
    where the surrogate carries them, as in `fit_length`) have a root-mean-square standardized error
    of at most 1 against the correction's prior sd plus print scatter.

    So before any run of the user's, the prior's spread at a design the study did not print is what
    the study's own cross-validation measures there: for k its stated spread is 6 % short (1.06);
    for c, whose surface is a constant in raw space, the log-normal stand-in understates how far its
    runs spread (2.46).
    """
    held = base.nested_predictions or base.loo_predictions
    if held is None:
        return 1.0
    r = np.log(y) - np.log(np.asarray(held.value, dtype=float))
    _, s0 = _log_moments(base, as_printed(dict(X)))
    sg = _local_sd(s0, noise)

    def excess(a: float) -> float:  # rms standardized error above 1; falls as the amplitude grows
        return float(np.sqrt(np.mean(r**2 / (a**2 * sg**2 + noise**2)))) - 1.0

    if excess(1.0) <= 0:
        return 1.0
    if excess(MAX_AMPLITUDE) > 0:
        return MAX_AMPLITUDE
    from scipy.optimize import brentq

    return float(brentq(excess, 1.0, MAX_AMPLITUDE, xtol=1e-6))


def settings_of(prior: Study, response: str) -> tuple[float, float, float]:
    """(length, amplitude, noise) of `response`'s correction, computed once per study surface (the
    design loop recalibrates many times), or as `keep_settings` gave them."""
    base = prior.models[response]
    if "_calibration_settings" not in base.__dict__:
        keep_settings(base, fit_settings(prior, response))
    return base.__dict__["_calibration_settings"]


def fit_settings(prior: Study, response: str) -> tuple[float, float, float]:
    """(length, amplitude, noise) of `response`'s correction, fitted to the study's runs."""
    base = prior.models[response]
    X, y = study_runs(prior, response)
    noise = noise_of(base)
    return fit_length(base, X, y, noise), fit_amplitude(base, X, y, noise), noise


def keep_settings(base: ResponseSurface, settings: tuple[float, float, float]) -> None:
    """Take `settings` as `base`'s (length, amplitude, noise): the shipped study surrogate's are
    stored beside it (`designer.model.study_settings`), so no command fits them again."""
    base.__dict__["_calibration_settings"] = tuple(settings)


@dataclass
class CalibratedSurface(ResponseSurface):
    """A study response surface updated by a user's runs (see the module docstring).

    Carries the study surface's fields (form, accuracy, ...) for reporting; predictions and the
    CasADi function are the calibrated ones, log-normal (Student t in log space, the study's dof).
    """

    runs: np.ndarray = field(default_factory=lambda: np.zeros((0, 6)))  # (n, 6) designs, factor order
    observed: np.ndarray = field(default_factory=lambda: np.zeros(0))  # (n,) measured values
    #: (n,) 1 for the user's runs (they carry the printer's departure), 0 for the study's own runs
    own: np.ndarray = field(default_factory=lambda: np.zeros(0))
    length: float = 1.0
    amplitude: float = 1.0
    noise: float = MIN_NOISE
    printer_sd: float = PRINTER_SD
    local_sd: float = LOCAL_SD

    @classmethod
    def from_base(
        cls,
        base: ResponseSurface,
        runs: np.ndarray,
        observed: np.ndarray,
        own: np.ndarray,
        settings: tuple[float, float, float],
        printer_sd: float = PRINTER_SD,
    ) -> CalibratedSurface:
        """`settings`: (length, amplitude, noise), as `settings_of` gives them."""
        shared = {f.name: getattr(base, f.name) for f in fields(ResponseSurface)}
        length, amplitude, noise = settings
        surf = cls(
            **shared,
            runs=runs,
            observed=observed,
            own=own,
            length=length,
            amplitude=amplitude,
            noise=noise,
            printer_sd=printer_sd,
        )
        surf._prepare(base)
        return surf

    def _prepare(self, base: ResponseSurface) -> None:
        """The system solved at the runs. What depends on their designs only is kept on the study
        surface (`designer.model.memo`: the loop recalibrates on the same designs with other
        imagined values); only the weights of the measured values, alpha, are solved each time."""
        self._base = base
        settings = (self.length, self.amplitude, self.noise, self.printer_sd, self.local_sd)
        self._key = array_key(self.runs, self.own, settings)
        mu0, self._Zu, self._sgu, self._Sb, self._Hu, self._Kinv, self._excess = memo_of(base, "_solved").get(
            self._key, lambda: self._solve(base)
        )
        self._alpha = self._Kinv @ (np.log(self.observed) - mu0)

    def _solve(self, base: ResponseSurface) -> tuple[np.ndarray, ...]:
        X = dict(zip(space.FACTOR_NAMES, self.runs.T, strict=True))
        mu0, s0 = _log_moments(base, X)
        self._Zu = coded(X)
        self._sgu = self.amplitude * _local_sd(s0, self.noise)
        self._Sb = mechanisms.prior_variances(self.printer_sd)
        #: the mechanism terms at the runs, zero for the study's (its printer is the reference)
        self._Hu = np.zeros((len(self.own), len(self._Sb)))
        mine = self.own > 0
        self._Hu[mine] = mechanisms.basis(base, self.runs[mine])
        R = _correlation(self._Zu, self._Zu, self.length)
        K = self._cross(R, self._sgu, self._Hu, self.own) + self.noise**2 * np.eye(len(mu0))
        self._Kinv = np.linalg.inv(K) if len(mu0) else np.zeros((0, 0))
        #: a run's prior variance as `log_moments` states it at its design, less its diagonal in K
        self._excess = self._prior_var(s0, self._Hu) - np.diag(K)
        return mu0, self._Zu, self._sgu, self._Sb, self._Hu, self._Kinv, self._excess

    def _cross(self, R: np.ndarray, sa: np.ndarray, Ha: np.ndarray, ua: np.ndarray) -> np.ndarray:
        """Prior covariance of log y between designs a (rows) and the runs (columns), given their
        correlation R (na, n): the study model's error, shared by every printer, plus on the user's
        printer (u = 1) the mechanism terms and the printer's own departure."""
        shared = np.outer(sa, self._sgu) * R
        printer = (Ha * self._Sb) @ self._Hu.T + self.local_sd**2 * np.outer(ua, self.own) * R
        return shared + printer

    def _prior_var(self, s0: np.ndarray, H: np.ndarray) -> np.ndarray:
        """Variance of log y on the user's printer before any run, at designs of study spread s0
        and mechanism terms H (n, terms)."""
        sg = _local_sd(s0, self.noise)
        return s0**2 + (self.amplitude**2 - 1) * sg**2 + H**2 @ self._Sb + self.local_sd**2

    def own_loo(self) -> Prediction:
        """Each of the user's runs predicted as `predict` would from every other run (the study's
        and the user's) with it left out, in closed form: for the Gaussian model in log space, the
        mean is log y_i - alpha_i / (K^-1)_ii and the variance 1 / (K^-1)_ii less the print scatter
        the diagonal carries (the settings come from the study, so nothing is refitted). One
        inversion instead of one calibration per run. Shape (n_own,), in the user's run order."""
        mine = self.own > 0
        d = np.diag(self._Kinv)[mine]
        mu = np.log(self.observed[mine]) - self._alpha[mine] / d
        s = np.sqrt(np.maximum(self._excess[mine] + 1.0 / d, self.noise**2))
        half = self.t95 * s
        return Prediction(np.exp(mu), np.exp(mu - half), np.exp(mu + half))

    @property
    def transform(self) -> str:
        return "log"

    def log_moments(self, X: Any) -> tuple[np.ndarray, np.ndarray]:
        """Calibrated predictive mean and scale of log y at designs X, arrays of shape (n,)."""
        key = (self._key, array_key(*(X[n] for n in space.FACTOR_NAMES)))
        mu0, C, s = memo_of(self._base, "_moments").get(key, lambda: self._moments(X))
        return mu0 + C @ self._alpha, s

    def _moments(self, X: Any) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """What `log_moments` at X takes from the runs' designs: mu0, the covariance with the runs
        C, and the scale."""
        mu0, s0 = _log_moments(self._base, X)
        Z = coded(X)
        sg = _local_sd(s0, self.noise)
        designs = np.column_stack(
            [np.broadcast_to(np.asarray(X[n], dtype=float), len(Z)) for n in space.FACTOR_NAMES]
        )
        H = mechanisms.basis(self._base, designs)
        C = self._cross(_correlation(Z, self._Zu, self.length), self.amplitude * sg, H, np.ones(len(Z)))
        var = self._prior_var(s0, H) - np.einsum("ij,jk,ik->i", C, self._Kinv, C)
        return mu0, C, np.sqrt(np.maximum(var, self.noise**2))

    def predict(self, X: Any) -> Prediction:
        mu, s = self.log_moments(X)
        half = self.t95 * s
        return Prediction(np.exp(mu), np.exp(mu - half), np.exp(mu + half))

    def casadi_function(self) -> ca.Function:
        x = ca.SX.sym("x", len(space.FACTOR_NAMES))
        value0, _, hi0 = self._base.casadi_function()(x)
        mu0 = ca.log(value0)
        s0 = (ca.log(hi0) - mu0) / self.t95
        sg = ca.sqrt(ca.fmax(s0**2 - self.noise**2, 0.25 * s0**2))
        h = mechanisms.symbolic(self._base, x)
        prior = s0**2 + (self.amplitude**2 - 1) * sg**2 + ca.dot(ca.DM(self._Sb), h * h) + self.local_sd**2
        var, mu = prior, mu0
        if len(self._Zu):
            z = ca.vertcat(*_coded_symbolic(x))
            d2 = ca.sum1((ca.repmat(z, 1, len(self._Zu)) - ca.DM(self._Zu.T)) ** 2).T
            R = matern52(d2, self.length)
            c = self.amplitude * sg * ca.DM(self._sgu) * R + self.local_sd**2 * ca.DM(self.own) * R
            c += ca.mtimes(ca.DM(self._Hu * self._Sb), h)
            var, mu = var - ca.bilin(ca.DM(self._Kinv), c, c), mu + ca.dot(c, ca.DM(self._alpha))
        half = self.t95 * ca.sqrt(ca.fmax(var, self.noise**2))
        out = [ca.exp(mu), ca.exp(mu - half), ca.exp(mu + half)]
        return ca.Function(self.response, [x], out, ["x"], ["value", "lo", "hi"])

    def mechanisms(self) -> dict[str, dict[str, Any]]:
        """What the user's runs say of each mechanism term (`designer.model.mechanisms`): posterior
        mean and 95 % interval of its coefficient, beside its prior sd. The factor as exp(beta)."""
        SH = self._Hu * self._Sb  # (n, terms)
        mean = SH.T @ self._alpha
        var = self._Sb - np.einsum("it,ij,jt->t", SH, self._Kinv, SH)
        half = 1.96 * np.sqrt(np.maximum(var, 0.0))
        out = {}
        for i, (name, sd) in enumerate(zip(mechanisms.names(), np.sqrt(self._Sb), strict=True)):
            value, low, high = mean[i], mean[i] - half[i], mean[i] + half[i]
            if name == mechanisms.FACTOR:
                value, low, high = np.exp([value, low, high])
            out[name] = {"value": float(value), "low": float(low), "high": float(high), "prior_sd": float(sd)}
        return out

    def printer_factor(self) -> Prediction:
        """The estimated printer/material factor exp(b) with its 95 % interval."""
        return Prediction.from_dict(self.mechanisms()[mechanisms.FACTOR])

    def page_data(self) -> dict[str, Any]:
        """What the profiler page needs to evaluate this calibration itself (profile.html's
        `calibrated`): the coded runs, the mechanism terms and the solved system, plain lists."""
        return {
            "factors": [[f.name, (f.low + f.high) / 2, (f.high - f.low) / 2] for f in space.FACTORS],
            "wall": space.WALL_MM,
            "line": space.NOZZLE_MM,
            "runs": self._Zu.tolist(),
            "own": self.own.tolist(),
            "sgu": self._sgu.tolist(),
            "hs": (self._Hu * self._Sb).tolist(),
            "sb": self._Sb.tolist(),
            "kinv": self._Kinv.tolist(),
            "alpha": self._alpha.tolist(),
            "local2": self.local_sd**2,
            "noise": self.noise,
            "length": self.length,
            "amplitude": self.amplitude,
        }

    def settings(self) -> dict[str, Any]:
        return {
            "length": self.length,
            "amplitude": self.amplitude,
            "noise": self.noise,
            "printer_sd": self.printer_sd,
            "local_sd": self.local_sd,
            "mechanisms": {m.name: m.sd for m in mechanisms.TERMS},
        }


def runs_table(runs: Any, surrogate: Study) -> Any:
    """The user's runs through `load_table` (factors checked, printable), restricted to responses
    the surrogate has; raise for a table that shares no response or no factor with it."""
    import pandas as pd

    from ..study.data import check_table_argument, load_table

    check_table_argument(runs, "runs")
    if runs is None:
        return pd.DataFrame()
    if isinstance(runs, pd.DataFrame) and runs.empty:
        return runs
    table = load_table(runs)
    responses = [r for r in surrogate.responses if r in table.columns]
    if not responses:
        raise DesignerError(
            f"runs has none of the surrogate's responses ({', '.join(surrogate.responses)})",
            "give measured coefficients of the same axis, e.g. the columns k_x and c_x "
            "(designer identify writes them)",
        )
    for name in space.FACTOR_NAMES:
        for v in table[name]:
            space.check_value(name, float(v), allow_extrapolation=True)
    return table


def study_runs(prior: Study, response: str) -> tuple[dict[str, np.ndarray], np.ndarray]:
    X = {n: np.asarray(prior.training[n], dtype=float) for n in space.FACTOR_NAMES}
    return X, np.asarray(prior.training[response], dtype=float)


def _study_evidence(prior: Study, response: str) -> tuple[np.ndarray, np.ndarray]:
    """The study's runs of `response` as printed, (n, 6) in factor order, and their values (n,):
    computed once per study surface (the design loop recalibrates many times)."""
    base = prior.models[response]
    if "_study_evidence" not in base.__dict__:
        X, y = study_runs(prior, response)
        ok = np.isfinite(y)
        printed = as_printed({n: v[ok] for n, v in X.items()})
        designs = np.column_stack([printed[n] for n in space.FACTOR_NAMES]).reshape(-1, 6)
        base.__dict__["_study_evidence"] = (designs, y[ok])
    return base.__dict__["_study_evidence"]


def evidence(
    prior: Study, response: str, user: Mapping[str, np.ndarray], observed: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(designs (n, 6) as printed, measured values (n,), own (n,)): the study's runs (own 0: the
    study's printer, the reference) and the user's (own 1), where the correction is observed.
    The study's runs observe the model's error directly: each one's residual from the study's own
    prediction is that error there (plus print scatter)."""
    study, values = _study_evidence(prior, response)
    printed = as_printed({n: np.asarray(user[n], dtype=float) for n in space.FACTOR_NAMES})
    mine = np.column_stack([printed[n] for n in space.FACTOR_NAMES]).reshape(-1, 6)
    observed = np.asarray(observed, dtype=float)
    own = np.r_[np.zeros(len(values)), np.ones(len(observed))]
    return np.vstack([study, mine]), np.concatenate([values, observed]), own


def calibrated(prior: S, runs: Any, printer_sd: float) -> S:
    """`calibrate`'s work once its arguments are checked: `prior` uncalibrated, `runs` the user's
    runs as columns (a DataFrame or a mapping of equal-length arrays, load_table's names; NaN where a
    response was not measured)."""
    wanted = [*space.FACTOR_NAMES, *prior.responses]  # other columns (a log's name, notes) are not data
    cols = {c: np.asarray(runs[c], dtype=float) for c in wanted if c in runs.keys()}
    if not cols or not len(cols[space.FACTOR_NAMES[0]]):
        return prior
    n = len(cols[space.FACTOR_NAMES[0]])
    models: dict[str, ResponseSurface] = {}
    for r, base in prior.models.items():
        rows = np.isfinite(cols[r]) if r in cols else np.zeros(n, bool)
        if not rows.any():
            models[r] = base
            continue
        user = {name: cols[name][rows] for name in space.FACTOR_NAMES}
        designs, observed, own = evidence(prior, r, user, cols[r][rows])
        settings = settings_of(prior, r)
        models[r] = CalibratedSurface.from_base(base, designs, observed, own, settings, printer_sd)
    keep = {c: cols[c] for c in [*space.FACTOR_NAMES, *(r for r in prior.responses if r in cols)]}
    return replace(prior, models=models, prior=prior, calibration=CalibrationRecord(keep, printer_sd))


def check_printer_sd(printer_sd: Any) -> float:
    """`printer_sd` as a float in (0, MAX_PRINTER_SD]; raise DesignerError naming it otherwise."""
    if not 0 < number_argument(printer_sd, "printer_sd", example="0.3") <= MAX_PRINTER_SD:
        raise DesignerError(
            f"printer_sd={printer_sd} is not in (0, {MAX_PRINTER_SD:g}]",
            "give e.g. printer_sd=0.3 (a printer factor within about x/÷ 1.8 at 95 %)",
        )
    return float(printer_sd)
