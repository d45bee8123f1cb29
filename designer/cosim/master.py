"""A fixed-step co-simulation master over a connection graph: Gauss-Seidel (default) or Jacobi.

A system exposes `inputs` and `outputs` (names), `feedthrough` (outputs depend on inputs at the same
instant), `get() -> array`, `set(array)` and `do_step(h)`. Gauss-Seidel reads the state-based systems'
outputs at t, then evaluates the feedthrough systems in dependency order (set inputs, read outputs at
the same instant), then sets the remaining inputs and steps everyone: no delay around a loop. Jacobi
reads every output first, so a feedthrough element answers with the inputs of the previous step.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..errors import DesignerError

ALGORITHMS = ("gauss-seidel", "jacobi")


class System(Protocol):
    inputs: list[str]
    outputs: list[str]
    feedthrough: bool

    def get(self) -> np.ndarray: ...
    def set(self, values: np.ndarray) -> None: ...
    def do_step(self, h: float) -> None: ...


@dataclass(frozen=True)
class Trace:
    """Time series of every output, columns named `system.variable`, rows at t = 0, h, ..., N h."""

    time: np.ndarray
    columns: list[str]
    values: np.ndarray

    def column(self, name: str) -> np.ndarray:
        return self.values[:, self.columns.index(name)]


def _order(systems: Mapping[str, System], sources: Mapping[str, set[str]]) -> list[str]:
    """Feedthrough systems sorted so each comes after the feedthrough systems feeding it."""
    pending = [n for n, s in systems.items() if s.feedthrough]
    done: list[str] = []
    while pending:
        ready = [n for n in pending if not (sources[n] & set(pending) - {n})]
        if not ready:
            raise DesignerError(
                f"the feedthrough systems {', '.join(pending)} form an algebraic loop",
                "break the loop with a system that has state",
            )
        done += ready
        pending = [n for n in pending if n not in ready]
    return done


class Master:
    """Steps `systems` joined by `connections` ("src.system.var" -> "dst.system.var") at a fixed step."""

    def __init__(
        self,
        systems: Mapping[str, System],
        connections: Sequence[tuple[str, str]],
        algorithm: str = "gauss-seidel",
    ) -> None:
        if algorithm not in ALGORITHMS:
            raise DesignerError(f"unknown algorithm '{algorithm}'", f"use one of: {', '.join(ALGORITHMS)}")
        self.systems = dict(systems)
        self.algorithm = algorithm
        self.columns = [f"{n}.{v}" for n, s in self.systems.items() for v in s.outputs]
        self._out = {}  # system -> slice into the output buffer
        start = 0
        for n, s in self.systems.items():
            self._out[n] = slice(start, start + len(s.outputs))
            start += len(s.outputs)
        wired = {n: np.full(len(s.inputs), -1) for n, s in self.systems.items()}
        sources: dict[str, set[str]] = {n: set() for n in self.systems}
        for src, dst in connections:
            i = self._index(src, "outputs")
            dn, dv = self._split(dst)
            j = self._position(dn, dv, "inputs")
            if wired[dn][j] >= 0:
                raise DesignerError(f"input {dst} is connected twice", "connect each input to one output")
            wired[dn][j] = i
            sources[dn].add(self.columns[i].split(".", 1)[0])
        for n, idx in wired.items():
            missing = [v for v, i in zip(self.systems[n].inputs, idx, strict=True) if i < 0]
            if missing:
                raise DesignerError(
                    f"inputs of {n} are not connected: {', '.join(missing)}",
                    "connect every input to an output",
                )
        self._src = wired
        self._feed = _order(self.systems, sources)
        self._state = [n for n, s in self.systems.items() if not s.feedthrough]

    def _split(self, ref: str) -> tuple[str, str]:
        name, _, var = ref.partition(".")
        if name not in self.systems:
            raise DesignerError(
                f"no system '{name}' in connection '{ref}'", f"systems: {', '.join(self.systems)}"
            )
        return name, var

    def _position(self, name: str, var: str, kind: str) -> int:
        names = getattr(self.systems[name], kind)
        if var not in names:
            raise DesignerError(
                f"system {name} has no {kind[:-1]} '{var}'", f"its {kind}: {', '.join(names)}"
            )
        return names.index(var)

    def _index(self, ref: str, kind: str) -> int:
        name, var = self._split(ref)
        return self._out[name].start + self._position(name, var, kind)

    def _exchange(self, buf: np.ndarray) -> None:
        """Bring every output in `buf` and every input to time t, per the algorithm."""
        systems = self.systems
        if self.algorithm == "jacobi":
            for n, s in systems.items():
                buf[self._out[n]] = s.get()
            for n, s in systems.items():
                if s.inputs:
                    s.set(buf[self._src[n]])
            return
        for n in self._state:
            buf[self._out[n]] = systems[n].get()
        for n in self._feed:
            s = systems[n]
            if s.inputs:
                s.set(buf[self._src[n]])
            buf[self._out[n]] = s.get()
        for n in self._state:
            s = systems[n]
            if s.inputs:
                s.set(buf[self._src[n]])

    def run(
        self,
        duration: float,
        step: float,
        progress: Callable[[float], None] | None = None,
    ) -> Trace:
        """Run from 0 to `duration` with macro step `step`; outputs are recorded after each exchange."""
        if not (np.isfinite(step) and step > 0):
            raise DesignerError(f"step {step:g} s is not positive", "give a positive step in seconds")
        if not (np.isfinite(duration) and duration >= step):
            raise DesignerError(f"duration {duration:g} s is shorter than one step", "give a longer duration")
        n = int(round(duration / step))
        values = np.empty((n + 1, len(self.columns)))
        every = max(1, n // 200)
        for i in range(n + 1):
            self._exchange(values[i])
            if i == n:
                break
            for s in self.systems.values():
                s.do_step(step)
            if not np.all(np.isfinite(values[i])):
                raise DesignerError(
                    f"the co-simulation diverged at t = {i * step:g} s",
                    "use a smaller step, or the gauss-seidel algorithm",
                )
            if progress is not None and i % every == 0:
                progress(i / n)
        if progress is not None:
            progress(1.0)
        return Trace(time=np.arange(n + 1) * step, columns=self.columns, values=values)
