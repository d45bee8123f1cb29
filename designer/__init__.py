"""flexjoint designer: from print settings of TPU flexible joints to stiffness, damping and FMUs.

The public API (computing returns data; writing and plotting are separate calls)::

    import designer
    table = designer.load_table()                      # the bundled study table (rig units)
    sur = designer.Surrogate().fit(table)              # or designer.Surrogate.load()
    pred = sur.predict(design)["k_x"]                  # designer.Prediction: value, low, high
    sug = designer.suggest(sur, k=0.8, c=2e-3)         # designer.Suggestion, ranked candidates
    mine = designer.calibrate(sur, "my_runs.csv")      # the surrogate updated by your own prints
    nxt = designer.next_prints(mine, k=0.8, n=3)       # what to print and measure next
    joint = designer.Joint.from_suggestion(sug)        # or Joint.from_design / from_coefficients
    designer.export_fmu(joint, "joint.fmu")            # export_modelica, export_mjcf, export_urdf, export_usd
    fits = designer.identify(["run1.csv"])             # rig logs -> coefficients
    result = designer.cosim.run(designer.cosim.load("arm.toml"))  # in memory; result.to_frame()

Every bad input raises `designer.DesignerError` naming the argument and the fix. The `designer`
command (package `designer_cli`) is a thin layer that parses, calls and prints. Names are imported
on first use, so `import designer` stays cheap.
"""

from __future__ import annotations

import importlib
from typing import Any

from .errors import DesignerError

__version__ = "0.1.0"

#: public name -> module that defines it (imported on first access)
_PUBLIC = {
    "load_table": "study.data",
    "Surrogate": "model.surrogate",
    "Prediction": "model.prediction",
    "suggest": "design.suggestions",
    "Suggestion": "design.candidates",
    "calibrate": "model.calibration",
    "next_prints": "design.next_prints",
    "Joint": "joint",
    "export_fmu": "export",
    "export_modelica": "export",
    "export_mjcf": "export",
    "export_urdf": "export",
    "export_sdf": "export",
    "export_usd": "export",
    "export_ssp": "export",
    "identify": "rig.identify",
}
#: public names that are subpackages
_SUBPACKAGES = ("cosim", "sweep")

__all__ = ["DesignerError", "__version__", *_PUBLIC, *_SUBPACKAGES]


def __getattr__(name: str) -> Any:
    if name in _SUBPACKAGES:
        return importlib.import_module(f".{name}", __name__)
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'designer' has no attribute {name!r}")
    mod = importlib.import_module(f".{module}", __name__)
    value = getattr(mod, name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(__all__)
