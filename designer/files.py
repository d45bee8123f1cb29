"""Writing files so that a failure or an interrupt leaves the old file or none, never half of one."""

from __future__ import annotations

import contextlib
import os
import tempfile
from collections.abc import Iterator
from pathlib import Path
from typing import IO

from .errors import DesignerError


def _check_dir(path: Path) -> Path:
    parent = path.resolve().parent
    if not parent.is_dir():
        raise DesignerError(f"cannot write {path}: folder {parent} does not exist", "create it first")
    if not os.access(parent, os.W_OK):
        raise DesignerError(f"cannot write {path}: folder {parent} is not writable", "choose another path")
    return parent


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "w", **kwargs) -> Iterator[IO]:
    """Open a temporary file beside `path`; rename it over `path` only when the block succeeds."""
    path = Path(path)
    parent = _check_dir(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part", dir=parent)
    try:
        with os.fdopen(fd, mode, **kwargs) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside `path` for writers that want a file name (zip, parquet, savefig)."""
    path = Path(path)
    parent = _check_dir(path)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".part" + path.suffix, dir=parent)
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def check_output_folder(path: str | Path) -> Path:
    """Check, before any work, that `path` is or can become a writable folder; returns it.

    Raises:
        DesignerError: `path` is a file, or it (or its nearest existing parent) is not writable.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise DesignerError(f"{path} is a file, not a folder", "give a folder for the results")
    existing = path
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir() or not os.access(existing, os.W_OK | os.X_OK):
        raise DesignerError(f"cannot write into {path}: {existing} is not writable", "choose another folder")
    return path


@contextlib.contextmanager
def atomic_folder(path: str | Path) -> Iterator[Path]:
    """A new folder beside `path` to fill; it replaces `path` only when the block succeeds.

    An existing folder at `path` is kept whole until the new one is complete, then removed; a
    failure or an interrupt removes the new folder and leaves the old one as it was.

    Raises:
        DesignerError: `path` is a file, or its parent folder is missing or not writable.
    """
    import shutil

    path = Path(path)
    if path.exists() and not path.is_dir():
        raise DesignerError(f"{path} is a file, not a folder", "give a folder")
    parent = _check_dir(path)
    tmp = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".part", dir=parent))
    try:
        yield tmp
        os.chmod(tmp, 0o755)
        old = None
        if path.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{path.name}.", suffix=".old", dir=parent))
            os.replace(path, old / path.name)
        os.replace(tmp, path)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def check_suffix(path: str | Path, suffixes: tuple[str, ...], *, what: str) -> Path:
    """Refuse a path whose suffix is not one of `suffixes` (a writer writes only its own format).

    Raises:
        DesignerError: naming the `path` argument, the format and the suffixes it takes.
    """
    path = Path(path)
    if path.suffix.lower() not in suffixes:
        raise DesignerError(
            f"path={str(path)!r} does not name {what} file", f"give a path ending in {' or '.join(suffixes)}"
        )
    return path
