"""How the ``poinsot`` command stops: Ctrl-C, SIGTERM and ``--time-limit``, at any moment.

The rule (``docs/reliability.md``): SIGINT and SIGTERM end the command with exit code 130 or
143 within a second, without a traceback, and leave nothing half-written; ``--time-limit``
ends it the same way with exit code 1, saying how far the run got. Four mechanisms make it hold
wherever the signal lands:

* **The handler comes first.** :func:`guard` installs the handlers as the first thing the
  command does, before the heavy imports (NumPy, SciPy, SymPy, matplotlib). The first signal
  raises :class:`KeyboardInterrupt` (:class:`Terminated` for SIGTERM, :class:`TimeLimitReached`
  for the time limit) where the program is; the compiled core checks for it every few
  milliseconds of its work. The clean-up that follows (removing the unfinished output folder)
  is not cut short by later signals.
* **A swallowed interrupt is raised again.** Library code that runs in weak-reference
  callbacks, destructors and the like cannot pass an exception on: Python prints
  ``Exception ignored in: …`` and goes on (matplotlib, during figure writing, ignored
  Ctrl-C this way). :func:`guard`'s ``sys.unraisablehook`` recognises the interrupt, says
  nothing, and delivers the signal again, until it lands in code that passes it on.
* **Atomic moves are held together.** The moves that complete an output folder run in
  :func:`poinsot._io.critical`, which holds a signal back until they are done.
* **A watchdog.** In the command's own process a thread wakes on the signal (through
  :func:`signal.set_wakeup_fd`, which the interpreter writes from its C-level handler, even
  while the main thread is busy in compiled code). If the program has not ended
  :data:`GRACE` seconds later, the watchdog removes what is being written
  (:func:`poinsot._io.emergency_cleanup`), prints the message and ends the process.

After the command has finished, a late signal ends the process at once with its code (the
output, if any, is complete by then).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading
import time

__all__ = ["GRACE", "Guard", "Terminated", "TimeLimitReached", "flush_streams", "guard"]

#: Seconds the watchdog lets the program end on its own after a signal.
GRACE = 0.6


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised where the program is, so that the same clean-up as Ctrl-C runs."""


class TimeLimitReached(KeyboardInterrupt):
    """The wall-clock budget of ``--time-limit`` is spent."""


def left_on_disk(written) -> str:
    """What a command that stopped early left on disk: its output folder ``written`` when it
    had been written in full before (a command sets ``args.written`` once it is), else
    nothing (an unfinished output folder is always removed)."""
    if written is not None:
        return f"the output folder {written}/ had been written in full before it"
    return "no partial output was left"


def _exit_code(signum: int) -> int:
    if signum == signal.SIGINT:
        return 130
    if signum == signal.SIGTERM:
        return 143
    return 1  # the time limit: a run that did not finish


