"""Response-surface surrogate of c and k per axis, fitted with CasADi and chosen by leave-one-out.

The forms are in `designer.model.forms`, the ridge fit in `designer.model.ridge`, the selection by
leave-one-out in `designer.model.selection`; this module holds the surrogate of every response, its
report, and its file (JSON, with a calibrated surrogate's own runs beside the study's surfaces).
Predictions carry 95 % prediction intervals.
"""

from __future__ import annotations

import hashlib
import json
from collections.abc import Callable
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path
from typing import Any

from .. import units
from ..errors import DesignerError, check_type, names_argument, path_argument
from ..files import atomic_write
from ..study import space
from . import stored, study_settings
from .calibration_record import CalibrationRecord
from .correction import calibrated, check_printer_sd
from .forms import as_printed, check_designs, check_varied
from .prediction import Prediction, ResponseSurface
from .ridge import ALPHAS
from .selection import select

FORMAT = "flexjoint-surrogate/1"
DEFAULT_NAME = "default.json"


@dataclass
class Surrogate:
    """Per-response surfaces over the six factors, with the table they were fitted to."""

    models: dict[str, ResponseSurface] = field(default_factory=dict)
    table_hash: str = ""
    #: the training runs: the six factors and the responses, in rig units
    training: dict[str, list[float]] = field(default_factory=dict)
    #: the study surrogate a calibrated one was updated from (`designer.calibrate`), else None
    prior: Surrogate | None = None
    #: a calibrated surrogate's user runs and settings (`designer.model.calibration_record`), else None
    calibration: CalibrationRecord | None = None

    @property
    def responses(self) -> list[str]:
        return list(self.models)

    @property
    def axes(self) -> list[str]:
        return [a for a in units.AXES if f"k_{a}" in self.models and f"c_{a}" in self.models]

    @property
    def id(self) -> str:
        """Content hash of the fitted surrogate (form, coefficients and training table).

        Numbers enter the hash at 10 significant digits, so a refit on another machine (another
        BLAS, last-bit differences) gets the same id as the file it reproduces.
        """
        payload = _rounded(json.loads(self._payload_json(include_id=False)))
        return hashlib.sha256(json.dumps(payload, sort_keys=True).encode()).hexdigest()[:16]

    @property
    def table(self):  # -> pandas.DataFrame; pandas imported lazily to keep `suggest` fast
        import pandas as pd

        return pd.DataFrame(self.training)

    def fit(
        self,
        table: Any,
        *,
        responses: list[str] | None = None,
        nested: bool = True,
        progress: Callable[[float], None] | None = None,
    ) -> Surrogate:
        """Fit c and k of every axis in a coefficient table (path or DataFrame, rig units).

        The table goes through `designer.load_table`, so its problems are named with column and row.
        `responses` picks columns such as ["k_x"]; None fits c and k of every axis present.
        `nested` False skips the nested leave-one-out (a report, not part of the fit: the fitted
        surfaces are the same), for callers that refit many times. `progress` is called with the
        fraction of responses fitted (0..1) after each.

        Raises:
            DesignerError: a malformed table (missing factor, NaN, non-positive k), an unknown
                response, fewer than 8 runs, or a factor that takes one value in every run.
        """
        from ..study.data import (
            axes_present,
            check_table_argument,
            coefficient_columns,
            load_table,
            table_hash,
        )

        check_table_argument(table, "table")
        table = load_table(table)
        axes = axes_present(table)
        if responses is None:
            responses = [f"{q}_{a}" for a in axes for q in ("c", "k")]
        responses = names_argument(responses, "responses", example='["k_x"]')
        unknown = [r for r in responses if r not in coefficient_columns(table)]
        if unknown or not responses:
            raise DesignerError(
                f"responses={responses} names column(s) the table lacks: "
                f"{', '.join(unknown) or 'none given'}",
                f"the table has {', '.join(coefficient_columns(table))}",
            )
        if len(table) < 8:
            raise DesignerError(f"the table has {len(table)} runs", "a surrogate needs at least 8")
        X = {n: table[n].to_numpy(dtype=float) for n in space.FACTOR_NAMES}
        check_varied(X)
        self.models = {}
        for i, r in enumerate(responses):
            self.models[r] = select(X, table[r].to_numpy(dtype=float), r, nested=nested)
            if progress is not None:
                progress((i + 1) / len(responses))
        self.prior = self.calibration = None
        self.table_hash = table_hash(table)
        self.training = {c: table[c].astype(float).tolist() for c in list(space.FACTOR_NAMES) + responses}
        self.training["run"] = (
            table["run"].astype(float).tolist()
            if "run" in table.columns
            else list(map(float, range(1, len(table) + 1)))
        )
        return self

    def model(self, response: str) -> ResponseSurface:
        try:
            return self.models[response]
        except KeyError:
            raise DesignerError(
                f"the surrogate has no response '{response}'",
                f"it has {', '.join(self.models)}; fit one on a table with that axis: Surrogate().fit(table)",
            ) from None

    def predict(
        self, designs: Any, *, responses: list[str] | None = None, allow_extrapolation: bool = False
    ) -> dict[str, Prediction]:
        """Predictions with 95 % PIs per response at the designs (rig units).

        Args:
            designs: the six factors, as a DataFrame, a mapping of arrays of shape (n,), or one design
                as a mapping of numbers.
            responses: which responses (e.g. ["k_x"]); None: all.
            allow_extrapolation: accept designs outside the tested ranges (flagged by the caller).

        Returns:
            {response: Prediction} with arrays of shape (n,).

        Raises:
            DesignerError: the surrogate is not fitted, a factor is missing, not a number or out of
                range, or a response is unknown.
        """
        if not self.models:
            raise DesignerError("the surrogate is not fitted", "call fit(table) or Surrogate.load() first")
        X = as_printed(check_designs(designs, allow_extrapolation))
        if responses is not None:
            responses = names_argument(responses, "responses", example='["k_x"]')
        return {r: self.model(r).predict(X) for r in (responses or self.responses)}

    def _payload_json(self, include_id: bool = True) -> str:
        payload: dict[str, Any] = {"format": FORMAT}
        if include_id:
            payload["id"] = self.id
        payload |= {
            "table_hash": self.table_hash,
            "n_runs": len(next(iter(self.training.values()), [])),
            "factors": {
                f.name: {
                    "unit": f.unit,
                    "low": f.low,
                    "high": f.high,
                    "levels": list(f.levels),
                    "categorical": f.categorical,
                }
                for f in space.FACTORS
            },
            "alphas": list(ALPHAS),
            "responses": {r: m.to_dict() for r, m in self.models.items()},
            "training": self.training,
        }
        if self.calibration is not None:
            payload["calibration"] = _calibration_payload(self)
        return json.dumps(payload, indent=1)

    def report(self) -> dict[str, Any]:
        """What the fit found, as plain data: per response its form, nested and own leave-one-out
        accuracy (labelled), influential runs, lack of fit where the table has replicates."""
        runs = self.training["run"]
        return {
            "surrogate_id": self.id,
            "table_hash": self.table_hash,
            "n_runs": len(runs),
            "responses": {
                r: {
                    "form": m.form,
                    "unit": m.unit,
                    "alpha": m.alpha,
                    "predictable": m.predictable,
                    "loo_nested": m.loo_nested,
                    "loo": m.loo,
                    "loo_label": "the selected form's own leave-one-out (optimistic: the form was chosen on "
                    "these errors); loo_nested repeats the whole selection without each run",
                    "influence": [d | {"run": int(runs[d["row"]])} for d in m.influence],
                    "lack_of_fit": m.lack_of_fit,
                    "candidates": m.candidates,
                }
                for r, m in self.models.items()
            },
        }

    def save(self, path: str | Path) -> Path:
        path = path_argument(path, "path", what="a .json file")
        with atomic_write(path) as fh:
            fh.write(self._payload_json() + "\n")
        return Path(path)

    @classmethod
    def load(cls, path: str | Path | None = None) -> Surrogate:
        """Read a surrogate saved by `save` (None: the one shipped, fitted to the bundled table).

        Raises:
            DesignerError: the file is missing, unreadable or not a surrogate.
        """
        p = default_path() if path is None else path_argument(path, "path", what="a surrogate .json file")
        try:
            d = json.loads(p.read_text())
        except FileNotFoundError:
            raise DesignerError(f"no such surrogate: {p}", "give a file written by designer fit") from None
        except RecursionError:
            raise DesignerError(f"surrogate {p} is nested too deeply to be one", stored.FIX) from None
        except (OSError, ValueError) as exc:
            raise DesignerError(f"cannot read surrogate {p}: {exc}", stored.FIX) from None
        if not isinstance(d, dict) or d.get("format") != FORMAT:
            raise DesignerError(f"{p} is not a {FORMAT} surrogate", stored.FIX)
        try:
            surrogate = cls.from_payload(d)
        except DesignerError as exc:
            raise DesignerError(f"surrogate {p}: {exc.problem}", stored.FIX) from None
        study_settings.attach(surrogate)  # the shipped study's calibration settings, not fitted again
        if "calibration" not in d:
            return surrogate
        return _recalibrate(surrogate, d["calibration"], p)

    @classmethod
    def from_payload(cls, d: dict[str, Any]) -> Surrogate:
        """The study surrogate of a parsed surrogate file, every value and shape checked.

        Raises:
            DesignerError: naming the key and what it holds.
        """
        responses = stored.mapping(d.get("responses"), "responses")
        if not responses:
            raise stored.bad("responses", "is empty")
        for r in responses:
            stored.check_response_name(r)
        training = stored.training_values(d.get("training"), list(responses))
        n_runs = len(training["run"])
        models = {r: ResponseSurface.from_dict(r, m, n_runs) for r, m in responses.items()}
        for model in models.values():
            stored.check_predictions(model, training)
        if not isinstance(d.get("table_hash"), str):
            raise stored.bad("table_hash", "is not a string")
        return cls(models=models, table_hash=d["table_hash"], training=training)


