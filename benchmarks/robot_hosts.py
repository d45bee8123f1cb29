"""Every hinge or slide joint written in the mesh-bearing MJCF robots of the installed packages, made
flexible in parallel and in series from the robot's own folder with relative paths, as a user types it.

Hosts: gymnasium-robotics' hands, Fetch and kitchen Franka; dm_control's Kinova Jaco, dog, fruit fly;
mujoco's test model. Each package folder is copied to a temporary folder first (nothing is written into
site-packages). Per export: exit status (0 written, 2 refused with a reason, 3 an internal error) and,
when written, the checks of tests/test_robot_hosts.py read from the compiled models: the joint's k and c
exact in SI, every other joint's numbers, every body's pose (reference and keyframes) and every
actuator gain unchanged or printed. Run: python benchmarks/robot_hosts.py [--limit N]
"""

from __future__ import annotations

import argparse
import collections
import importlib.util
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

#: (package, folder in it copied whole, model files in that folder whose own joints are tried)
HOSTS = [
    (
        "gymnasium_robotics",
        "envs/assets",
        [
            "adroit_hand/adroit_hammer.xml",
            "adroit_hand/adroit_door.xml",
            "hand/manipulate_block.xml",
            "fetch/pick_and_place.xml",
            "kitchen_franka/kitchen_assets/kitchen_env_model.xml",
        ],
    ),
    ("dm_control", "third_party/kinova", ["jaco_arm.xml"]),
    ("dm_control", "suite", ["dog.xml"]),
    ("dm_control", "locomotion/walkers/assets/fruitfly_v2", ["fruitfly.xml"]),
    ("mujoco", "testdata", ["model.xml"]),
]


def _folder(package: str, sub: str) -> Path | None:
    spec = importlib.util.find_spec(package)
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations))) / sub


def main() -> int:
    import mujoco

    from designer.errors import DesignerError
    from designer.export.mjcf import export_mjcf
    from designer.joint import Joint
    from designer.validate.export import gain_changes, joint_numbers, other_joint_changes, pose_changes

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--limit", type=int, default=0, help="joints per model (0: all)")
    args = parser.parse_args()
    joint = Joint.from_coefficients(
        {"theta": {"k": 50.0, "c": 0.5, "m": 1e-5}, "x": {"k": 0.8, "c": 2e-3, "m": 0.01}}
    )
    si = {a: joint.axes[a].si() for a in joint.axes}
    counts: collections.Counter = collections.Counter()
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for package, sub, files in HOSTS:
            source = _folder(package, sub)
            if source is None or not source.is_dir():
                print(f"{package}/{sub}: not installed")
                continue
            folder = Path(tmp) / package / sub
            shutil.copytree(source, folder, ignore=shutil.ignore_patterns("*.py", "__pycache__"))
            for model in files:
                os.chdir(folder / Path(model).parent)
                file = Path(model).name
                spec = mujoco.MjSpec.from_file(file)
                before = mujoco.MjModel.from_xml_path(file)
                text = Path(file).read_text()
                kinds = (mujoco.mjtJoint.mjJNT_HINGE, mujoco.mjtJoint.mjJNT_SLIDE)
                names = [j.name for j in spec.joints if j.type in kinds and j.name and f'"{j.name}"' in text]
                for name in names[: args.limit or None]:
                    axis = "theta" if spec.joint(name).type == mujoco.mjtJoint.mjJNT_HINGE else "x"
                    for form in ("parallel", "series"):
                        out = Path(f"flex_{form}.xml")  # relative, in the robot's folder
                        case = f"{package} {file} {name} {form}"
                        try:
                            written = export_mjcf(
                                joint, out, into=Path(file), joint_name=name, axis=axis, form=form
                            )
                        except DesignerError as exc:
                            counts["refused"] += 1
                            print(f"refused  {case}: {str(exc)[:150]}")
                            continue
                        except Exception as exc:  # noqa: BLE001 - the survey reports, it does not stop
                            counts["internal error"] += 1
                            print(f"ERROR    {case}: {type(exc).__name__}: {str(exc)[:200]}")
                            continue
                        after = mujoco.MjModel.from_xml_path(str(out))
                        got = joint_numbers(after, name)
                        problems = []
                        if (got["stiffness"][0], got["damping"][0]) != (si[axis]["k"], si[axis]["c"]):
                            problems.append(f"k, c compiled as {got['stiffness'][0]}, {got['damping'][0]}")
                        problems += other_joint_changes(before, after, name)
                        problems += pose_changes(before, after)
                        unsaid = [
                            g
                            for g in gain_changes(before, after)
                            if g.split(" ")[0] not in " ".join(written.notes)
                        ]
                        problems += [f"unstated gain change {g}" for g in unsaid]
                        counts["changed" if problems else "exact"] += 1
                        print(
                            f"{'CHANGED' if problems else 'ok':8} {case}"
                            + (f": {problems[:4]}" if problems else "")
                        )
    total = sum(counts.values())
    print(
        f"\n{total} exports in {time.perf_counter() - start:.0f} s: "
        + ", ".join(f"{n} {k}" for k, n in counts.items())
    )
    return 1 if counts["internal error"] or counts["changed"] else 0


if __name__ == "__main__":
    sys.exit(main())
