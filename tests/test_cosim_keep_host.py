"""A robot joint's own spring, damper and armature in the host model: zeroed by default (the flexible
joint replaces them, and the result says so), kept in parallel with `keep_host`; the validation
reference follows the same choice. Checked against physics: springs and dampers in parallel add,
so keeping a host stiffness Kh and damping Ch runs as a flexure of k + Kh and c + Ch would."""

from __future__ import annotations

import numpy as np
import pytest

from designer import DesignerError, Joint, cosim
from designer.cosim import JointSource, Scenario, Sine

HOST_K, HOST_C, HOST_ARMATURE = 0.2, 0.004, 1e-5  # N.m/rad, N.m.s/rad, kg.m^2 in the host model
FLEX_K, FLEX_C = 330.0, 0.83  # N.mm/rad, N.mm.s/rad (rig units): 0.33 N.m/rad, 8.3e-4 N.m.s/rad

PENDULUM = """<mujoco>
  <option gravity="0 0 -9.81"/>
  <worldbody>
    <body name="link" pos="0 0 0">
      <joint name="j1" type="hinge" axis="0 1 0" stiffness="{k}" damping="{c}" armature="{a}"/>
      <geom type="capsule" fromto="0 0 0 0.1 0 0" size="0.01" mass="0.05"/>
    </body>
  </worldbody>
</mujoco>
"""


def _scenario(tmp_path, *, keep_host: bool, k=FLEX_K, c=FLEX_C, armature=HOST_ARMATURE, moving=True):
    model = tmp_path / f"pendulum_{keep_host}_{k}_{c}_{armature}.xml"
    model.write_text(PENDULUM.format(k=HOST_K, c=HOST_C, a=armature))
    joint = Joint.from_coefficients({"theta": {"k": k, "c": c}}, name="j1")
    return Scenario(
        duration=0.5,
        step=5e-4,
        model=model,
        joints={"j1": JointSource(joint=joint, keep_host=keep_host)},
        motors={"j1": Sine(0.3, 2.0)} if moving else {},
        validation_steps=(5e-4, 2.5e-4),
    )


def _angle(result) -> np.ndarray:
    return result.column("robot.j1.q")


def test_host_elements_are_zeroed_by_default_and_said(tmp_path):
    with cosim.prepare(_scenario(tmp_path, keep_host=False)) as session:
        result = session.run(validate=True)
        model = session.master.systems["robot"].model
        assert model.jnt_stiffness[0] == 0 and model.dof_damping[0] == 0 and model.dof_armature[0] == 0
    (note,) = [n for n in result.notes if "'j1'" in n]
    assert "stiffness 0.2 -> 0 N.m/rad" in note and "damping 0.004 -> 0 N.m.s/rad" in note
    assert "armature 1e-05 -> 0 kg.m^2" in note and "keep_host = true" in note
    assert result.validation["max_error"] < 1e-3  # the reference zeroed them too


def test_keep_host_keeps_them_in_parallel_and_the_reference_follows(tmp_path):
    with cosim.prepare(_scenario(tmp_path, keep_host=True)) as session:
        result = session.run(validate=True)
        model = session.master.systems["robot"].model
        assert model.jnt_stiffness[0] == pytest.approx(HOST_K) and model.dof_damping[0] == pytest.approx(
            HOST_C
        )
    assert not [n for n in result.notes if "'j1'" in n]
    assert result.validation["max_error"] < 1e-3


def test_kept_host_spring_and_damper_add_to_the_flexures(tmp_path):
    """Parallel elements add: a kept host (Kh, Ch) runs as a flexure of (k + Kh, c + Ch) without it.
    The motor is held at 0, so both act on the same angle (the host's spring pulls towards the joint's
    zero, the flexure towards the motor's angle); gravity deflects the link."""
    same = dict(armature=0.0, moving=False)
    kept = cosim.run(_scenario(tmp_path, keep_host=True, **same))
    summed = cosim.run(
        _scenario(tmp_path, keep_host=False, k=FLEX_K + HOST_K * 1e3, c=FLEX_C + HOST_C * 1e3, **same)
    )
    alone = cosim.run(_scenario(tmp_path, keep_host=False, **same))
    gap = np.max(np.abs(_angle(kept) - _angle(summed)))
    assert gap < 0.02 * np.max(np.abs(_angle(alone) - _angle(kept)))  # the host's share is visible
    # rad: the same motion, up to how each damper is integrated (MuJoCo's Euler takes a joint's own
    # damping implicitly, the co-simulated flexure's force explicitly: 4e-4 of a 0.07 rad sag here)
    assert gap < 1e-3


def test_keep_host_must_be_true_or_false_in_a_scenario_file(tmp_path):
    (tmp_path / "s.toml").write_text(
        '[simulation]\nduration = 0.1\nstep = 1e-3\n[robot]\nmodel = "arm"\n'
        '[joints.j1]\ncoefficients = {k = 330, c = 0.83}\nkeep_host = "yes"\n'
    )
    with pytest.raises(DesignerError, match=r"keep_host = 'yes' is not true or false"):
        cosim.load(tmp_path / "s.toml")
