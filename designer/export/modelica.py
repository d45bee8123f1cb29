"""Export a Joint as a Modelica package built from the Modelica Standard Library (MSL 4, or 3.2.3).

MSL 4 keeps SI types in `Modelica.Units.SI`; MSL 3.2.3 in `Modelica.SIunits`. The components used
(Translational/Rotational SpringDamper with `c`, `d`; Mass `m`; Inertia `J`; flanges) are the same in both.
"""

from __future__ import annotations

import html
import json
from pathlib import Path

from .. import units
from ..errors import DesignerError
from ..files import atomic_write, check_suffix
from ..joint import Joint, check_joint

#: supported MSL versions and the package holding their SI types
MSL_UNITS = {"4.0.0": "Modelica.Units.SI", "3.2.3": "Modelica.SIunits"}

_MSL = {
    False: (
        "Translational",
        "TranslationalSpringConstant",
        "TranslationalDampingConstant",
        "Mass",
        "m",
        "Mass",
    ),
    True: ("Rotational", "RotationalSpringConstant", "RotationalDampingConstant", "Inertia", "J", "Inertia"),
}


def _q(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"')


def modelica_text(joint: Joint, *, msl: str = "4.0.0") -> str:
    """The package: one model with, per axis, flanges, a SpringDamper and (m known) a Mass/Inertia.

    Raises:
        DesignerError: `msl` is not a supported MSL version.
    """
    if not isinstance(msl, str) or msl not in MSL_UNITS:
        raise DesignerError(f"msl={msl!r} is not supported", f"use one of: {', '.join(MSL_UNITS)}")
    si_types = MSL_UNITS[msl]
    decl, eqs = [], []
    for a, ac in joint.axes.items():
        lib, k_type, c_type, body, body_param, m_type = _MSL[units.is_rotational(a)]
        si = ac.si()
        mech = f"Modelica.Mechanics.{lib}"
        decl += [
            f'  parameter {si_types}.{k_type} k_{a} = {si["k"]!r} "stiffness on {a}; {_q(ac.origin)}";',
            f'  parameter {si_types}.{c_type} c_{a} = {si["c"]!r} "damping on {a}; {_q(ac.origin)}";',
            f'  {mech}.Interfaces.Flange_a flange_a_{a} "fixed side of axis {a}";',
            f'  {mech}.Interfaces.Flange_b flange_b_{a} "moving side of axis {a}";',
            f"  {mech}.Components.SpringDamper springDamper_{a}(c = k_{a}, d = c_{a});",
        ]
        eqs.append(f"  connect(flange_a_{a}, springDamper_{a}.flange_a);")
        if si["m"] is None:
            eqs.append(f"  connect(springDamper_{a}.flange_b, flange_b_{a});")
        else:
            decl += [
                f'  parameter {si_types}.{m_type} m_{a} = {si["m"]!r} "moving {body.lower()} on {a}";',
                f"  {mech}.Components.{body} {body.lower()}_{a}({body_param} = m_{a});",
            ]
            eqs += [
                f"  connect(springDamper_{a}.flange_b, {body.lower()}_{a}.flange_a);",
                f"  connect({body.lower()}_{a}.flange_b, flange_b_{a});",
            ]
    prov = html.escape(json.dumps(joint.to_dict(), indent=2, sort_keys=True, default=str))
    info = f"<html><p>3D-printed TPU flexible joint, SI units.</p><pre>{prov}</pre></html>"
    return "\n".join(
        [
            f'package {joint.name} "3D-printed TPU flexible joint (flexjoint designer)"',
            f'  model Joint "spring-damper per axis: {", ".join(joint.axes)}"',
            *("  " + d for d in decl),
            "  equation",
            *("  " + e for e in eqs),
            f'    annotation(Documentation(info = "{_q(info)}"));',
            "  end Joint;",
            f'  annotation(uses(Modelica(version = "{msl}")));',
            f"end {joint.name};",
            "",
        ]
    )


def export_modelica(joint: Joint, path: str | Path, *, msl: str = "4.0.0") -> Path:
    """Write the package as a single .mo file (atomically) for MSL `msl` and return its path.

    Raises:
        DesignerError: a path not ending in .mo, or an unsupported `msl`.
    """
    path = check_suffix(path, (".mo",), what="a Modelica")
    check_joint(joint)
    text = modelica_text(joint, msl=msl)
    with atomic_write(path) as fh:
        fh.write(text)
    return path
