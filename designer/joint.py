"""A flexible joint: per-axis m, c, k in rig units with their provenance, and its SI view.

A `Joint` is what every exporter (FMU, Modelica, MJCF, URDF) and the co-simulation consume. It is
built from coefficients typed by hand, from a design through the surrogate, or from a suggestion.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from . import units
from .errors import DesignerError, check_type, describe, number_argument, path_argument
from .files import display_path
from .mass import specimen_mass
from .study import space

if TYPE_CHECKING:
    from .design.candidates import Suggestion
    from .model.prediction import Prediction
    from .model.surrogate import Surrogate

#: Howell's pseudo-rigid-body characteristic radius factor for a fixed-guided/cantilever beam
PRB_GAMMA = 0.85


#: largest m, c or k in rig units a joint may have (1e9 N/mm is 1e12 N/m, stiffer than a 10 mm steel
#: cube, ~2e9 N/m); above it a number is a unit mistake, and squared in a simulation it overflows
MAX_COEFFICIENT = 1e9
#: smallest non-zero m, c or k in rig units (as for coefficient tables): below it, a subnormal such as
#: 5e-324 is a typing or unit mistake, not a joint (its natural frequency and time step underflow)
MIN_COEFFICIENT = 1e-12


@dataclass(frozen=True)
class AxisCoefficients:
    """One axis of a joint in rig units; `m` may be None (force element needs none)."""

    axis: str
    k: float
    c: float
    m: float | None = None
    #: "k" and "c" as predicted by the surrogate (value and 95 % PI), when they come from it
    predicted: Mapping[str, Prediction] = field(default_factory=dict)
    #: where these numbers come from, e.g. "measured", "surrogate", "derived (PRB model)"
    origin: str = "entered by hand"

    def __post_init__(self) -> None:
        units.check_axis(self.axis)
        for q in ("k", "c", "m"):
            v = getattr(self, q)
            if v is None:
                continue
            if not math.isfinite(v) or v < 0 or (q != "c" and v == 0):
                raise DesignerError(
                    f"{q} on axis {self.axis} = {v:g} {units.rig_unit(q, self.axis)} is not a valid value",
                    f"give a finite, {'non-negative' if q == 'c' else 'positive'} number",
                )
            object.__setattr__(self, q, v + 0.0)  # -0.0 is 0: never written as "-0" into an FMU
            if 0 < v < MIN_COEFFICIENT:
                unit = units.rig_unit(q, self.axis)
                raise DesignerError(
                    f"{q} on axis {self.axis} = {v:g} {unit} is below any physical joint",
                    f"give it in rig units, at least {MIN_COEFFICIENT:g} {unit}"
                    + (" (or 0 for no damping)" if q == "c" else ""),
                )
            if v > MAX_COEFFICIENT:
                unit = units.rig_unit(q, self.axis)
                raise DesignerError(
                    f"{q} on axis {self.axis} = {v:g} {unit} is beyond any physical joint",
                    f"give it in rig units, at most {MAX_COEFFICIENT:g} {unit}",
                )

    def si(self) -> dict[str, float | None]:
        """m, c, k in SI units (kg or kg.m^2; N.s/m or N.m.s/rad; N/m or N.m/rad)."""
        return {
            "m": None if self.m is None else units.to_si("m", self.axis, self.m),
            "c": units.to_si("c", self.axis, self.c),
            "k": units.to_si("k", self.axis, self.k),
        }


@dataclass(frozen=True)
class Joint:
    """A joint: its axes and a provenance record (print settings, surrogate id, PIs, notes)."""

    name: str
    axes: dict[str, AxisCoefficients]
    provenance: dict[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not self.axes:
            raise DesignerError("a joint needs at least one axis", "give axes={'x': JointAxis(...)}")
        check_type(self.name, str, "name", expected="a str", fix="give e.g. name='knee'")
        if not self.name.isidentifier():
            raise DesignerError(
                f"joint name '{self.name}' is not an identifier",
                "use letters, digits and underscores, starting with a letter",
            )

    @classmethod
    def from_coefficients(
        cls, coefficients: Mapping[str, Mapping[str, float | None]], *, name: str = "FlexJoint"
    ) -> Joint:
        """A joint from numbers in rig units: {axis: {"k": .., "c": .., "m": ..}} (m optional).

        k in N/mm (N.mm/rad), c in N.s/mm (N.mm.s/rad), m in kg (kg.m^2) per DESIGN.md.

        Raises:
            DesignerError: an unknown axis, a missing k or c, or a value that is not finite and positive.
        """
        fix = "give coefficients={'x': {'k': 0.8, 'c': 2e-3}} in rig units"
        check_type(coefficients, Mapping, "coefficients", expected="a mapping of axes", fix=fix)
        axes = {}
        for a, v in coefficients.items():
            if not isinstance(v, Mapping) or not {"k", "c"} <= set(v):
                raise DesignerError(
                    f"coefficients[{a!r}] = {v!r} needs k and c",
                    "give coefficients={'x': {'k': 0.8, 'c': 2e-3}} in rig units",
                )
            unknown = set(v) - {"k", "c", "m"}
            if unknown:
                raise DesignerError(
                    f"coefficients[{a!r}] has unknown key(s) {', '.join(sorted(unknown))}", "use k, c and m"
                )
            m = v.get("m")
            axes[a] = AxisCoefficients(
                axis=a,
                k=_number(v["k"], f"{a}.k"),
                c=_number(v["c"], f"{a}.c"),
                m=None if m is None else _number(m, f"{a}.m"),
            )
        return cls(name=name, axes=axes, provenance={"source": "entered by hand"})

    @classmethod
    def from_design(
        cls,
        params: Mapping[str, float],
        *,
        surrogate: Surrogate | None = None,
        axes: Sequence[str] = ("x",),
        name: str = "FlexJoint",
        allow_extrapolation: bool = False,
    ) -> Joint:
        """A joint predicted by the surrogate for the six print settings `params` (rig units).

        The surrogate's 95 % PIs, the print settings and the mass from geometry go into the joint; a
        rotational axis asked of a translational surrogate comes from the pseudo-rigid-body model.
        `surrogate` None: the shipped default.

        Raises:
            DesignerError: a factor missing or out of its tested range (unless `allow_extrapolation`),
                an axis the surrogate cannot give.
        """
        if not hasattr(params, "items"):  # a Mapping or a pandas Series of the six factors
            fix = "give params={'density': 60, 'length': 24, 'width': 4.5, ...} with all six factors"
            raise DesignerError(f"params is {describe(params)}, not a mapping of factors", fix)
        params = space.check_design(params, allow_extrapolation)
        from .model.surrogate import Surrogate

        if surrogate is None:
            surrogate = Surrogate.load()
        if not callable(getattr(surrogate, "predict", None)):  # any object with Surrogate's interface
            fix = "give Surrogate.load() (the shipped one) or Surrogate().fit(table)"
            raise DesignerError(f"surrogate is {describe(surrogate)}, not a Surrogate", fix)
        pred = surrogate.predict({n: [v] for n, v in params.items()}, allow_extrapolation=True)
        base = {
            a: AxisCoefficients(
                axis=a,
                k=float(pred[f"k_{a}"].value[0]),
                c=float(pred[f"c_{a}"].value[0]),
                predicted={q: pred[f"{q}_{a}"].at(0) for q in ("k", "c")},
                origin=f"predicted by surrogate {surrogate.id} from the print settings",
            )
            for a in surrogate.axes
        }
        prov = {
            "source": f"surrogate {surrogate.id} prediction from print settings",
            "params": params,
            "surrogate": surrogate.id,
            "notes": ["extrapolation allowed: the design may lie outside the data"]
            if allow_extrapolation
            else [],
        }
        return cls(name=name, axes=_axes_from(base, axes, params["length"]), provenance=prov).with_masses()

    @classmethod
    def from_suggestion(
        cls,
        suggestion: Suggestion | str | Path,
        *,
        candidate: int = 1,
        axes: Sequence[str] | None = None,
        name: str = "FlexJoint",
    ) -> Joint:
        """A joint from candidate `candidate` (1 = best) of a suggestion, or of its saved JSON file.

        Raises:
            DesignerError: the file is not a suggestion, or the candidate does not exist.
        """
        from .design.candidates import Suggestion

        where = "the suggestion"
        if not isinstance(suggestion, Suggestion):
            path = path_argument(suggestion, "suggestion", what="a suggestion (designer suggest --json)")
            where = f"suggestion {display_path(path.name)}"
            suggestion = Suggestion.load(path)
        n = len(suggestion.candidates)
        if not 1 <= number_argument(candidate, "candidate", example="1 (the best)") <= n:
            raise DesignerError(
                f"candidate {candidate} does not exist in {where}",
                f"choose 1 to {n}" if n else "the suggestion has no candidates",
            )
        cand = suggestion.candidates[candidate - 1]
        params = space.check_design(cand.params, allow_extrapolation=True)
        a = suggestion.axis
        base = {
            a: AxisCoefficients(
                axis=a,
                k=float(cand.predicted["k"].value),
                c=float(cand.predicted["c"].value),
                predicted=dict(cand.predicted),
                origin=f"predicted for candidate {candidate} of {where}",
            )
        }
        prov = {
            "source": f"{where.removeprefix('the ')}, candidate {candidate}",
            "params": params,
            "surrogate": suggestion.surrogate_id,
            "targets": {q: t.goal for q, t in suggestion.targets.items()},
            "desirability": cand.desirability,
            "reachable": suggestion.reachable,
        }
        return cls(
            name=name, axes=_axes_from(base, axes or [a], params["length"]), provenance=prov
        ).with_masses()

    def axis(self, name: str) -> AxisCoefficients:
        try:
            return self.axes[units.check_axis(name)]
        except KeyError:
            raise DesignerError(
                f"joint '{self.name}' has no axis '{name}'",
                f"it has: {', '.join(self.axes)}; use one of those, or build the joint on axis '{name}' too",
            ) from None

    def with_masses(self) -> Joint:
        """Fill missing masses from the design's geometry; an error if there is no design."""
        params = self.provenance.get("params")
        out = {}
        for a, ac in self.axes.items():
            if ac.m is not None:
                out[a] = ac
                continue
            if params is None:
                raise DesignerError(
                    f"axis {a} of joint '{self.name}' has no mass",
                    "give m (kg) in its coefficients, or build the joint with Joint.from_design so its "
                    "mass follows from geometry",
                )
            m = specimen_mass(params)
            if units.is_rotational(a):
                m = m * (PRB_GAMMA * params["length"] * units.MM) ** 2
            out[a] = replace(ac, m=m)
        prov = dict(self.provenance)
        prov.setdefault("notes", [])
        prov["notes"] = list(prov["notes"]) + [
            "mass from geometry: 0.8 mm solid walls, infilled core, TPU 1210 kg/m^3"
        ]
        return replace(self, axes=out, provenance=prov)

    def to_dict(self) -> dict[str, Any]:
        """Plain data (rig units and SI) for joint.json and --json output."""
        return {
            "name": self.name,
            "axes": {
                a: {
                    "rig": {"k": ac.k, "c": ac.c, "m": ac.m},
                    "predicted": {q: p.to_dict() for q, p in ac.predicted.items()},
                    "rig_units": {q: units.rig_unit(q, a) for q in ("k", "c", "m")},
                    "si": ac.si(),
                    "si_units": {q: units.si_unit(q, a) for q in ("k", "c", "m")},
                    "origin": ac.origin,
                }
                for a, ac in self.axes.items()
            },
            "provenance": self.provenance,
        }


