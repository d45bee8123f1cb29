"""Where the FlexJoint C runtime is, and the model's layout and capabilities, read from the one place
they are declared: `fmus/FlexJoint/config.h` (as the Modelica Reference FMUs keep them in the model's
config.h).

The C runtime compiles the same file, so the value references and capability flags written into a
modelDescription.xml are those the binary implements.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from functools import cache
from importlib import resources
from pathlib import Path

from ..errors import DesignerError


def source_dir() -> Path:
    """The folder holding the C runtime (`fmus/` in the checkout, `designer/fmus` when installed)."""
    return Path(str(resources.files("designer.fmus")))


CAPABILITIES = (
    "HAS_EVENT_MODE",
    "PROVIDES_DIRECTIONAL_DERIVATIVES",
    "PROVIDES_ADJOINT_DERIVATIVES",
    "CAN_GET_AND_SET_FMU_STATE",
    "CAN_SERIALIZE_FMU_STATE",
    "NEEDS_COMPLETED_INTEGRATOR_STEP",
    "CAN_HANDLE_VARIABLE_COMMUNICATION_STEP_SIZE",
    "N_EVENT_INDICATORS",
)


@dataclass(frozen=True)
class Layout:
    """Model identifier, axis and field names in value-reference order, the stride and the flags."""

    model_identifier: str
    axes: tuple[str, ...]
    fields: tuple[str, ...]
    vr_time: int
    stride: int
    capabilities: dict[str, int]

    def value_reference(self, axis: str, field: str) -> int:
        """`stride * (axis index + 1) + field index`, as the runtime's lookup decodes it."""
        return self.stride * (self.axes.index(axis) + 1) + self.fields.index(field)

    def flag(self, name: str) -> str:
        """A capability as an XML boolean, "true" or "false"."""
        return "true" if self.capabilities[name] else "false"


def _define(text: str, name: str) -> str:
    m = re.search(rf"^#define {name} (.+?)\s*$", text, re.M)
    if m is None:
        raise DesignerError(
            f"config.h declares no {name}", "reinstall flexjoint-designer: its FMU sources are incomplete"
        )
    return m.group(1)


def _names(text: str, name: str) -> tuple[str, ...]:
    return tuple(re.findall(r'"([^"]*)"', _define(text, name)))


@cache
def layout() -> Layout:
    """Parse `FlexJoint/config.h`; checks the field enum against FIELD_NAMES and N_AXES.

    Raises:
        DesignerError: if the header lacks a declaration or disagrees with itself.
    """
    text = (source_dir() / "FlexJoint" / "config.h").read_text()
    axes, fields = _names(text, "AXIS_NAMES"), _names(text, "FIELD_NAMES")
    enum = re.search(r"enum \{ (F_\w+(?:, F_\w+)*), N_FIELDS \};", text)
    if enum is None or [f.strip()[2:].lower() for f in enum.group(1).split(",")] != list(fields):
        raise DesignerError(
            "config.h: the field enum does not match FIELD_NAMES", "fix fmus/FlexJoint/config.h"
        )
    if len(axes) != int(_define(text, "N_AXES")):
        raise DesignerError("config.h: AXIS_NAMES does not have N_AXES names", "fix fmus/FlexJoint/config.h")
    return Layout(
        model_identifier=_define(text, "MODEL_IDENTIFIER").strip('"'),
        axes=axes,
        fields=fields,
        vr_time=int(_define(text, "VR_TIME")),
        stride=int(_define(text, "VR_AXIS_STRIDE")),
        capabilities={c: int(_define(text, c)) for c in CAPABILITIES},
    )
