"""Co-simulation master and robot adapter, with the spring-damper law as a Python force element."""

import numpy as np
import pytest

from designer.cosim import Master, Robot, SpringDamper, load_spec
from designer.cosim.references import Chirp, Sine, Step, Trajectory
from designer.errors import DesignerError

K, C = 0.3, 8e-4  # N.m/rad, N.m.s/rad: a printed joint of about 300 N.mm/rad
MOTORS = {"j1": Sine(0.5, 0.5), "j2": Step(0.3, 1.0)}


class Law:
    """tau = -(k s + c v) with direct feedthrough, as the joint FMU's force interface computes it."""

    feedthrough = True
    inputs = ["s", "v"]
    outputs = ["f"]

    def __init__(self):
        self.f = np.zeros(1)

    def set(self, x):
        self.f[0] = -(K * x[0] + C * x[1])

    def get(self):
        return self.f.copy()

    def do_step(self, h):
        pass


def cosim(step, duration, algorithm="gauss-seidel", integrator="euler"):
    robot = Robot(load_spec(), MOTORS, step, integrator)
    systems = {"robot": robot, "f1": Law(), "f2": Law()}
    wires = [(f"robot.{j}.{v}", f"f{i}.{v}") for i, j in ((1, "j1"), (2, "j2")) for v in "sv"]
    wires += [("f1.f", "robot.j1.tau"), ("f2.f", "robot.j2.tau")]
    return Master(systems, wires, algorithm).run(duration, step)


def in_engine(step, duration, integrator="euler"):
    springs = {j: SpringDamper(K, C) for j in MOTORS}
    return Master({"robot": Robot(load_spec(), MOTORS, step, integrator, in_engine=springs)}, []).run(
        duration, step
    )


def angles(res):
    return np.column_stack([res.column("robot.j1.q"), res.column("robot.j2.q")])


def test_gauss_seidel_matches_in_engine_reference_with_euler():
    err = np.abs(angles(cosim(1e-3, 10.0)) - angles(in_engine(1e-3, 10.0))).max()
    assert err <= 1e-6
    # the joint really deflects, so the comparison means something
    assert np.abs(cosim(1e-3, 2.0).column("robot.j2.s")).max() > 0.05


def test_gauss_seidel_error_falls_with_the_step():
    fine = angles(in_engine(1e-4, 2.0, "rk4"))
    steps = [4e-3, 2e-3, 1e-3, 5e-4]
    errors = [np.abs(angles(cosim(h, 2.0)) - fine[:: int(round(h / 1e-4))]).max() for h in steps]
    for big, small, e_big, e_small in zip(steps, steps[1:], errors, errors[1:], strict=False):
        assert e_small <= e_big * (small / big) * 1.05


def test_jacobi_lags_one_step_and_goes_unstable_where_gauss_seidel_does_not():
    gs, jac = cosim(1e-3, 2.0), cosim(1e-3, 2.0, "jacobi")
    # Jacobi's torque at step n is the Gauss-Seidel law applied to the deflection of step n-1
    s, v, tau = (jac.column(c) for c in ("robot.j1.s", "robot.j1.v", "f1.f"))
    assert np.allclose(tau[2:], -(K * s[1:-1] + C * v[1:-1]), rtol=0, atol=1e-15)
    assert np.allclose(gs.column("f1.f"), -(K * gs.column("robot.j1.s") + C * gs.column("robot.j1.v")))
    assert np.abs(angles(cosim(4e-3, 2.0))).max() < 2.0
    assert np.abs(angles(cosim(2e-3, 2.0, "jacobi"))).max() < 2.0
    with pytest.raises(DesignerError, match="diverged"):
        cosim(2.5e-3, 2.0, "jacobi")


def test_master_rejects_bad_graphs():
    robot = Robot(load_spec(), MOTORS, 1e-3)
    with pytest.raises(DesignerError, match="not connected"):
        Master({"robot": robot}, [])
    with pytest.raises(DesignerError, match="no output"):
        Master({"robot": robot, "f": Law()}, [("robot.j9.s", "f.s")])
    with pytest.raises(DesignerError, match="algebraic loop"):
        Master({"a": Law(), "b": Law()}, [("a.f", "b.s"), ("a.f", "b.v"), ("b.f", "a.s"), ("b.f", "a.v")])
    with pytest.raises(DesignerError, match="not positive"):
        Master(
            {"robot": Robot(load_spec(), MOTORS, 1e-3, in_engine={j: SpringDamper(K, C) for j in MOTORS})}, []
        ).run(1.0, -1e-3)


def test_robot_rejects_unknown_joint_and_integrator():
    with pytest.raises(DesignerError, match="no joint 'elbow'.*j1, j2"):
        Robot(load_spec(), {"elbow": Step(1.0)}, 1e-3)
    with pytest.raises(DesignerError, match="unknown integrator"):
        Robot(load_spec(), MOTORS, 1e-3, "verlet")


def test_n_link_arm_has_n_hinges():
    from designer.cosim.robot import joint_names

    assert joint_names(load_spec(None, [0.1, 0.1, 0.05], [0.1, 0.1, 0.05])) == ["j1", "j2", "j3"]
    with pytest.raises(DesignerError, match="one length and one mass"):
        load_spec(None, [0.1], [0.1, 0.2])


def test_references(tmp_path):
    assert Step(0.5, at=1.0)(0.99) == (0.0, 0.0) and Step(0.5, at=1.0)(1.0) == (0.5, 0.0)
    q, dq = Sine(2.0, 0.25)(1.0)
    assert q == pytest.approx(2.0) and dq == pytest.approx(0.0, abs=1e-12)
    # the rig chirp: instantaneous frequency f0 at 0 and f1 at the end of the sweep
    chirp, eps = Chirp(sweep=100.0), 1e-6
    for t, f in ((0.0, 0.2), (100.0, 1.85)):
        q, dq = chirp(t)
        assert abs(dq) <= 2 * np.pi * f * 1.0 + 1e-9
        q2, _ = chirp(t + eps)
        assert (q2 - q) / eps == pytest.approx(dq, rel=1e-4, abs=1e-6)
    csv = tmp_path / "traj.csv"
    csv.write_text("t,q\n0,0\n1,2\n2,2\n")
    traj = Trajectory.from_csv(csv)
    assert traj(0.5) == (1.0, 2.0) and traj(5.0) == (2.0, 0.0)
    csv.write_text("t,angle\n0,0\n")
    with pytest.raises(DesignerError, match="no column 'q'"):
        Trajectory.from_csv(csv)
