"""Writing files so that a failure or an interrupt leaves the old file or none, never half of one.

Output paths are probed before any work (`check_output`): a folder where a file is expected (or the
reverse), a folder that does not exist or cannot be written (read-only, /proc), and too little free
space for the estimated size are reported up front instead of after a long computation. Files are
written to a temporary name beside the target and renamed over it (`atomic_write`, `atomic_path`); a
folder of results is staged beside its target and moved in at the end (`atomic_folder`); a cached build
appears as a whole folder or not at all (`cache_entry`).

Concurrent writers: each one writes its own temporary file, so two processes writing one output leave
the last complete one, never a mix; two writing one results folder move their files in one after the
other under a lock on its parent folder. An output path that is a symbolic link is followed: the file
it points to is replaced atomically (the link stays), never truncated and rewritten in place.
"""

from __future__ import annotations

import contextlib
import errno
import os
import shutil
import signal
import tempfile
import threading
from collections.abc import Iterable, Iterator
from pathlib import Path
from typing import IO

from .errors import DesignerError, path_argument

# head room kept free on the target's disk beyond the estimated size (file system metadata, temp files)
_SPARE_BYTES = 1 << 20
_SIGNALS = {getattr(signal, n) for n in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, n)}


def format_bytes(n: float) -> str:
    """1536 -> '1.5 KiB': sizes in messages, binary units, two significant figures at most."""
    for unit in ("B", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            # two significant figures without an exponent: 300 MiB, not 3e+02 MiB
            return f"{n:.0f} {unit}" if unit == "B" else f"{float(f'{n:.2g}'):g} {unit}"
        n /= 1024
    raise AssertionError("unreachable")


def _existing_ancestor(path: Path) -> Path:
    """The nearest folder above `path` (absolute) that exists."""
    for parent in path.parents:
        if parent.exists():
            return parent
    return Path(path.anchor)


def _probe(folder: Path, path: Path) -> None:
    """Create and remove a file in `folder`: os.access cannot see read-only mounts or /proc as root."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=".probe.", dir=folder)
    except OSError as exc:
        raise DesignerError(
            f"cannot write {path}: folder {folder} is not writable ({exc.strerror or exc})",
            "choose a path in a folder you can write to",
        ) from None
    os.close(fd)
    os.unlink(tmp)


def check_output(
    path: str | Path,
    *,
    suffixes: Iterable[str] | None = None,
    estimate_bytes: float = 0,
    inputs: Iterable[str | Path] = (),
) -> Path:
    """Check before any work that the file `path` can be written; returns it resolved.

    Args:
        path: the file to be written (its folder must exist).
        suffixes: accepted file suffixes, lower case with the dot (None: any).
        estimate_bytes: expected size; the target's disk must have this much free plus 1 MiB.
        inputs: the files the command reads; the output must not be one of them (writing it would
            replace the input, a raw log the user cannot make again).

    Raises:
        DesignerError: a folder where a file is expected, a wrong suffix, a folder that is missing or
            cannot be written, an output that is an input, or too little free space (with the estimate).
    """
    p = Path(path).expanduser().absolute()
    size = len(os.fsencode(p.name))
    if size > NAME_MAX:
        raise DesignerError(
            f"cannot write {path}: its name is {size} bytes, more than the {NAME_MAX} a file name can have",
            "give a shorter name",
        )
    if p.is_dir():
        raise DesignerError(
            f"cannot write {path}: it is a folder", f"give a file name, e.g. {Path(path) / 'out'}"
        )
    if suffixes is not None:
        allowed = sorted(suffixes)
        if p.suffix.lower() not in allowed:
            raise DesignerError(
                f"cannot write {path}: the suffix '{p.suffix}' is not {' or '.join(allowed)}",
                f"name the file with {' or '.join(allowed)}",
            )
    for source in inputs:
        if p.exists() and Path(source).exists() and os.path.samefile(p, source):
            raise DesignerError(
                f"cannot write {path}: it is the input {source}, which the output would replace",
                "give the output another name",
            )
    if not p.parent.is_dir():
        raise DesignerError(f"cannot write {path}: folder {p.parent} does not exist", "create it first")
    return _room(p, p.parent, path, estimate_bytes)


def check_output_folder(path: str | Path, files: Iterable[str] = (), *, estimate_bytes: float = 0) -> Path:
    """Check, before any work, that `path` is or can become a writable folder (made with its parents
    when missing, by its writer) where none of `files` (the names the command writes into it) is a
    folder; returns it resolved.

    Raises:
        DesignerError: `path` is a file, it (or its nearest existing parent) is not a writable folder,
            one of `files` is a folder there, or its disk has too little free space for
            `estimate_bytes` (with the estimate).
    """
    p = Path(path).expanduser().absolute()
    if p.exists() and not p.is_dir():
        raise DesignerError(f"cannot write into {path}: it is a file", "give a folder (new or existing)")
    folder = p if p.is_dir() else _existing_ancestor(p)
    if not folder.is_dir():
        raise DesignerError(f"cannot create {path}: {folder} is not a folder", "choose another path")
    check_not_folders(p, files)
    return _room(p, folder, path, estimate_bytes)


def _room(p: Path, folder: Path, path: str | Path, estimate_bytes: float) -> Path:
    """`p` once `folder` (where it goes) is writable and its disk has `estimate_bytes` free plus 1 MiB."""
    _probe(folder, Path(path))
    free = shutil.disk_usage(folder).free
    if estimate_bytes + _SPARE_BYTES > free:
        raise DesignerError(
            f"not enough space for {path}: about {format_bytes(estimate_bytes)} needed, "
            f"{format_bytes(free)} free on its disk",
            "free some space or write to another disk",
        )
    return p


#: the longest file name most file systems take, in bytes (ext4, XFS, Btrfs, tmpfs, APFS, NTFS)
NAME_MAX = 255
#: the bytes a temporary name adds to its affixes: mkstemp's 8 random characters
_RANDOM = 8
#: the longest suffix kept on a temporary file name (writers such as savefig read the format from it)
_SUFFIX_MAX = 16


def temporary_affixes(name: str, tail: str, suffix: str = "") -> tuple[str, str]:
    """(prefix, suffix) for mkstemp/mkdtemp of a temporary entry beside `name`:
    `.name.XXXXXXXX<tail><suffix>`, or `.XXXXXXXX<tail><suffix>` where that would pass NAME_MAX bytes (a
    legal name of up to 255 bytes must be writable, not refused as "File name too long")."""
    suffix = suffix if len(suffix.encode(errors="surrogateescape")) <= _SUFFIX_MAX else ""
    prefix = f".{name}."
    size = len((prefix + tail + suffix).encode(errors="surrogateescape")) + _RANDOM
    if not utf8(name + suffix):  # bytes that are not UTF-8: writers such as pyarrow refuse the path
        return ".", tail + (suffix if utf8(suffix) else "")
    return (prefix if size <= NAME_MAX else "."), tail + suffix


def utf8(text: str) -> bool:
    """Whether `text` encodes as UTF-8: a path from bytes that are not UTF-8 (`l\\xff.csv` on the
    command line) holds surrogate escapes, which many writers refuse."""
    try:
        text.encode()
    except UnicodeEncodeError:
        return False
    return True


def display_path(path: str | Path) -> str:
    """`path` as text that can be written anywhere (JSON, XML, a Modelica comment, a hash): its bytes
    that are not UTF-8 as \\xNN escapes."""
    return os.fsencode(str(path)).decode("utf-8", "backslashreplace")


def _followed(path: str | Path) -> Path:
    """`path` with symbolic links followed (the file to replace), unchanged when it is no link."""
    path = Path(path)
    return Path(os.path.realpath(path)) if path.is_symlink() else path


def _check_dir(path: Path) -> Path:
    parent = path.absolute().parent
    if not parent.is_dir():
        raise DesignerError(f"cannot write {path}: folder {parent} does not exist", "create it first")
    if path.is_dir():
        raise DesignerError(f"cannot write {path}: it is a folder", f"give a file name, e.g. {path / 'out'}")
    return parent


def _space_error(path: Path, exc: OSError) -> OSError | DesignerError:
    """ENOSPC/EDQUOT while writing `path` as a DesignerError; any other OSError unchanged."""
    if exc.errno in (errno.ENOSPC, errno.EDQUOT):
        return DesignerError(
            f"the disk filled up while writing {path}", "free some space or write to another disk"
        )
    if exc.errno in (errno.EACCES, errno.EPERM, errno.EROFS):
        return DesignerError(f"cannot write {path}: {exc.strerror}", "choose a path you can write to")
    return exc


@contextlib.contextmanager
def atomic_write(path: str | Path, mode: str = "w", **kwargs) -> Iterator[IO]:
    """Open a temporary file beside `path`; rename it over `path` only when the block succeeds.

    Raises:
        DesignerError: the folder is missing or not writable, `path` is a folder, or the disk is full.
    """
    with atomic_path(path) as tmp, open(tmp, mode, **kwargs) as fh:
        yield fh
        fh.flush()
        os.fsync(fh.fileno())


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path beside `path` for writers that want a file name (zip, parquet, savefig).

    When `path` is a symbolic link, the file it points to is the one replaced (the temporary file is
    made beside that file, so the rename stays on its disk and is atomic).

    Raises:
        DesignerError: the folder is missing or not writable, `path` is a folder, or the disk is full.
    """
    path = _followed(path)
    parent = _check_dir(path)
    try:
        prefix, suffix = temporary_affixes(path.name, ".part", path.suffix)
        fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=suffix, dir=parent)
    except OSError as exc:
        raise _space_error(path, exc) from None
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o644)
        os.replace(tmp, path)
    except OSError as exc:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise _space_error(path, exc) from None
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def check_not_folders(folder: Path, names: Iterable[str]) -> None:
    """Refuse when a file to be written into `folder` exists there as a folder (the user's own):
    moving the results in would replace it and everything in it.

    Raises:
        DesignerError: naming the folder in the way.
    """
    for name in names:
        p = folder / name
        if p.is_dir():
            n = sum(1 for _ in p.iterdir())
            raise DesignerError(
                f"cannot write {p}: a folder of that name is there ({n} entries), which the output "
                "would replace",
                "move that folder away or write the results to another folder",
            )


