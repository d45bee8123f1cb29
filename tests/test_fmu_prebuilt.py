"""The FMU binaries the package ships (fmus/binaries) against their sources and the platforms they claim.

- They are the sources: rebuilt with the pinned Zig into a temporary folder, byte for byte.
- Their floors, read from the binaries: the Linux ones need at most glibc 2.17, the macOS ones declare
  macOS 10.15 (x86_64) and 11.0 (arm64).
- They run where they claim: tests/fmu_host.c (a small FMI 2/3 importer) is compiled natively, for
  Windows and for aarch64 Linux with Zig; the Windows DLL runs under Wine and the aarch64 .so under
  qemu-user on the same step sequence as the native x86_64 .so, FMI 2 and 3, co-simulation and model
  exchange, from a folder named with a space and non-ASCII letters, with the resource location in
  every form the standards allow. Each skips with its reason where the tool is missing.
- An exported FMU's sources/ build by following only the FMU's own build description (FMI 3
  buildDescription.xml, FMI 2 <SourceFiles>), and two joints built from source link into one program.
"""

from __future__ import annotations

import os
import re
import shutil
import struct
import subprocess
import sys
import zipfile
from pathlib import Path
from urllib.parse import quote
from xml.etree import ElementTree

import numpy as np
import pytest

from designer.export import build, prebuilt
from designer.export.fmu import export_fmu
from designer.joint import Joint

HERE = Path(__file__).parent
SHIPPED = build.source_dir() / "binaries"
ZIG = [sys.executable, "-m", "ziglang", "cc"]
needs_zig = pytest.mark.skipif(not build.zig_available(), reason="ziglang is not installed (test extra)")
AARCH64_ROOT = Path("/usr/aarch64-linux-gnu")  # Debian's libc6-arm64-cross: the loader qemu-user needs

# the body interface: x.f (input force, 107) drives the mass; x.s (105) and x.v (106) are its states
VR_K, VR_S, VR_V, VR_F = 102, 105, 106, 107
STEP, STEPS = 1e-4, 300


def _glibc_versions(data: bytes) -> list[tuple[int, ...]]:
    return [tuple(map(int, v.split(b"."))) for v in re.findall(rb"GLIBC_(\d+(?:\.\d+)+)\x00", data)]


def _macos_minimum(data: bytes) -> tuple[int, int]:
    """(major, minor) from a 64-bit Mach-O's LC_BUILD_VERSION or LC_VERSION_MIN_MACOSX load command."""
    magic, _, _, _, ncmds = struct.unpack_from("<IiiII", data, 0)
    assert magic == 0xFEEDFACF
    offset = 32
    for _ in range(ncmds):
        cmd, size = struct.unpack_from("<II", data, offset)
        if cmd == 0x32:  # LC_BUILD_VERSION: platform, minos, sdk, ntools
            platform, minos = struct.unpack_from("<II", data, offset + 8)
            assert platform == 1, "PLATFORM_MACOS"
            return minos >> 16, (minos >> 8) & 0xFF
        if cmd == 0x24:  # LC_VERSION_MIN_MACOSX: version, sdk
            version = struct.unpack_from("<I", data, offset + 8)[0]
            return version >> 16, (version >> 8) & 0xFF
        offset += size
    raise AssertionError("no macOS minimum version load command")


def test_shipped_binaries_are_recorded_for_these_sources():
    recorded, _, version = (SHIPPED / "SOURCES.sha256").read_text().split()
    assert recorded == build.sources_hash(), "fmus/ changed: run python scripts/build_fmu_binaries.py"
    for fmi_version in (2, 3):
        for platform in build.PLATFORMS:
            assert build.shipped_binary(fmi_version, platform) is not None, (fmi_version, platform)
    assert re.fullmatch(r"\d+\.\d+\.\d+", version)


