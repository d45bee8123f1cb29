"""Random FMI 2 and FMI 3 call sequences (tests/fuzz/fmi_fuzz.c) against the runtime built with
AddressSanitizer + UBSan, and under valgrind: no report, no crash, no leak. Bounded for CI; a longer
run is `fmi_fuzz SEED CALLS ...` by hand (see the harness's header)."""

from __future__ import annotations

import shutil
import subprocess
import zipfile
from pathlib import Path
from xml.etree import ElementTree

import pytest

from designer.export import build
from designer.export.fmu import export_fmu
from designer.joint import Joint

HARNESS = Path(__file__).parent / "fuzz" / "fmi_fuzz.c"
CI_CALLS = 300_000  # per seed, two seeds: about 4 s with the sanitizers
VALGRIND_CALLS = 20_000


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    """The four exports (FMI 2/3 x force/body) unpacked, and the harness's arguments."""
    if shutil.which("cc") is None:
        pytest.skip("no C compiler")
    d = tmp_path_factory.mktemp("fuzz")
    mp = pytest.MonkeyPatch()
    mp.setenv("XDG_CACHE_HOME", str(d / "cache"))
    joint = Joint.from_coefficients(
        {"x": {"k": 0.8, "c": 2e-3, "m": 0.01}, "theta": {"k": 300, "c": 0.8, "m": 2e-6}}
    )
    args = []
    for version in (2, 3):
        for interface in ("force", "body"):
            u = d / f"u{version}{interface}"
            with zipfile.ZipFile(export_fmu(joint, d / f"{u.name}.fmu", version, interface)) as z:
                z.extractall(u)
            root = ElementTree.parse(u / "modelDescription.xml").getroot()
            location = (u / "resources").as_uri() if version == 2 else f"{u / 'resources'}/"
            args += [location, root.get("guid") or root.get("instantiationToken")]
    mp.undo()
    sources = [d / "u2body" / "sources" / Path(c).name for c in build.c_sources(2)]
    sources.append(d / "u3body" / "sources" / "fmi3Functions.c")
    includes = [f"-I{d / 'u2body' / 'sources'}", f"-I{d / 'u3body' / 'sources'}"]
    return d, [*includes, str(HARNESS), *map(str, sources)], args


def _compile(setup, name: str, flags: list[str]) -> Path:
    d, files, _ = setup
    exe = d / name
    done = subprocess.run(
        ["cc", "-std=gnu99", "-g", "-O1", *flags, *files, "-o", str(exe), "-lm"],
        capture_output=True,
        text=True,
    )
    if done.returncode != 0 and flags:
        pytest.skip(f"the compiler cannot build with {' '.join(flags)}: {done.stderr[-300:]}")
    assert done.returncode == 0, done.stderr
    return exe


@pytest.fixture(scope="module")
def asan(setup):
    return _compile(setup, "fuzz_asan", ["-fsanitize=address,undefined", "-fno-sanitize-recover=all"])


@pytest.mark.parametrize("seed", [1, 2])
def test_fuzzed_call_sequences_are_clean_under_asan_and_ubsan(setup, asan, seed):
    exe = asan
    done = subprocess.run([str(exe), str(seed), str(CI_CALLS), *setup[2]], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr[-3000:]
    assert "runtime error" not in done.stderr and "AddressSanitizer" not in done.stderr
    words = done.stdout.split()
    calls, logs = int(words[0]), int(words[2])
    assert calls >= CI_CALLS and logs > CI_CALLS // 10  # the errors were logged, so the FMUs were exercised


def test_both_fmi_layers_are_clean_under_valgrind(setup):
    if shutil.which("valgrind") is None:
        pytest.skip("valgrind not installed (.ci/run installs it)")
    exe = _compile(setup, "fuzz_plain", [])
    cmd = [
        "valgrind",
        "-q",
        "--error-exitcode=9",
        "--leak-check=full",
        "--errors-for-leak-kinds=definite,indirect",
    ]
    done = subprocess.run(
        [*cmd, str(exe), "3", str(VALGRIND_CALLS), *setup[2]], capture_output=True, text=True
    )
    assert done.returncode == 0, done.stderr[-3000:]