def _move_in(stage: Path, target: Path) -> None:
    """Move every entry of `stage` into the existing folder `target`, replacing same-named files;
    a folder in the way of a file is refused before anything moves."""
    check_not_folders(target, [e.name for e in stage.iterdir() if not e.is_dir()])
    prefix, suffix = temporary_affixes(target.name, ".old")
    trash = Path(tempfile.mkdtemp(prefix=prefix, suffix=suffix, dir=target.parent))
    try:
        for entry in stage.iterdir():
            dest = target / entry.name
            if dest.exists() or dest.is_symlink():
                os.replace(dest, trash / entry.name)
            os.replace(entry, dest)
    finally:
        shutil.rmtree(trash, ignore_errors=True)


@contextlib.contextmanager
def atomic_folder(path: str | Path, files: Iterable[str] = ()) -> Iterator[Path]:
    """A staging folder beside `path`, moved into place when the block succeeds (removed when not).

    A missing or empty target is replaced by the staged folder in one rename; into an existing folder
    the staged entries replace their namesakes (other files there stay), with SIGINT/SIGTERM/SIGHUP
    held back during the moves so an interrupt never leaves old and new outputs mixed. A staged file
    never replaces a folder; `files`, the names the block may write, are checked for that up front.

    Raises:
        DesignerError: `path` is a file, its folder cannot be created or written, or one of `files`
            is a folder there.
    """
    target = _followed(check_output_folder(path, files))
    target.parent.mkdir(parents=True, exist_ok=True)
    prefix, suffix = temporary_affixes(target.name, ".part")
    stage = Path(tempfile.mkdtemp(prefix=prefix, suffix=suffix, dir=target.parent))
    try:
        yield stage
        os.chmod(stage, 0o755)
        with signals_held(), _locked(target.parent):  # another process moving in waits
            if target.is_dir() and any(target.iterdir()):
                _move_in(stage, target)
            else:
                os.replace(stage, target)
    except OSError as exc:
        raise _space_error(target, exc) from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