def _calibration_payload(surrogate: Surrogate) -> dict[str, Any]:
    """A calibrated surrogate's user runs and settings, as saved beside the study's surfaces."""
    cal = surrogate.calibration or {}
    settings = {r: m.settings() for r, m in surrogate.models.items() if hasattr(m, "settings")}
    return {
        "printer_sd": cal["printer_sd"],
        "runs": {c: [None if v != v else float(v) for v in column] for c, column in cal["columns"].items()},
        "settings": settings,
    }


def _recalibrate(prior: Surrogate, d: Any, path: Path) -> Surrogate:
    """Rebuild a saved calibrated surrogate: its study surfaces updated again by its saved runs."""
    try:
        runs = stored.calibration_runs(d["runs"], prior.responses)
        return calibrated(prior, runs, check_printer_sd(float(d["printer_sd"])))
    except DesignerError as exc:
        raise DesignerError(f"surrogate {path}: {exc.problem}", exc.fix) from None
    except (KeyError, TypeError, ValueError, OverflowError) as exc:
        raise DesignerError(
            f"the calibration block of {path} is incomplete ({exc})",
            "recalibrate it with designer calibrate",
        ) from None


def _rounded(obj: Any) -> Any:
    """`obj` (parsed JSON) with every float rounded to 10 significant digits."""
    if isinstance(obj, float):
        return float(f"{obj:.10g}")
    if isinstance(obj, dict):
        return {k: _rounded(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_rounded(v) for v in obj]
    return obj


def default_path() -> Path:
    return Path(str(resources.files("designer.surrogates") / DEFAULT_NAME))


def check_surrogate(value: Any, name: str = "surrogate") -> None:
    """Raise unless `value` is a fitted Surrogate.

    Raises:
        DesignerError: naming the argument `name`, e.g. for `designer.suggest(None)`.
    """
    fix = "give Surrogate.load() (the shipped one) or Surrogate().fit(table)"
    check_type(value, Surrogate, name, expected="a Surrogate", fix=fix)
    if not value.models:
        raise DesignerError(f"{name} is not fitted", fix)
