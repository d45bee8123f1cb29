"""The rig scenario: the virtual rig's hub chirp drives one joint FMU's body interface; its metrics, its
validation against a monolithic solution, and its log in the rig's schema."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, ClassVar

import numpy as np

from .. import units
from ..errors import DesignerError
from .master import Master, Series, System, Trace
from .references import Chirp
from .rig import HubServo, reference
from .scenario import JointSource, Laws, Progress, Scenario, Tracer

if TYPE_CHECKING:
    import pandas as pd


@dataclass(frozen=True, kw_only=True)
class RigScenario(Scenario):
    """The virtual rig: `rig_joint` (needs a mass) is driven by `hub` (default: the study's chirp,
    1 rad, 0.2 to 1.85 Hz over 2200 s); `factors` go into the rig log's sidecar."""

    rig_joint: JointSource | None = None
    hub: Chirp | None = None
    factors: Mapping[str, float] | None = None

    kind: ClassVar[str] = "rig"
    keyword: ClassVar[str] = "rig_joint"
    interface: ClassVar[str] = "body"

    def own_fields(self) -> dict[str, Any]:
        src = self.rig_joint
        if not isinstance(src, JointSource):
            raise DesignerError(f"rig_joint is a {type(src).__name__}", "give a JointSource")
        src = src.check()
        if src.joint is not None and src.joint.axis(src.axis).m is None:
            raise DesignerError(
                f"the rig joint has no mass on axis {src.axis}",
                "give its m, or build it from a design so the mass follows from geometry",
            )
        hub = Chirp() if self.hub is None else self.hub
        hub.check_sampling(1.0 / self.step, what="1 / step")
        out: dict[str, Any] = {"rig_joint": src, "hub": hub}
        if self.factors is not None:
            from ..study import space

            out["factors"] = space.check_design(self.factors)
        return out

    def sources(self) -> dict[str, JointSource]:
        return {} if self.rig_joint is None else {"rig": self.rig_joint}

    def signals(self) -> int:
        return 6

    def wire(self, fmus: Mapping[str, System], step: float) -> Master:
        a = self.rig_joint.axis
        systems = {"joint": fmus["rig"], "hub": HubServo(self.hub, 0.0, 0.0)}
        connections = [(f"joint.{a}.s", "hub.s"), (f"joint.{a}.v", "hub.v"), ("hub.f", f"joint.{a}.f")]
        return Master(systems, connections, self.algorithm)

    def reset(self, master: Master, laws: Callable[[], Laws], step: float) -> None:
        """The hub back at rest, its servo loop tuned to the case's joint."""
        hub = master.systems["hub"]
        hub.reset()
        hub.tune(laws()["rig"], step)

    def metrics(self, trace: Trace, laws: Laws) -> dict[str, Any]:
        """The hub's tracking of the joint and the peak load on the specimen."""
        a = self.rig_joint.axis
        s, q = trace.column(f"joint.{a}.s"), trace.column("hub.q")
        return {
            "rig": {
                "axis": a,
                "tracking_rms": float(np.sqrt(np.mean((q - s) ** 2))),
                "peak_load": float(units.from_si("F", a, np.max(np.abs(trace.column("hub.f"))))),
                "peak_load_unit": units.rig_unit("F", a),
                "coefficients_si": dict(laws["rig"]),
            }
        }

    def validate(self, trace: Tracer, case: Mapping, laws: Laws, progress: Progress) -> dict[str, Any]:
        """Against the same closed loop solved monolithically (scipy DOP853), at the scenario's step
        and at each validation step."""
        p, rows = laws["rig"], []
        steps = sorted(self.validation_steps, reverse=True)
        for i, h in enumerate([self.step, *steps]):
            res = trace(case, step=h, duration=self.validation_duration)
            s = res.column(f"joint.{self.rig_joint.axis}.s")
            error = np.max(np.abs(s - reference(p["m"], p["c"], p["k"], self.hub, res.time)))
            rows.append({"step": h, "max_error": float(error)})
            if progress is not None:
                progress((i + 1) / (len(steps) + 1))
        return {
            "reference": "monolithic scipy DOP853, rtol 1e-11",
            "max_error": rows[0]["max_error"],
            "steps": rows[1:],
        }

    def notes(self, master: Master) -> tuple[str, ...]:
        return ()

    def write_extra(self, series: Series, folder: Path) -> list[Path]:
        """`rig_log.csv` (and its sidecar of factors), as `log` gives it."""
        from ..rig.logs import write_log

        return [write_log(self.log(series), folder / "rig_log.csv", self.factors)]

    def log(self, series: Series) -> pd.DataFrame:
        """A rig run (its `Result` or `Trace`) as a rig log: t, the axis' coordinate and load in rig
        units, the hub angle.

        The load is held over each step, so the sensor's sample at t_n is the mean of the loads held
        either side of it: read at one edge, the log would look half a step late (extra damping k h / 2).
        """
        import pandas as pd

        from ..rig.logs import LOAD

        a = self.rig_joint.axis
        held = series.column("hub.f")
        sensed = np.concatenate([held[:1], 0.5 * (held[1:] + held[:-1])])
        return pd.DataFrame(
            {
                "t": series.time,
                a: units.from_si("r", a, series.column(f"joint.{a}.s")),
                LOAD[a]: units.from_si("F", a, sensed),
                "hub": series.column("hub.q"),
            }
        )

    def factors_of(self, joint: str) -> Mapping[str, float] | None:
        return self.factors
