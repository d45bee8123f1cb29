"""Brent's bracketing root finder, step for step as `scipy.optimize.brentq` computes it.

Why not scipy: `scipy.optimize` costs about 0.3 s of CPU to import, a quarter of `designer calibrate`
and of every `designer next --surrogate`, for one root per study surface (`correction.fit_amplitude`).
This is scipy's C `brentq` (scipy/optimize/Zeros/brentq.c, Charles Harris) in Python floats: the same
IEEE double operations in the same order, so the same root to the last bit
(tests/test_roots.py checks it against scipy on the study's own surfaces and on random brackets).
"""

from __future__ import annotations

import math
from collections.abc import Callable

from designer.errors import DesignerError

#: scipy's default relative tolerance (4 machine epsilons) and iteration limit
RTOL = 4 * 2.220446049250313e-16
MAXITER = 100


def brentq(
    f: Callable[[float], float],
    xa: float,
    xb: float,
    xtol: float = 2e-12,
    rtol: float = RTOL,
    maxiter: int = MAXITER,
) -> float:
    """A root of `f` in [xa, xb], where f(xa) and f(xb) differ in sign; as scipy.optimize.brentq."""
    xpre, xcur = float(xa), float(xb)
    xblk = fblk = spre = scur = 0.0
    fpre, fcur = float(f(xpre)), float(f(xcur))
    if fpre == 0:
        return xpre
    if fcur == 0:
        return xcur
    if math.copysign(1.0, fpre) == math.copysign(1.0, fcur):
        raise DesignerError(
            f"brentq: f(xa) and f(xb) have the same sign on [{xa}, {xb}]; pass a bracket of a root"
        )
    for _ in range(maxiter):
        if fpre != 0 and fcur != 0 and math.copysign(1.0, fpre) != math.copysign(1.0, fcur):
            xblk, fblk = xpre, fpre
            spre = scur = xcur - xpre
        if abs(fblk) < abs(fcur):
            xpre, xcur, xblk = xcur, xblk, xcur
            fpre, fcur, fblk = fcur, fblk, fcur
        delta = (xtol + rtol * abs(xcur)) / 2
        sbis = (xblk - xcur) / 2
        if fcur == 0 or abs(sbis) < delta:
            return xcur
        if abs(spre) > delta and abs(fcur) < abs(fpre):
            if xpre == xblk:  # interpolate
                stry = -fcur * (xcur - xpre) / (fcur - fpre)
            else:  # extrapolate (inverse quadratic)
                dpre = (fpre - fcur) / (xpre - xcur)
                dblk = (fblk - fcur) / (xblk - xcur)
                stry = -fcur * (fblk * dblk - fpre * dpre) / (dblk * dpre * (fblk - fpre))
            if 2 * abs(stry) < min(abs(spre), 3 * abs(sbis) - delta):  # good short step
                spre, scur = scur, stry
            else:  # bisect
                spre = scur = sbis
        else:  # bisect
            spre = scur = sbis
        xpre, fpre = xcur, fcur
        xcur += scur if abs(scur) > delta else (delta if sbis > 0 else -delta)
        fcur = float(f(xcur))
    raise DesignerError(
        f"brentq: no convergence in {maxiter} iterations on [{xa}, {xb}]; widen xtol or maxiter"
    )
