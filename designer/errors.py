"""The one exception type the CLI turns into a one-line message and exit code 2."""

from __future__ import annotations


class DesignerError(ValueError):
    """Bad input or an impossible request: the message names the problem and the fix."""

    def __init__(self, problem: str, fix: str | None = None) -> None:
        self.problem = problem
        self.fix = fix
        super().__init__(f"{problem} ({fix})" if fix else problem)
