"""The threads a run may use: the CPUs this process may run on, for every kind of ensemble
(rigid bodies, constrained systems) that spreads its members over the compiled core's pool."""

from __future__ import annotations

import os

__all__ = ["available_cpus"]


def available_cpus() -> int:
    """The CPUs this process may run on.

    >>> available_cpus() >= 1
    True
    """
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # pragma: no cover - macOS, Windows
        return os.cpu_count() or 1
