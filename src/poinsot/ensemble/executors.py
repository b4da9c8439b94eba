"""Where an ensemble's chunks run: in this process, one after the other, each chunk's members
in parallel on the compiled core's threads; or on a Dask cluster; and the progress bar.

Chunks are produced lazily and at most a few per Dask worker are in flight, so the inputs of a
huge ensemble are never all cut at once. Results are handed to ``absorb`` in the order they
finish; each carries its member range, so the order does not matter.
"""

from __future__ import annotations

import sys
from collections import deque

from .._threads import available_cpus
from .tasks import run_chunk

__all__ = ["available_cpus", "check_client", "run_chunks"]

#: Chunks in flight per worker.
IN_FLIGHT = 2


def check_client(client):
    """``client`` must be a ``dask.distributed.Client`` (Dask is imported only here)."""
    try:
        from distributed import Client
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ValueError(
            "`client` needs dask.distributed, which is not installed (pip install "
            "'poinsot[distributed]')"
        ) from exc
    if not isinstance(client, Client):
        raise ValueError(
            f"`client` must be a dask.distributed.Client, found {type(client).__name__}"
        )
    return client


class _Progress:
    """tqdm over members when wanted; a callable ``(done, total)``; or nothing."""

    def __init__(self, progress, total, n_chunks):
        self.callback = None
        self.bar = None
        self.done = 0
        self.total = total
        if callable(progress) and not isinstance(progress, bool):
            self.callback = progress
            return
        asked = progress is True
        if progress is None:
            progress = n_chunks > 1 and sys.stderr.isatty()
        elif not isinstance(progress, bool):
            raise TypeError(f"`progress` must be a bool or a callable, found {progress!r}")
        if progress:
            try:
                from tqdm.auto import tqdm
            except ImportError as exc:  # the optional extra is missing
                if not asked:  # the bar was only a default: stay silent
                    return
                raise ValueError(
                    "`progress=True` draws a bar with tqdm, which is not installed (pip install "
                    "'poinsot[progress]'), or pass a callable (done, total)"
                ) from exc
            self.bar = tqdm(total=total, unit="member", unit_scale=True, desc="ensemble")

    def update(self, k):
        self.done += k
        if self.bar is not None:
            self.bar.update(k)
        if self.callback is not None:
            self.callback(self.done, self.total)

    def close(self):
        if self.bar is not None:
            self.bar.close()


def run_chunks(spec, tasks, total, chunk, absorb, *, threads=None, client=None, progress=None,
               views=None):  # fmt: skip
    """Run every :class:`~poinsot.ensemble.tasks.ChunkTask` of ``tasks`` (an iterator) and hand
    each output to ``absorb``. In this process, ``views(start, stop)`` (when given) says where
    a chunk writes its states in place."""
    if client is not None and threads is not None:
        raise ValueError("`threads` has no effect with `client`: the Dask workers run the "
                         "chunks (give each worker its threads when starting the cluster); "
                         "drop one of them")  # fmt: skip
    n_chunks = -(-total // chunk)
    bar = _Progress(progress, total, n_chunks)
    try:
        if client is not None:
            _run_dask(check_client(client), spec, tasks, absorb, bar)
            return
        if threads is not None and (not isinstance(threads, int) or threads < 1):
            raise ValueError(f"`threads` must be a positive integer, found {threads!r}")
        workers = threads or available_cpus()
        for task in tasks:
            out = run_chunk(spec, task, workers, views and views(task.start, task.stop))
            absorb(out)
            bar.update(out.stop - out.start)
    finally:
        bar.close()


def _pump(submit, tasks, workers, absorb, bar, next_done):
    """Keep ``IN_FLIGHT`` chunks per Dask worker running; absorb each as it finishes."""
    pending = set()
    queue = deque()
    for task in tasks:
        pending.add(submit(task))
        if len(pending) >= IN_FLIGHT * workers:
            for fut in next_done(pending):
                pending.discard(fut)
                queue.append(fut)
        while queue:
            out = queue.popleft().result()
            absorb(out)
            bar.update(out.stop - out.start)
    while pending:
        for fut in next_done(pending):
            pending.discard(fut)
            out = fut.result()
            absorb(out)
            bar.update(out.stop - out.start)


def _run_dask(client, spec, tasks, absorb, bar):
    """Chunks on the cluster's workers: the spec is scattered once, each task travels as
    arrays, the workers call the same compiled core (one thread per chunk: the cluster runs
    chunks side by side)."""
    from distributed import wait as dask_wait

    workers = max(1, len(client.scheduler_info().get("workers", {})))
    [spec_future] = client.scatter([spec], broadcast=True, hash=False)  # a fresh key per run

    def submit(task):
        return client.submit(run_chunk, spec_future, task, pure=False)

    _pump(submit, tasks, workers, absorb, bar,
          lambda fs: dask_wait(list(fs), return_when="FIRST_COMPLETED").done)  # fmt: skip
