"""Robots from installed packages for the export and co-simulation tests: where a package's model
folder is, and a folder of links to it to run from (nothing copied into the repository, nothing
written into site-packages)."""

from __future__ import annotations

import importlib.metadata
import importlib.util
import os
import shutil
from pathlib import Path

import pytest


def package_dir(name: str, sub: str) -> Path | None:
    """Folder `sub` of the installed package `name` (its import name), None when not installed."""
    spec = importlib.util.find_spec(name)
    if spec is None or not spec.submodule_search_locations:
        return None
    return Path(next(iter(spec.submodule_search_locations))) / sub


def linked_folder(source: Path, target: Path) -> Path:
    """`source`'s files linked into `target`: exports are new files beside the links, so the model's
    relative paths resolve as shipped."""
    shutil.copytree(source, target, copy_function=os.symlink, ignore=shutil.ignore_patterns("__pycache__"))
    return target


def example_robot_data() -> Path:
    """example-robot-data's installed share folder, the `package://example-robot-data/` of its URDFs
    (pytest.skip when not installed)."""
    try:
        dist = importlib.metadata.distribution("example-robot-data")
    except importlib.metadata.PackageNotFoundError:
        pytest.skip("example-robot-data is not installed")
    return Path(dist.locate_file("cmeel.prefix/share/example-robot-data"))
