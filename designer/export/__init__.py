"""Exporters of a Joint: FMU (FMI 2/3), Modelica package, MJCF, URDF, SDF, USD and SSP.

Each writer takes a `designer.Joint` and a path, writes atomically, refuses a suffix that is not its
format, and returns the path written (the robot formats a `RobotExport`: the path, usable as one, and
the step advice the file states).
"""

from __future__ import annotations

import importlib
from typing import Any

_PUBLIC = {
    "export_fmu": "fmu",
    "export_modelica": "modelica",
    "export_mjcf": "mjcf",
    "export_urdf": "urdf",
    "export_sdf": "urdf",
    "export_usd": "usd",
    "export_ssp": "ssp",
}

__all__ = list(_PUBLIC)


def __getattr__(name: str) -> Any:
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'designer.export' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value
