"""Design sweeps: many co-simulations of one scenario (grid, suggestion candidates, Monte Carlo over the
surrogate's prediction intervals) on local processes or Dask, one results table, and task-level tuning."""

from .cases import MAX_CASES, Case, check_size, make_cases
from .limits import Limit, parse_limit
from .run import SweepResult, run
from .spec import Cases, Spec, load
from .summary import write_results

__all__ = [
    "MAX_CASES",
    "Case",
    "Cases",
    "Limit",
    "Spec",
    "SweepResult",
    "check_size",
    "load",
    "make_cases",
    "parse_limit",
    "run",
    "write_results",
]
