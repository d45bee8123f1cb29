"""FMU binaries for every common platform, cross-compiled with Zig: each binary's object format and
architecture read from its header (parsed here), every function its FMI header declares exported,
the FMI 2 / FMI 3 folder names, fmpy's validation, byte-identical exports, and `--platforms`."""

from __future__ import annotations

import json
import os
import re
import shutil
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest
from fmpy.validation import validate_fmu

from designer.errors import DesignerError
from designer.export import build
from designer.export.fmu import export_fmu
from designer.joint import Joint

pytestmark = pytest.mark.skipif(not build.zig_available(), reason="ziglang is not installed")

# FMI 2.0.4 section 2.3: linux64/win64/darwin64 mean 64-bit x86; other platforms use FMI 3 tuples
FOLDERS = {
    2: {"linux64", "aarch64-linux", "win64", "darwin64", "aarch64-darwin"},
    3: {"x86_64-linux", "aarch64-linux", "x86_64-windows", "x86_64-darwin", "aarch64-darwin"},
}
ARCH = {"linux64": "x86_64", "win64": "x86_64", "darwin64": "x86_64"}


@pytest.fixture(scope="module")
def fmus(tmp_path_factory):
    d = tmp_path_factory.mktemp("plat")
    mp = pytest.MonkeyPatch()
    # our binary cache is throw-away; Zig's own cache (its C runtimes per target) is kept where it was
    default_zig = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "zig"
    mp.setenv("ZIG_GLOBAL_CACHE_DIR", os.environ.get("ZIG_GLOBAL_CACHE_DIR", str(default_zig)))
    mp.setenv("XDG_CACHE_HOME", str(d / "cache"))
    joint = Joint.from_coefficients({"theta": {"k": 330, "c": 0.83, "m": 2e-6}})
    yield {v: export_fmu(joint, d / f"all{v}.fmu", v, "force", platforms="all") for v in (2, 3)}, joint, d
    mp.undo()


def object_format(data: bytes) -> tuple[str, str]:
    """(format, architecture) from the file header: ELF, PE (a DLL) or Mach-O (a dylib)."""
    if data[:4] == b"\x7fELF":
        assert data[4] == 2 and data[5] == 1, "64-bit little-endian"
        assert struct.unpack_from("<H", data, 16)[0] == 3, "ET_DYN: a shared object"
        machine = struct.unpack_from("<H", data, 18)[0]
        return "ELF", {62: "x86_64", 183: "aarch64"}[machine]
    if data[:2] == b"MZ":
        pe = struct.unpack_from("<I", data, 0x3C)[0]
        assert data[pe : pe + 4] == b"PE\0\0"
        machine, characteristics = (
            struct.unpack_from("<H", data, pe + 4)[0],
            struct.unpack_from("<H", data, pe + 22)[0],
        )
        assert characteristics & 0x2000, "IMAGE_FILE_DLL"
        return "PE", {0x8664: "x86_64", 0xAA64: "aarch64"}[machine]
    magic, cputype, _, filetype = struct.unpack_from("<IiII", data, 0)
    assert magic == 0xFEEDFACF and filetype == 6, "64-bit Mach-O MH_DYLIB"
    return "Mach-O", {0x01000007: "x86_64", 0x0100000C: "aarch64"}[cputype]


def required_functions(version: int) -> set[str]:
    """Every function the FMI header declares for export (`FMI2_Export fmi2XTYPE fmi2X;`)."""
    header = (build.source_dir() / "include" / f"fmi{version}Functions.h").read_text()
    return set(re.findall(rf"FMI{version}_Export\s+fmi{version}\w+TYPE\s+(fmi{version}\w+);", header))


def exported(path: Path, fmt: str) -> set[str]:
    """The names a shared library exports, by llvm-nm (ELF, Mach-O) or llvm-objdump (PE)."""
    if fmt == "PE":
        out = subprocess.run(
            ["llvm-objdump", "-p", str(path)], capture_output=True, text=True, check=True
        ).stdout
        table = out.split("Export Table:", 1)[1].split("\n\n", 1)[0]
        return set(re.findall(r"^\s+\d+\s+0x[0-9a-f]+\s+(\w+)$", table, re.M))
    flags = ["-D"] if fmt == "ELF" else ["--extern-only"]
    cmd = ["llvm-nm", *flags, "--defined-only", str(path)]
    out = subprocess.run(cmd, capture_output=True, text=True, check=True).stdout
    names = [line.split()[-1] for line in out.splitlines() if line.strip()]
    return {n[1:] if fmt == "Mach-O" else n for n in names}


