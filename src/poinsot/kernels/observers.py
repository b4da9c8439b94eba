"""Observers: what a driver records of every step without storing the trajectory.

An observer is a named tuple of arrays that the drivers update after each step through
``observe(observer, lane, t0, y0, t1, y1)`` (the member ``lane`` went from ``y0`` at ``t0`` to
``y1`` at ``t1``; the states are arrays or tuples in the engine's principal frame). The default,
:data:`NoObserver`, compiles to nothing.

:data:`FlipObserver` counts the flips of the tennis-racket (Dzhanibekov) motion: the sign
changes of ω along the intermediate principal axis (component 1 of the principal frame, moments
ascending), with the crossing time interpolated linearly within the step (an error O(h²)).
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

from .jit import generic, kernel
from .layout import OMEGA_AT

__all__ = ["FlipObserver", "NoObserver", "flip_observer", "observe"]

#: Records nothing.
NoObserver = namedtuple("NoObserver", ["nothing"])
#: Per member: ``first`` and ``last`` flip times (NaN before a flip) and ``count``; lane ``i``
#: of the system observed is member ``i + offset`` (an ensemble's block of members).
FlipObserver = namedtuple("FlipObserver", ["first", "last", "count", "offset"])


def flip_observer(n: int):
    """A :data:`FlipObserver` for ``n`` members, with no flip recorded."""
    return FlipObserver(np.full(n, np.nan), np.full(n, np.nan), np.zeros(n), 0)


@generic
def observe(observer, lane, t0, y0, t1, y1):
    """Record what ``observer`` wants of member ``lane``'s step from ``(t0, y0)`` to
    ``(t1, y1)``."""


@observe.register(NoObserver)
@kernel(inline=True)
def _observe_nothing(observer, lane, t0, y0, t1, y1):
    return None


@observe.register(FlipObserver)
@kernel(inline=True)
def _observe_flips(observer, lane, t0, y0, t1, y1):
    a = y0[OMEGA_AT + 1]
    b = y1[OMEGA_AT + 1]
    if (a < 0.0 and b >= 0.0) or (a > 0.0 and b <= 0.0):
        t = t0 + (t1 - t0) * a / (a - b)
        k = lane + observer.offset
        if observer.count[k] == 0.0:
            observer.first[k] = t
        observer.last[k] = t
        observer.count[k] += 1.0
    return None
