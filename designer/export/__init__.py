"""Exporters of a Joint: FMU (FMI 2/3), Modelica package, MJCF and URDF.

Each writer takes a `designer.Joint` and a path, writes atomically, refuses a suffix that is not its
format, and returns the path written.
"""

from __future__ import annotations

import importlib
from typing import Any

_PUBLIC = {
    "export_fmu": "fmu",
    "export_modelica": "modelica",
    "export_mjcf": "robot",
    "export_urdf": "robot",
}

__all__ = list(_PUBLIC)


def __getattr__(name: str) -> Any:
    module = _PUBLIC.get(name)
    if module is None:
        raise AttributeError(f"module 'designer.export' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value
