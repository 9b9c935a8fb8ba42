"""Exceptions of masonryfw.

Every error a user can cause derives from :class:`MasonryError`; the CLI turns
it into a message and exit code 1 without a traceback.
"""
from __future__ import annotations


class MasonryError(Exception):
    """Base class of every error caused by bad input or a failed solve."""


class SpecError(MasonryError):
    """A builder spec is invalid; the message names the key and the value."""


class ModelError(MasonryError):
    """A model or result dataset is invalid.

    ``problems`` holds every problem found (see :class:`masonryfw.format.checks.Problem`),
    not only the first.
    """

    def __init__(self, message: str, problems: list | None = None):
        self.problems = list(problems or [])
        if self.problems:
            message = message + "\n" + "\n".join(f"  - {p}" for p in self.problems)
        super().__init__(message)


class PluginError(MasonryError):
    """A plugin, solver, comparator or option is unknown, duplicated or invalid."""


class SolveError(MasonryError):
    """A solver ran but could not produce a result (infeasible, diverged, ...)."""


class Interrupted(MasonryError):
    """Ctrl-C (or SIGTERM) stopped a command; the message says what was kept. The CLI exits with 130
    (143 after SIGTERM)."""


def listed(indices, limit: int = 20) -> str:
    """``"12, 13 and 5 more"``: the first ``limit`` indices of a message, then how many more."""
    items = [str(int(i)) for i in indices]
    more = len(items) - limit
    return ", ".join(items[:limit]) + (f" and {more} more" if more > 0 else "")
