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
            [
                i
                for i, (o, k) in enumerate(zip(self.objects, self.kinds, strict=True))
                if o == obj and kind in (None, k)
            ],
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


def _layer(moves: Moves, rows: np.ndarray, z: float) -> np.ndarray:
    """The segments of `rows` on the printed layer nearest z."""
    seg = moves.segments[rows]
    levels = np.unique(seg[:, 4])
    level = levels[np.abs(levels - z).argmin()]
    return rows[seg[:, 4] == level]


def layer_heights(moves: Moves, obj: str) -> np.ndarray:
    """The distinct steps between an object's layers above its first (mm, to 1e-4)."""
    levels = np.unique(moves.segments[moves.select(obj), 4])
    return np.unique(np.round(np.diff(levels[1:]), 4))


def infill_directions(moves: Moves, obj: str, z: float) -> list[float]:
    """The three directions (deg mod 180, rounded) carrying most of the internal infill's length
    on the layer nearest z."""
    seg = moves.segments[_layer(moves, moves.select(obj, "Internal infill"), z)]
    length = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    angle = np.round(np.degrees(np.arctan2(seg[:, 3] - seg[:, 1], seg[:, 2] - seg[:, 0])) % 180) % 180
    totals = {a: length[angle == a].sum() for a in np.unique(angle)}
    return sorted(sorted(totals, key=totals.get)[-3:])


def infill_density(moves: Moves, obj: str, z: float, direction: float) -> float:
    """The cubic infill's density (%) from the spacing of its lines along `direction` on the layer
    nearest z. PrusaSlicer spaces a sparse infill's lines by the flow's spacing over the density
    (Flow::spacing: width - height (1 - pi/4)), and its cubic pattern splits the density over
    three directions: density = 3 spacing / line pitch."""
    rows = _layer(moves, moves.select(obj, "Internal infill"), z)
    seg = moves.segments[rows]
    length = np.hypot(seg[:, 2] - seg[:, 0], seg[:, 3] - seg[:, 1])
    angle = np.degrees(np.arctan2(seg[:, 3] - seg[:, 1], seg[:, 2] - seg[:, 0])) % 180
    along = (np.abs((angle - direction + 90) % 180 - 90) < 0.5) & (length > 1.0)
    a = np.radians(direction)
    offsets = np.unique(np.round(seg[along, :2] @ np.array([-np.sin(a), np.cos(a)]), 3))
    pitch = float(np.median(np.diff(offsets)))
    height, width = seg[along, 5].mean(), seg[along, 6].mean()
    return 100.0 * 3.0 * (width - height * (1.0 - np.pi / 4.0)) / pitch


def perimeters(moves: Moves, obj: str, z: float) -> float:
    """Perimeter loops per island on the layer nearest z (each island has one external loop)."""
    ext = len(set(moves.runs[_layer(moves, moves.select(obj, "External perimeter"), z)]))
    inner = len(set(moves.runs[_layer(moves, moves.select(obj, "Perimeter"), z)]))
    return (ext + inner) / ext


def beam(moves: Moves, obj: str, above: float, within: float) -> tuple[float, float, float]:
    """The printed beam's length, width and height (mm) between two blocks along x.

    Length: the gap between the blocks' external perimeters on a layer `above` the beam, less one
    line width (a perimeter's centre lies half a width inside the part's edge). Width: the beam's
    external perimeters across the gap's middle on a layer `within` the beam, plus one line width.
    Height: the top of the highest layer extruding across the gap's middle.
    """
    ext = moves.segments[_layer(moves, moves.select(obj, "External perimeter"), above)]
    xs = np.unique(np.round(np.r_[ext[:, 0], ext[:, 2]], 4))
    gap = int(np.diff(xs).argmax())
    left, right = xs[gap], xs[gap + 1]
    width = ext[:, 6].mean()
    mid = (left + right) / 2

    def crossing(seg: np.ndarray) -> np.ndarray:
        return (np.minimum(seg[:, 0], seg[:, 2]) < mid) & (np.maximum(seg[:, 0], seg[:, 2]) > mid)

    every = moves.segments[moves.select(obj)]
    top = every[crossing(every), 4].max()
    low = moves.segments[_layer(moves, moves.select(obj, "External perimeter"), within)]
    low = low[crossing(low)]
    t = (mid - low[:, 0]) / (low[:, 2] - low[:, 0])
    ys = low[:, 1] + t * (low[:, 3] - low[:, 1])
    return float(right - left - width), float(ys.max() - ys.min() + width), float(top)


def walls(moves: Moves, obj: str, z: float, x: float) -> tuple[float, float]:
    """The two walls' thickness (mm) across the line at `x` on the layer nearest z: from the part's
    edge (the external perimeter's centre less half its width) to where PrusaSlicer bounds the infill,
    half a flow spacing (width - height (1 - pi/4)) beyond the centre of the innermost perimeter."""
    rows = _layer(moves, moves.select(obj), z)
    seg = moves.segments[rows]
    kinds = np.array([moves.kinds[i] for i in rows])
    cross = (np.minimum(seg[:, 0], seg[:, 2]) < x) & (np.maximum(seg[:, 0], seg[:, 2]) > x)
    cross &= np.isin(kinds, ["External perimeter", "Perimeter"])
    seg = seg[cross]
    ys = seg[:, 1] + (x - seg[:, 0]) / (seg[:, 2] - seg[:, 0]) * (seg[:, 3] - seg[:, 1])
    order = np.argsort(ys)
    ys, seg = ys[order], seg[order]
    half = len(ys) // 2
    spacing = seg[:, 6] - seg[:, 5] * (1.0 - np.pi / 4.0)
    low = ys[half - 1] + spacing[half - 1] / 2 - (ys[0] - seg[0, 6] / 2)
    high = ys[-1] + seg[-1, 6] / 2 - (ys[half] - spacing[half] / 2)
    return float(low), float(high)


def share_within(seg: np.ndarray, start: float, end: float) -> np.ndarray:
    """Each segment's share of its length between x = start and x = end (a segment across x, of no
    length along it, counts whole when it lies between)."""
    lo, hi = seg[:, [0, 2]].min(axis=1), seg[:, [0, 2]].max(axis=1)
    across = hi - lo < 1e-6
    inside = np.clip(np.minimum(hi, end) - np.maximum(lo, start), 0, None)
    return np.where(across, (lo >= start) & (lo <= end), inside / np.where(across, 1, hi - lo))


def bottom_shell(moves: Moves, obj: str, start: float, end: float, height: float) -> float:
    """The top (print z, mm) of the solid layers at the bottom of the part between x = start and
    x = end: the last of the layers from the first up, below `height` / 2, extruding there no
    sparse infill ("Internal infill")."""
    rows = moves.select(obj)
    seg = moves.segments[rows]
    kinds = np.array([moves.kinds[i] for i in rows])
    there = share_within(seg, start, end) > 0
    top = 0.0
    for z in np.unique(seg[there, 4]):
        if z > height / 2 or (there & (seg[:, 4] == z) & (kinds == "Internal infill")).any():
            break
        top = float(z)
    return top
