"""`export mjcf --into` a robot whose joint lives in an <include>d file, as Gymnasium-Robotics ships
the Shadow hand (`hand/manipulate_block.xml` includes `robot.xml`, a fragment of bodies without a
<worldbody>): the refusal names the file that writes the joint and a command that flattens the
model, and that command, run verbatim from the message, gives a file the export goes into."""

from __future__ import annotations

import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from clitools import run_process

gymnasium_robotics = pytest.importorskip("gymnasium_robotics")
ASSETS = Path(gymnasium_robotics.__file__).parent / "envs" / "assets"
JOINT = "robot0:FFJ3"
EXPORT = ["export", "mjcf", "--k", "50", "--c", "0.5", "--m", "1e-5", "--axis", "theta", "--joint", JOINT]


@pytest.fixture()
def hand(tmp_path: Path) -> Path:
    """A copy of the hand's folder with the meshes and textures it names relative to it."""
    for name in ("hand", "stls", "textures"):
        shutil.copytree(ASSETS / name, tmp_path / name)
    return tmp_path / "hand"


def one_line(err: str) -> str:
    return " ".join(err.split())


def test_a_joint_from_an_include_names_its_file_and_the_flattening_that_works(hand):
    r = run_process([*EXPORT, "--into", "manipulate_block.xml", "-o", "flex.xml"], cwd=hand)
    assert r.returncode == 2, r.stderr
    err = one_line(r.stderr)
    assert "not written in manipulate_block.xml itself but in robot.xml" in err, err
    assert "Traceback" not in r.stderr and not (hand / "flex.xml").exists()
    command = re.search(r'python -c "([^"]+)"', err).group(1)  # the user runs it as the message says
    subprocess.run([sys.executable, "-c", command], cwd=hand, check=True)
    into = re.search(r"--into '([^']+)'", err).group(1)
    r = run_process([*EXPORT, "--into", into, "-o", "flex.xml"], cwd=hand)
    assert r.returncode == 0, r.stderr
    import mujoco

    model = mujoco.MjModel.from_xml_path(str(hand / "flex.xml"))
    j = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, JOINT)
    assert model.jnt_stiffness[j] == pytest.approx(50e-3) and model.dof_damping[model.jnt_dofadr[j]] == (
        pytest.approx(0.5e-3)
    )


def test_the_included_fragment_itself_is_named_as_one(hand):
    r = run_process([*EXPORT, "--into", "robot.xml", "-o", "flex.xml"], cwd=hand)
    assert r.returncode == 2, r.stderr
    err = one_line(r.stderr)
    assert (
        "written in robot.xml outside any <worldbody>" in err and "flatten the model that includes it" in err
    )
    assert "no hinge or slide joint of that name" not in err, err