def _binaries(path: Path) -> dict[str, tuple[str, bytes]]:
    """{platform folder: (archive name, bytes)} of the FMU's binaries."""
    with zipfile.ZipFile(path) as z:
        return {n.split("/")[1]: (n, z.read(n)) for n in z.namelist() if n.startswith("binaries/")}


@pytest.mark.parametrize("version", [2, 3])
def test_every_platform_binary_has_its_object_format_and_architecture(fmus, version):
    binaries = _binaries(fmus[0][version])
    assert set(binaries) == FOLDERS[version]
    for folder, (name, data) in binaries.items():
        fmt, arch = object_format(data)
        system = folder.split("-")[-1] if "-" in folder else re.sub(r"\d+$", "", folder)
        expected = {"linux": ("ELF", ".so"), "win": ("PE", ".dll"), "windows": ("PE", ".dll")}
        assert (fmt, Path(name).suffix) == expected.get(system, ("Mach-O", ".dylib")), name
        assert arch == ARCH.get(folder, folder.split("-")[0]), name
    assert validate_fmu(str(fmus[0][version])) == []


@pytest.mark.skipif(
    not (shutil.which("llvm-nm") and shutil.which("llvm-objdump")), reason="no llvm-nm/objdump"
)
@pytest.mark.parametrize("version", [2, 3])
def test_every_platform_binary_exports_every_fmi_function(fmus, version, tmp_path):
    assert len(required_functions(version)) == (44 if version == 2 else 75)
    for folder, (name, data) in _binaries(fmus[0][version]).items():
        (tmp_path / folder).write_bytes(data)
        missing = required_functions(version) - exported(tmp_path / folder, object_format(data)[0])
        assert not missing, (name, sorted(missing))


def test_windows_dll_imports_only_the_c_runtime_and_kernel32(fmus, tmp_path):
    if not shutil.which("llvm-objdump"):
        pytest.skip("llvm-objdump not installed")
    with zipfile.ZipFile(fmus[0][3]) as z:
        (tmp_path / "j.dll").write_bytes(z.read("binaries/x86_64-windows/FlexJoint.dll"))
    out = subprocess.run(
        ["llvm-objdump", "-p", str(tmp_path / "j.dll")], capture_output=True, text=True
    ).stdout
    dlls = {d.lower() for d in re.findall(r"DLL Name: (\S+)", out)}
    assert dlls and all(
        d == "kernel32.dll" or d == "msvcrt.dll" or d.startswith("api-ms-win-crt") for d in dlls
    )


def test_exports_for_all_platforms_are_byte_identical(fmus):
    paths, joint, d = fmus
    again = export_fmu(joint, d / "again.fmu", 2, "force", platforms="all")
    assert again.read_bytes() == paths[2].read_bytes()


def test_platform_list_and_refusals(fmus):
    paths, joint, d = fmus
    one = export_fmu(joint, d / "one.fmu", 3, "force", platforms=["aarch64-darwin", "host"])
    with zipfile.ZipFile(one) as z:
        assert {n.split("/")[1] for n in z.namelist() if n.startswith("binaries/")} == {
            "aarch64-darwin",
            build.host_platform(),
        }
    with pytest.raises(DesignerError, match="unknown platform"):
        export_fmu(joint, d / "bad.fmu", 3, "force", platforms="riscv64-linux")


def test_cli_default_is_all_platforms_with_ziglang(fmus, tmp_path):
    cmd = "from designer_cli.main import main; main()"
    args = ["export", "fmu", "--k", "0.8", "--c", "2e-3", "-o", str(tmp_path / "j.fmu"), "--json"]
    done = subprocess.run([sys.executable, "-I", "-c", cmd, *args], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["platforms"] == list(build.PLATFORMS)


def test_cli_platforms_option(fmus, tmp_path):
    out = tmp_path / "j.fmu"
    env = dict(os.environ)
    cmd = "from designer_cli.main import main; main()"
    args = [
        "export",
        "fmu",
        "--k",
        "0.8",
        "--c",
        "2e-3",
        "--platforms",
        "x86_64-windows,host",
        "-o",
        str(out),
    ]
    done = subprocess.run(
        [sys.executable, "-I", "-c", cmd, *args, "--json"], capture_output=True, text=True, env=env
    )
    assert done.returncode == 0, done.stderr
    assert json.loads(done.stdout)["platforms"] == sorted(
        {"x86_64-windows", build.host_platform()}, key=list(build.PLATFORMS).index
    )
    bad_args = [*args[:-4], "--platforms", "sparc", "-o", str(out)]
    bad = subprocess.run(
        [sys.executable, "-I", "-c", cmd, *bad_args], capture_output=True, text=True, env=env
    )
    assert bad.returncode == 2 and "unknown platform" in bad.stderr + bad.stdout
    assert "Traceback" not in bad.stderr
