"""Design sweeps: many co-simulations of one scenario (grid, suggestion candidates, Monte Carlo over the
surrogate's prediction intervals) on local processes or Dask, one results table, and task-level tuning."""

from .cases import Case, make_cases
from .limits import Limit, parse_limit
from .run import SweepResult, run
from .spec import Cases, Spec, load
from .summary import write_results

__all__ = [
    "Case",
    "Cases",
    "Limit",
    "Spec",
    "SweepResult",
    "load",
    "make_cases",
    "parse_limit",
    "run",
    "write_results",
]
