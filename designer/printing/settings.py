"""Slicer settings of one print: the study's process (cubic infill, rectilinear when solid, a 0.8 mm
shell from a 0.4 mm nozzle, TPU at 210 C on a 60 C bed) and the print's own layer height, infill
density and angle.

Two dialects: PrusaSlicer's option names (its `.ini` and the 3MF's `Slic3r_PE` configs) and
OrcaSlicer / Bambu Studio's (the 3MF's `model_settings.config` and `project_settings.config`).
Per object go the settings a print varies; the plate-wide ones (printer, filament, temperatures)
are the same for every print of a batch.
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from ..study import space

#: the study's material and process
MATERIAL = "TPU"
NOZZLE_C = 210
BED_C = 60
INFILL_PATTERN = "cubic"
#: the pattern of a 100 % infill: cubic's three crossing directions, each a third full, leave a
#: lattice (PrusaSlicer refuses it at 100 %, and its own dialog switches to rectilinear); rectilinear
#: lays the lines side by side, along the raster and across it layer by layer
SOLID_PATTERN = "rectilinear"
FILAMENT_MM = 1.75
FIRST_LAYER_MM = 0.2
#: the wall: two 0.4 mm lines, 0.8 mm, on the sides, top and bottom
PERIMETERS = round(space.WALL_MM / space.NOZZLE_MM)
#: TPU prints slowly: the volumetric flow PrusaSlicer caps every move at, mm^3/s
MAX_FLOW = 2.5
#: the study's printer, an Ender 3: 220 x 220 mm build plate
BED_MM = 220.0
#: the G-code's end: both heaters off (PrusaSlicer's default end switches the nozzle off only and
#: leaves the bed at 60 C), the head homed along X, the motors off
END_GCODE = ("M104 S0 ; nozzle heater off", "M140 S0 ; bed heater off", "G28 X0 ; home X", "M84 ; motors off")


def solid_layers(layer: float) -> int:
    """Top solid layers making at least the 0.8 mm shell at this layer height."""
    return math.ceil(space.WALL_MM / layer - 1e-9)


def bottom_layers(layer: float) -> int:
    """Bottom solid layers making at least the 0.8 mm shell over the FIRST_LAYER_MM first layer (at
    0.12 mm layers 6, 0.8 mm; counted as top layers, 7 had made 0.92 mm)."""
    return 1 + math.ceil((space.WALL_MM - FIRST_LAYER_MM) / layer - 1e-9)


def wall_line_width(layer: float) -> float:
    """The perimeter line width (mm) at which the PERIMETERS lines make the model's 0.8 mm wall at
    this layer height, the infill starting WALL_MM in from the part's edge.

    PrusaSlicer lays the external perimeter's centre half a width in from the edge, each next one a
    flow spacing further (spacing = width - layer (1 - pi/4), its Flow::spacing) and bounds the
    infill half a spacing beyond the last: the wall is width / 2 + (n - 1/2) spacing. With 0.4 mm
    lines that was 0.74 mm at 0.2 mm layers and 0.76 mm at 0.12 mm, leaving a wider core than the
    model's (a 2.0 mm beam's 0.53 mm, not 0.4 mm).
    """
    n, flat = PERIMETERS, layer * (1 - math.pi / 4)
    return round((space.WALL_MM + (n - 0.5) * flat) / n, 4)


def _number(value: float) -> str:
    return f"{value:g}"


def printed_density(params: Mapping[str, float]) -> float:
    """The infill density (%) a print is sliced at: its own, or 100 when the model treats its
    section as solid (`space.infill_matters`: the two walls leave at most one nozzle line).

    PrusaSlicer does not fill such a core by itself: a 2.0 mm beam at 20 % printed its two
    perimeters around a 0.5 mm strip holding 2 % of the section in infill lines (0.74 of the
    section extruded), while the model predicts the section solid whatever the nominal density.
    """
    return params["density"] if space.infill_matters(params) else 100.0


def infill_pattern(density: float) -> str:
    """PrusaSlicer's infill pattern at `density` %: the study's cubic, rectilinear when solid."""
    return SOLID_PATTERN if density >= 100 else INFILL_PATTERN


def prusa_object(params: Mapping[str, float]) -> dict[str, str]:
    """PrusaSlicer's per-object options of one print (what the 3MF's object config holds)."""
    layers = str(solid_layers(params["layer"]))
    density = printed_density(params)
    return {
        "layer_height": _number(params["layer"]),
        "fill_density": f"{_number(density)}%",
        "fill_pattern": infill_pattern(density),
        "fill_angle": _number(params["raster"]),
        "perimeters": str(PERIMETERS),
        # fixed-width perimeters: Arachne (PrusaSlicer 2.5's default) varies them along the beam,
        # its walls 0.791 to 0.799 mm where the classic generator's are 0.7996 all along
        "perimeter_generator": "classic",
        # the core between the walls: classic perimeters fill one narrower than two lines with gap
        # fill, solid (a 2.2 mm beam's 0.6 mm core at 20 %: 0.98 of the section extruded), where
        # the model has infill at the print's density; a solid section's core is one line of gap fill
        "gap_fill_enabled": "1" if density >= 100 else "0",
        "perimeter_extrusion_width": _number(wall_line_width(params["layer"])),
        "external_perimeter_extrusion_width": _number(wall_line_width(params["layer"])),
        "top_solid_layers": layers,
        "bottom_solid_layers": str(bottom_layers(params["layer"])),
        "top_solid_min_thickness": _number(space.WALL_MM),
        "bottom_solid_min_thickness": _number(space.WALL_MM),
        # no infill line anchored to the perimeter: in a narrow beam the anchors run along it,
        # whatever the raster (a 3.5 mm beam at 45 deg: 31 % of its infill at 0 deg, 1.3x the density)
        "infill_anchor": "0",
        "infill_anchor_max": "0",
    }


def prusa_plate() -> dict[str, str]:
    """PrusaSlicer's plate-wide options: printer, TPU filament, line widths, temperatures.

    Every line but the perimeters (per object, `wall_line_width`) is one nozzle wide (0.4 mm); the
    first layer's too, perimeters included, inside the solid bottom shell; sparse infill is never
    turned solid for being small (`solid_infill_below_area` 0), which would print a narrow
    beam solid whatever its density; objects are labelled in the G-code.
    """
    width = _number(space.NOZZLE_MM)
    bed = _number(BED_MM)
    return {
        "printer_technology": "FFF",
        "bed_shape": f"0x0,{bed}x0,{bed}x{bed},0x{bed}",
        "nozzle_diameter": width,
        "filament_diameter": _number(FILAMENT_MM),
        "filament_type": "FLEX",
        "filament_max_volumetric_speed": _number(MAX_FLOW),
        "temperature": str(NOZZLE_C),
        "first_layer_temperature": str(NOZZLE_C),
        "bed_temperature": str(BED_C),
        "first_layer_bed_temperature": str(BED_C),
        "first_layer_height": _number(FIRST_LAYER_MM),
        "extrusion_width": width,
        "first_layer_extrusion_width": width,
        "infill_extrusion_width": width,
        "solid_infill_extrusion_width": width,
        "top_infill_extrusion_width": width,
        "solid_infill_below_area": "0",
        "gcode_label_objects": "1",
        "end_gcode": "\\n".join(END_GCODE) + "\\n",
    }


def prusa_plate_of(params: Mapping[str, float]) -> dict[str, str]:
    """The plate's options in a 3MF whose first print has settings `params`: the plate-wide ones and
    that print's own. Each object's options override the plate's; without them PrusaSlicer fills
    the plate's with its defaults (0.3 mm layers, 3 perimeters, 20 % stars infill), which its G-code
    then reports as the print's settings and which no object of the plate is printed with."""
    return prusa_plate() | prusa_object(params)


