"""Where an exported joint comes from: numbers typed by hand, a design via the surrogate, a suggestion."""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from .. import space, units
from ..errors import DesignerError
from ..joint import AxisCoefficients, Joint, rotational_from_translational


def _check_axes(axes: Sequence[str]) -> list[str]:
    out = [units.check_axis(a) for a in axes]
    if len(set(out)) != len(out):
        raise DesignerError(f"axis given twice in {', '.join(out)}", "give each --axis once")
    return out


def from_numbers(
    axes: Sequence[str],
    k: Sequence[float],
    c: Sequence[float],
    m: Sequence[float] = (),
    name: str = "FlexJoint",
) -> Joint:
    """A joint from rig-unit coefficients, one k and one c (and optionally one m) per axis, in order."""
    axes = _check_axes(axes)
    if len(k) != len(axes) or len(c) != len(axes) or len(m) not in (0, len(axes)):
        raise DesignerError(
            f"{len(axes)} axis/axes but {len(k)} --k, {len(c)} --c and {len(m)} --m",
            "give one --k and one --c per --axis (and one --m per axis, or none), in the same order",
        )
    coefficients = {
        a: AxisCoefficients(axis=a, k=float(k[i]), c=float(c[i]), m=float(m[i]) if m else None)
        for i, a in enumerate(axes)
    }
    return Joint(name=name, axes=coefficients, provenance={"source": "entered by hand"})


def _axes_from(
    base: dict[str, AxisCoefficients], wanted: Sequence[str], length_mm: float
) -> dict[str, AxisCoefficients]:
    """The wanted axes from the predicted ones; a rotational axis not predicted comes from the PRB model."""
    out = {}
    for a in _check_axes(wanted):
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


def from_design(
    params: Mapping[str, float],
    axes: Sequence[str] = ("x",),
    name: str = "FlexJoint",
    allow_extrapolation: bool = False,
    surrogate: Any = None,
) -> Joint:
    """A joint predicted by the surrogate for a design; PIs, print settings and mass in provenance."""
    params = space.validate(params, allow_extrapolation)
    if surrogate is None:
        from ..surrogate import Surrogate

        surrogate = Surrogate.load_default()
    import pandas as pd

    pred = surrogate.predict(pd.DataFrame([params]))
    base = {}
    for a in units.AXES:
        if f"k_{a}" not in surrogate.responses or f"c_{a}" not in surrogate.responses:
            continue
        k, c = pred[f"k_{a}"], pred[f"c_{a}"]
        base[a] = AxisCoefficients(
            axis=a,
            k=float(k.value[0]),
            c=float(c.value[0]),
            k_pi95=(float(k.lo[0]), float(k.hi[0])),
            c_pi95=(float(c.lo[0]), float(c.hi[0])),
            origin=f"predicted by surrogate {surrogate.id} from the print settings",
        )
    prov = {
        "source": f"surrogate {surrogate.id} prediction from print settings",
        "params": params,
        "surrogate": surrogate.id,
        "notes": []
        if not allow_extrapolation
        else ["extrapolation allowed: the design may lie outside the data"],
    }
    return Joint(name=name, axes=_axes_from(base, axes, params["length"]), provenance=prov).with_masses()


def from_suggestion(
    path: str | Path, candidate: int = 1, axes: Sequence[str] | None = None, name: str = "FlexJoint"
) -> Joint:
    """A joint from `designer suggest --json` output: candidate N (1 = best), its predictions and PIs."""
    path = Path(path)
    try:
        data = json.loads(path.read_text())
        axis = units.check_axis(data["axis"])
        candidates = data["candidates"]
    except (OSError, ValueError, KeyError, TypeError) as exc:
        raise DesignerError(
            f"cannot read a suggestion from {path}: {exc}", "give the output of 'designer suggest --json'"
        ) from None
    if not 1 <= candidate <= len(candidates):
        raise DesignerError(
            f"candidate {candidate} does not exist in {path}", f"choose 1 to {len(candidates)}"
        )
    cand = candidates[candidate - 1]
    try:
        params = space.validate(cand["params"], allow_extrapolation=True)
        k, c = cand["predicted"]["k"], cand["predicted"]["c"]
        base = {
            axis: AxisCoefficients(
                axis=axis,
                k=float(k["value"]),
                c=float(c["value"]),
                k_pi95=tuple(k["pi95"]) if k.get("pi95") else None,
                c_pi95=tuple(c["pi95"]) if c.get("pi95") else None,
                origin=f"predicted for candidate {candidate} of {path.name}",
            )
        }
    except (KeyError, TypeError) as exc:
        raise DesignerError(
            f"candidate {candidate} in {path} lacks {exc}", "give the output of 'designer suggest --json'"
        ) from None
    prov = {
        "source": f"suggestion {path.name}, candidate {candidate}",
        "params": params,
        "targets": data.get("targets"),
        "desirability": cand.get("desirability"),
        "reachable": data.get("reachable"),
    }
    return Joint(
        name=name, axes=_axes_from(base, axes or [axis], params["length"]), provenance=prov
    ).with_masses()
