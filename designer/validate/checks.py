"""The framework of `designer validate`: a check is a function of a `Context` returning a `CheckResult`.

One module per subsystem (`designer.validate.study`, `designer.validate.stats`,
`designer.validate.model`, `designer.validate.export`, `designer.validate.rig`, `designer.validate.cosim`)
and shares its fixtures with the tests; `run_checks` runs them and `designer.validate.report` renders them.
"""

from __future__ import annotations

import importlib
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:
    import pandas as pd


@dataclass
class CheckResult:
    """The verdict of one check and the evidence for it: a table of numbers and figures."""

    name: str
    passed: bool
    summary: str
    table: pd.DataFrame | None = None
    figures: list[Path] = field(default_factory=list)
    seconds: float = 0.0

    def to_dict(self) -> dict[str, Any]:
        return {
            "name": self.name,
            "passed": self.passed,
            "summary": self.summary,
            "table": None if self.table is None else self.table.to_dict(orient="records"),
            "figures": [str(p) for p in self.figures],
            "seconds": self.seconds,
        }


@dataclass
class Context:
    """What the checks share: the coefficient table, where figures go, the surrogate (made once)."""

    table: pd.DataFrame
    figures: Path
    source: str = "bundled study table"
    _surrogate: Any = None

    @property
    def surrogate(self) -> Any:
        """The shipped surrogate when it was fitted to this table, else one fitted to it now."""
        if self._surrogate is None:
            from ..model.surrogate import Surrogate
            from ..study.data import table_hash

            sur = Surrogate.load()
            if sur.table_hash != table_hash(self.table):
                sur = Surrogate().fit(self.table)
            self._surrogate = sur
        return self._surrogate


Check = Callable[[Context], CheckResult]

#: the checks `designer validate` runs, in report order: (module, function)
CHECKS: tuple[tuple[str, str], ...] = (
    ("designer.validate.study", "check_dataset"),
    ("designer.validate.stats", "check_table4"),
    ("designer.validate.stats", "check_main_effects"),
    ("designer.validate.model", "check_surrogate_loo"),
    ("designer.validate.export", "check_fmus"),
    ("designer.validate.export", "check_mjcf_into"),
    ("designer.validate.export", "check_ssp"),
    ("designer.validate.rig", "check_identification"),
    ("designer.validate.cosim", "check_cosim"),
)


def default_checks() -> list[Check]:
    """The check functions of CHECKS, imported now."""
    return [getattr(importlib.import_module(module), name) for module, name in CHECKS]


def title(check: Check) -> str:
    """A check's name for a report when it could not produce its own."""
    return check.__name__.removeprefix("check_").replace("_", " ").capitalize()


def run_checks(
    ctx: Context,
    checks: Sequence[Check] | None = None,
    *,
    progress: Callable[[float], None] | None = None,
) -> list[CheckResult]:
    """Run each check (default: all of CHECKS), timing it.

    A check that raises anything (a DesignerError, or a fault in a library it drives) fails with
    the error as its summary; the other checks still run. Ctrl-C still stops the run.
    """
    checks = default_checks() if checks is None else list(checks)
    results = []
    for i, check in enumerate(checks):
        start = time.perf_counter()
        try:
            result = check(ctx)
        except Exception as exc:  # noqa: BLE001 - a crashing check is a failed check, not an aborted report
            result = CheckResult(title(check), False, f"could not run: {type(exc).__name__}: {exc}")
        result.seconds = time.perf_counter() - start
        results.append(result)
        if progress is not None:
            progress((i + 1) / len(checks))
    return results
