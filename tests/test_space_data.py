"""Design space validation and the coefficient-table loader."""

import numpy as np
import pandas as pd
import pytest

from designer import units
from designer.errors import DesignerError
from designer.mass import specimen_mass
from designer.study import data, space


def test_bundled_table_is_the_study_table():
    t = data.load_table()
    assert len(t) == 44
    assert list(t.columns[:8]) == [*space.FACTOR_NAMES, "c_x", "k_x"]
    assert data.axes_present(t) == ["x"]
    assert t.loc[0, "k_x"] == pytest.approx(0.679) and t.loc[43, "c_x"] == pytest.approx(2.5e-3)


def test_validate_names_factor_value_and_range():
    ok = space.check_design(dict(density=60, length=24, width=4.5, height=9, layer=0.16, raster=0))
    assert ok["layer"] == 0.16
    with pytest.raises(DesignerError, match=r"width = 9 mm is outside the tested range 2 to 7 mm"):
        space.check_design(dict(density=60, length=24, width=9, height=9, layer=0.16, raster=0))
    with pytest.raises(DesignerError, match="layer = 0.15 mm is not a tested level"):
        space.check_value("layer", 0.15)
    with pytest.raises(DesignerError, match="missing factor"):
        space.check_design(dict(density=60))
    with pytest.raises(DesignerError, match="unknown factor 'colour'"):
        space.check_value("colour", 1)
    with pytest.raises(DesignerError, match="not a finite number"):
        space.check_value("height", float("nan"))
    assert space.check_value("width", 9, allow_extrapolation=True) == 9


def test_infill_note_at_two_mm_width():
    notes = space.printability_notes(dict(density=20, length=24, width=2, height=9, layer=0.12, raster=0))
    assert any("infill density has no effect" in n for n in notes)
    assert not space.printability_notes(dict(density=20, length=24, width=4.5, height=9))


def test_mass_from_geometry():
    # 24 x 4.5 x 9 mm, 0.8 mm walls, 60 % core: (40.5 - 21.46) + 0.6 * 21.46 = 31.916 mm^2
    m = specimen_mass(dict(density=60, length=24, width=4.5, height=9))
    assert m == pytest.approx(1210 * 31.916 * 24 * 1e-9, rel=1e-12)
    # a core no wider than a nozzle line prints solid, whatever the infill
    solid = specimen_mass(dict(density=20, length=24, width=2, height=9))
    assert solid == pytest.approx(1210 * 2 * 9 * 24 * 1e-9)


def test_units_round_trip():
    assert units.to_si("k", "x", 0.8) == pytest.approx(800.0)
    assert units.to_si("c", "theta", 2.0) == pytest.approx(2e-3)
    assert units.from_si("c", "x", units.to_si("c", "x", 2e-3)) == pytest.approx(2e-3)
    assert units.rig_unit("k", "psi") == "N.mm/rad" and units.si_unit("k", "x") == "N/m"
    with pytest.raises(DesignerError, match="unknown axis"):
        units.check_axis("w")


def _write(tmp_path, df, name="t.csv"):
    p = tmp_path / name
    df.to_csv(p, index=False)
    return p


def test_loader_reads_a_user_table_with_rotational_axes(tmp_path):
    t = data.load_table()
    user = t[list(space.FACTOR_NAMES)].copy()
    user["k_theta_Nmm_per_rad"] = 100.0
    user["c_theta"] = 0.5
    user["m_theta"] = 1e-6
    loaded = data.load_table(_write(tmp_path, user))
    assert data.axes_present(loaded) == ["theta"]
    assert data.coefficient_columns(loaded) == ["m_theta", "c_theta", "k_theta"]
    pq = tmp_path / "t.parquet"
    user.to_parquet(pq)
    assert data.table_hash(data.load_table(pq)) == data.table_hash(loaded)


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda d: d.drop(columns=["height"]), "missing factor column"),
        (lambda d: d.assign(k_x=np.where(d.index == 3, np.nan, d.k_x)), "column 'k_x' row 4"),
        (lambda d: d.assign(k_x=-d.k_x), "must be positive"),
        (lambda d: d.rename(columns={"k_x": "k_x_N_per_m"}), "gives k_x in 'N_per_m'"),
        (lambda d: d.assign(layer=0.3), "not a level"),
        (lambda d: d.drop(columns=["k_x", "c_x"]), "no coefficient columns"),
    ],
)
def test_loader_rejects_bad_tables(tmp_path, mutate, message):
    bad = mutate(data.load_table())
    with pytest.raises(DesignerError, match=message):
        data.load_table(_write(tmp_path, bad))


def test_loader_rejects_unreadable_files(tmp_path):
    p = tmp_path / "x.parquet"
    p.write_text("not parquet")
    with pytest.raises(DesignerError, match="cannot read"):
        data.load_table(p)
    with pytest.raises(DesignerError, match="no such table"):
        data.load_table(tmp_path / "missing.csv")
    assert isinstance(data.normalise(pd.read_csv(data.bundled_path())), pd.DataFrame)
