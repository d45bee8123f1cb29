"""Compile the FlexJoint FMU binary once per platform, cached by content hash.

The binary is the same for every joint (the joint's numbers live in the FMU's resources), so an export
after the first build copies a cached file: no compiler, milliseconds. The host's binary is built with
the system C compiler; the other platforms (and the host when there is no system compiler) with the
Zig toolchain from PyPI (`ziglang`, `python -m ziglang cc -target ...`) when it is installed.

Platforms are named by their FMI 3 platform tuple. Binary folders: FMI 3 uses the tuple; FMI 2
standardises only linux64, win64 and darwin64, meaning 64-bit x86 (FMI 2.0.4 section 2.3), and for any
other platform names the FMI 3 tuple, so the aarch64 binaries go in aarch64-linux and aarch64-darwin.
"""

from __future__ import annotations

import hashlib
import importlib.util
import os
import platform as _platform
import shlex
import shutil
import subprocess
import sys
import tempfile
from collections.abc import Sequence
from importlib import resources
from pathlib import Path

from ..errors import DesignerError
from ..files import atomic_path

FLAGS: tuple[str, ...] = (
    "-std=gnu99",
    "-O2",
    "-fPIC",
    "-shared",
    "-fvisibility=hidden",
    "-Werror=implicit-function-declaration",
)
#: FMI 3 platform tuples this module builds, and the Zig target of each
PLATFORMS: dict[str, str] = {
    "x86_64-linux": "x86_64-linux-gnu",
    "aarch64-linux": "aarch64-linux-gnu",
    "x86_64-windows": "x86_64-windows-gnu",
    "x86_64-darwin": "x86_64-macos",
    "aarch64-darwin": "aarch64-macos",
}
_FMI2_FOLDERS = {"x86_64-linux": "linux64", "x86_64-windows": "win64", "x86_64-darwin": "darwin64"}
#: Zig flags on top of FLAGS: strip (no debug paths in the binary) and a path-free macOS install name
_ZIG_FLAGS = ("-s",)
#: the C files of one FMI version's binary, as shipped flat in the FMU's sources/ folder
_RUNTIME = ("runtime/instance.c", "runtime/state.c", "FlexJoint/model.c")
_HEADERS = ("runtime/instance.h", "runtime/model.h", "FlexJoint/config.h")
_FMI_HEADERS = {
    2: ("include/fmi2Functions.h", "include/fmi2FunctionTypes.h", "include/fmi2TypesPlatform.h"),
    3: ("include/fmi3Functions.h", "include/fmi3FunctionTypes.h", "include/fmi3PlatformTypes.h"),
}


def source_dir() -> Path:
    """The folder holding the C runtime (`fmus/` in the checkout, `designer/fmus` when installed)."""
    return Path(str(resources.files("designer.fmus")))


def c_sources(fmi_version: int) -> list[str]:
    """The C files (relative to source_dir) compiled into the FMI `fmi_version` binary."""
    return [*_RUNTIME, f"runtime/fmi{fmi_version}Functions.c"]


def source_files(fmi_version: int) -> list[str]:
    """Every file (relative to source_dir) an importer needs to rebuild the binary."""
    return sorted(
        [*c_sources(fmi_version), *_HEADERS, *_FMI_HEADERS[fmi_version]], key=lambda p: Path(p).name
    )


def host_platform() -> str:
    """This machine's FMI 3 platform tuple, e.g. x86_64-linux.

    Raises:
        DesignerError: on an operating system or architecture this module cannot build for.
    """
    machine = _platform.machine().lower()
    machine = {"amd64": "x86_64", "arm64": "aarch64"}.get(machine, machine)
    system = {"linux": "linux", "darwin": "darwin", "win32": "windows"}.get(sys.platform, sys.platform)
    tuple_ = f"{machine}-{system}"
    if tuple_ not in PLATFORMS:
        raise DesignerError(
            f"building FMU binaries on {tuple_} is not supported",
            f"export with source_only=True, or for one of: {', '.join(PLATFORMS)}",
        )
    return tuple_


def platform_folder(fmi_version: int, platform: str | None = None) -> str:
    """The binaries/ sub-folder of `platform` (default: this machine) for FMI `fmi_version`."""
    platform = platform or host_platform()
    return _FMI2_FOLDERS.get(platform, platform) if fmi_version == 2 else platform


def library_name(platform: str | None = None) -> str:
    """FlexJoint.so, .dll or .dylib for `platform` (default: this machine)."""
    from .layout import layout

    system = (platform or host_platform()).split("-", 1)[1]
    return layout().model_identifier + {"windows": ".dll", "darwin": ".dylib"}.get(system, ".so")


def zig_available() -> bool:
    """True if the `ziglang` package (the Zig C cross-compiler) is importable."""
    return importlib.util.find_spec("ziglang") is not None


