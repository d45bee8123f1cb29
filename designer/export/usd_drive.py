"""Authoring a UsdPhysics joint's drive and PhysX joint attributes from SI values.

The flexure is a joint's drive (`UsdPhysics.DriveAPI`, instance "angular" on a revolute joint,
"linear" on a prismatic one); its moving inertia and friction go into PhysX's `physxJoint:armature`
and `physxJoint:jointFriction` (PhysxJointAPI). usd-core has no PhysxSchema module, so those are
authored by their schema names, the schema applied by name, as PhysX's own converters write them.
"""

from __future__ import annotations

from .. import units

#: PhysX's joint attributes (PhysxJointAPI), authored by name: usd-core has no PhysxSchema
PHYSX_JOINT_API = "PhysxJointAPI"
ARMATURE = "physxJoint:armature"
FRICTION = "physxJoint:jointFriction"


def drive_instance(rotational: bool) -> str:
    """The DriveAPI instance of a revolute ("angular") or prismatic ("linear") joint."""
    return "angular" if rotational else "linear"


def physx_joint_attribute(prim, name: str):
    """The PhysX joint attribute `name` of `prim` (a float), the PhysxJointAPI schema applied by name."""
    from pxr import Sdf

    if PHYSX_JOINT_API not in prim.GetAppliedSchemas():
        prim.AddAppliedSchema(PHYSX_JOINT_API)
    return prim.CreateAttribute(name, Sdf.ValueTypeNames.Float, custom=False)


def set_drive(prim, rotational: bool, values: dict[str, float], stage_units: tuple[float, float]) -> None:
    """Author on joint `prim` the drive's `values` given in SI: any of k (stiffness), c (damping),
    r (targetPosition), F (maxForce); m (armature) and friction go to the PhysX joint attributes.
    `stage_units` is (metersPerUnit, kilogramsPerUnit)."""
    from pxr import UsdPhysics

    instance = drive_instance(rotational)
    has = prim.HasAPI(UsdPhysics.DriveAPI, instance)
    drive = UsdPhysics.DriveAPI(prim, instance) if has else UsdPhysics.DriveAPI.Apply(prim, instance)
    attrs = {
        "k": drive.CreateStiffnessAttr,
        "c": drive.CreateDampingAttr,
        "r": drive.CreateTargetPositionAttr,
        "F": drive.CreateMaxForceAttr,
    }
    for q, value in values.items():
        if q == "friction":
            physx_joint_attribute(prim, FRICTION).Set(float(value))
            continue
        scaled = value * units.usd_factor(q, rotational, *stage_units)
        if q == "m":
            physx_joint_attribute(prim, ARMATURE).Set(scaled)
        else:
            attrs[q]().Set(scaled)
