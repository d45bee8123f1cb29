"""A bounded store of computed arrays, kept on the object they are derived from.

The design loop recalibrates one study surface hundreds of times on the same designs with other
imagined measurements (`designer.design.next_prints`): what depends on the designs only (the solved
covariance at the runs, the predictive terms at a batch of candidates) is computed once and read
back, the same arrays, so results do not change. A store holds at most BUDGET bytes and is emptied
when full, so a session that calibrates large tables again and again does not grow without bound.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable
from typing import Any

import numpy as np

#: bytes one store may hold; a result larger than a sixteenth of it is computed but not kept
BUDGET = 64 << 20


class Memo:
    """Results by key, up to `budget` bytes of arrays."""

    def __init__(self, budget: int = BUDGET) -> None:
        self.budget = budget
        self.items: dict[Hashable, tuple[Any, ...]] = {}
        self.held = 0

    def __reduce__(self) -> tuple[type, tuple[int]]:
        """A copy (copy, deepcopy, pickle) starts empty: the store is a cache, not the surface's data."""
        return Memo, (self.budget,)

    def get(self, key: Hashable, make: Callable[[], tuple[Any, ...]]) -> tuple[Any, ...]:
        """The result kept for `key`, else `make()` (kept when it fits)."""
        found = self.items.get(key)
        if found is not None:
            return found
        value = make()
        size = sum(v.nbytes for v in value if isinstance(v, np.ndarray))
        if size <= self.budget // 16:
            if self.held + size > self.budget:
                self.items.clear()
                self.held = 0
            self.items[key] = value
            self.held += size
        return value


def memo_of(owner: Any, name: str) -> Memo:
    """The store `name` kept on `owner` (created empty on first use)."""
    return owner.__dict__.setdefault(name, Memo())


def array_key(*arrays: Any) -> tuple[Any, ...]:
    """A hashable key of arrays' shapes and values (float64, as the calibration computes with)."""
    out = []
    for a in arrays:
        a = np.asarray(a, dtype=float)
        out += [a.shape, a.tobytes()]
    return tuple(out)
