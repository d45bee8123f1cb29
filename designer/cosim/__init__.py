"""Co-simulation of joint FMUs with a MuJoCo robot or the virtual rig.

sc = designer.cosim.load("examples/two_link_arm.toml")    # or designer.cosim.Scenario(...)
result = designer.cosim.run(sc)                           # in memory, nothing written
with designer.cosim.prepare(sc) as session:               # set-up once, then many runs
    results = [session.run({"j1": {"theta.k": k}}) for k in (0.2, 0.3)]  # SI parameters
frame = result.to_frame()                                 # t [s], then system.variable in SI
designer.cosim.write_outputs(result, "results/")          # time series, metrics.json, plot.png
"""

from .master import Master, Trace
from .references import Chirp, Sine, Step, Trajectory
from .result import Result
from .rig_scenario import RigScenario
from .robot import Robot, SpringDamper, load_spec, planar_arm_xml
from .robot_scenario import RobotScenario
from .run import plot_result, run, write_outputs
from .scenario import JointSource, Scenario
from .scenario_file import load
from .session import Session, prepare

__all__ = [
    "Chirp",
    "JointSource",
    "Master",
    "Result",
    "RigScenario",
    "Robot",
    "RobotScenario",
    "Scenario",
    "Session",
    "Sine",
    "SpringDamper",
    "Step",
    "Trace",
    "Trajectory",
    "load",
    "load_spec",
    "planar_arm_xml",
    "prepare",
    "plot_result",
    "run",
    "write_outputs",
]