def prusa_ini(params: Mapping[str, float], print_id: str) -> str:
    """A PrusaSlicer config (`--load FILE.ini`) slicing one print as the study printed it."""
    lines = [f"# print {print_id}: PrusaSlicer settings written by flexjoint designer"]
    options = prusa_plate_of(params)
    lines += [f"{key} = {value}" for key, value in sorted(options.items())]
    return "\n".join(lines) + "\n"


#: OrcaSlicer / Bambu Studio's names of PrusaSlicer's per-object options
ORCA_NAMES = {
    "layer_height": "layer_height",
    "fill_density": "sparse_infill_density",
    "fill_pattern": "sparse_infill_pattern",
    "fill_angle": "infill_direction",
    "perimeters": "wall_loops",
    "perimeter_generator": "wall_generator",
    "gap_fill_enabled": "gap_fill_target",
    "perimeter_extrusion_width": "inner_wall_line_width",
    "external_perimeter_extrusion_width": "outer_wall_line_width",
    "top_solid_layers": "top_shell_layers",
    "bottom_solid_layers": "bottom_shell_layers",
    "top_solid_min_thickness": "top_shell_thickness",
    "bottom_solid_min_thickness": "bottom_shell_thickness",
    "infill_anchor": "infill_anchor",
    "infill_anchor_max": "infill_anchor_max",
}


