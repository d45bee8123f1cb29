"""Compile the co-simulation kernel (fmus/kernel/*.c) once, against the `mujoco` wheel's headers and library.

The kernel calls MuJoCo's C API, so it is built with the headers the installed wheel ships and linked
to that wheel's libmujoco (the one the Python bindings already loaded). The shared library is cached
by a hash of the kernel and FMI sources, MuJoCo's headers and library, the compiler and the flags, in
`$XDG_CACHE_HOME/flexjoint-designer/kernel`: after the first run, no compiler is needed.
"""

from __future__ import annotations

import hashlib
import shlex
import shutil
import sys
from pathlib import Path

from ..errors import DesignerError
from ..export.build import FLAGS as BUILD_FLAGS
from ..export.build import cache_dir, compile_c, find_compiler
from ..export.layout import source_dir
from ..files import cache_entry

#: the FMU binary's flags, plus -ffp-contract=off and no sin/cos builtins: the arithmetic of the
#: Python master, bit for bit
FLAGS: tuple[str, ...] = (
    *BUILD_FLAGS,
    "-ffp-contract=off",
    "-fno-builtin-sin",
    "-fno-builtin-cos",
    "-pthread",
)
SOURCES = ("kernel/master.c", "kernel/systems.c", "kernel/references.c")
HEADERS = (
    "kernel/kernel.h",
    "include/fmi2FunctionTypes.h",
    "include/fmi2TypesPlatform.h",
    "include/fmi3FunctionTypes.h",
    "include/fmi3PlatformTypes.h",
)


def mujoco_paths() -> tuple[Path, Path]:
    """The `mujoco` wheel's include folder and its libmujoco shared library.

    Raises:
        DesignerError: the wheel ships no headers or no library (an unusual MuJoCo install).
    """
    import mujoco

    root = Path(mujoco.__file__).parent
    include = root / "include"
    libs = sorted(root.glob("libmujoco*.dylib" if sys.platform == "darwin" else "libmujoco.so*"))
    if not (include / "mujoco" / "mujoco.h").is_file() or not libs:
        raise DesignerError(
            f"the mujoco package in {root} ships no C headers or no libmujoco",
            "install the mujoco wheel from PyPI (pip install mujoco), or run with engine='python'",
        )
    return include, libs[0]


def _key(compiler: list[str], include: Path, lib: Path) -> str:
    h = hashlib.sha256()
    root = source_dir()
    for rel in (*SOURCES, *HEADERS):
        h.update(rel.encode() + b"\0" + (root / rel).read_bytes() + b"\0")
    for header in sorted((include / "mujoco").glob("*.h")):
        h.update(header.name.encode() + b"\0" + header.read_bytes() + b"\0")
    exe = Path(shutil.which(compiler[0]) or compiler[0]).resolve()
    for path in (exe, lib.resolve()):
        st = path.stat()
        h.update(f"{path}|{st.st_size}|{st.st_mtime_ns}|".encode())
    h.update(f"{shlex.join(compiler)}|{' '.join(FLAGS)}|{sys.platform}".encode())
    return h.hexdigest()[:24]


def build_kernel() -> Path:
    """The kernel's shared library for this machine and MuJoCo, compiled on first use.

    Raises:
        DesignerError: no C compiler, or compiling failed (the compiler's message is included).
    """
    compiler = find_compiler()
    include, lib = mujoco_paths()
    name = "kernel.dylib" if sys.platform == "darwin" else "kernel.so"
    target = cache_dir().parent / "kernel" / _key(compiler, include, lib) / name
    if target.is_file():
        return target
    root = source_dir()
    with cache_entry(target) as tmp:
        cmd = [
            *compiler,
            *FLAGS,
            f"-I{include}",
            f"-I{root / 'include'}",
            *(str(root / c) for c in SOURCES),
            "-o",
            str(tmp),
            str(lib),
            f"-Wl,-rpath,{lib.parent}",
            "-lm",
        ]
        compile_c(cmd, name=compiler[0], what="the co-simulation kernel", instead="use engine='python'")
    return target
