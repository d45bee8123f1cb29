"""Values a thousand off, as users type them: a target in SI where the rig's unit is expected
(`--k 800` meaning 800 N/m), and the direction of the slip on a rotational axis, where the SI value
is a thousand times *smaller* (0.3 N.m/rad is 300 N.mm/rad)."""

from __future__ import annotations

import pytest
from clitools import run_inprocess

import designer
from designer.model.plausibility import likely_slip, unit_slip


def test_slip_direction_follows_the_units_table():
    assert unit_slip("k", "x", 1000.0) == ("a value in N/m rather than N/mm", 1e-3)
    assert unit_slip("k", "x", 1e-3) == ("a load logged in kN rather than N", 1e3)
    assert unit_slip("k", "x", 1e-3, logged=False) is None  # a typed target has no load channel
    # rotational: N.m/rad is the smaller number, so a value typed in it is 1/1000 of the rig's
    assert unit_slip("k", "theta", 1000.0) is None
    cause, multiplier = unit_slip("k", "theta", 1e-3, logged=False)
    assert cause == "a value in N.m/rad rather than N.mm/rad" and multiplier == 1e3
    assert likely_slip("k", "theta", 1e-3).endswith("multiply by 1000")
    assert unit_slip("k", "x", 5.0) is None and likely_slip("k", "x", 5.0) == ""
    # within the tolerance of a thousand, not beyond it
    assert unit_slip("k", "x", 1000.0 * 7.9) and unit_slip("k", "x", 1000.0 * 8.1) is None


@pytest.fixture(scope="module")
def study():
    return designer.Surrogate.load()


@pytest.mark.parametrize(
    ("goal", "hint"),
    [
        ({"k": 800.0}, "(a value in N/m rather than N/mm? that is k=0.8 N/mm)"),
        ({"k": 0.3, "axis": "theta"}, "(a value in N.m/rad rather than N.mm/rad? that is k=300 N.mm/rad)"),
        ({"k": 0.8, "c": 2.2}, "(a value in N.s/m rather than N.s/mm? that is c=0.0022 N.s/mm)"),
    ],
)
def test_a_target_typed_in_si_names_the_value_meant(study, goal, hint):
    sug = designer.suggest(study, top=1, **goal)
    assert sum(hint in s for s in sug.statements) == 1, sug.statements


@pytest.mark.parametrize("goal", [{"k": 50.0}, {"k": 800.0, "axis": "theta"}, {"k": 2e-4}, {"k": 0.8}])
def test_no_hint_where_no_unit_explains_the_value(study, goal):
    sug = designer.suggest(study, top=1, **goal)
    assert not any("rather than" in s for s in sug.statements), sug.statements


def test_cli_next_with_a_target_in_n_per_m(capsys):
    code, out, err = run_inprocess(["next", "--k", "800"], capsys)
    assert code == 1, (out, err)
    assert "that is k=0.8 N/mm" in " ".join(out.split()), out