class Guard:
    """The command's signal handling (see the module); made and installed by :func:`guard`.

    Attributes
    ----------
    signum : int or None
        The first signal received (SIGINT, SIGTERM, or SIGALRM for the time limit).
    stage : str
        What the command is doing, for the time limit's message ("simulating", …).
    progress : str
        How far that stage got (``"t = 3.2 s of [0, 20] s (16 %)"``), or "".
    """

    def __init__(self, *, process: bool, time_limit: float | None = None):
        self.process = process
        self.time_limit = time_limit
        #: the command's arguments, whose ``written`` names its output folder once complete
        self.args = None
        self.signum: int | None = None
        self.stage = "starting"
        self.progress = ""
        self._raised = False
        self._in_hook = False  # inside `_unraisable`, which delivers the signal again
        self._finished = False
        self._previous: dict = {}
        self._hook = None
        self._done = threading.Event()
        self._wakeup = None

    # ----------------------------------------------------------------- what is going on
    def at(self, stage: str, progress: str = "") -> None:
        """Record the stage the command is in (and how far it got)."""
        self.stage, self.progress = stage, progress

    def message(self) -> str:
        """What the command says when a signal or the time limit ends it."""
        left = left_on_disk(getattr(self.args, "written", None))
        if self.signum == signal.SIGTERM:
            return f"poinsot: terminated; {left}"
        if self.signum == signal.SIGINT or self.signum is None:
            return f"poinsot: interrupted; {left}"
        where = self.stage + (f": {self.progress}" if self.progress else "")
        return f"poinsot: time limit of {self.time_limit:g} s reached while {where}; {left}"

    @property
    def exit_code(self) -> int:
        return 130 if self.signum is None else _exit_code(self.signum)

    # ----------------------------------------------------------------- the handlers
    def _handler(self, signum, frame):
        if self._finished:  # the command is done: its output is whole; end now
            flush_streams()
            os._exit(_exit_code(signum))
        if self.signum is None:
            self.signum = signum
        if self._in_hook:
            # the delivery again landed before the hook that made it returned (a loaded
            # machine): raised here, Python would only print it; deliver it once more
            self._deliver_again()
            return
        if self._raised:  # the clean-up is under way: it is not cut short
            return
        self._raised = True
        if self.signum == signal.SIGTERM:
            raise Terminated
        if self.signum == getattr(signal, "SIGALRM", None):
            raise TimeLimitReached
        raise KeyboardInterrupt

    def _unraisable(self, unraisable):
        """An interrupt raised where Python can only print it (a weak-reference callback, a
        destructor): say nothing and deliver the signal again."""
        if self.signum is not None and isinstance(unraisable.exc_value, KeyboardInterrupt):
            self._in_hook = True
            try:
                self._raised = False
                self._deliver_again()
            finally:
                self._in_hook = False
            return
        (self._hook or sys.__unraisablehook__)(unraisable)

    def _deliver_again(self):
        """The signal delivered again from another thread, a moment later (raised in the
        hook, it would be swallowed again)."""
        import _thread

        threading.Timer(0.002, _thread.interrupt_main, (self.signum,)).start()

    def install(self) -> Guard:
        """Install the handlers (main thread only; elsewhere nothing is installed)."""
        if threading.current_thread() is not threading.main_thread():
            return self
        for sig in (signal.SIGINT, signal.SIGTERM):
            self._previous[sig] = signal.signal(sig, self._handler)
        self._hook, sys.unraisablehook = sys.unraisablehook, self._unraisable
        if self.process:
            self._start_watchdog()
        if self.time_limit is not None:
            self.limit(self.time_limit)
        return self

    def limit(self, seconds: float) -> None:
        """Give the command ``seconds`` of wall-clock time from now (SIGALRM)."""
        self.time_limit = seconds
        if not self._previous:  # not installed (not the main thread)
            return
        if signal.SIGALRM not in self._previous:
            self._previous[signal.SIGALRM] = signal.signal(signal.SIGALRM, self._handler)
        signal.setitimer(signal.ITIMER_REAL, seconds)

    def finish(self) -> None:
        """The command is done. In its own process, a later signal ends the process at once;
        called in-process (``main([...])``), the previous handlers come back."""
        self._done.set()
        if signal.SIGALRM in self._previous:
            signal.setitimer(signal.ITIMER_REAL, 0)
        if self.process:
            self._finished = True
            return
        for sig, handler in self._previous.items():
            signal.signal(sig, handler)
        self._previous.clear()
        if self._hook is not None:
            sys.unraisablehook = self._hook
            self._hook = None

    # ----------------------------------------------------------------- the watchdog
    def _start_watchdog(self) -> None:
        read, write = os.pipe()
        os.set_blocking(write, False)
        try:
            signal.set_wakeup_fd(write, warn_on_full_buffer=False)
        except (ValueError, OSError):  # pragma: no cover - not the main thread
            os.close(read)
            os.close(write)
            return
        self._wakeup = (read, write)
        threading.Thread(target=self._watch, args=(read,), name="poinsot-watchdog",
                         daemon=True).start()  # fmt: skip

    def _watch(self, read: int) -> None:
        from .._io import emergency_cleanup, in_critical

        ours = {signal.SIGINT, signal.SIGTERM, getattr(signal, "SIGALRM", -1)}
        signum = None
        while signum is None:
            try:
                data = os.read(read, 64)
            except OSError:  # pragma: no cover
                return
            if not data:  # pragma: no cover
                return
            signum = next((b for b in data if b in ours), None)
        deadline = time.monotonic() + GRACE
        while time.monotonic() < deadline or (in_critical() and time.monotonic() < deadline + 5):
            if self._done.wait(0.02):
                return
        # the program did not end in time (stuck in compiled code, or the interrupt was lost)
        if self.signum is None:
            self.signum = signum
        emergency_cleanup()
        try:
            os.write(2, (self.message() + "\n").encode())
        except OSError:  # pragma: no cover
            pass
        os._exit(self.exit_code)


def flush_streams() -> None:
    """Flush stdout and stderr, saying nothing if they are closed or broken."""
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):  # a closed or broken stream: nothing more to say
            stream.flush()


def guard(*, process: bool, time_limit: float | None = None) -> Guard:
    """A :class:`Guard` for one command, installed."""
    return Guard(process=process, time_limit=time_limit).install()
