"""A fixed-step co-simulation master over a connection graph: Gauss-Seidel (default) or Jacobi.

A system exposes `inputs` and `outputs` (names), `feedthrough` (it can give outputs for inputs set at
the same instant), `get() -> array`, `set(array)`, `do_step(h)` and optionally `delay` (None, or a
sentence saying which of its outputs lag their inputs by one step; collected into `Trace.delays`).

The exchange at t = i h, before every system steps from t to t + h (this is the exact sequence; an
FMU system maps `get`/`set`/`do_step` to FMI calls as `cosim.fmu` describes):
- Gauss-Seidel: (1) `get` every state system (not feedthrough), in the order given; (2) for each
  feedthrough system in dependency order: `set` its inputs, then `get` its outputs (a force element
  runs as Model Exchange, where that sequence is defined); (3) `set` the inputs of every state system;
  record the outputs; (4) `do_step(h)` on every system in the order given. No delay around a loop
  whose feedthrough elements run as Model Exchange.
- Jacobi: `get` every system, then `set` every system, record, `do_step(h)` everyone: a feedthrough
  element answers with the inputs of the previous step.
A force element that offers co-simulation only is not feedthrough: it is read before it is set, a
one-step delay, stated in `Trace.delays`.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from typing import Protocol

import numpy as np

from ..errors import DesignerError

ALGORITHMS = ("gauss-seidel", "jacobi")


class System(Protocol):
    """A system the master steps. `reset()` brings it back to t = 0 for a new run (a prepared
    Session resets every system before each run). A system the compiled kernel can run also has
    `binding() -> designer.cosim.binding.Binding` (the kernel contract)."""

    inputs: list[str]
    outputs: list[str]
    feedthrough: bool

    def get(self) -> np.ndarray: ...
    def set(self, values: np.ndarray) -> None: ...
    def do_step(self, h: float) -> None: ...
    def reset(self) -> None: ...


class Series(Protocol):
    """A run's time series as its readers use it: `time` (s) and `column(name)`. A `Trace` is one, and
    so is a `designer.cosim.Result`."""

    time: np.ndarray

    def column(self, name: str) -> np.ndarray: ...


@dataclass(frozen=True)
class Trace:
    """Time series of every output, columns named `system.variable`, rows at t = 0, h, ..., N h.

    `delays` names every output that lags its inputs by one step (empty: none); `engine` says what
    ran the loop: "python" (this master) or "kernel" (the compiled kernel).
    """

    time: np.ndarray
    columns: list[str]
    values: np.ndarray
    delays: tuple[str, ...] = ()
    engine: str = "python"

    def column(self, name: str) -> np.ndarray:
        return self.values[:, self.columns.index(name)]


def diverged(t: float) -> DesignerError:
    """The error for a non-finite output in the row of time `t` (s)."""
    return DesignerError(
        f"the co-simulation diverged at t = {t:g} s", "use a smaller step, or the gauss-seidel algorithm"
    )


def steps(duration: float, step: float) -> int:
    """The number of macro steps of `step` s in `duration` s.

    Raises:
        DesignerError: the step is not positive or the duration is shorter than one step.
    """
    if not (np.isfinite(step) and step > 0):
        raise DesignerError(f"step {step:g} s is not positive", "give a positive step in seconds")
    if not (np.isfinite(duration) and duration >= step):
        raise DesignerError(f"duration {duration:g} s is shorter than one step", "give a longer duration")
    return int(round(duration / step))


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
        self._schedule = self.schedule()

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

    def sources(self, name: str) -> list[int]:
        """The output column feeding each input of system `name`, in its `inputs` order."""
        return [int(i) for i in self._src[name]]

    def output_slice(self, name: str) -> slice:
        """The columns of system `name`'s outputs in a row of `columns`."""
        return self._out[name]

    def delays(self) -> tuple[str, ...]:
        """The systems' statements of outputs lagging their inputs by one step (see FmuSystem.delay)."""
        return tuple(d for s in self.systems.values() if (d := getattr(s, "delay", None)))

    def schedule(self) -> list[tuple[str, str]]:
        """One exchange as ("get" | "set", system) operations in order; the compiled kernel runs the same.

        Gauss-Seidel: the state-based systems' outputs at t, then each feedthrough system in
        dependency order (set its inputs, read its outputs), then the state-based systems' inputs.
        Jacobi: every output first, then every input.
        """
        systems = self.systems
        if self.algorithm == "jacobi":
            return [("get", n) for n in systems] + [("set", n) for n, s in systems.items() if s.inputs]
        ops = [("get", n) for n in self._state]
        for n in self._feed:
            ops += [("set", n)] if systems[n].inputs else []
            ops.append(("get", n))
        return ops + [("set", n) for n in self._state if systems[n].inputs]

    def _exchange(self, buf: np.ndarray) -> None:
        """Bring every output in `buf` and every input to time t, per the schedule."""
        for op, n in self._schedule:
            if op == "get":
                buf[self._out[n]] = self.systems[n].get()
            else:
                self.systems[n].set(buf[self._src[n]])

    def run(
        self,
        duration: float,
        step: float,
        progress: Callable[[float], None] | None = None,
    ) -> Trace:
        """Run from 0 to `duration` with macro step `step`; outputs are recorded after each exchange."""
        n = steps(duration, step)
        values = np.empty((n + 1, len(self.columns)))
        every = max(1, n // 200)
        for i in range(n + 1):
            self._exchange(values[i])
            if i == n:
                break
            for s in self.systems.values():
                s.do_step(step)
            if not np.all(np.isfinite(values[i])):
                raise diverged(i * step)
            if progress is not None and i % every == 0:
                progress(i / n)
        if progress is not None:
            progress(1.0)
        return Trace(time=np.arange(n + 1) * step, columns=self.columns, values=values, delays=self.delays())
