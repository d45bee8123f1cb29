"""The calibration's store of design-only terms (`designer.model.memo`, issue 38): recalibrating on
the same designs with other values reuses the solved covariance yet gives exactly what a fresh
calibration gives, and the store stays within its byte budget."""

import numpy as np

import designer
from designer.model import memo
from designer.model.calibration import new_printer, with_runs

ROW = {"density": 60.0, "length": 24.0, "width": 4.5, "height": 9.0, "layer": 0.16, "raster": 0.0}
POOL = {n: np.array([v, v * 1.1 if n in ("length", "width") else v]) for n, v in ROW.items()}


def predictions(surrogate):
    p = surrogate.predict(POOL, allow_extrapolation=True)
    return {r: (q.value, q.low, q.high) for r, q in p.items()}


def test_the_same_designs_with_other_values_equal_a_fresh_calibration():
    prior = new_printer(designer.Surrogate.load())
    first = with_runs(prior, [ROW | {"k_x": 0.8, "c_x": 0.002}])
    predictions(first)
    again = with_runs(prior, [ROW | {"k_x": 1.6, "c_x": 0.004}])  # the designs' terms from the store
    kept = predictions(again)
    for base in prior.models.values():
        base.__dict__.pop("_solved", None), base.__dict__.pop("_moments", None)
    fresh = predictions(with_runs(prior, [ROW | {"k_x": 1.6, "c_x": 0.004}]))
    for r in fresh:
        for got, want in zip(kept[r], fresh[r], strict=True):
            np.testing.assert_array_equal(got, want)
    assert not np.array_equal(predictions(first)["k_x"][0], kept["k_x"][0])  # the values count


def test_the_store_keeps_within_its_budget():
    store = memo.Memo(budget=16 * 800)
    calls = []

    def make(n):
        def build():
            calls.append(n)
            return (np.zeros(n),)  # n float64: 8 n bytes

        return build

    store.get("a", make(100))
    store.get("a", make(100))
    assert calls == [100] and store.held == 800
    store.get("big", make(200))  # 1600 bytes: over a sixteenth of the budget, computed but not kept
    store.get("big", make(200))
    assert calls == [100, 200, 200] and "big" not in store.items
    for i in range(20):
        store.get(i, make(100))
    assert store.held <= store.budget and len(store.items) <= 16
