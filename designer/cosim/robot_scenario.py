"""The robot scenario: flexible joints of a MuJoCo model (or the built-in planar arm), each driven by a
motor reference; its metrics, and its validation against the same spring-dampers inside MuJoCo."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, ClassVar

import numpy as np

from ..errors import DesignerError
from ..export.urdf_packages import check_package_paths
from .host import host_integrator, integrator_name, take_host_actuators
from .kernel import run_master
from .master import Master, Series, System, Trace
from .metrics import joint_metrics
from .references import Chirp, Reference, Sine, Step, Trajectory
from .robot import ARM_LENGTHS, ARM_MASSES, Robot, SpringDamper, check_joints, free_host_joints, load_spec
from .scenario import JointSource, Laws, Progress, Scenario, Tracer, positive

#: MuJoCo's integrators that take an actuator's velocity-dependent force implicitly
IMPLICIT = ("implicit", "implicitfast")


@dataclass(frozen=True, kw_only=True)
class RobotScenario(Scenario):
    """A robot scenario (lengths in m, masses in kg).

    `joints` maps hinge or slide joints of the model (None: the built-in planar arm with `lengths`
    and `masses`, hinges j1..jN) to their `JointSource`; `motors` gives each joint's motor reference
    (default: held at 0).
    """

    joints: Mapping[str, JointSource] = field(default_factory=dict)
    motors: Mapping[str, Reference] = field(default_factory=dict)
    model: Path | None = None
    lengths: tuple[float, ...] = ARM_LENGTHS
    masses: tuple[float, ...] = ARM_MASSES
    #: a URDF's package://NAME/ folders {NAME: folder}, as ROS's package path
    package_paths: Mapping[str, Path] = field(default_factory=dict)

    kind: ClassVar[str] = "robot"
    keyword: ClassVar[str] = "joints"
    interface: ClassVar[str] = "force"

    def model_spec(self):
        """The robot model's MuJoCo spec, as the scenario names it (see `robot.load_spec`)."""
        return load_spec(self.model, self.lengths, self.masses, self.package_paths)

    def own_fields(self) -> dict[str, Any]:
        out: dict[str, Any] = {}
        if self.model is not None:
            out["model"] = Path(self.model)
        else:
            lengths = tuple(positive(v, "lengths") for v in self.lengths)
            masses = tuple(positive(v, "masses") for v in self.masses)
            if not lengths or len(lengths) != len(masses):
                raise DesignerError(
                    f"lengths ({len(lengths)}) and masses ({len(masses)}) differ in number",
                    "give one length and one mass per link",
                )
            out |= {"lengths": lengths, "masses": masses}
        out["package_paths"] = check_package_paths(self.package_paths)
        spec = load_spec(
            out.get("model"),
            out.get("lengths", self.lengths),
            out.get("masses", self.masses),
            out["package_paths"],
        )
        check_joints(spec, list(self.joints))
        for name, src in self.joints.items():
            if not isinstance(src, JointSource):
                raise DesignerError(f"joints['{name}'] is a {type(src).__name__}", "give a JointSource")
        out["joints"] = {name: src.check() for name, src in self.joints.items()}
        extra = set(self.motors) - set(self.joints)
        if extra:
            raise DesignerError(
                f"motors name joint(s) without a flexible joint: {', '.join(sorted(extra))}",
                f"flexible joints: {', '.join(self.joints)}",
            )
        for name, ref in self.motors.items():
            if not isinstance(ref, (Step, Sine, Chirp, Trajectory)):
                raise DesignerError(
                    f"motors['{name}'] is a {type(ref).__name__}", "give a Step, Sine, Chirp or Trajectory"
                )
        out["motors"] = {j: self.motors.get(j, Step(0.0)) for j in self.joints}
        return out

    def sources(self) -> dict[str, JointSource]:
        return dict(self.joints)

    def signals(self) -> int:
        return 5 * len(self.joints)

    def wire(self, fmus: Mapping[str, System], step: float) -> Master:
        systems: dict[str, System] = {"robot": robot_system(self, step)}
        connections = []
        for name, src in self.joints.items():
            a = src.axis
            systems[name] = fmus[name]
            connections += [
                (f"robot.{name}.s", f"{name}.{a}.s"),
                (f"robot.{name}.v", f"{name}.{a}.v"),
                (f"{name}.{a}.f", f"robot.{name}.tau"),
            ]
        return Master(systems, connections, self.algorithm)

    def reset(self, master: Master, laws: Callable[[], Laws], step: float) -> None:
        master.systems["robot"].reset()

    def metrics(self, trace: Trace, laws: Laws) -> dict[str, Any]:
        """Per joint: tracking, deflection, overshoot, settling and energy (see metrics.joint_metrics)."""
        return {
            j: joint_metrics(
                trace.time,
                trace.column(f"robot.{j}.q"),
                trace.column(f"robot.{j}.motor"),
                trace.column(f"robot.{j}.v"),
                laws[j]["c"],
                self.motors[j],
            )
            for j in self.joints
        }

    def validate(self, trace: Tracer, case: Mapping, laws: Laws, progress: Progress) -> dict[str, Any]:
        """Against the in-engine spring-dampers at the same step, and against RK4 at a quarter of the
        smallest validation step."""
        duration, joints = self.validation_duration, list(self.joints)
        steps = sorted(self.validation_steps, reverse=True)
        fine = min(steps) / 4
        ref_fine = _angles(robot_reference(self, laws, fine, duration, "rk4"), joints)
        same = _angles(trace(case, duration=duration), joints)
        same_ref = _angles(robot_reference(self, laws, self.step, duration, self.integrator), joints)
        integrator = self.integrator or integrator_name(self.model_spec())
        explicit = (
            f" (under {integrator}: a force set each step, as co-simulated)" if integrator in IMPLICIT else ""
        )
        rows = []
        for i, h in enumerate(steps):
            ratio = int(round(h / fine))
            if abs(ratio * fine - h) > 1e-9 * h:
                raise DesignerError(
                    f"validation step {h:g} s is not a multiple of {fine:g} s",
                    "use steps halving from the largest",
                )
            q = _angles(trace(case, step=h, duration=duration), joints)
            q_same = _angles(robot_reference(self, laws, h, duration, self.integrator), joints)
            rows.append(
                {
                    "step": h,
                    "max_error": float(np.max(np.abs(q - ref_fine[::ratio]))),
                    "max_error_same_step": float(np.max(np.abs(q - q_same))),
                }
            )
            if progress is not None:
                progress((i + 1) / len(steps))
        return {
            "reference": f"in-engine MuJoCo general actuator{explicit}; steps against RK4 at {fine:g} s",
            "max_error": float(np.max(np.abs(same - same_ref))),
            "steps": rows,
        }

    def notes(self, master: Master) -> tuple[str, ...]:
        return tuple(master.systems["robot"].notes)

    def write_extra(self, series: Series, folder: Path) -> list[Path]:
        return []

    def factors_of(self, joint: str) -> Mapping[str, float] | None:
        return None


