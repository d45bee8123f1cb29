"""The inertia a USD robot joint moves, from the bodies' MassAPI, for the step advice.

The bodies on body1's side of the joint (found through the other joints, never back through body0)
are placed where the stage puts them (their world transforms as authored, the robot's reference
pose) and held to each other: their inertia about the joint's world axis (each body's principal
inertia turned onto the axis, plus mass times its centre's squared distance from the axis) is the
joint-space inertia with the other joints held; on a prismatic joint it is their total mass. In SI.
"""

from __future__ import annotations

import math
from collections import deque

AXES = {"X": (1.0, 0.0, 0.0), "Y": (0.0, 1.0, 0.0), "Z": (0.0, 0.0, 1.0)}


def _frame(stage, body_path, local_pos, local_rot):
    """The joint frame's world position and rotation (Gf), given its body and its place in that body."""
    from pxr import Gf, Usd, UsdGeom

    rot = Gf.Rotation(Gf.Quatd(local_rot.GetReal(), Gf.Vec3d(local_rot.GetImaginary())))
    pos = Gf.Vec3d(local_pos)
    if body_path is None:
        return pos, rot
    world = UsdGeom.Xformable(stage.GetPrimAtPath(body_path)).ComputeLocalToWorldTransform(
        Usd.TimeCode.Default()
    )
    world = Gf.Matrix4d(world).RemoveScaleShear()
    return world.Transform(pos), rot * world.ExtractRotation()


def _moved_bodies(stage, joint) -> list:
    """The body paths on body1's side of `joint`, through every other joint of the stage."""
    from pxr import Usd, UsdPhysics

    def ends(j):
        s = UsdPhysics.Joint(j)
        return s.GetBody0Rel().GetTargets(), s.GetBody1Rel().GetTargets()

    first, second = ends(joint)
    links: dict = {}
    for prim in Usd.PrimRange.Stage(stage):
        if prim.IsA(UsdPhysics.Joint) and prim != joint:
            b0, b1 = ends(prim)
            for x in b0:
                for y in b1:
                    links.setdefault(x, set()).add(y)
                    links.setdefault(y, set()).add(x)
    seen, queue = set(second), deque(second)
    while queue:
        for nxt in links.get(queue.popleft(), ()):
            if nxt not in seen and nxt not in first:
                seen.add(nxt)
                queue.append(nxt)
    return sorted(seen)


def moved_inertia(stage, joint, rotational: bool) -> tuple[float, str | None]:
    """The inertia (kg.m^2) or mass (kg) that robot joint `joint` moves, the other joints held, and
    None; or (0, the path of the first moved body that states no positive mass, or no inertia on a
    revolute joint)."""
    from pxr import Gf, Usd, UsdGeom, UsdPhysics

    meters, kilograms = UsdGeom.GetStageMetersPerUnit(stage), UsdPhysics.GetStageKilogramsPerUnit(stage)
    s = UsdPhysics.Joint(joint)
    body0 = s.GetBody0Rel().GetTargets()
    pos, rot = _frame(
        stage, body0[0] if body0 else None, s.GetLocalPos0Attr().Get(), s.GetLocalRot0Attr().Get()
    )
    token = joint.GetAttribute("physics:axis").Get() or "X"
    axis = rot.TransformDir(Gf.Vec3d(*AXES[token])).GetNormalized()
    total = 0.0
    for path in _moved_bodies(stage, joint):
        prim = stage.GetPrimAtPath(path)
        mass_api = UsdPhysics.MassAPI(prim)
        m = mass_api.GetMassAttr().Get() if prim.HasAPI(UsdPhysics.MassAPI) else None
        if not m or m <= 0:
            return 0.0, str(path)
        m *= kilograms
        if not rotational:
            total += m
            continue
        # MassAPI's fallbacks mean "computed from the shapes": centre -inf (taken as the body's origin),
        # principal axes (0, 0, 0, 0) (taken as the body's axes), diagonal inertia 0 (not stated)
        diagonal = mass_api.GetDiagonalInertiaAttr().Get() or Gf.Vec3f(0)
        if not any(diagonal):
            return 0.0, str(path)
        world = Gf.Matrix4d(UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default()))
        world = world.RemoveScaleShear()
        local = mass_api.GetCenterOfMassAttr().Get()
        local = Gf.Vec3d(local) if local is not None and all(math.isfinite(v) for v in local) else Gf.Vec3d(0)
        centre = world.Transform(local)
        principal = mass_api.GetPrincipalAxesAttr().Get()
        principal = principal if principal is not None and principal.GetLength() > 0 else Gf.Quatf(1)
        turn = Gf.Rotation(Gf.Quatd(principal.GetReal(), Gf.Vec3d(principal.GetImaginary())))
        n = (turn * world.ExtractRotation()).GetInverse().TransformDir(axis)
        spin = sum(d * c * c for d, c in zip(diagonal, n, strict=True)) * kilograms * meters**2
        r = (centre - pos) * meters
        across = r - axis * (r * axis)
        total += spin + m * across.GetLength() ** 2
    return total, None
