"""The memory a run may take: what this machine has available now, read once per check, so
that a run that would not fit is refused with its estimate instead of running out of memory
(docs/reliability.md, "A bounded cost")."""

from __future__ import annotations

import os

__all__ = ["available_memory", "format_bytes"]


def available_memory() -> int | None:
    """Bytes of memory this process could take now without swapping: Linux's
    ``MemAvailable``, else the free physical pages; None where neither is known.

    >>> m = available_memory()
    >>> m is None or m > 0
    True
    """
    try:
        with open("/proc/meminfo", encoding="ascii") as f:
            for line in f:
                if line.startswith("MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:  # pragma: no cover - macOS and other Unixes
        return int(os.sysconf("SC_AVPHYS_PAGES")) * int(os.sysconf("SC_PAGE_SIZE"))
    except (ValueError, OSError, AttributeError):  # pragma: no cover - Windows
        return None


def format_bytes(n: float) -> str:
    """A size for a message: ``"9 GB"``, ``"12.5 MB"``, ``"800 B"`` (powers of 1000).

    >>> format_bytes(9.0e9), format_bytes(12_500_000), format_bytes(800)
    ('9 GB', '12.5 MB', '800 B')
    """
    for unit, size in (("TB", 1e12), ("GB", 1e9), ("MB", 1e6), ("kB", 1e3)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{n:.0f} B"
