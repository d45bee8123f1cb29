"""Resource limits checked before a large allocation: estimate the memory a run needs and refuse early.

A run that cannot fit is refused with its estimate instead of failing with a MemoryError (or the
machine swapping) minutes in.
"""

from __future__ import annotations

import os

from .errors import DesignerError
from .files import format_bytes

# share of the available memory one run may plan to use (the rest: the interpreter, other programs)
MEMORY_SHARE = 0.8


def available_memory() -> int:
    """Bytes of memory available to a new allocation (Linux MemAvailable; else free physical pages)."""
    try:
        with open("/proc/meminfo") as fh:
            for line in fh:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    try:
        return os.sysconf("SC_AVPHYS_PAGES") * os.sysconf("SC_PAGE_SIZE")
    except (ValueError, OSError, AttributeError):
        return 1 << 62  # unknown: do not refuse


def check_memory(estimate_bytes: float, *, what: str, fix: str) -> None:
    """Refuse `what` when its estimated peak memory exceeds the share of the available memory it may use.

    Args:
        estimate_bytes: the run's estimated peak memory, bytes.
        what: the run, for the message, e.g. "a 1e+09 s rig log at 1000 Hz".
        fix: how to make the run smaller.

    Raises:
        DesignerError: "a 1e+09 s rig log at 1000 Hz needs about 1.1e+02 TiB of memory, 12 GiB available".
    """
    available = available_memory()
    if estimate_bytes > MEMORY_SHARE * available:
        raise DesignerError(
            f"{what} needs about {format_bytes(estimate_bytes)} of memory, "
            f"{format_bytes(available)} available",
            fix,
        )