@needs_zig
def test_shipped_binaries_are_the_sources_byte_for_byte(tmp_path):
    recorded_zig = (SHIPPED / "SOURCES.sha256").read_text().split()[-1]
    if prebuilt.zig_version() != recorded_zig:
        pytest.skip(f"Zig {prebuilt.zig_version()} is installed; the binaries were built with {recorded_zig}")
    prebuilt.build_all(tmp_path)
    shipped = sorted(p.relative_to(SHIPPED) for p in SHIPPED.rglob("*") if p.is_file())
    rebuilt = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*") if p.is_file())
    assert rebuilt == shipped
    drifted = [str(p) for p in shipped if (SHIPPED / p).read_bytes() != (tmp_path / p).read_bytes()]
    assert not drifted, f"{drifted} differ from a rebuild: run scripts/build_fmu_binaries.py and commit"


@pytest.mark.parametrize("fmi_version", [2, 3])
def test_linux_binaries_need_at_most_glibc_2_17(fmi_version):
    for platform in ("x86_64-linux", "aarch64-linux"):
        data = (SHIPPED / f"fmi{fmi_version}" / platform / "FlexJoint.so").read_bytes()
        versions = _glibc_versions(data)
        assert versions, "the binary names the glibc versions it needs"
        assert max(versions) <= (2, 17), (platform, max(versions))


@pytest.mark.parametrize("fmi_version", [2, 3])
def test_macos_binaries_declare_their_minimum(fmi_version):
    for platform, minimum in (("x86_64-darwin", (10, 15)), ("aarch64-darwin", (11, 0))):
        data = (SHIPPED / f"fmi{fmi_version}" / platform / "FlexJoint.dylib").read_bytes()
        assert _macos_minimum(data) == minimum, platform


# --- running them: a native, a Windows (Wine) and an aarch64 (qemu-user) host ------------------------


def _compile_host(out: Path, target: str | None) -> Path:
    include = build.source_dir() / "include"
    compiler = ["cc"] if target is None else [*ZIG, "-target", target]
    libs = [] if target and "windows" in target else ["-ldl"]
    cmd = [*compiler, "-std=c99", "-O1", f"-I{include}", str(HERE / "fmu_host.c"), "-o", str(out), *libs]
    subprocess.run(cmd, check=True, capture_output=True, cwd=out.parent)
    return out


@pytest.fixture(scope="module")
def hosts(tmp_path_factory):
    """{name: (command prefix, binary platform, path style)} for every host that can run here."""
    d = tmp_path_factory.mktemp("hosts")
    found, missing = {}, {}
    if shutil.which("cc"):
        found["native"] = ([str(_compile_host(d / "host", None))], "x86_64-linux", "posix")
    else:
        missing["native"] = "no C compiler"
    if not build.zig_available():
        missing["wine"] = missing["qemu"] = "ziglang is not installed"
        return found, missing, d
    if shutil.which("wine"):
        exe = _compile_host(d / "host.exe", "x86_64-windows-gnu")
        found["wine"] = (["wine", str(exe)], "x86_64-windows", "windows")
    else:
        missing["wine"] = "wine is not installed (apt-get install wine64; .ci/run does)"
    if shutil.which("qemu-aarch64") and (AARCH64_ROOT / "lib" / "ld-linux-aarch64.so.1").exists():
        exe = _compile_host(d / "host-aarch64", "aarch64-linux-gnu.2.17")
        found["qemu"] = (["qemu-aarch64", "-L", str(AARCH64_ROOT), str(exe)], "aarch64-linux", "posix")
    else:
        missing["qemu"] = "qemu-user or libc6-arm64-cross is not installed (.ci/run installs both)"
    return found, missing, d


@pytest.fixture(scope="module")
def unpacked(tmp_path_factory):
    """{fmi_version: (folder, token)}: body-interface FMUs unpacked under a non-ASCII folder name."""
    joint = Joint.from_coefficients({"x": {"k": 0.8, "c": 2e-3, "m": 0.01}})
    root = tmp_path_factory.mktemp("fmus") / "Jürgen ü"
    out = {}
    for v in (2, 3):
        path = export_fmu(joint, root.parent / f"body{v}.fmu", v, "body")
        folder = root / f"fmi{v}"
        with zipfile.ZipFile(path) as z:
            z.extractall(folder)
        md = ElementTree.parse(folder / "modelDescription.xml").getroot()
        out[v] = folder, md.get("guid") or md.get("instantiationToken")
    return out


def _windows(path: Path) -> str:
    return "Z:" + str(path).replace("/", "\\")  # Wine's Z: drive is /