def resolve_platforms(platforms: str | Sequence[str]) -> list[str]:
    """ "all", "host" or platform tuples (a list or a comma-separated string) as a list of tuples.

    Raises:
        DesignerError: for an unknown tuple, or another platform than the host without ziglang.
    """
    if isinstance(platforms, str):
        platforms = [p.strip() for p in platforms.split(",") if p.strip()]
    if list(platforms) == ["all"]:
        names = list(PLATFORMS)
    elif list(platforms) == ["host"]:
        names = [host_platform()]
    else:
        names = [p if p != "host" else host_platform() for p in platforms]
    unknown = [p for p in names if p not in PLATFORMS]
    if unknown or not names:
        raise DesignerError(
            f"unknown platform(s) {', '.join(unknown) or '(none given)'}",
            f'use platforms="all", "host" or some of: {", ".join(PLATFORMS)}',
        )
    if not zig_available() and any(p != host_platform() for p in names):
        raise DesignerError(
            "building for other platforms than this machine needs the Zig toolchain",
            'pip install ziglang, or use platforms="host"',
        )
    return sorted(set(names), key=list(PLATFORMS).index)


def find_compiler() -> list[str]:
    """The C compiler command: $CC if set, else the first of cc, gcc, clang on PATH."""
    env = os.environ.get("CC", "").strip()
    if env:
        cmd = shlex.split(env)
        if shutil.which(cmd[0]) is None:
            raise DesignerError(
                f"the C compiler '{cmd[0]}' named by $CC was not found",
                "install a C compiler (for example apt-get install gcc), point CC at it, "
                "or export with source_only=True and build from the FMU's sources/",
            )
        return cmd
    for name in ("cc", "gcc", "clang"):
        if shutil.which(name):
            return [name]
    raise DesignerError(
        "no C compiler found (tried $CC, cc, gcc, clang)",
        "install one (for example apt-get install gcc), or export with source_only=True and build the "
        "binary from the FMU's sources/ (fmpy: python -m fmpy compile joint.fmu)",
    )


def _compiler(platform: str) -> tuple[list[str], list[str]]:
    """The compiler command and its extra flags for `platform`: the system one for the host (Zig if
    there is none and $CC names none), Zig for the others."""
    if platform == host_platform():
        try:
            return find_compiler(), []
        except DesignerError:
            if os.environ.get("CC", "").strip() or not zig_available():
                raise
    extra = [*_ZIG_FLAGS, "-target", PLATFORMS[platform]]
    if platform.endswith("darwin"):
        extra.append(f"-Wl,-install_name,{library_name(platform)}")
    return [sys.executable, "-m", "ziglang", "cc"], extra


def cache_dir() -> Path:
    """Where built binaries are kept: $XDG_CACHE_HOME/flexjoint-designer/fmu, else ~/.cache/..."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "flexjoint-designer" / "fmu"


def _build_key(fmi_version: int, compiler: list[str], extra: list[str], platform: str) -> str:
    """Hash of the sources, the compiler (resolved path, size, mtime), the flags and the platform."""
    h = hashlib.sha256()
    root = source_dir()
    for rel in source_files(fmi_version):
        h.update(rel.encode() + b"\0" + (root / rel).read_bytes() + b"\0")
    exe = Path(shutil.which(compiler[0]) or compiler[0]).resolve()
    if compiler[1:3] == ["-m", "ziglang"]:
        exe = Path(str(importlib.util.find_spec("ziglang").origin)).parent / "zig"
    st = exe.stat() if exe.exists() else None
    stamp = f"{st.st_size}|{st.st_mtime_ns}" if st else "?"
    h.update(f"{exe}|{stamp}|{shlex.join(compiler)}|{' '.join(FLAGS)}|{' '.join(extra)}".encode())
    h.update(f"|{platform}".encode())
    return h.hexdigest()[:24]


def build_binary(fmi_version: int, platform: str | None = None) -> Path:
    """The FlexJoint shared library for FMI `fmi_version` on `platform` (default: this machine),
    compiled on first use.

    Raises:
        DesignerError: if no compiler can build for the platform or the compilation fails.
    """
    platform = platform or host_platform()
    compiler, extra = _compiler(platform)
    key = _build_key(fmi_version, compiler, extra, platform)
    target = cache_dir() / f"fmi{fmi_version}-{platform}-{key}" / library_name(platform)
    if target.is_file():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    root = source_dir()
    includes = sorted({f"-I{root / Path(rel).parent}" for rel in source_files(fmi_version)})
    with tempfile.TemporaryDirectory(prefix="designer-build-") as tmp, atomic_path(target) as out:
        built = Path(tmp) / library_name(platform)  # Zig writes .lib/.pdb beside a DLL: keep them out
        cmd = [*compiler, *FLAGS, *extra, *includes, *(str(root / c) for c in c_sources(fmi_version))]
        libs = ["-lm"] if not platform.endswith(("windows", "darwin")) else []
        _run([*cmd, "-o", str(built), *libs], compiler[0] if compiler[0] != sys.executable else "zig")
        shutil.copyfile(built, out)
    return target


def _run(cmd: list[str], name: str) -> None:
    compile_c(cmd, name=name, what="the FMU binary", instead="export with source_only=True")


def compile_c(cmd: list[str], *, name: str, what: str, instead: str) -> None:
    """Run a compiler command building `what`; a failure is a DesignerError with the compiler's message.

    `instead` says what the caller can do without a compiler (e.g. "export with source_only=True").
    """
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, check=False)
    except OSError as exc:
        raise DesignerError(
            f"could not run the C compiler '{name}': {exc}", f"check $CC, or {instead}"
        ) from None
    if done.returncode != 0:
        raise DesignerError(
            f"compiling {what} failed:\n{done.stderr.strip()}",
            f"check the compiler with '{name} --version', or {instead}",
        )
