"""The URDF exports as Gazebo reads them: libsdformat (Gazebo's own parser and URDF converter).

A small C++ program (tests/sdformat_probe.cc) is built against the system's libsdformat and prints the
links, joints, springs and damping it finds; skipped when the library or a C++ compiler is missing.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from designer.export.urdf import export_urdf
from designer.joint import Joint

PROBE = Path(__file__).with_name("sdformat_probe.cc")


@pytest.fixture(scope="module")
def probe(tmp_path_factory) -> Path:
    """The probe, built once against libsdformat (found by pkg-config)."""
    cxx = shutil.which("g++") or shutil.which("c++")
    if cxx is None or shutil.which("pkg-config") is None:
        pytest.skip("no C++ compiler or pkg-config (apt-get install g++ pkg-config)")
    found = subprocess.run(["pkg-config", "--cflags", "--libs", "sdformat12"], capture_output=True, text=True)
    if found.returncode != 0:
        pytest.skip("libsdformat 12 is not installed (apt-get install libsdformat-dev)")
    exe = tmp_path_factory.mktemp("probe") / "sdformat_probe"
    subprocess.run([cxx, "-O0", str(PROBE), "-o", str(exe), *found.stdout.split()], check=True)
    return exe


def gazebo_reads(probe: Path, path: Path) -> dict[str, object]:
    """What libsdformat loads from `path`: link and joint counts, per joint (k, rest, c), errors."""
    out = subprocess.run([str(probe), str(path)], capture_output=True, text=True, check=True).stdout
    read: dict[str, object] = {"joints": {}, "errors": []}
    for line in out.splitlines():
        words = line.split()
        if words[0] == "links":
            read["links"], read["joint_count"] = int(words[1]), int(words[3])
        elif words[0] == "joint":
            read["joints"][words[1]] = tuple(float(w) for w in words[3::2]) if len(words) > 2 else None
        else:
            read["errors"].append(line)
    return read


def test_standalone_urdf_reaches_gazebo_with_every_link_and_spring(probe, tmp_path):
    """The chain's base has real mass, so Gazebo's converter keeps it and everything after it (a mass-0
    root made an empty model: 0 links)."""
    joint = Joint.from_coefficients(
        {"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}, "x": {"k": 0.8, "c": 2e-3, "m": 0.01}}
    )
    read = gazebo_reads(probe, export_urdf(joint, tmp_path / "j.urdf", rest=0.2).path)
    assert read["errors"] == [] and read["links"] == 3 and read["joint_count"] == 3
    assert read["joints"]["FlexJoint_theta"] == (0.05, 0.2, 5e-4)
    assert read["joints"]["FlexJoint_x"] == (800.0, 0.2, 2.0)


def test_urdf_into_a_robot_reaches_gazebo_with_the_spring(probe, tmp_path):
    """Franka Panda (pybullet_data; its KUKA iiwa loads in libsdformat as an empty model as shipped)."""
    pybullet_data = pytest.importorskip("pybullet_data")
    folder = shutil.copytree(f"{pybullet_data.getDataPath()}/franka_panda", tmp_path / "panda")
    joint = Joint.from_coefficients({"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}})
    before = gazebo_reads(probe, folder / "panda.urdf")
    out = export_urdf(
        joint, folder / "flex.urdf", into=folder / "panda.urdf", joint_name="panda_joint4", rest=-0.1
    )
    after = gazebo_reads(probe, out.path)
    assert (after["links"], after["joint_count"]) == (before["links"], before["joint_count"]) > (0, 0)
    assert after["joints"]["panda_joint4"] == (0.05, -0.1, 5e-4)
    others = {n: v for n, v in after["joints"].items() if n != "panda_joint4"}
    assert others == {n: v for n, v in before["joints"].items() if n != "panda_joint4"}
