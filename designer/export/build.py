"""Compile the FlexJoint FMU binary once per platform with the system C compiler, cached by content hash.

The binary is the same for every joint (the joint's numbers live in the FMU's resources), so an export
after the first build copies a cached file: no compiler, milliseconds.
"""

from __future__ import annotations

import hashlib
import os
import platform
import shlex
import shutil
import subprocess
import sys
from importlib import resources
from pathlib import Path

from ..errors import DesignerError
from ..files import atomic_path

MODEL_IDENTIFIER = "FlexJoint"
FLAGS: tuple[str, ...] = (
    "-std=gnu99",
    "-O2",
    "-fPIC",
    "-shared",
    "-fvisibility=hidden",
    "-Werror=implicit-function-declaration",
)
#: the C files of one FMI version's binary, as shipped flat in the FMU's sources/ folder
_RUNTIME = ("runtime/instance.c", "FlexJoint/model.c")
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


def platform_folder(fmi_version: int) -> str:
    """The binaries/ sub-folder for this machine: linux64 (FMI 2) or x86_64-linux (FMI 3), etc."""
    machine = {"amd64": "x86_64", "arm64": "aarch64"}.get(
        platform.machine().lower(), platform.machine().lower()
    )
    system = {"linux": "linux", "darwin": "darwin"}.get(sys.platform)
    if system is None:
        raise DesignerError(
            f"building FMU binaries on {sys.platform} is not supported",
            "export with source_only=True and build the binary with the platform's FMI tooling",
        )
    if fmi_version == 2:
        return system + ("64" if machine in ("x86_64", "aarch64") else "32")
    return f"{machine}-{system}"


def library_name() -> str:
    return MODEL_IDENTIFIER + (".dylib" if sys.platform == "darwin" else ".so")


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


def cache_dir() -> Path:
    """Where built binaries are kept: $XDG_CACHE_HOME/flexjoint-designer/fmu, else ~/.cache/..."""
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "flexjoint-designer" / "fmu"


def _build_key(fmi_version: int, compiler: list[str]) -> str:
    """Hash of the sources, the compiler (resolved path, size, mtime) and the flags."""
    h = hashlib.sha256()
    root = source_dir()
    for rel in source_files(fmi_version):
        h.update(rel.encode() + b"\0" + (root / rel).read_bytes() + b"\0")
    exe = Path(shutil.which(compiler[0]) or compiler[0]).resolve()
    st = exe.stat()
    h.update(f"{exe}|{st.st_size}|{st.st_mtime_ns}|{shlex.join(compiler)}|{' '.join(FLAGS)}".encode())
    h.update(f"|{platform_folder(fmi_version)}".encode())
    return h.hexdigest()[:24]


def build_binary(fmi_version: int) -> Path:
    """The FlexJoint shared library for FMI `fmi_version` on this platform, compiled on first use."""
    compiler = find_compiler()
    target = cache_dir() / f"fmi{fmi_version}-{_build_key(fmi_version, compiler)}" / library_name()
    if target.is_file():
        return target
    target.parent.mkdir(parents=True, exist_ok=True)
    root = source_dir()
    includes = sorted({f"-I{root / Path(rel).parent}" for rel in source_files(fmi_version)})
    with atomic_path(target) as tmp:
        cmd = [
            *compiler,
            *FLAGS,
            *includes,
            *(str(root / c) for c in c_sources(fmi_version)),
            "-o",
            str(tmp),
            "-lm",
        ]
        try:
            done = subprocess.run(cmd, capture_output=True, text=True, check=False)
        except OSError as exc:
            raise DesignerError(
                f"could not run the C compiler '{compiler[0]}': {exc}",
                "check $CC, or export with source_only=True",
            ) from None
        if done.returncode != 0:
            raise DesignerError(
                f"compiling the FMU binary failed:\n{done.stderr.strip()}",
                "check the compiler with 'cc --version', or export with source_only=True",
            )
    return target