def _angles(res: Trace, joints) -> np.ndarray:
    return np.column_stack([res.column(f"robot.{j}.q") for j in joints])


def robot_system(
    sc: RobotScenario,
    step: float,
    *,
    integrator: str | None = None,
    in_engine: Mapping[str, SpringDamper] | None = None,
    as_cosimulated: bool = False,
) -> Robot:
    """The robot of a (checked) robot scenario at physics step `step` (s): the one place a scenario's
    MuJoCo model is built. `in_engine` computes those joints' spring-dampers inside MuJoCo. Each
    flexible joint's own stiffness, damping and armature in the host model are zeroed unless its
    source says `keep_host`, and the host's actuators on it are taken out (see `host`); `integrator`
    (default the scenario's, else the model's own) is MuJoCo's. `Robot.notes` says what changed, for
    the run and its reference alike. `as_cosimulated`: under an implicit integrator the in-engine laws
    are explicit, as the co-simulation exchanges its torques (see `SpringDamper`); the sweeps'
    open-loop rollout needs them implicit."""
    spec = sc.model_spec()
    notes = free_host_joints(spec, [j for j, src in sc.joints.items() if not src.keep_host])
    notes += take_host_actuators(spec, list(sc.joints))
    name, said = host_integrator(spec, integrator or sc.integrator)
    if in_engine and as_cosimulated and name in IMPLICIT:  # the co-simulated torque is explicit
        in_engine = {j: replace(law, explicit=True) for j, law in in_engine.items()}
    return Robot(spec, sc.motors, step, name, in_engine=in_engine, notes=notes + said)


def robot_reference(
    sc: RobotScenario, laws: Mapping, step: float, duration: float, integrator: str | None
) -> Trace:
    """The same robot with every joint's spring-damper computed inside MuJoCo, as the co-simulation
    exchanges it (explicitly under an implicit integrator; `integrator` None: the scenario's)."""
    springs = {j: SpringDamper(p["k"], p["c"], p["offset"]) for j, p in laws.items()}
    robot = robot_system(sc, step, integrator=integrator, in_engine=springs, as_cosimulated=True)
    return run_master(Master({"robot": robot}, []), duration, step)
