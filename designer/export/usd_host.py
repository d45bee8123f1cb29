"""Make one joint of the user's USD robot a flexible joint in parallel, as a layer over the robot.

The written layer has the robot's file as its only sublayer (its path relative to the layer's folder,
so the two move together) and the robot's stage metadata (stage metadata is read from the root layer
only: without it the robot's metersPerUnit, upAxis and defaultPrim would be lost); its only opinions
are over the joint prim: the drive (UsdPhysics.DriveAPI) set to the flexure's k, c and rest, and the
PhysX armature where the robot has none. The robot's file is opened, never written. Before the layer
replaces the output, usd-core composes it from beside the output and it is compared with the robot
attribute by attribute (every prim, attribute, time sample, relationship and applied schema): only
the joint's edited values may differ, and they must read back as written.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

from .. import units
from ..errors import DesignerError
from ..joint import Joint
from . import robot
from .stability import StepAdvice, step_advice
from .usd_drive import ARMATURE, FRICTION, drive_instance, set_drive
from .usd_layer import over_layer, stage_changes, write_over

#: what the advice's inertia is for a robot joint
INERTIA_BASIS = (
    "about the joint axis at the robot's authored pose: the bodies the joint moves (MassAPI mass, "
    "diagonalInertia, principalAxes, centerOfMass), the other joints held, plus the armature"
)


@dataclass
class UsdHost:
    """The robot as usd-core composes it, the joint prim to make flexible and the stage's units."""

    path: Path
    stage: object
    joint: object
    rotational: bool

    @property
    def units(self) -> tuple[float, float]:
        """(metersPerUnit, kilogramsPerUnit) of the robot's stage."""
        from pxr import UsdGeom, UsdPhysics

        return UsdGeom.GetStageMetersPerUnit(self.stage), UsdPhysics.GetStageKilogramsPerUnit(self.stage)

    def si(self, quantity: str, value: float) -> float:
        """A joint value as the stage states it, in SI."""
        return value / units.usd_factor(quantity, self.rotational, *self.units)


def open_host(host: Path, joint_name: str) -> UsdHost:
    """Open the robot and find its revolute or prismatic joint named (or at the path) `joint_name`.

    Raises:
        DesignerError: no such file, not a USD stage, no such joint, or several of that name.
    """
    from pxr import Tf, Usd, UsdPhysics

    if not host.is_file():
        raise DesignerError(f"into={str(host)!r} does not exist", "give the path of the robot's USD file")
    if host.suffix.lower() not in (".usd", ".usda", ".usdc", ".usdz"):
        raise DesignerError(
            f"into={str(host)!r} is not a USD file (.usd, .usda, .usdc or .usdz)",
            "convert the robot to USD first (Isaac Sim's URDF or MJCF importer, urdf2any), or export urdf "
            "or mjcf into it",
        )
    try:
        stage = Usd.Stage.Open(str(host))
    except Tf.ErrorException as exc:
        said = re.findall(r"'([^']+)'", str(exc))  # usd-core's own sentence, without its source location
        raise DesignerError(
            f"usd-core cannot open into={str(host)!r}: {said[-1] if said else str(exc).strip()}",
            "give a USD file that usd-core opens (usdcat FILE shows the problem)",
        ) from None
    kinds = [
        p
        for p in Usd.PrimRange.Stage(stage)
        if p.IsA(UsdPhysics.RevoluteJoint) or p.IsA(UsdPhysics.PrismaticJoint)
    ]
    found = [p for p in kinds if joint_name in (p.GetName(), str(p.GetPath()))]
    if len(found) != 1:
        have = ", ".join(str(p.GetPath()) for p in kinds) or "none"
        problem = "names several joints" if found else "is not a revolute or prismatic joint of the robot"
        raise DesignerError(
            f"joint_name={joint_name!r} {problem}",
            f"give a name or path; its revolute and prismatic joints: {have}",
        )
    return UsdHost(host, stage, found[0], found[0].IsA(UsdPhysics.RevoluteJoint))


