"""A deadline for a block of test code, so that a hang fails the test instead of stalling the
suite (imported by name: pytest puts tests/ on sys.path).

No new dependency: ``SIGALRM`` (``signal.setitimer``) raises :class:`Hang` in Python code and
at the compiled core's interrupt checks, which run every few milliseconds of its work; a hard
backstop, ``faulthandler.dump_traceback_later``, ends the whole process with every thread's
traceback if even that cannot get through (a compiled loop that never checks), so the suite
fails loudly rather than hanging.
"""

from __future__ import annotations

import contextlib
import faulthandler
import signal
import sys
import threading


class Hang(BaseException):
    """The block ran past its deadline (a BaseException, so that no ``except Exception`` in
    the code under test can swallow it)."""


@contextlib.contextmanager
def deadline(seconds: float, what: str = "the call"):
    """Run the block within ``seconds`` of wall-clock time, or raise :class:`Hang`."""
    if threading.current_thread() is not threading.main_thread():  # pragma: no cover
        yield
        return

    def expired(signum, frame):
        raise Hang(f"{what} ran longer than {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expired)
    outer = signal.setitimer(signal.ITIMER_REAL, seconds)
    faulthandler.dump_traceback_later(3 * seconds + 30, exit=True, file=sys.__stderr__)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        faulthandler.cancel_dump_traceback_later()
        signal.signal(signal.SIGALRM, previous)
        if outer[0]:  # an enclosing deadline keeps running
            signal.setitimer(signal.ITIMER_REAL, outer[0])
