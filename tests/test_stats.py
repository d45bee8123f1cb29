"""Statistics: Table 4 reproduced, ANOVA contributions, MANOVA statistics, correlations, CLI."""

import json
import subprocess
import sys

import numpy as np
import pytest

from designer.study.data import load_table
from designer.study.stats import anova, compare_table4, correlation, manova, paper_table4

CLI = [sys.executable, "-I", "-c", "from designer_cli.main import main; main()"]


def test_table4_reproduced():
    cmp = compare_table4(load_table())
    assert len(cmp) == 7
    big = cmp[cmp["F_paper"] > 1]
    assert set(big["source"]) == {"Intercept", "layer", "width", "height"}
    assert (big["F_diff_pct"].abs() <= 10).all()
    assert (cmp["significant"] == (cmp["p_paper"] < 0.05)).all()
    assert cmp["agrees"].all()


def test_anova_contributions_and_degrees_of_freedom():
    table = load_table()
    a = anova(table, "k_x").set_index("source")
    assert a.loc["Residual", "df"] == len(table) - 7 == 37
    assert (a.drop(index=["Intercept", "Residual"])["df"] == 1).all()
    total = ((table["k_x"] - table["k_x"].mean()) ** 2).sum()
    assert a.loc["height", "contribution_pct"] == pytest.approx(100 * a.loc["height", "sum_sq"] / total)
    assert np.isnan(a.loc["Intercept", "contribution_pct"])


def test_manova_statistics_agree_for_one_df_terms():
    rows = manova(load_table())
    by = {(r["source"], r["statistic"]): r for r in rows}
    assert {s for _, s in by} == {"Pillai", "Wilks", "Hotelling-Lawley", "Roy"}
    for source in ("width", "height"):
        fs = [by[(source, s)]["F"] for s in ("Pillai", "Wilks", "Hotelling-Lawley", "Roy")]
        assert np.allclose(fs, fs[0])  # single-DF hypotheses: the four tests coincide
        assert by[(source, "Wilks")]["df1"] == 2 and by[(source, "Wilks")]["df2"] == 36
    assert manova(load_table(), ["k_x"]) == []


def test_correlation_signs_match_the_paper():
    corr = correlation(load_table())
    assert corr.loc["width", "k_x"] < 0  # wider specimens are softer (paper, Fig 13)
    assert corr.loc["k_x", "k_x"] == pytest.approx(1.0)


def test_paper_table4_is_bundled():
    assert list(paper_table4()["source"]) == [
        "Intercept",
        "raster",
        "layer",
        "width",
        "height",
        "length",
        "density",
    ]


def test_cli_analyze_json():
    out = subprocess.run(CLI + ["analyze", "--json"], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    doc = json.loads(out.stdout)
    assert {"source", "F", "p"} <= set(doc["anova"]["k_x"][0])
    assert doc["manova"] and "k_x" in doc["correlation"]
    assert all(r["agrees"] for r in doc["table4"]["rows"]) and "rounds" in doc["table4"]["note"]
