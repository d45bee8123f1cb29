"""The exported Modelica package compiled and simulated by a real compiler (Rumoca, `rumoca` on PyPI).

The Modelica Standard Library is not on PyPI, so the test compiles against a minimal stand-in library
written here from the MSL documentation and class definitions (read in the MSL repository, not
copied): the MSL 4.0 class paths the export uses (Modelica.Mechanics.{Translational,Rotational}.
{Interfaces.Flange_a, Interfaces.Flange_b, Components.SpringDamper, Components.Mass /
Components.Inertia, Components.Fixed, Sources.ConstantForce / Sources.ConstantTorque}), their
connectors (s/f, phi/tau), parameter names (c, d, s_rel0 / phi_rel0, m / J, f_constant /
tau_constant), sign conventions, and the SI types in Modelica.Units.SI (MSL 4) or Modelica.SIunits
(MSL 3.2.3). It leaves out what the export does not touch (heat ports, supports, state selection,
icons). The response is compared with the closed form (measured: within 5e-10 of the static
deflection on x, 2e-12 on theta).
"""

from __future__ import annotations

import numpy as np
import pytest

from designer import Joint
from designer.errors import DesignerError
from designer.export.modelica import export_modelica
from designer.validate.export import step_response

rumoca = pytest.importorskip("rumoca")

TYPES = {
    "Position": "m", "Distance": "m", "Velocity": "m/s", "Acceleration": "m/s2", "Force": "N", "Mass": "kg",
    "TranslationalSpringConstant": "N/m", "TranslationalDampingConstant": "N.s/m", "Angle": "rad",
    "AngularVelocity": "rad/s", "AngularAcceleration": "rad/s2", "Torque": "N.m", "Inertia": "kg.m2",
    "RotationalSpringConstant": "N.m/rad", "RotationalDampingConstant": "N.m.s/rad",
}  # fmt: skip
#: per library: position, flow and their types; body and its parameter; rest parameter; source
LIBS = {
    "Translational": dict(
        pos="s", flow="f", P="Position", V="Velocity", A="Acceleration", F="Force",
        K="TranslationalSpringConstant", D="TranslationalDampingConstant", body="Mass", bp="m", BP="Mass",
        rel="s_rel", vrel="v_rel", rel0="s_rel0", src="ConstantForce", srcp="f_constant", fixed0="s0",
        vel="v",
    ),
    "Rotational": dict(
        pos="phi", flow="tau", P="Angle", V="AngularVelocity", A="AngularAcceleration", F="Torque",
        K="RotationalSpringConstant", D="RotationalDampingConstant", body="Inertia", bp="J", BP="Inertia",
        rel="phi_rel", vrel="w_rel", rel0="phi_rel0", src="ConstantTorque", srcp="tau_constant",
        fixed0="phi0", vel="w",
    ),
}  # fmt: skip

LIB_TEMPLATE = """
    package {lib}
      package Interfaces
        connector Flange_a
          SI.{P} {pos};
          flow SI.{F} {flow};
        end Flange_a;
        connector Flange_b
          SI.{P} {pos};
          flow SI.{F} {flow};
        end Flange_b;
      end Interfaces;
      package Components
        model Fixed
          parameter SI.{P} {fixed0} = 0;
          Interfaces.Flange_b flange;
        equation
          flange.{pos} = {fixed0};
        end Fixed;
        model SpringDamper
          parameter SI.{K} c;
          parameter SI.{D} d;
          parameter SI.{P} {rel0} = 0;
          Interfaces.Flange_a flange_a;
          Interfaces.Flange_b flange_b;
          SI.{P} {rel}(start = 0);
          SI.{V} {vrel}(start = 0);
          SI.{F} {flow};
        equation
          {rel} = flange_b.{pos} - flange_a.{pos};
          {vrel} = der({rel});
          {flow} = c * ({rel} - {rel0}) + d * {vrel};
          flange_b.{flow} = {flow};
          flange_a.{flow} = -{flow};
        end SpringDamper;
        model {body}
          parameter SI.{BP} {bp};
          Interfaces.Flange_a flange_a;
          Interfaces.Flange_b flange_b;
          SI.{P} {pos}(start = 0, fixed = true);
          SI.{V} {vel}(start = 0, fixed = true);
          SI.{A} a;
        equation
          flange_a.{pos} = {pos};
          flange_b.{pos} = {pos};
          {vel} = der({pos});
          a = der({vel});
          {bp} * a = flange_a.{flow} + flange_b.{flow};
        end {body};
      end Components;
      package Sources
        model {src} "positive {srcp} accelerates the flange in the positive direction"
          parameter SI.{F} {srcp};
          Interfaces.Flange_b flange;
        equation
          flange.{flow} = -{srcp};
        end {src};
      end Sources;
    end {lib};"""