def rotational_from_translational(ac: AxisCoefficients, axis: str, length_mm: float) -> AxisCoefficients:
    """Pseudo-rigid-body conversion: K_rot = k (gamma L)^2, likewise c and the inertia of m."""
    if units.is_rotational(ac.axis) or not units.is_rotational(axis):
        raise DesignerError(
            f"cannot derive axis {axis} from axis {ac.axis}",
            "the PRB conversion maps a translational axis onto a rotational one",
        )
    arm_mm = PRB_GAMMA * length_mm
    scale = arm_mm**2  # N/mm * mm^2 = N.mm/rad

    return AxisCoefficients(
        axis=axis,
        k=ac.k * scale,
        c=ac.c * scale,
        m=None if ac.m is None else ac.m * (arm_mm * units.MM) ** 2,
        predicted={q: p.scaled(scale) for q, p in ac.predicted.items()},
        origin=f"derived, not measured: pseudo-rigid-body model from axis {ac.axis}, "
        f"K = k (gamma L)^2, gamma = {PRB_GAMMA}, L = {length_mm:g} mm",
    )


def _number(value: Any, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise DesignerError(f"coefficient {where} = {value!r} is not a number", "give a finite number")
    return float(value)


def check_joint(value: Any, name: str = "joint") -> None:
    """Raise unless `value` is a Joint.

    Raises:
        DesignerError: naming the argument `name` (e.g. `export_fmu(None, ...)`).
    """
    fix = "make one with Joint.from_coefficients, Joint.from_design or Joint.from_suggestion"
    check_type(value, Joint, name, expected="a Joint", fix=fix)


def _axes_from(
    base: Mapping[str, AxisCoefficients], wanted: Sequence[str], length_mm: float
) -> dict[str, AxisCoefficients]:
    """The wanted axes from the predicted ones; a rotational axis not predicted comes from the PRB model."""
    if isinstance(wanted, str):  # axes="theta": one axis
        wanted = [wanted]
    check_type(wanted, Sequence, "axes", expected="a list of axes", fix="give e.g. axes=['x', 'theta']")
    out: dict[str, AxisCoefficients] = {}
    for a in wanted:
        a = units.check_axis(a)
        if a in out:
            raise DesignerError(f"axis {a} is asked for twice in axes={list(wanted)}", "give each axis once")
        if a in base:
            out[a] = base[a]
        elif units.is_rotational(a) and any(not units.is_rotational(b) for b in base):
            source = next(b for b in base if not units.is_rotational(b))
            out[a] = rotational_from_translational(base[source], a, length_mm)
        else:
            raise DesignerError(
                f"there are no coefficients for axis {a}",
                f"available: {', '.join(base)} (a rotational axis can be derived from a translational one)",
            )
    return out


def from_one_source(
    *,
    coefficients: Mapping[str, Mapping[str, float | None]] | None = None,
    design: Mapping[str, float] | None = None,
    suggestion: Suggestion | str | Path | None = None,
    candidate: int = 1,
    axes: Sequence[str] | None = None,
    name: str = "FlexJoint",
    allow_extrapolation: bool = False,
    surrogate: Surrogate | None = None,
) -> Joint:
    """The joint from exactly one of `coefficients`, `design` or `suggestion` (the rule every caller shares).

    Raises:
        DesignerError: none or several sources given, or the chosen source is invalid.
    """
    given = [
        n for n, v in (("coefficients", coefficients), ("design", design), ("suggestion", suggestion)) if v
    ]
    if len(given) != 1:
        raise DesignerError(
            "give the joint one way: " + (f"got {' and '.join(given)}" if given else "none given"),
            "give exactly one of coefficients=, design= or suggestion=",
        )
    if coefficients:
        if axes is not None and list(axes) != list(coefficients):
            raise DesignerError(
                f"axes={list(axes)} differ from the axes of coefficients ({', '.join(coefficients)})",
                "leave axes out: the coefficients name their axes",
            )
        return Joint.from_coefficients(coefficients, name=name)
    if design:
        return Joint.from_design(
            design,
            surrogate=surrogate,
            axes=axes or ("x",),
            name=name,
            allow_extrapolation=allow_extrapolation,
        )
    return Joint.from_suggestion(suggestion, candidate=candidate, axes=axes, name=name)