def host_axis(joint: Joint, axis: str | None, host: UsdHost, joint_name: str) -> str:
    a = robot.pick_axis(joint, axis, host.rotational)
    if units.is_rotational(a) != host.rotational:
        kind = "revolute" if host.rotational else "prismatic"
        raise DesignerError(
            f"axis={a!r} is {'rotational' if units.is_rotational(a) else 'translational'} but robot joint "
            f"'{joint_name}' is {kind}",
            "give an axis of the same kind as the robot joint",
        )
    return a


def joint_span(host: UsdHost) -> tuple[float, float] | None:
    """The joint's limits in SI (rad or m), None when it has none (UsdPhysics: unauthored or infinite)."""
    from pxr import UsdPhysics

    schema = (UsdPhysics.RevoluteJoint if host.rotational else UsdPhysics.PrismaticJoint)(host.joint)
    lo, hi = schema.GetLowerLimitAttr().Get(), schema.GetUpperLimitAttr().Get()
    if lo is None or hi is None or not (math.isfinite(lo) and math.isfinite(hi)):
        return None
    return host.si("r", lo), host.si("r", hi)


def host_values(host: UsdHost) -> dict[str, float | None]:
    """The joint's drive and PhysX values in SI; None where the robot authors none."""
    from pxr import UsdPhysics

    drive = UsdPhysics.DriveAPI.Get(host.joint, drive_instance(host.rotational))
    has = host.joint.HasAPI(UsdPhysics.DriveAPI, drive_instance(host.rotational))
    get = {
        "k": drive.GetStiffnessAttr,
        "c": drive.GetDampingAttr,
        "r": drive.GetTargetPositionAttr,
        "F": drive.GetMaxForceAttr,
    }
    old: dict[str, float | None] = {}
    for q, attr in get.items():
        value = attr().Get() if has else None
        old[q] = None if value is None else host.si(q, value)
    for q, name in (("m", ARMATURE), ("friction", FRICTION)):
        attr = host.joint.GetAttribute(name)
        value = attr.Get() if attr else None
        old[q] = None if value is None else (value if q == "friction" else host.si(q, value))
    old["type"] = drive.GetTypeAttr().Get() if has else None
    return old


def _values(
    host: UsdHost, joint: Joint, a: str, rest: float | None, allow_outside_range: bool
) -> tuple[dict[str, float], tuple[str, ...]]:
    """The drive's new values (SI) and one note per robot value changed or kept (old -> new, SI)."""
    si = joint.axes[a].si()
    old = host_values(host)
    name = host.joint.GetName()
    unit = "rad" if host.rotational else "m"
    span = joint_span(host)
    new = {"k": si["k"], "c": si["c"]}
    notes = []
    if rest is None:
        rest, moved = robot.rest_inside(old["r"] or 0.0, span, unit, "targetPosition")
        if moved is not None:
            notes.append(moved)
        elif old["r"] is None:
            notes.append(f"targetPosition set to {rest:.4g} {unit} (give rest to set another)")
        else:
            notes.append(f"targetPosition kept at the host's {rest:.4g} {unit} (give rest to set it)")
    else:
        robot.check_rest(rest, span, name, unit, allow_outside_range)
    new["r"] = rest
    if old["m"]:
        notes.append(
            f"{ARMATURE} kept at the host's {old['m']:.4g} (the motor's; the flexure's own moving "
            f"inertia {si['m'] if si['m'] is not None else 0:.3g} not added)"
        )
    elif si["m"] is not None:
        new["m"] = si["m"]
    if old["F"] is not None and math.isfinite(old["F"]):
        force = "N.m" if host.rotational else "N"
        notes.append(f"maxForce kept at the host's {old['F']:.4g} {force}: it caps the spring's force")
    if old["friction"]:
        notes.append(f"{FRICTION} kept at the host's {old['friction']:.4g} (the flexure adds none)")
    labels = {"k": "stiffness", "c": "damping", "r": "targetPosition", "m": ARMATURE}
    notes += [
        f"{labels[q]}: {'none' if old[q] is None else format(old[q], '.4g')} -> {v:.4g} (SI)"
        for q, v in new.items()
        if v != old[q]
    ]
    if old["type"] == "acceleration":
        notes.append("drive type: acceleration -> force (the flexure's k and c are forces, not per inertia)")
    return new, tuple(notes)


