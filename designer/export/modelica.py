"""Export a Joint as a Modelica package built from the Modelica Standard Library (MSL 4)."""

from __future__ import annotations

import html
import json
from pathlib import Path

from .. import units
from ..files import atomic_write, check_suffix
from ..joint import Joint

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


def modelica_text(joint: Joint) -> str:
    """The package: one model with, per axis, flanges, a SpringDamper and (m known) a Mass/Inertia."""
    decl, eqs = [], []
    for a, ac in joint.axes.items():
        lib, k_type, c_type, body, body_param, m_type = _MSL[units.is_rotational(a)]
        si = ac.si()
        mech = f"Modelica.Mechanics.{lib}"
        decl += [
            f"  parameter Modelica.Units.SI.{k_type} k_{a} = {si['k']!r} "
            f'"stiffness on {a}; {_q(ac.origin)}";',
            f'  parameter Modelica.Units.SI.{c_type} c_{a} = {si["c"]!r} "damping on {a}; {_q(ac.origin)}";',
            f'  {mech}.Interfaces.Flange_a flange_a_{a} "fixed side of axis {a}";',
            f'  {mech}.Interfaces.Flange_b flange_b_{a} "moving side of axis {a}";',
            f"  {mech}.Components.SpringDamper springDamper_{a}(c = k_{a}, d = c_{a});",
        ]
        eqs.append(f"  connect(flange_a_{a}, springDamper_{a}.flange_a);")
        if si["m"] is None:
            eqs.append(f"  connect(springDamper_{a}.flange_b, flange_b_{a});")
        else:
            decl += [
                f'  parameter Modelica.Units.SI.{m_type} m_{a} = {si["m"]!r} "moving {body.lower()} on {a}";',
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
            '  annotation(uses(Modelica(version = "4.0.0")));',
            f"end {joint.name};",
            "",
        ]
    )


def export_modelica(joint: Joint, path: str | Path) -> Path:
    """Write the package as a single .mo file (atomically) and return its path."""
    path = check_suffix(path, (".mo",), what="a Modelica")
    with atomic_write(path) as fh:
        fh.write(modelica_text(joint))
    return path
