"""`forms.check_designs` checks a whole factor column at once (issue 38: the loop's predictions
checked 10 000 values one by one): it must accept and refuse exactly what `space.check_value`,
value by value, accepts and refuses, with the same message, at the edges of every range and level."""

import numpy as np
import pytest

from designer.errors import DesignerError
from designer.model.forms import check_designs
from designer.study import space

BASE = {"density": 60.0, "length": 24.0, "width": 4.5, "height": 9.0, "layer": 0.16, "raster": 0.0}


def edge_values(f: space.Factor) -> list[float]:
    """Values on, just inside and just outside every bound and level the checks compare with."""
    lo, hi = space.printable_limits(f)
    marks = [f.low, f.high, lo, hi, *f.levels]
    out = [np.nan, np.inf, -np.inf, 0.0, -1.0, 1e308]
    for m in marks:
        for d in (0.0, 5e-10, 1e-9, 1.5e-9, 1e-6, 0.3):
            out += [m - d, m + d, m * (1 + d), m * (1 - d)]
    return out


def scalar_verdict(name: str, values: list[float], extrapolate: bool) -> str | None:
    try:
        for v in values:
            space.check_value(name, float(v), extrapolate)
    except DesignerError as exc:
        return str(exc)
    return None


def column_verdict(name: str, values: list[float], extrapolate: bool) -> str | None:
    designs = {n: np.full(len(values), v) for n, v in BASE.items()} | {name: np.array(values)}
    try:
        check_designs(designs, extrapolate)
    except DesignerError as exc:
        return str(exc)
    return None


@pytest.mark.parametrize("extrapolate", [False, True])
@pytest.mark.parametrize("f", space.FACTORS, ids=lambda f: f.name)
def test_a_column_passes_exactly_when_each_value_does(f, extrapolate):
    rng = np.random.default_rng(38)
    values = edge_values(f)
    for v in values:  # one value alone
        assert column_verdict(f.name, [v], extrapolate) == scalar_verdict(f.name, [v], extrapolate), v
    good = [v for v in values if scalar_verdict(f.name, [v], extrapolate) is None]
    assert good, "no edge value is valid: the comparison would be empty"
    for _ in range(50):  # columns of valid values with, sometimes, bad ones among them
        column = list(rng.choice(good, size=6)) + (
            list(rng.choice(values, size=1)) if rng.random() < 0.5 else []
        )
        rng.shuffle(column)
        assert column_verdict(f.name, column, extrapolate) == scalar_verdict(f.name, column, extrapolate), (
            column
        )