#: OrcaSlicer / Bambu Studio's names of PrusaSlicer's infill patterns (their "zig-zag" is rectilinear)
ORCA_PATTERNS = {INFILL_PATTERN: "cubic", SOLID_PATTERN: "zig-zag"}
#: OrcaSlicer's gap fill (an enum of where) for PrusaSlicer's (on or off)
ORCA_GAP_FILL = {"1": "everywhere", "0": "nowhere"}


def orca_object(params: Mapping[str, float]) -> dict[str, str]:
    """OrcaSlicer / Bambu Studio's per-object options of one print (model_settings.config): the
    PrusaSlicer options under their names, the infill's line width and no small infill turned solid."""
    width = _number(space.NOZZLE_MM)
    options = {ORCA_NAMES[key]: value for key, value in prusa_object(params).items()}
    options["sparse_infill_pattern"] = ORCA_PATTERNS[options["sparse_infill_pattern"]]
    options["gap_fill_target"] = ORCA_GAP_FILL[options["gap_fill_target"]]
    return options | {
        "sparse_infill_line_width": width,
        "minimum_sparse_infill_area": "0",
    }


def orca_plate(params: Mapping[str, float]) -> dict[str, list[str] | str]:
    """OrcaSlicer / Bambu Studio's plate options in a 3MF whose first print has settings `params`
    (project_settings.config; filament options are lists, one entry per filament): the plate-wide
    ones and that print's own, as `prusa_plate_of`."""
    return orca_object(params) | {
        "machine_end_gcode": "\n".join(END_GCODE) + "\n",
        "nozzle_diameter": [_number(space.NOZZLE_MM)],
        "filament_type": [MATERIAL],
        "filament_diameter": [_number(FILAMENT_MM)],
        "filament_max_volumetric_speed": [_number(MAX_FLOW)],
        "nozzle_temperature": [str(NOZZLE_C)],
        "nozzle_temperature_initial_layer": [str(NOZZLE_C)],
        "hot_plate_temp": [str(BED_C)],
        "hot_plate_temp_initial_layer": [str(BED_C)],
        "initial_layer_print_height": _number(FIRST_LAYER_MM),
    }


def printed_height(height: float, layer: float) -> float:
    """The beam height a slicer prints: the first layer, then whole layers (a slicer cuts each
    layer at its middle, so a top between layer boundaries goes up or down by up to half a layer)."""
    n = math.floor((height - FIRST_LAYER_MM) / layer + 0.5)
    return round(FIRST_LAYER_MM + max(n, 0) * layer, 6)
