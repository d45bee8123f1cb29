"""Build the FMU binaries the package ships (`python scripts/build_fmu_binaries.py [FOLDER]` runs it).

Ten binaries (FMI 2 and 3 for each of build.PLATFORMS) compiled with Zig from the C sources, with
fixed flags and relative paths (no timestamps, no machine paths, stripped), into
`FOLDER/fmi{2,3}/<platform>/FlexJoint.<so|dll|dylib>`, and `FOLDER/SOURCES.sha256` recording
build.sources_hash() and the Zig version. FOLDER defaults to the `binaries/` folder beside the sources,
which is what a checkout commits and a wheel carries; tests build into a temporary folder and compare.
"""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Callable
from pathlib import Path

from ..files import atomic_path
from . import build


def zig_version() -> str:
    """The version of the installed ziglang package's compiler."""
    done = subprocess.run([sys.executable, "-m", "ziglang", "version"], capture_output=True, text=True)
    return done.stdout.strip()


def build_all(folder: str | Path | None = None, *, progress: Callable[[str], None] | None = None) -> Path:
    """Compile all ten shipped binaries with Zig into `folder` (default: source_dir()/binaries).

    Raises:
        DesignerError: if ziglang is not installed or a compilation fails.
    """
    folder = Path(folder) if folder is not None else build.source_dir() / "binaries"
    for fmi_version in (2, 3):
        for platform in build.PLATFORMS:
            if progress:
                progress(f"FMI {fmi_version} {platform}")
            compiler, extra = build.platform_compiler(platform, zig=True)
            out = folder / f"fmi{fmi_version}" / platform / build.library_name(platform)
            out.parent.mkdir(parents=True, exist_ok=True)
            with atomic_path(out) as tmp:
                build.compile_binary(fmi_version, platform, compiler, extra, tmp)
    with atomic_path(folder / "SOURCES.sha256") as tmp:
        tmp.write_text(f"{build.sources_hash()}  zig {zig_version()}\n")
    return folder
