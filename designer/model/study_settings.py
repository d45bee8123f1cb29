"""The shipped study surrogate's calibration settings, fitted once and stored beside it.

A calibration's local correction has a length scale and an amplitude fitted to the study's own
held-out residuals (`designer.model.correction.fit_settings`); they depend on the study surrogate
only, yet every `designer next`, `calibrate` and `next --surrogate` would fit them again, and the
amplitude's root alone imports scipy's `optimize` (about 0.3 s of CPU). They are stored in
`surrogates/default_settings.json`, keyed by the study surrogate's id and by a hash of the code that
fits them (`correction.py`): a surrogate with another id, or a changed fit, is fitted as before, so a
stale file never gives other results, only the old time. `tests/test_study_settings.py` checks the
file is current and equal to a fresh fit. Regenerate after a change of either:

    python tests/test_study_settings.py
"""

from __future__ import annotations

import hashlib
import json
from importlib import resources
from pathlib import Path
from typing import Any

from . import correction

NAME = "default_settings.json"


def path() -> Path:
    return Path(str(resources.files("designer.surrogates") / NAME))


def code_hash() -> str:
    """sha256 of the module that fits the settings, as installed."""
    return hashlib.sha256(Path(correction.__file__).read_bytes()).hexdigest()[:16]


def stored() -> dict[str, Any] | None:
    """The stored file's content, None when there is none (an install without it fits as before)."""
    try:
        return json.loads(path().read_text())
    except FileNotFoundError:
        return None


def attach(surrogate: Any) -> bool:
    """Give a study surrogate (`designer.model.surrogate.Surrogate`, uncalibrated) its stored
    settings when the file holds them for its id and for the current fitting code; True if it did."""
    d = stored()
    if d is None or d.get("code") != code_hash() or d.get("surrogate_id") != surrogate.id:
        return False
    for response, (length, amplitude, noise) in d["settings"].items():
        if response in surrogate.models:
            correction.keep_settings(surrogate.models[response], (length, amplitude, noise))
    return True


def fitted(surrogate: Any) -> dict[str, Any]:
    """The file's content for `surrogate`: its id, the code hash and every response's settings,
    fitted now."""
    return {
        "about": "calibration settings (length, amplitude, noise) of the shipped study surrogate per "
        "response, from designer.model.correction.fit_settings; python tests/test_study_settings.py",
        "surrogate_id": surrogate.id,
        "code": code_hash(),
        "settings": {r: list(correction.fit_settings(surrogate, r)) for r in surrogate.models},
    }