def _locations(fmi_version: int, resources: Path, style: str) -> dict[str, str]:
    """Every resource location form: FMI 2.0.4 section 2.1.5 (file URIs, RFC 8089) or FMI 3's path."""
    if fmi_version == 3:
        native = _windows(resources) + "\\" if style == "windows" else f"{resources}/"
        return {"native path": native}
    path = "/Z:" + str(resources) if style == "windows" else str(resources)
    encoded = quote(path, safe="/:")  # a space and UTF-8 letters percent-encoded
    forms = {
        "file:///": "file://" + encoded + "/",
        "file:/": "file:" + encoded,
        "file://localhost/": "file://localhost" + encoded + "/",
        "not percent-encoded": "file://" + path + "/",
    }
    if style == "windows":
        forms["file:///C|/ (legacy)"] = "file://" + encoded.replace("/Z:", "/Z|", 1)
    return forms


def _script(dll: str, fmi_version: int, kind: str, token: str, location: str, steps: int) -> str:
    lines = [f"dll\t{dll}", f"fmi\t{fmi_version}", f"kind\t{kind}", f"token\t{token}"]
    lines += [f"resources\t{location}", "nx\t2", "init\t0", f"get\t{VR_K}"]
    for i in range(steps):
        force = float(0.5 * np.sin(2 * np.pi * 40 * i * STEP) + 0.1)  # N: a known, non-trivial input
        lines += [f"set\t{VR_F}\t{force!r}", f"step\t{STEP!r}", f"get\t{VR_S}", f"get\t{VR_V}"]
    return "\n".join(lines) + "\n"


def _run(host, folder: Path, fmi_version: int, kind: str, token: str, location: str, steps: int):
    command, platform, style = host
    binary = folder / "binaries" / build.platform_folder(fmi_version, platform) / build.library_name(platform)
    dll = _windows(binary) if style == "windows" else str(binary)
    env = {**os.environ, "WINEDEBUG": "-all", "WINEDLLOVERRIDES": "mscoree,mshtml="}
    done = subprocess.run(
        command,
        input=_script(dll, fmi_version, kind, token, location, steps).encode(),
        capture_output=True,
        timeout=300,
        env=env,
    )
    out = done.stdout.decode(errors="replace")
    assert done.returncode == 0 and "error" not in out, (location, out[-300:], done.stderr.decode()[-500:])
    return np.array([float(v) for v in out.split()])


@pytest.mark.parametrize("fmi_version", [2, 3])
@pytest.mark.parametrize("kind", ["cs", "me"])
@pytest.mark.parametrize("where", ["wine", "qemu"])
def test_foreign_binary_matches_the_native_one(hosts, unpacked, fmi_version, kind, where):
    found, missing, _ = hosts
    if where not in found or "native" not in found:
        pytest.skip(missing.get(where) or missing["native"])
    folder, token = unpacked[fmi_version]
    resources = folder / "resources"
    native_location = next(iter(_locations(fmi_version, resources, "posix").values()))
    reference = _run(found["native"], folder, fmi_version, kind, token, native_location, STEPS)
    assert reference[0] == 800.0 and len(reference) == 1 + 2 * STEPS  # k from resources, in N/m
    assert np.ptp(reference[1::2]) > 1e-5  # the mass moved
    style = found[where][2]
    for form, location in _locations(fmi_version, resources, style).items():
        steps = STEPS if form in ("file:///", "native path") else 3  # each form loads; one runs long
        result = _run(found[where], folder, fmi_version, kind, token, location, steps)
        expected = reference[: len(result)]
        scale = np.maximum(np.abs(expected), np.abs(reference[1::2]).max())
        assert np.all(np.abs(result - expected) <= 1e-12 * scale), (where, form)


# --- sources/ -----------------------------------------------------------------------------------------


