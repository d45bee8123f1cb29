"""Checks the plot tests share: an image was written, has the expected size and is not blank."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np


def load_rgb(path: Path) -> np.ndarray:
    """The PNG's pixels as floats in 0..1, shape (height, width, 3)."""
    from matplotlib.image import imread

    return np.asarray(imread(path))[..., :3]


def assert_picture(path: Path, size: tuple[int, int] | None = None, min_size: tuple[int, int] = (200, 150)):
    """The PNG exists, is (width, height) `size` or at least `min_size`, and is not blank."""
    assert path.is_file() and path.stat().st_size > 0, path
    rgb = load_rgb(path)
    h, w = rgb.shape[:2]
    if size is not None:
        assert (w, h) == size, (w, h)
    assert w >= min_size[0] and h >= min_size[1], (w, h)
    assert rgb.std() > 0.05, f"{path.name} looks blank: pixel standard deviation {rgb.std():.4f}"
    background = np.median(rgb.reshape(-1, 3), axis=0)
    drawn = np.abs(rgb - background).max(axis=2) > 0.1
    assert drawn.mean() > 0.01, f"{path.name}: only {drawn.mean():.2%} of the pixels are drawn"
    return rgb


def chromium() -> str | None:
    """A headless Chromium on this machine, if any."""
    for name in ("chromium-headless-shell", "chromium", "chromium-browser", "google-chrome"):
        exe = shutil.which(name)
        if exe:
            return exe
    return None


def dump_dom(exe: str, page: Path) -> str:
    """Load `page` in headless Chromium, let its scripts run, and return the resulting DOM."""
    out = subprocess.run(
        [
            exe,
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--virtual-time-budget=5000",
            "--dump-dom",
            page.resolve().as_uri(),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    return out.stdout
