"""The whole path from Python: fit, predict, suggest, export an FMU, co-simulate in memory.

Run: python examples/api_tour.py [folder]   (writes joint.fmu and arm.toml into the folder, default .)
"""

import sys
from pathlib import Path

import designer

out = Path(sys.argv[1] if len(sys.argv) > 1 else ".")
out.mkdir(parents=True, exist_ok=True)
table = designer.load_table()  # the study's 44 runs as a DataFrame, rig units
surrogate = designer.Surrogate().fit(table)
design = {"density": 60, "length": 24, "width": 4.5, "height": 9, "layer": 0.16, "raster": 0}
k = surrogate.predict(design)["k_x"]  # a Prediction: value, low, high (95 % PI), N/mm
print(f"k_x = {k.value[0]:.3g} N/mm, 95 % PI {k.low[0]:.3g} to {k.high[0]:.3g}")
suggestion = designer.suggest(surrogate, k=0.8, fixed={"length": 24}, top=3)
best = suggestion.candidates[0]
p = best.predicted["k"]
print(f"print {best.params}: k_x = {p.value:.3g} N/mm, 95 % PI {p.low:.3g} to {p.high:.3g}")
joint = designer.Joint.from_suggestion(suggestion, axes=["theta"], name="j1")
fmu = designer.export_fmu(joint, out / "joint.fmu")  # FMI 2, force interface, SI units
(out / "arm.toml").write_text(f"""[simulation]
duration = 1.0
step = 1e-3
[robot]
model = "arm"
[joints.j1]
fmu = "{fmu.resolve()}"
reference = {{ type = "step", amplitude = 0.3, at = 0.1 }}
""")
result = designer.cosim.run(designer.cosim.load(out / "arm.toml"))  # in memory, nothing written
frame = result.to_frame()  # t [s], robot.j1.q [rad], j1.theta.f [N.m], ...
print(frame[["t", "robot.j1.q", "j1.theta.f"]].tail(3))
print(f"overshoot {result.metrics['j1']['overshoot_pct']:.3g} %")