@contextlib.contextmanager
def _locked(folder: Path) -> Iterator[None]:
    """An exclusive lock between processes on `folder` itself (flock, released with the descriptor:
    no lock file to leave behind); no lock where flock does not exist (Windows)."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - Windows
        yield
        return
    fd = os.open(folder, os.O_RDONLY)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX)
        yield
    finally:
        os.close(fd)


@contextlib.contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT, SIGTERM and SIGHUP held back inside the block and delivered when it ends, so a stop
    never lands halfway through it.

    Python runs signal handlers in the main thread only, so there the handlers are swapped for a
    recorder for the block's length (blocking the signal with pthread_sigmask would not do: the
    kernel hands a process-directed signal to any other thread that does not block it, and Python
    still runs its handler in the main thread). In other threads no handler can interrupt the block.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    came: list[int] = []
    before = {sig: signal.signal(sig, lambda sig, _frame: came.append(sig)) for sig in _SIGNALS}
    try:
        yield
    finally:
        for sig, handler in before.items():
            signal.signal(sig, signal.SIG_DFL if handler is None else handler)
        for sig in dict.fromkeys(came):
            signal.raise_signal(sig)


@contextlib.contextmanager
def temporary_folder(prefix: str) -> Iterator[Path]:
    """A new temporary folder, removed whole at the end. Unlike tempfile.TemporaryDirectory, a stop
    (SIGTERM, Ctrl-C) that lands while the folder is made or removed cannot leave it behind: both are
    done with the stop held back (an interrupted rmtree left a half-removed folder in TMPDIR)."""
    folder = None
    try:
        with signals_held():
            folder = Path(tempfile.mkdtemp(prefix=prefix))
        yield folder
    finally:
        if folder is not None:
            with signals_held():
                shutil.rmtree(folder, ignore_errors=True)


@contextlib.contextmanager
def private_tempdir(prefix: str) -> Iterator[Path]:
    """A temporary folder, removed whole at the end, that is also where third-party code makes its
    temporary files meanwhile (tempfile.tempdir): fmpy's extract and simulate_fmu remove their folders
    only when they succeed, so an error or an interrupt inside them left unpacked FMUs in /tmp."""
    with temporary_folder(prefix) as tmp:
        old = tempfile.tempdir
        tempfile.tempdir = str(tmp)
        try:
            yield tmp
        finally:
            tempfile.tempdir = old


@contextlib.contextmanager
def cache_entry(target: str | Path) -> Iterator[Path]:
    """A path to build the cached file `target` at, in a staging folder that becomes `target`'s folder
    (named for the cache key) in one rename when the block succeeds: the entry exists whole or not at
    all, whatever interrupts the build. A concurrent build of the same key that finished first is kept
    (ours is dropped: the same sources, the same file).

    Raises:
        DesignerError: the cache folder cannot be created or written, or the disk is full.
    """
    target = Path(target)
    entry = target.parent
    try:
        entry.parent.mkdir(parents=True, exist_ok=True)
        prefix, suffix = temporary_affixes(entry.name, ".part")
        stage = Path(tempfile.mkdtemp(prefix=prefix, suffix=suffix, dir=entry.parent))
    except OSError as exc:
        raise _space_error(entry, exc) from None
    try:
        yield stage / target.name
        os.chmod(stage, 0o755)
        try:
            os.rename(stage, entry)  # replaces an empty folder (an older version's leftover) too
        except OSError as exc:
            if exc.errno not in (errno.EEXIST, errno.ENOTEMPTY) or not target.is_file():
                raise
    except OSError as exc:
        raise _space_error(entry, exc) from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


_DELIMITERS = {";": "semicolons", "\t": "tabs", "|": "vertical bars"}


def check_table_file(path: str | Path, *, parquet: bool) -> None:
    """Check a table file before parsing it, for messages a parser cannot give.

    Args:
        path: the file.
        parquet: whether its suffix names Parquet (else it is read as comma-separated CSV).

    Raises:
        DesignerError: missing, a folder, empty, binary where text is expected, Parquet named as CSV
            or the reverse, or a CSV separated by semicolons, tabs or bars (named) instead of commas.
    """
    p = Path(path)
    if not p.exists():
        raise DesignerError(f"no such file: {p}", "check the path")
    if p.is_dir():
        raise DesignerError(f"cannot read {p}: it is a folder", "give a CSV or Parquet file")
    with open(p, "rb") as fh:
        head = fh.read(4096)
    if not head:
        raise DesignerError(f"cannot read {p}: it is empty", "give a table with a header row and data rows")
    if parquet != head.startswith(b"PAR1"):
        kind = "a Parquet file" if head.startswith(b"PAR1") else "not a Parquet file"
        raise DesignerError(
            f"cannot read {p}: it is {kind}",
            "name Parquet files .parquet or .pq, and CSV files anything else",
        )
    if parquet:
        return
    # up to the header row: the first line that is not a comment (a logger's '# rate: 1000 Hz' above it)
    lines = head.splitlines() or [head]
    row = next((i for i, x in enumerate(lines) if not x.lstrip(b"\xef\xbb\xbf \t").startswith(b"#")), 0)
    if head.startswith((b"\xff\xfe", b"\xfe\xff")):
        raise DesignerError(f"cannot read {p}: it is UTF-16 text", "save it as UTF-8 comma-separated CSV")
    try:
        text = b"\n".join(lines[: row + 1]).decode("utf-8-sig").split("\n")[-1]
    except UnicodeDecodeError:
        text = "\0" if b"\0" in head else ""
        if not text:
            raise DesignerError(
                f"cannot read {p}: it is not UTF-8 text (Latin-1 or Windows-1252, from an old spreadsheet?)",
                "save it as UTF-8 comma-separated CSV",
            ) from None
    if "\0" in text or b"\0" in head:
        raise DesignerError(
            f"cannot read {p}: it is not a text CSV file (it holds binary data)",
            "give a CSV or Parquet table",
        )
    if "," not in text:
        used = [name for d, name in _DELIMITERS.items() if d in text]
        if used:
            raise DesignerError(
                f"cannot read {p}: it is separated by {used[0]}, not commas",
                "save it as comma-separated CSV (decimal point '.'), or as Parquet",
            )


def check_suffix(path: str | Path, suffixes: tuple[str, ...], *, what: str) -> Path:
    """Refuse a path whose suffix is not one of `suffixes` (a writer writes only its own format).

    Raises:
        DesignerError: naming the `path` argument, the format and the suffixes it takes.
    """
    path = path_argument(path, "path", what=f"{what} file")
    if path.suffix.lower() not in suffixes:
        raise DesignerError(
            f"path={str(path)!r} does not name {what} file", f"give a path ending in {' or '.join(suffixes)}"
        )
    return path
