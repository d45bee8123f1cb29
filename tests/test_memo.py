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


def test_calibrations_through_the_store_equal_fresh_ones():
    """The same designs with other values reuse the stored terms, other designs get their own; both
    give exactly what a calibration with the stores emptied gives."""
    prior = new_printer(designer.Surrogate.load())
    first = predictions(with_runs(prior, [ROW | {"k_x": 0.8, "c_x": 0.002}]))
    rows = {
        "other values": [ROW | {"k_x": 1.6, "c_x": 0.004}],
        "another design": [ROW | {"width": 3.0, "k_x": 0.8, "c_x": 0.002}],
    }
    kept = {name: predictions(with_runs(prior, r)) for name, r in rows.items()}
    for base in prior.prior.models.values():  # the study surfaces, which keep the stores
        base.__dict__.pop("_solved", None), base.__dict__.pop("_moments", None)
    for name, r in rows.items():
        fresh = predictions(with_runs(prior, r))
        for response in fresh:
            for got, want in zip(kept[name][response], fresh[response], strict=True):
                np.testing.assert_array_equal(got, want, err_msg=f"{name} {response}")
        assert not np.array_equal(first["k_x"][0], fresh["k_x"][0]), name  # the run counts


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


def test_a_copy_of_a_surface_carries_no_store():
    import copy
    import pickle

    prior = new_printer(designer.Surrogate.load())
    predictions(with_runs(prior, [ROW | {"k_x": 0.8, "c_x": 0.002}]))
    base = prior.prior.models["k_x"]  # the study surface the calibrations are made from
    assert base.__dict__["_solved"].items
    for copied in (copy.deepcopy(base), pickle.loads(pickle.dumps(base.__dict__["_solved"]))):
        store = copied.__dict__["_solved"] if not isinstance(copied, memo.Memo) else copied
        assert isinstance(store, memo.Memo) and not store.items and store.held == 0
