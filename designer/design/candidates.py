"""A suggestion and its candidate designs, as data and as the JSON a user keeps and passes on."""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from .. import units
from ..errors import DesignerError, describe
from ..model.prediction import Prediction
from ..study import space
from .targets import TOLERANCE, Target


@dataclass
class Candidate:
    """One design: the six print settings, the predicted k and c, and how well it meets the goals.

    `p_within`: probability that a printed joint meets every predictable target within the
    tolerance (None without such a target); `probability`: the same per response with a target;
    `desirability`: composite D over the predictable responses (None without one); `any`: factors
    with no effect on this design (density when the walls fill the section; `params` then holds the
    value predicted with, 100 % = solid); `extrapolated`: factors outside their tested range.
    """

    params: dict[str, float]
    predicted: dict[str, Prediction]
    desirability: float | None
    rel_error: dict[str, float]
    extrapolated: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    p_within: float | None = None
    probability: dict[str, float] = field(default_factory=dict)
    any: list[str] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        return {
            "params": self.params,
            "any": self.any,
            "predicted": {q: p.to_dict() for q, p in self.predicted.items()},
            "p_within": self.p_within,
            "probability": self.probability,
            "desirability": self.desirability,
            "rel_error": self.rel_error,
            "extrapolated": self.extrapolated,
            "notes": self.notes,
        }

    @classmethod
    def from_dict(cls, c: Mapping[str, Any], *, where: str) -> Candidate:
        extra = c.get("extrapolated", [])
        return cls(
            params=space.check_design(c["params"], allow_extrapolation=True),
            predicted={q: Prediction.from_dict(p, where=f"{where} {q}") for q, p in c["predicted"].items()},
            desirability=None if c.get("desirability") is None else float(c["desirability"]),
            rel_error=dict(c.get("rel_error", {})),
            extrapolated=list(extra) if isinstance(extra, list) else (["unknown"] if extra else []),
            notes=list(c.get("notes", [])),
            p_within=None if c.get("p_within") is None else float(c["p_within"]),
            probability=dict(c.get("probability", {})),
            any=list(c.get("any", [])),
        )


@dataclass
class Suggestion:
    """The result of `suggest`: ranked candidates and plain statements about the goals."""

    axis: str
    targets: dict[str, Target]
    candidates: list[Candidate]
    reachable: bool
    statements: list[str]
    predictability: dict[str, dict[str, Any]]
    surrogate_id: str
    fixed: dict[str, float]
    tolerance: float = TOLERANCE
    #: per response with a goal: {"measured": [lo, hi], "predicted": [lo, hi] or None (not computed)}
    ranges: dict[str, dict[str, Any]] = field(default_factory=dict)
    #: measured runs nearest a target the surrogate cannot reach but the data has seen
    nearest_runs: list[dict[str, Any]] = field(default_factory=list)

    def to_dict(self) -> dict[str, Any]:
        def goal(q: str) -> Any:
            t = self.targets.get(q)
            return None if t is None else t.goal

        return {
            "axis": self.axis,
            "units": {q: units.rig_unit(q, self.axis) for q in ("k", "c")},
            "targets": {q: goal(q) for q in ("k", "c")},
            "goals": {q: t.to_dict() for q, t in self.targets.items()},
            "tolerance": self.tolerance,
            "fixed": self.fixed,
            "reachable": self.reachable,
            "statements": self.statements,
            "predictability": self.predictability,
            "ranges": self.ranges,
            "nearest_runs": self.nearest_runs,
            "surrogate_id": self.surrogate_id,
            "candidates": [c.to_dict() for c in self.candidates],
        }

    @classmethod
    def from_dict(cls, d: Mapping[str, Any], *, where: str = "suggestion") -> Suggestion:
        """Read back `to_dict` output (a `designer suggest --json` file); DesignerError when malformed."""
        _check_schema(d, where)
        try:
            axis = units.check_axis(d["axis"])
            goals = d.get("goals") or {
                q: {"kind": "target", "value": v, "low": 0.0, "high": math.inf}
                for q, v in d["targets"].items()
                if v is not None
            }
            targets = {
                q: Target(
                    q,
                    None if g.get("value") is None else float(g["value"]),
                    float(g.get("low", 0.0)),
                    float(g.get("high", math.inf)),
                    float(g.get("importance", 1.0)),
                    str(g.get("kind", "target")),
                    float(g.get("weight", 1.0)),
                )
                for q, g in goals.items()
            }
            candidates = [
                Candidate.from_dict(c, where=f"{where} candidate {i + 1}")
                for i, c in enumerate(d["candidates"])
            ]
            return cls(
                axis,
                targets,
                candidates,
                bool(d.get("reachable", True)),
                list(d.get("statements", [])),
                dict(d.get("predictability", {})),
                str(d.get("surrogate_id", "")),
                dict(d.get("fixed", {})),
                float(d.get("tolerance", TOLERANCE)),
                dict(d.get("ranges", {})),
                list(d.get("nearest_runs", [])),
            )
        except (KeyError, TypeError, ValueError, AttributeError) as exc:
            raise DesignerError(
                f"{where} is not a suggestion (missing or malformed {exc})",
                "use the output of designer.suggest(...).to_dict()",
            ) from None

    @classmethod
    def load(cls, path: str | Path) -> Suggestion:
        """Read a suggestion saved as JSON; DesignerError naming `path` when it cannot be read."""
        import json

        path = Path(path)
        try:
            data = json.loads(path.read_text(encoding="utf-8-sig"))  # a BOM (Windows editors) is fine
        except (OSError, ValueError) as exc:
            raise DesignerError(
                f"cannot read a suggestion from path={str(path)!r}: {exc}",
                "give a JSON file written from Suggestion.to_dict()",
            ) from None
        if not isinstance(data, dict):
            raise DesignerError(
                f"{path.name} is not a suggestion", "give a JSON file written from Suggestion.to_dict()"
            )
        return cls.from_dict(data, where=path.name)


