"""G-code read back from the slicer, independently of `designer`: the extrusion moves of each
labelled object with their layer, feature type and line width, and the temperatures commanded.

Only what PrusaSlicer writes by itself is used: `;Z:` and `;HEIGHT:` at each layer change,
`;TYPE:` and `;WIDTH:` before each feature, `; printing object NAME` around each object's moves
(`gcode_label_objects`), G0/G1 moves with absolute or relative E (M82/M83, G92), M104/M109 and
M140/M190 temperatures.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

_WORD = re.compile(r"([XYZEF])(-?\d*\.?\d+)")


@dataclass
class Moves:
    """Extrusion segments (one row each) and the temperatures of a G-code file."""

    #: columns: x0, y0, x1, y1, z (print_z of the layer), height (layer), width, e (mm of filament)
    segments: np.ndarray
    objects: list[str]
    kinds: list[str]
    #: the index of the extrusion run (moves without a travel between them) of each segment
    runs: np.ndarray
    nozzle_c: list[float] = field(default_factory=list)
    bed_c: list[float] = field(default_factory=list)

    def select(self, obj: str, kind: str | None = None) -> np.ndarray:
        """Rows of the segments of object `obj` (and of feature `kind` when given)."""
        return np.array(
            [i for i, (o, k) in enumerate(zip(self.objects, self.kinds)) if o == obj and kind in (None, k)],
            dtype=int,
        )


def read(path) -> Moves:
    """Parse a G-code file into `Moves`."""
    x = y = e = 0.0
    z = height = width = 0.0
    relative_e = False
    obj, kind = "", ""
    rows, objects, kinds, runs = [], [], [], []
    run = 0
    nozzle, bed = [], []
    with open(path) as fh:
        for line in fh:
            if line.startswith(";"):
                if line.startswith(";Z:"):
                    z = float(line[3:])
                elif line.startswith(";HEIGHT:"):
                    height = float(line[8:])
                elif line.startswith(";TYPE:"):
                    kind = line[6:].strip()
                    run += 1
                elif line.startswith(";WIDTH:"):
                    width = float(line[7:])
                elif line.startswith("; printing object "):
                    obj = line[len("; printing object ") :].split(" id:")[0].strip()
                    run += 1
                elif line.startswith("; stop printing object"):
                    obj = ""
                    run += 1
                continue
            code = line.split(";", 1)[0].strip()
            if not code:
                continue
            head = code.split()[0]
            words = dict((k, float(v)) for k, v in _WORD.findall(code[len(head) :]))
            if head in ("M104", "M109") and "S" in code:
                nozzle.append(float(re.search(r"S(\d+\.?\d*)", code)[1]))
            elif head in ("M140", "M190") and "S" in code:
                bed.append(float(re.search(r"S(\d+\.?\d*)", code)[1]))
            elif head == "M82":
                relative_e = False
            elif head == "M83":
                relative_e = True
            elif head == "G92" and "E" in words:
                e = words["E"]
            elif head in ("G0", "G1"):
                nx, ny = words.get("X", x), words.get("Y", y)
                de = 0.0
                if "E" in words:
                    de = words["E"] if relative_e else words["E"] - e
                    e = e + words["E"] if relative_e else words["E"]
                moved = (nx, ny) != (x, y)
                if moved and de > 0:
                    rows.append((x, y, nx, ny, z, height, width, de))
                    objects.append(obj)
                    kinds.append(kind)
                    runs.append(run)
                elif moved:
                    run += 1
                x, y = nx, ny
    return Moves(np.array(rows, dtype=float).reshape(-1, 8), objects, kinds, np.array(runs), nozzle, bed)
