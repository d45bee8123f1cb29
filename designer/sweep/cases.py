"""The cases of a sweep, as plain data: per joint k and c on its axis (rig units), plus descriptive inputs.

Cases are generated in the calling process (seeded), so every executor evaluates the same numbers;
each case carries a key, a hash of its coefficients and of everything else its result depends on
(the scenario and the evaluation path), by which a rerun recognises finished cases.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

import numpy as np

from .. import units
from ..cosim.scenario import JointSource
from ..errors import DesignerError
from ..files import format_bytes
from ..limits import check_memory
from ..model.surrogate import Surrogate
from ..study import space
from .draws import joint_draws, on_axis, source_axis
from .spec import Spec


@dataclass(frozen=True)
class Case:
    """One case: `coefficients` {joint: {"k", "c"}} in rig units on each joint's axis; `inputs` the
    descriptive columns (print settings, candidate numbers, surrogate-axis draws); `key` its hash."""

    index: int
    coefficients: dict[str, dict[str, float]]
    inputs: dict[str, float] = field(default_factory=dict)
    key: str = ""


def context_key(spec: Spec) -> str:
    """Hash of what every case's result depends on besides its coefficients: scenario and path."""
    with np.printoptions(threshold=2**31, precision=17):
        text = repr(spec.scenario) + spec.path
    return hashlib.sha256(text.encode()).hexdigest()


def finish(cases: list[Case], spec: Spec) -> list[Case]:
    """The cases with k and c for every scenario joint (the scenario's own where a case leaves a joint
    alone) and their keys: a hash of the coefficients and of the spec's context."""
    context = context_key(spec)
    base = {j: base_coefficients(src) for j, src in spec.scenario.sources().items()}
    out = []
    for case in cases:
        coefficients = {j: case.coefficients.get(j, base[j]) for j in base}
        payload = json.dumps({"c": coefficients, "ctx": context}, sort_keys=True)
        out.append(
            replace(case, coefficients=coefficients, key=hashlib.sha256(payload.encode()).hexdigest()[:20])
        )
    return out


def si_law(src: JointSource, coefficients: dict[str, float]) -> dict[str, float]:
    """The SI k and c of a case's joint (rig units in, on the joint's axis)."""
    return {q: units.to_si(q, src.axis, coefficients[q]) for q in ("k", "c")}


def base_coefficients(src: JointSource) -> dict[str, float]:
    """The k and c (rig units, the joint's axis) a scenario joint runs with when a case leaves it alone."""
    if src.joint is not None:
        ac = src.joint.axis(src.axis)
        out = {"k": ac.k, "c": ac.c}
    else:
        from ..cosim.fmu import read_parameters

        si = read_parameters(src.fmu, src.axis)
        out = {q: units.from_si(q, src.axis, si[q]) for q in ("k", "c")}
    for q in ("k", "c"):
        if f"{src.axis}.{q}" in src.parameters:
            out[q] = units.from_si(q, src.axis, float(src.parameters[f"{src.axis}.{q}"]))
    return out


def design_of(spec: Spec, joint: str) -> dict[str, float]:
    """The print settings of a joint: given in the sweep, or those its scenario joint was built from."""
    if joint in spec.cases.designs:
        return space.check_design(spec.cases.designs[joint])
    src = spec.scenario.sources()[joint]
    params = None if src.joint is None else src.joint.provenance.get("params")
    params = params or spec.scenario.factors_of(joint)
    if params is None:
        raise DesignerError(
            f"joint {joint} has no print settings to vary or draw around",
            f"give the scenario joint a design or a suggestion, or add [cases.designs.{joint}]",
        )
    return dict(params)


def load_surrogate(spec: Spec) -> Surrogate:
    return Surrogate.load(spec.surrogate)


def _predicted(surrogate: Surrogate, design: dict[str, float], axis: str) -> dict[str, float]:
    src = source_axis(surrogate, axis)
    pred = surrogate.predict(design, responses=[f"k_{src}", f"c_{src}"])
    predicted = (float(pred[f"k_{src}"].value[0]), float(pred[f"c_{src}"].value[0]))
    k, c = on_axis(predicted, source=src, axis=axis, length_mm=design["length"])
    return {"k": k, "c": c}


