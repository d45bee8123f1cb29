"""The shipped study surrogate's calibration settings stored beside it (surrogates/default_settings.json,
`designer.model.study_settings`) are current and equal to a fresh fit, and a loaded surrogate uses
them: the loop's commands then import neither scipy's optimize nor pandas (issue 38).

Regenerate after a change of the shipped surrogate or of designer/model/correction.py:
    python tests/test_study_settings.py
"""

import json
import subprocess
import sys
from pathlib import Path

from designer.model import correction, study_settings
from designer.model.surrogate import Surrogate, default_path

CHECKOUT = Path(__file__).resolve().parents[1] / "surrogates" / study_settings.NAME


def fresh() -> Surrogate:
    """The shipped surrogate as its file holds it, without the stored settings."""
    return Surrogate.from_payload(json.loads(default_path().read_text()))


def test_the_stored_settings_are_current_and_equal_a_fresh_fit():
    d = study_settings.stored()
    assert d is not None, "no stored settings: python tests/test_study_settings.py"
    want = study_settings.fitted(fresh())
    assert d["surrogate_id"] == want["surrogate_id"], "the shipped surrogate changed: regenerate"
    assert d["code"] == want["code"], "correction.py changed: python tests/test_study_settings.py"
    assert d["settings"] == want["settings"]  # exactly: JSON floats round-trip


def test_a_loaded_surrogate_takes_them_and_another_fits_its_own():
    loaded = Surrogate.load()
    stored = study_settings.stored()["settings"]
    for r, m in loaded.models.items():
        assert m.__dict__["_calibration_settings"] == tuple(stored[r])
    other = fresh()
    other.models["k_x"].coef = other.models["k_x"].coef * 1.01  # another surrogate: another id
    assert not study_settings.attach(other)
    assert "_calibration_settings" not in other.models["k_x"].__dict__
    assert correction.settings_of(other, "k_x") == correction.fit_settings(other, "k_x")


def test_new_printer_imports_neither_scipy_optimize_nor_pandas():
    code = (
        "import sys, designer; from designer.model.calibration import new_printer;"
        "new_printer(designer.Surrogate.load());"
        "print(sorted(m for m in ('scipy.optimize', 'pandas') if m in sys.modules))"
    )
    done = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True, check=True)
    assert done.stdout.strip() == "[]"


if __name__ == "__main__":
    CHECKOUT.write_text(json.dumps(study_settings.fitted(fresh()), indent=1) + "\n")
    print(f"wrote {CHECKOUT}")