def check_drive(prim, rotational: bool, stage_units: tuple[float, float], values: dict[str, float]) -> None:
    """Raise unless joint `prim` reads back the drive `values` (SI, as `set_drive` takes them) as the
    32-bit floats they were written as, in the stage's units."""
    import numpy as np
    from pxr import UsdPhysics

    drive = UsdPhysics.DriveAPI.Get(prim, drive_instance(rotational))
    read = {
        "k": drive.GetStiffnessAttr,
        "c": drive.GetDampingAttr,
        "r": drive.GetTargetPositionAttr,
        "F": drive.GetMaxForceAttr,
        "m": lambda: prim.GetAttribute(ARMATURE),
        "friction": lambda: prim.GetAttribute(FRICTION),
    }
    for q, v in values.items():
        scale = 1.0 if q == "friction" else units.usd_factor(q, rotational, *stage_units)
        want, got = float(np.float32(v * scale)), read[q]().Get()
        if got != want:
            raise RuntimeError(f"joint {prim.GetPath()} reads {q} = {got!r}, not {want!r}")


def _check(host: UsdHost, values: dict[str, float], edited: set[str]) -> Callable[[object], None]:
    """A check of the layered stage: the joint holds `values` and nothing else changed."""

    def check(after) -> None:
        changes = stage_changes(host.stage, after, {host.joint.GetPath(): edited})
        if changes:
            raise RuntimeError(f"the layer changes more than the joint's drive: {'; '.join(changes)}")
        check_drive(after.GetPrimAtPath(host.joint.GetPath()), host.rotational, host.units, values)

    return check


def into_parallel(
    joint: Joint,
    host: Path,
    path: Path,
    *,
    joint_name: str,
    axis: str | None = None,
    rest: float | None = None,
    allow_outside_range: bool = False,
) -> tuple[dict[str, StepAdvice], tuple[str, ...]]:
    """Write at `path` a layer over USD robot `host` with its joint `joint_name` made this flexible joint.

    The joint's drive gets stiffness k and damping c (the drive becomes the flexure: a motor's gains on
    it are replaced, its maxForce kept and stated) and targetPosition `rest` (SI; None keeps the
    robot's target when inside the joint's limits, else the limits' nearest value, stated; a given rest
    outside them is refused unless `allow_outside_range`); physxJoint:armature the flexure's moving
    inertia only where the robot has none. Returns the joint's step advice (see `usd_inertia`; none when
    a body it moves states no mass) and one note per robot value changed or kept (old -> new, SI).

    Raises:
        DesignerError: no such file or joint, an axis of the wrong kind, a rest outside the range.
    """
    from pxr import UsdPhysics

    from .usd_inertia import moved_inertia

    h = open_host(host, joint_name)
    a = host_axis(joint, axis, h, joint_name)
    values, notes = _values(h, joint, a, rest, allow_outside_range)
    layer, stage = over_layer(h.stage, h.path, path.suffix)
    prim = stage.GetPrimAtPath(h.joint.GetPath())
    set_drive(prim, h.rotational, values, h.units)
    drive = UsdPhysics.DriveAPI.Get(prim, drive_instance(h.rotational))
    if drive.GetTypeAttr().Get() == "acceleration":
        drive.CreateTypeAttr().Set("force")
    del stage, prim, drive
    spec = layer.GetPrimAtPath(h.joint.GetPath())
    write_over(layer, h.path, path, _check(h, values, set(spec.attributes.keys())))
    si = joint.axes[a].si()
    inertia, missing = moved_inertia(h.stage, h.joint, h.rotational)
    if missing:
        return {}, (
            *notes,
            f"no step advice: body {missing} states no mass or inertia (PhysX computes them from its shapes)",
        )
    armature = values.get("m") or h.si("m", h.joint.GetAttribute(ARMATURE).Get() or 0.0)
    return {h.joint.GetName(): step_advice(si["k"], si["c"], inertia + armature, basis=INERTIA_BASIS)}, notes
