"""Co-simulation of joint FMUs with a MuJoCo robot or the virtual rig: master, robot adapter, scenarios."""

from .master import Master, Result
from .robot import Robot, SpringDamper, load_spec, planar_arm_xml
from .run import simulate
from .scenario import Scenario, load

__all__ = [
    "Master",
    "Result",
    "Robot",
    "SpringDamper",
    "Scenario",
    "load",
    "load_spec",
    "planar_arm_xml",
    "simulate",
]