def _described_sources(folder: Path, fmi_version: int) -> tuple[list[str], list[str]]:
    """(C files, libraries) as the FMU describes them: FMI 3 buildDescription.xml, FMI 2 <SourceFiles>."""
    if fmi_version == 3:
        root = ElementTree.parse(folder / "sources" / "buildDescription.xml").getroot()
        config = root.find("BuildConfiguration")
        files = [f.get("name") for f in config.iter("SourceFile")]
        return files, [lib.get("name") for lib in config.iter("Library")]
    md = ElementTree.parse(folder / "modelDescription.xml").getroot()
    lists = [[f.get("name") for f in kind.iter("File")] for kind in md.findall("./*/SourceFiles")]
    assert lists and all(names == lists[0] for names in lists)
    return lists[0], ["m"]  # FMI 2 has no element for libraries; the C math library is implied by C99


def _compile_sources(folder: Path, fmi_version: int, out: Path, prefix: str | None = None, shared=True):
    files, libs = _described_sources(folder, fmi_version)
    src = folder / "sources"
    defines = [f"-DFMI{fmi_version}_FUNCTION_PREFIX={prefix}"] if prefix else []
    cmd = ["cc", "-std=c99", "-O2", f"-I{src}", *defines, *(str(src / f) for f in files)]
    if shared:
        cmd += ["-shared", "-fPIC", "-o", str(out), *(f"-l{lib}" for lib in libs)]
    else:
        cmd += ["-c"]
    subprocess.run(cmd, check=True, capture_output=True, cwd=out.parent)


needs_cc = pytest.mark.skipif(shutil.which("cc") is None, reason="no C compiler")


@needs_cc
@pytest.mark.parametrize("fmi_version", [2, 3])
def test_sources_build_from_their_description_and_match_the_shipped_binary(
    hosts, unpacked, tmp_path, fmi_version
):
    found, missing, _ = hosts
    if "native" not in found:
        pytest.skip(missing["native"])
    folder, token = unpacked[fmi_version]
    copy = tmp_path / "rebuilt"
    shutil.copytree(folder, copy)
    binary = copy / "binaries" / build.platform_folder(fmi_version, "x86_64-linux") / "FlexJoint.so"
    _compile_sources(copy, fmi_version, binary)
    location = next(iter(_locations(fmi_version, copy / "resources", "posix").values()))
    for kind in ("cs", "me"):
        shipped = _run(found["native"], folder, fmi_version, kind, token, location, STEPS)
        rebuilt = _run(found["native"], copy, fmi_version, kind, token, location, STEPS)
        np.testing.assert_allclose(rebuilt, shipped, rtol=1e-12, atol=1e-15)
    from fmpy import simulate_fmu
    from fmpy.validation import validate_fmu

    assert validate_fmu(str(copy)) == []
    r = simulate_fmu(str(copy), stop_time=0.05, step_size=1e-4, start_values={"x.f": 0.1}, output=["x.s"])
    assert r["x.s"][-1] == pytest.approx(0.1 / 800, rel=0.05)  # settles at F/k


LINKER = r"""
#include <stdio.h>
#include "fmi3Functions.h"
#define DECLARE(p) \
    fmi3Instance p##fmi3InstantiateCoSimulation(fmi3String, fmi3String, fmi3String, fmi3Boolean, \
        fmi3Boolean, fmi3Boolean, fmi3Boolean, const fmi3ValueReference[], size_t, fmi3InstanceEnvironment, \
        fmi3LogMessageCallback, fmi3IntermediateUpdateCallback); \
    fmi3Status p##fmi3GetFloat64(fmi3Instance, const fmi3ValueReference[], size_t, fmi3Float64[], size_t); \
    void p##fmi3FreeInstance(fmi3Instance);
DECLARE(a_)
DECLARE(b_)
int main(int argc, char **argv) {
    fmi3ValueReference k = 102;
    fmi3Float64 ka = 0, kb = 0;
    fmi3Instance a = a_fmi3InstantiateCoSimulation("a", argv[1], argv[2], 0, 0, 0, 0, NULL, 0, 0, 0, 0);
    fmi3Instance b = b_fmi3InstantiateCoSimulation("b", argv[3], argv[4], 0, 0, 0, 0, NULL, 0, 0, 0, 0);
    if (!a || !b) return 1;
    a_fmi3GetFloat64(a, &k, 1, &ka, 1);
    b_fmi3GetFloat64(b, &k, 1, &kb, 1);
    printf("%.17g %.17g\n", ka, kb);
    a_fmi3FreeInstance(a);
    b_fmi3FreeInstance(b);
    return 0;
}
"""