def grid(spec: Spec) -> list[Case]:
    """Every combination of the grid's values; print settings go through the surrogate (predicted values)."""
    axes = [(j, q, values) for j, table in spec.cases.joints.items() for q, values in table.items()]
    surrogate = None
    for j, table in spec.cases.joints.items():
        keys = set(table)
        if keys <= {"k", "c"}:
            continue
        bad = keys - set(space.FACTOR_NAMES)
        if bad or keys & {"k", "c"}:
            raise DesignerError(
                f"grid of joint {j} mixes or misnames keys: {', '.join(sorted(keys))}",
                f"vary k and c, or print settings ({', '.join(space.FACTOR_NAMES)}), not both",
            )
        surrogate = surrogate or load_surrogate(spec)
    cases = []
    for i, combo in enumerate(itertools.product(*[values for _, _, values in axes])):
        chosen: dict[str, dict[str, float]] = {}
        for (j, q, _), v in zip(axes, combo, strict=True):
            chosen.setdefault(j, {})[q] = v
        coefficients, inputs = {}, {}
        for j, values in chosen.items():
            inputs.update({f"{j}.{q}": v for q, v in values.items()})
            if set(values) <= {"k", "c"}:
                coefficients[j] = base_coefficients(spec.scenario.sources()[j]) | values
            else:
                design = space.check_design(design_of(spec, j) | values)
                coefficients[j] = _predicted(surrogate, design, spec.scenario.sources()[j].axis)
        cases.append(Case(i, coefficients, inputs))
    return cases


def suggestion(spec: Spec) -> list[Case]:
    """One case per combination of suggestion candidates over the sweep's joints."""
    from ..joint import Joint

    path: Path = spec.cases.file
    from ..design.candidates import Suggestion

    n = len(Suggestion.load(path).candidates)
    numbers = spec.cases.candidates or tuple(range(1, n + 1))
    joints = list(spec.cases.joints)
    cases = []
    for i, combo in enumerate(itertools.product(numbers, repeat=len(joints))):
        coefficients, inputs = {}, {}
        for j, cand in zip(joints, combo, strict=True):
            src = spec.scenario.sources()[j]
            joint = Joint.from_suggestion(path, candidate=cand, axes=[src.axis], name=f"joint_{j}")
            ac = joint.axis(src.axis)
            coefficients[j] = {"k": ac.k, "c": ac.c}
            inputs[f"{j}.candidate"] = float(cand)
            inputs.update({f"{j}.{f}": float(v) for f, v in joint.provenance["params"].items()})
        cases.append(Case(i, coefficients, inputs))
    return cases


def montecarlo(spec: Spec) -> list[Case]:
    """`n` seeded draws of every chosen joint's k and c from the surrogate's predictive distribution."""
    surrogate = load_surrogate(spec)
    rng = np.random.default_rng(spec.cases.seed)
    n = spec.cases.n
    draws = {}
    for j in spec.cases.joints:
        draws[j] = joint_draws(
            surrogate, design=design_of(spec, j), axis=spec.scenario.sources()[j].axis, n=n, rng=rng
        )
    cases = []
    for i in range(n):
        coefficients = {j: {"k": float(d["k"][i]), "c": float(d["c"][i])} for j, d in draws.items()}
        inputs = {
            f"{j}.{q}": float(v[i]) for j, d in draws.items() for q, v in d.items() if q not in ("k", "c")
        }
        cases.append(Case(i, coefficients, inputs))
    return cases


#: the most cases a sweep builds unless told otherwise (`max_cases`): a million co-simulations are
#: hours on a cluster; more is usually a grid with one axis too many
MAX_CASES = 1_000_000
#: memory per case planned for: the case and its result row (measured 1.5 kB for a two-joint grid's
#: cases and rows of ten values; the summary's table and the metrics columns take more)
BYTES_PER_CASE = 4096


def case_count(spec: Spec) -> int:
    """How many cases `spec` makes, counted without building them."""
    c = spec.cases
    if c.type == "grid":
        return math.prod(len(values) for table in c.joints.values() for values in table.values())
    if c.type == "suggestion":
        from ..design.candidates import Suggestion

        numbers = len(c.candidates) or len(Suggestion.load(c.file).candidates)
        return numbers ** len(c.joints)
    return c.n


def check_size(spec: Spec, max_cases: int = MAX_CASES) -> int:
    """The number of cases, checked before any is built: at most `max_cases`, and their memory within
    what the machine has.

    Raises:
        DesignerError: more cases than `max_cases` (naming the count, its memory and the argument
            that allows more), or more memory than available.
    """
    n = case_count(spec)
    need = format_bytes(n * BYTES_PER_CASE)
    if n > max_cases:
        raise DesignerError(
            f"the sweep makes {n:.3g} cases (about {need} of memory, each a co-simulation of "
            f"{spec.scenario.duration:g} s), more than the {max_cases} a sweep makes unless told",
            f"vary fewer values, or pass max_cases={n} if that many are meant",
        )
    check_memory(n * BYTES_PER_CASE, what=f"a sweep of {n:.3g} cases", fix="vary fewer values")
    return n


def make_cases(spec: Spec, *, max_cases: int = MAX_CASES) -> list[Case]:
    """The spec's cases, each keyed by its hash.

    Raises:
        DesignerError: as `check_size`, before any case is built; a bad grid key or suggestion file.
    """
    check_size(spec, max_cases)
    made = {"grid": grid, "suggestion": suggestion, "montecarlo": montecarlo}[spec.cases.type](spec)
    return finish(made, spec)
