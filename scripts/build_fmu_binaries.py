"""Rebuild the FMU binaries the package ships, after a change to fmus/ (needs the `build` extra: Zig).

    python scripts/build_fmu_binaries.py            # into fmus/binaries/, then commit them
    python scripts/build_fmu_binaries.py /tmp/out   # elsewhere, e.g. to compare

tests/test_fmu_prebuilt.py rebuilds them the same way and fails when the committed ones drift.
"""

import sys
import time

from designer.export import prebuilt


def main() -> int:
    start = time.perf_counter()
    folder = prebuilt.build_all(
        sys.argv[1] if len(sys.argv) > 1 else None,
        progress=lambda what: print(f"building {what}", flush=True),
    )
    print(f"wrote {folder} in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
