"""The loop benchmark's oracle (benchmarks/bench_loop_oracle.py) on tiny exact beliefs: its posterior
picks the printer the prints came from, and its P is the normal probability the scatter gives."""

import sys
from pathlib import Path

import numpy as np
from scipy.stats import norm

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
import bench_loop_oracle as oracle_bench  # noqa: E402

NOISE = 0.025


def two_printers() -> oracle_bench.Oracle:
    """Two particles over three designs: B is 30 % stiffer than A at design 1 and equal elsewhere."""
    logs = np.log(np.array([[0.5, 0.8, 1.2], [0.5, 1.04, 1.2]]))
    return oracle_bench.Oracle(logs, NOISE)


def test_prints_pick_the_particle_they_came_from():
    oracle = two_printers()
    factor = 1.1  # printer A with factor 1.1: design 0 measures 0.55, design 1 measures 0.88
    w, ess = oracle.posterior([0, 1], [np.log(0.55), np.log(0.88)])
    per = w.sum(axis=1)
    assert per[0] > 0.999 and abs(w.sum() - 1) < 1e-12
    assert ess < 1.01
    mean = (w[0] / per[0]) @ oracle.b
    assert abs(mean - np.log(factor)) < 0.005


def test_one_print_cannot_tell_printers_apart_where_they_agree():
    oracle = two_printers()
    w, ess = oracle.posterior([0], [np.log(0.55)])
    assert abs(w.sum(axis=1)[0] - 0.5) < 1e-9 and abs(ess - 2) < 1e-9


def test_p_is_the_scatter_probability_when_the_printer_is_known():
    oracle = two_printers()
    w, _ = oracle.posterior([0, 1], [np.log(0.55), np.log(0.88)])
    target = 1.2 * 1.1  # design 2 lands on it in expectation
    p = oracle.p_hit(w, target, np.array([2]))[0]
    per = w[0] / w[0].sum()
    sd = np.sqrt(per @ oracle.b**2 - (per @ oracle.b) ** 2 + NOISE**2)
    expected = norm.cdf(np.log(1.1) / sd) - norm.cdf(np.log(0.9) / sd)
    assert abs(p - expected) < 0.01 and p > 0.99


def test_before_any_print_p_is_the_share_of_factors_that_land():
    """Factor uniform in 0.6-1.5 on one particle: a target 0.9 x base lands for factors 0.81-0.99
    (within +-10 %), a share 0.2 of the range, blurred by the scatter only at the edges."""
    oracle = oracle_bench.Oracle(np.log(np.array([[1.0]])), NOISE)
    p = oracle.first_round(0.9, np.array([0]))[0]
    assert abs(p - 0.18 / 0.9) < 0.01
