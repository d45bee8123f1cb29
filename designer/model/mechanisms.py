"""How a user's printer departs from the study's: terms with a physical meaning, each with a prior.

A printed joint on another printer differs from the study's at the same settings through mechanisms
an engineer can name. In log space, at a design x, the printer adds ``h(x)' beta`` to the study's
log k (or log c), one term per mechanism:

- factor: h = 1, prior sd `printer_sd` (0.3): filament modulus and extrusion, a factor within
  x/÷ 1.8 at 95 %;
- width offset: h = d mu0 / d width (1/mm), sd 0.15 mm: over- or under-extrusion, FDM walls land
  0.1-0.3 mm off (TPU mostly wider);
- height offset: h = d mu0 / d height (1/mm), sd 0.15 mm: the same for the printed height;
- infill: h = d mu0 / d density x density x ln(density / 100), sd 0.3: another infill pattern, whose
  effect scales as density^(1 + beta);
- layer adhesion: h = layer coded to [-1, 1] (0.12 mm -> -1, 0.2 mm -> +1), sd 0.10: bonding between
  layers changes with layer height, about ±10 % per 0.04 mm;
- raster: h = -1 at 0 deg, +1 at 45 deg, sd 0.05: the raster's share of the load path differs;
- layer x raster: h = the product of the two, sd 0.05: adhesion losses that depend on both.

``mu0`` is the study surface's log prediction, so an offset of width moves the design along the
study's own response: a physical offset, not a free shape. The derivatives are CasADi's exact
gradients of the study surface (the profiler page computes the same by forward differentiation of
the surface's expression). Where the walls fill the section (as printed at 100 %) the infill term is
zero. beta is learned from the user's prints (`designer.model.correction`), jointly with the study
model's local error and the printer's own smooth departure beyond these terms.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import casadi as ca
import numpy as np

from ..study import space
from .prediction import ResponseSurface


@dataclass(frozen=True)
class Mechanism:
    """One term of a printer's departure from the study: its name, the unit of its coefficient, and
    the prior sd of that coefficient."""

    name: str
    unit: str
    sd: float
    meaning: str


#: the terms after the overall factor (whose sd is the user's `printer_sd`), in the order of h(x)
TERMS: tuple[Mechanism, ...] = (
    Mechanism("width_offset", "mm", 0.15, "printed width minus the nominal"),
    Mechanism("height_offset", "mm", 0.15, "printed height minus the nominal"),
    Mechanism("infill", "", 0.3, "change of the infill's density exponent"),
    Mechanism("layer", "", 0.10, "log change per coded layer step (0.04 mm)"),
    Mechanism("raster", "", 0.05, "log change from 0 to 45 deg raster, halved"),
    Mechanism("layer_raster", "", 0.05, "layer and raster together"),
)
#: the name of the overall term, first in h(x)
FACTOR = "factor"


def names() -> list[str]:
    return [FACTOR] + [m.name for m in TERMS]


def prior_variances(printer_sd: float) -> np.ndarray:
    """The prior variances of beta, shape (n_terms,): the factor's from `printer_sd`, the rest fixed."""
    return np.array([printer_sd**2] + [m.sd**2 for m in TERMS])


def symbolic(base: ResponseSurface, x: Any) -> Any:
    """h(x) as a CasADi column of the six factors `x` (factor order), shape (n_terms, 1)."""
    i = space.FACTOR_NAMES.index
    mu0 = ca.log(base.casadi_function()(x)[0])
    grad = ca.gradient(mu0, x)
    rho = x[i("density")]
    layer, raster = space.BY_NAME["layer"], space.BY_NAME["raster"]
    lc = (x[i("layer")] - (layer.low + layer.high) / 2) / ((layer.high - layer.low) / 2)
    rs = (x[i("raster")] - (raster.low + raster.high) / 2) / ((raster.high - raster.low) / 2)
    infill = grad[i("density")] * rho * ca.log(rho / 100.0)
    return ca.vertcat(1.0, grad[i("width")], grad[i("height")], infill, lc, rs, lc * rs)


def basis_function(base: ResponseSurface) -> ca.Function:
    """h as a CasADi function of one design (factor order), cached on the study surface."""
    if "_mechanism_basis" not in base.__dict__:
        x = ca.SX.sym("x", len(space.FACTOR_NAMES))
        base.__dict__["_mechanism_basis"] = ca.Function("mechanisms", [x], [symbolic(base, x)])
    return base.__dict__["_mechanism_basis"]


def basis(base: ResponseSurface, designs: np.ndarray) -> np.ndarray:
    """h at designs (n, 6) in factor order (as printed), shape (n, n_terms)."""
    if len(designs) == 0:
        return np.zeros((0, len(TERMS) + 1))
    f = basis_function(base)
    return np.asarray(f.map(len(designs))(designs.T)).T