_SUGGESTION_KEYS = (
    "axis", "units", "targets", "goals", "tolerance", "fixed", "reachable", "statements", "predictability",
    "ranges", "nearest_runs", "surrogate_id", "candidates", "desirability_bounds",
)  # fmt: skip
_CANDIDATE_KEYS = (
    "params", "any", "predicted", "p_within", "probability", "desirability", "rel_error", "extrapolated",
    "notes",
)  # fmt: skip


def _check_schema(d: Any, where: str) -> None:
    """The keys of a suggestion dict: required ones present, none unknown (with the closest valid one)."""
    from ..keys import check_keys

    fix = "use the output of designer.suggest(...).to_dict() (designer suggest --json)"
    if not isinstance(d, Mapping):
        raise DesignerError(f"{where} is not a suggestion (a JSON {type(d).__name__}, not an object)", fix)
    missing = [k for k in ("axis", "targets", "candidates") if k not in d]
    if missing:
        has = ", ".join(f"'{k}'" for k in list(d)[:6]) or "nothing"
        absent = ", ".join(map(repr, missing))
        raise DesignerError(f"{where} is not a suggestion: no {absent} (it has {has})", fix)
    check_keys(d, _SUGGESTION_KEYS, where=where)
    _check_types(d, _SUGGESTION_TYPES, where, fix)
    if not isinstance(d["candidates"], list) or not d["candidates"]:
        raise DesignerError(f"{where}: 'candidates' is not a non-empty list", fix)
    for i, c in enumerate(d["candidates"], 1):
        if not isinstance(c, Mapping) or "params" not in c or "predicted" not in c:
            raise DesignerError(f"{where}: candidate {i} has no 'params' and 'predicted'", fix)
        check_keys(c, _CANDIDATE_KEYS, where=f"candidate {i} of {where}")
        _check_types(c, _CANDIDATE_TYPES, f"candidate {i} of {where}", fix)
        for name, v in c["params"].items():  # float() would take "60" and true (1 %) silently
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                raise DesignerError(
                    f"candidate {i} of {where}: {name} = {json_text(v)} is {describe(v)}, not a number",
                    "write the number without quotes, e.g. 60",
                )


#: the JSON types of a suggestion's entries (hand-edited files: "targets": [0.8], "axis": 3)
_SUGGESTION_TYPES = {
    "axis": str, "units": dict, "targets": dict, "goals": dict, "tolerance": (int, float), "fixed": dict,
    "reachable": bool, "statements": list, "predictability": dict, "ranges": dict, "nearest_runs": list,
    "surrogate_id": str, "candidates": list,
}  # fmt: skip
_CANDIDATE_TYPES = {
    "params": dict, "any": list, "predicted": dict, "p_within": (int, float, type(None)),
    "probability": dict, "desirability": (int, float, type(None)), "rel_error": dict,
    "extrapolated": (list, bool), "notes": list,
}  # fmt: skip
_JSON_NAMES = {str: "a string", dict: "an object", list: "a list", bool: "true or false", int: "a number"}


def _check_types(d: Mapping[str, Any], types: Mapping[str, Any], where: str, fix: str) -> None:
    """Raise for the first entry of `d` whose JSON type is not the one `types` gives."""
    for key, want in types.items():
        if key not in d:
            continue
        v = d[key]
        wants = want if isinstance(want, tuple) else (want,)
        numeric = float in wants or int in wants
        if not isinstance(v, wants) or (isinstance(v, bool) and bool not in wants and numeric):
            expected = " or ".join(dict.fromkeys(_JSON_NAMES.get(t, "null") for t in wants))
            raise DesignerError(f"{where}: '{key}' is {json_text(v)}, not {expected}", fix)


def json_text(v: Any) -> str:
    """A JSON value as written in the file, shortened: 3, "x", [0.8], {...}."""
    import json

    text = json.dumps(v, default=str)
    return text if len(text) <= 40 else text[:37] + "..."
