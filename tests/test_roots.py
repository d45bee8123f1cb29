"""designer.model.roots.brentq against scipy.optimize.brentq (the reference it replaces on the
design loop's path): the same root to the last bit, on the study's own surfaces and random brackets."""

import math
import subprocess
import sys

import numpy as np
import pytest
from scipy.optimize import brentq as scipy_brentq

from designer.errors import DesignerError
from designer.model import correction
from designer.model.roots import brentq
from designer.model.surrogate import Surrogate


def test_the_study_amplitudes_equal_scipys_to_the_last_bit(monkeypatch):
    study = Surrogate.load()
    ours, theirs = {}, {}
    for r in study.responses:
        X, y = correction.study_runs(study, r)
        base = study.models[r]
        noise = correction.noise_of(base)
        ours[r] = correction.fit_amplitude(base, X, y, noise)
        with monkeypatch.context() as m:
            m.setattr(correction, "brentq", scipy_brentq)
            theirs[r] = correction.fit_amplitude(base, X, y, noise)
    assert ours == theirs
    assert any(1.0 < a < correction.MAX_AMPLITUDE for a in ours.values())  # a root was searched


@pytest.mark.parametrize("seed", range(40))
def test_random_functions_give_scipys_root_bit_for_bit(seed):
    rng = np.random.default_rng(seed)
    root = float(rng.uniform(-3, 3))
    p = float(rng.uniform(0.3, 3))
    scale = float(rng.uniform(0.1, 10))
    shape = seed % 4

    def f(x: float) -> float:
        d = x - root
        return [scale * d, math.copysign(abs(d) ** p, d) * scale, math.tanh(d) + 0.1 * d**3, math.exp(d) - 1][
            shape
        ]

    a, b = root - float(rng.uniform(0.01, 5)), root + float(rng.uniform(0.01, 5))
    for xtol in (2e-12, 1e-6, 1e-3):
        for lo, hi in ((a, b), (b, a)):
            try:
                expected = scipy_brentq(f, lo, hi, xtol=xtol)
            except RuntimeError:  # scipy gives up after 100 iterations (flat |d|**p roots): so do we
                with pytest.raises(DesignerError, match="no convergence"):
                    brentq(f, lo, hi, xtol=xtol)
            else:
                assert brentq(f, lo, hi, xtol=xtol) == expected


def test_a_bracket_without_a_sign_change_is_a_designer_error():
    with pytest.raises(DesignerError, match="same sign"):
        brentq(lambda x: x * x + 1, -1, 1)


def test_the_design_loop_does_not_import_scipy_optimize():
    code = (
        "import sys, designer; from designer.model.surrogate import Surrogate; "
        "from designer.model.calibration import new_printer; new_printer(Surrogate.load()); "
        "print('scipy.optimize' in sys.modules)"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == "False"
