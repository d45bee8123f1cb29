"""The FlexJoint FMU binary per platform: shipped prebuilt, or compiled once and cached by content hash.

The binary is the same for every joint (the joint's numbers live in the FMU's resources), so the
package ships the ten binaries (FMI 2 and 3, five platforms) built by `python -m
designer.export.prebuilt` with Zig, beside a hash of the C sources and flags they were built from. An
export copies them: no compiler. Only when the sources' hash differs (an edited checkout) or the caller
asks (`rebuild=True`) is a binary compiled: the host's with the system C compiler, the other platforms
(and the host when there is no system compiler) with the Zig toolchain from PyPI (`ziglang`, the
`build` extra), then kept in a cache keyed by sources, compiler and flags.

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
from collections.abc import Sequence
from pathlib import Path

from ..errors import DesignerError, check_type
from ..files import cache_entry, temporary_folder
from .layout import layout, source_dir

#: no fused multiply-add contraction: aarch64 would fuse a*b+c where x86_64 cannot, and a joint's
#: numbers would then differ by platform (1e-12 after 300 steps, measured under qemu-user)
FLAGS: tuple[str, ...] = (
    "-std=gnu99",
    "-O2",
    "-ffp-contract=off",
    "-fPIC",
    "-shared",
    "-fvisibility=hidden",
    "-Werror=implicit-function-declaration",
)
#: FMI 3 platform tuples this module builds, and the Zig target of each: glibc 2.17 (RHEL 7 and every
#: later Linux), macOS 10.15 on x86_64 and 11.0 (the first arm64 release) on aarch64
PLATFORMS: dict[str, str] = {
    "x86_64-linux": "x86_64-linux-gnu.2.17",
    "aarch64-linux": "aarch64-linux-gnu.2.17",
    "x86_64-windows": "x86_64-windows-gnu",
    "x86_64-darwin": "x86_64-macos.10.15",
    "aarch64-darwin": "aarch64-macos.11.0",
}
_FMI2_FOLDERS = {"x86_64-linux": "linux64", "x86_64-windows": "win64", "x86_64-darwin": "darwin64"}
#: Zig flags on top of FLAGS: strip (no debug paths in the binary) and a path-free macOS install name
_ZIG_FLAGS = ("-s",)
#: the C files of one FMI version's binary, as shipped flat in the FMU's sources/ folder
_RUNTIME = ("runtime/instance.c", "runtime/state.c", "FlexJoint/model.c")
_HEADERS = ("runtime/instance.h", "runtime/model.h", "runtime/names.h", "FlexJoint/config.h")
_FMI_HEADERS = {
    2: ("include/fmi2Functions.h", "include/fmi2FunctionTypes.h", "include/fmi2TypesPlatform.h"),
    3: ("include/fmi3Functions.h", "include/fmi3FunctionTypes.h", "include/fmi3PlatformTypes.h"),
}


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
    system = (platform or host_platform()).split("-", 1)[1]
    return layout().model_identifier + {"windows": ".dll", "darwin": ".dylib"}.get(system, ".so")


def zig_available() -> bool:
    """True if the `ziglang` package (the Zig C cross-compiler) is importable."""
    return importlib.util.find_spec("ziglang") is not None


def resolve_platforms(platforms: str | Sequence[str]) -> list[str]:
    """ "all", "host" or platform tuples (a list or a comma-separated string) as a list of tuples.

    Raises:
        DesignerError: for an unknown tuple.
    """
    if isinstance(platforms, str):
        platforms = [p.strip() for p in platforms.split(",") if p.strip()]
    fix = f'give platforms="all", "host" or a list of: {", ".join(PLATFORMS)}'
    check_type(platforms, (list, tuple), "platforms", expected="a str or a list of str", fix=fix)
    for p in platforms:
        check_type(p, str, "platforms", expected="a list of str", fix=fix)
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


def zig_flags(platform: str) -> list[str]:
    """The Zig flags on top of FLAGS for `platform`: strip, target, a path-free macOS install name."""
    extra = [*_ZIG_FLAGS, "-target", PLATFORMS[platform]]
    if platform.endswith("darwin"):
        extra.append(f"-Wl,-install_name,{library_name(platform)}")
    return extra


def platform_compiler(platform: str, *, zig: bool = False) -> tuple[list[str], list[str]]:
    """The compiler command and its extra flags for `platform`: the system one for the host (Zig if
    there is none and $CC names none, or if `zig`), Zig for the others.

    Raises:
        DesignerError: if the platform needs Zig and the ziglang package is not installed.
    """
    if platform == host_platform() and not zig:
        try:
            return find_compiler(), []
        except DesignerError:
            if os.environ.get("CC", "").strip() or not zig_available():
                raise
    if not zig_available():
        raise DesignerError(
            f"compiling the FMU binary for {platform} needs the Zig toolchain, which is not installed",
            'pip install "flexjoint-designer[build]" (or pip install ziglang), or use platforms="host"',
        )
    return [sys.executable, "-m", "ziglang", "cc"], zig_flags(platform)


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


def sources_hash() -> str:
    """SHA-256 of every C source and header of both FMI versions, the flags and the Zig targets: what
    the shipped binaries were built from (`fmus/binaries/SOURCES.sha256`)."""
    h = hashlib.sha256()
    root = source_dir()
    for rel in sorted({*source_files(2), *source_files(3)}):
        h.update(rel.encode() + b"\0" + (root / rel).read_bytes() + b"\0")
    for platform in PLATFORMS:
        h.update(f"{platform}|{' '.join(FLAGS)}|{' '.join(zig_flags(platform))}\n".encode())
    return h.hexdigest()


def shipped_binary(fmi_version: int, platform: str) -> Path | None:
    """The prebuilt binary the package ships for `platform`, or None when there is none or the C
    sources were edited since it was built (their hash differs from the one recorded beside it)."""
    folder = source_dir() / "binaries"
    path = folder / f"fmi{fmi_version}" / platform / library_name(platform)
    try:
        recorded = (folder / "SOURCES.sha256").read_text().split()[0]
    except (OSError, IndexError):
        return None
    return path if path.is_file() and recorded == sources_hash() else None


def needs_compiling(fmi_version: int, platforms: str | Sequence[str], *, rebuild: bool = False) -> list[str]:
    """The platforms among `platforms` whose binary an export would compile (no shipped binary matches
    the sources, or `rebuild`) rather than copy; cached builds count as compiling."""
    names = resolve_platforms(platforms)
    return names if rebuild else [p for p in names if shipped_binary(fmi_version, p) is None]


def build_binary(
    fmi_version: int, platform: str | None = None, *, rebuild: bool = False, zig: bool = False
) -> Path:
    """The FlexJoint shared library for FMI `fmi_version` on `platform` (default: this machine): the
    shipped prebuilt one, or compiled (and cached) when the sources changed or `rebuild` is set.
    `zig` compiles the host's binary with Zig too, as the shipped ones are.

    Raises:
        DesignerError: if no compiler can build for the platform or the compilation fails.
    """
    platform = platform or host_platform()
    shipped = None if rebuild else shipped_binary(fmi_version, platform)
    if shipped is not None:
        return shipped
    compiler, extra = platform_compiler(platform, zig=zig)
    key = _build_key(fmi_version, compiler, extra, platform)
    target = cache_dir() / f"fmi{fmi_version}-{platform}-{key}" / library_name(platform)
    if target.is_file():
        return target
    with cache_entry(target) as out:
        compile_binary(fmi_version, platform, compiler, extra, out)
    return target


def compile_binary(fmi_version: int, platform: str, compiler: list[str], extra: list[str], out: Path) -> None:
    """Compile the FMI `fmi_version` binary for `platform` into `out`. The compiler runs in the source
    folder on relative paths, so no path of this machine ends up in the binary."""
    root = source_dir()
    includes = sorted({f"-I{Path(rel).parent}" for rel in source_files(fmi_version)})
    with temporary_folder("designer-build-") as tmp:
        built = Path(tmp) / library_name(platform)  # Zig writes .lib/.pdb beside a DLL: keep them out
        cmd = [*compiler, *FLAGS, *extra, *includes, *c_sources(fmi_version)]
        libs = ["-lm"] if not platform.endswith(("windows", "darwin")) else []
        name = compiler[0] if compiler[0] != sys.executable else "zig"
        compile_c(
            [*cmd, "-o", str(built), *libs],
            name=name,
            what="the FMU binary",
            instead="export with source_only=True",
            cwd=root,
        )
        shutil.copyfile(built, out)


def compile_c(cmd: list[str], *, name: str, what: str, instead: str, cwd: Path | None = None) -> None:
    """Run a compiler command building `what`; a failure is a DesignerError with the compiler's message.

    `instead` says what the caller can do without a compiler (e.g. "export with source_only=True").
    """
    # the compiler's own temporary files (gcc's cc*.s, cc*.o) go to a folder removed afterwards, so an
    # interrupt that kills the compiler cannot leave them in the user's temporary folder
    with temporary_folder("designer-cc-") as scratch:
        env = {**os.environ, "TMPDIR": str(scratch), "TMP": str(scratch), "TEMP": str(scratch)}
        try:
            proc = subprocess.Popen(
                cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, cwd=cwd, env=env
            )
        except OSError as exc:
            raise DesignerError(
                f"could not run the C compiler '{name}': {exc}", f"check $CC, or {instead}"
            ) from None
        try:
            _, stderr = proc.communicate()
        except BaseException:  # interrupted: stop the compiler (its driver removes its files) first
            proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            raise
    if proc.returncode != 0:
        raise DesignerError(
            f"compiling {what} failed:\n{stderr.strip()}",
            f"check the compiler with '{name} --version', or {instead}",
        )