@needs_cc
def test_two_joints_built_from_source_link_into_one_program(tmp_path):
    """FMI 3 section 2.2.1: with FMI3_FUNCTION_PREFIX each joint's sources get their own names, so two
    link into one executable (no duplicate symbol), and each instance reads its own start values."""
    args = []
    objects = []
    for prefix, k in (("a_", 0.8), ("b_", 1.6)):
        joint = Joint.from_coefficients({"x": {"k": k, "c": 2e-3, "m": 0.01}})
        folder = tmp_path / prefix
        with zipfile.ZipFile(export_fmu(joint, tmp_path / f"{prefix}.fmu", 3, "body", source_only=True)) as z:
            z.extractall(folder)
        build_dir = tmp_path / f"obj_{prefix}"
        build_dir.mkdir()
        _compile_sources(folder, 3, build_dir / "x", prefix=prefix, shared=False)
        objects += sorted(str(p) for p in build_dir.glob("*.o"))
        token = ElementTree.parse(folder / "modelDescription.xml").getroot().get("instantiationToken")
        args += [token, str(folder / "resources")]
    (tmp_path / "main.c").write_text(LINKER)
    include = build.source_dir() / "include"
    exe = tmp_path / "two"
    subprocess.run(
        ["cc", "-std=c99", f"-I{include}", str(tmp_path / "main.c"), *objects, "-o", str(exe), "-lm"],
        check=True,
        capture_output=True,
    )
    out = subprocess.run([str(exe), *args], capture_output=True, text=True, check=True).stdout
    assert [float(v) for v in out.split()] == [800.0, 1600.0]


# --- designer cosim picks the platform's own binary ----------------------------------------------------


def test_cosim_names_the_platforms_own_fmi2_binary(hosts, unpacked, monkeypatch, tmp_path):
    """FMPy 0.3.32 looks for an FMI 2 binary in linux64 (64-bit x86) on aarch64 Linux too, and in
    darwin64 on Apple Silicon; FMI 2.0.4 has no aarch64 folder, so the exports put it in aarch64-linux.
    `designer cosim` names the binary of its own platform, as FMI 3 does; under qemu that binary runs
    the joint as the native one does."""
    from designer import cosim
    from designer.cosim.fmu import library_path

    folder, token = unpacked[2]
    assert library_path(folder, 2, "FlexJoint") == str(folder / "binaries" / "linux64" / "FlexJoint.so")
    for platform in ("aarch64-linux", "aarch64-darwin"):
        name = "FlexJoint.so" if platform.endswith("linux") else "FlexJoint.dylib"
        assert library_path(folder, 2, "FlexJoint", platform) == str(folder / "binaries" / platform / name)
    assert library_path(folder, 2, "Other") is None  # not in the FMU: FMPy chooses and says what it missed
    # on an aarch64 Linux machine (platform.machine() says so) a run loads binaries/aarch64-linux
    monkeypatch.setattr(build._platform, "machine", lambda: "aarch64")
    aarch64 = str(folder / "binaries" / "aarch64-linux" / "FlexJoint.so")
    assert library_path(folder, 2, "FlexJoint") == aarch64
    scenario = tmp_path / "arm.toml"
    scenario.write_text(
        '[simulation]\nduration = 0.01\nstep = 1e-3\n[robot]\nmodel = "arm"\n[joints.j1]\n'
        "coefficients = { k = 330, c = 0.83 }\n"
    )
    with pytest.raises(Exception, match=r"binaries/aarch64-linux/FlexJoint\.so"):  # an x86_64 machine
        cosim.run(cosim.load(scenario))
    monkeypatch.undo()
    found, missing, _ = hosts
    if "qemu" not in found or "native" not in found:
        pytest.skip(missing.get("qemu") or missing["native"])
    location = next(iter(_locations(2, folder / "resources", "posix").values()))
    native = _run(found["native"], folder, 2, "me", token, location, STEPS)
    emulated = _run(found["qemu"], folder, 2, "me", token, location, STEPS)
    assert np.all(np.abs(emulated - native) <= 1e-12 * np.max(np.abs(native)))