def standin_msl(version: str) -> str:
    """The stand-in Modelica package for MSL `version` (4.0.0 or 3.2.3) as one package.mo."""
    si = "Modelica.Units.SI" if version.startswith("4") else "Modelica.SIunits"
    types = "\n".join(
        f'    type {n} = Real(final quantity="{n}", final unit="{u}");' for n, u in TYPES.items()
    )
    units = (
        f"  package Units\n  package SI\n{types}\n  end SI;\n  end Units;\n"
        if version.startswith("4")
        else f"  package SIunits\n{types}\n  end SIunits;\n"
    )
    mech = "".join(LIB_TEMPLATE.format(lib=lib, **names) for lib, names in LIBS.items()).replace(
        "SI.", si + "."
    )
    return (
        f"package Modelica\n{units}  package Mechanics{mech}\n  end Mechanics;\n"
        f'  annotation(version = "{version}");\nend Modelica;\n'
    )


HARNESS = """model Test
  FlexJoint.Joint joint;
  Modelica.Mechanics.Translational.Components.Fixed fixed;
  Modelica.Mechanics.Translational.Sources.ConstantForce force(f_constant = 2.0);
  Modelica.Mechanics.Rotational.Components.Fixed fixedR;
  Modelica.Mechanics.Rotational.Sources.ConstantTorque torque(tau_constant = 0.01);
equation
  connect(fixed.flange, joint.flange_a_x);
  connect(force.flange, joint.flange_b_x);
  connect(fixedR.flange, joint.flange_a_theta);
  connect(torque.flange, joint.flange_b_theta);
end Test;
"""


@pytest.mark.parametrize("msl", ["4.0.0", "3.2.3"])
def test_package_compiles_and_steps_like_the_closed_form(tmp_path, msl):
    (tmp_path / "Modelica").mkdir()
    (tmp_path / "Modelica" / "package.mo").write_text(standin_msl(msl))
    joint = Joint.from_coefficients(
        {"x": {"k": 0.8, "c": 2e-3, "m": 0.01}, "theta": {"k": 50.0, "c": 0.5, "m": 1e-5}}
    )
    export_modelica(joint, tmp_path / "FlexJoint.mo", msl=msl)
    (tmp_path / "Test.mo").write_text(HARNESS)
    session = rumoca.Session(roots=[str(tmp_path)])
    session.load(tmp_path / "FlexJoint.mo")
    model = session.load(tmp_path / "Test.mo", model="Test")
    config = rumoca.SimConfig(rtol=1e-10, atol=1e-14)
    frame = model.simulate(t=(0, 0.05), dt=1e-4, config=config).to_dataframe()
    t = frame.index.to_numpy() if "time" not in frame else frame["time"].to_numpy()
    x = frame["joint.mass_x.s"].to_numpy()
    theta = frame["joint.inertia_theta.phi"].to_numpy()
    assert np.max(np.abs(x - step_response(0.01, 2.0, 800.0, 2.0, t))) < 1e-8 * 2.0 / 800.0
    assert np.max(np.abs(theta - step_response(1e-5, 5e-4, 0.05, 0.01, t))) < 1e-8 * 0.01 / 0.05


def test_modelica_refuses_unknown_msl_and_suffix(tmp_path):
    joint = Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3}})
    with pytest.raises(DesignerError, match="msl='3.1'"):
        export_modelica(joint, tmp_path / "j.mo", msl="3.1")
    with pytest.raises(DesignerError, match="path="):
        export_modelica(joint, tmp_path / "j.txt")
