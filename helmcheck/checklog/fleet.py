"""Running an archive's per-file tasks: in this process, in a pool of processes, or on a cluster.

This module owns how the :func:`~.fleettask.judge_file` tasks of one archive check are run and
their entries collected: :func:`run_tasks` calls ``on_done(entry)`` for each file as it
finishes, in completion order (the summary sorts them by path, so nothing downstream depends on
that order), and returns every entry.

* ``jobs == 1``: one after another in this process.
* ``jobs > 1``: a :class:`concurrent.futures.ProcessPoolExecutor` of that many worker processes
  (forked: a worker does not re-import the caller's main script), each judging one file at a
  time, the largest files first (so a long log started last does not leave the other workers
  idle at the end). The workers ignore SIGINT, SIGTERM and SIGHUP: Ctrl-C at a terminal reaches
  the whole process group, and only this process decides what an interruption means. A worker
  that dies without an answer (killed, out of memory) leaves its files ``error`` and the others
  go on in a new pool.
* ``cluster`` (``tcp://HOST:PORT``): the same tasks on a Dask distributed scheduler
  (:mod:`.cluster`).

An interruption (:class:`KeyboardInterrupt`, which SIGTERM and SIGHUP raise too,
:mod:`helmcheck.signals`) stops the run at once: files not finished get no entry, the workers
are ended, and :class:`Stopped` carries the entries of the files that did finish (their results
directories are complete: a directory is only ever left without its ``check-key.json``, so it
is judged again next time).
"""

from __future__ import annotations

import multiprocessing
import signal
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from typing import Any, Callable, Optional, Sequence

from .fleettask import FileTask, Options, judge_file

__all__ = ["run_tasks", "Stopped"]

OnDone = Callable[[dict[str, Any]], None]


class Stopped(KeyboardInterrupt):
    """The run was interrupted; ``entries`` are those of the files that finished."""

    def __init__(self, entries: list[dict[str, Any]], cause: BaseException):
        super().__init__(str(cause))
        self.entries = entries
        self.cause = cause


def run_tasks(tasks: Sequence[FileTask], opts: Options, *, jobs: int = 1, cluster: Optional[str] = None,
              on_done: OnDone = lambda e: None, sizes: Optional[Sequence[int]] = None) -> list[dict[str, Any]]:
    """Run every task (module docstring); ``sizes`` (bytes, one per task) orders them largest first."""
    order = list(tasks)
    if sizes is not None:
        by_size = dict(zip((t.rel for t in tasks), sizes))
        order.sort(key=lambda t: -by_size[t.rel])
    entries: list[dict[str, Any]] = []

    def done(entry: dict[str, Any]) -> None:
        entries.append(entry)
        on_done(entry)

    try:
        if cluster is not None:
            from .cluster import run_on_cluster
            run_on_cluster(cluster, order, opts, done)
        elif jobs <= 1 or len(order) <= 1:
            for t in order:
                done(judge_file(t, opts))
        else:
            _run_pool(order, opts, jobs, done)
    except KeyboardInterrupt as e:
        raise Stopped(entries, e) from None
    return entries


def _quiet_worker() -> None:
    for name in ("SIGINT", "SIGTERM", "SIGHUP"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_IGN)


def _run_pool(tasks: list[FileTask], opts: Options, jobs: int, done: OnDone) -> None:
    pending = list(tasks)
    tries: dict[str, int] = {}
    while pending:
        others = {p.pid for p in multiprocessing.active_children()}
        pool = ProcessPoolExecutor(max_workers=min(jobs, len(pending)), initializer=_quiet_worker,
                                   mp_context=multiprocessing.get_context("fork"))
        try:
            futures = {pool.submit(judge_file, t, opts): t for t in pending}
            pending = []
            waiting = set(futures)
            while waiting:
                finished, waiting = wait(waiting, return_when=FIRST_COMPLETED)
                for fut in finished:
                    task = futures[fut]
                    try:
                        entry = fut.result()
                    except BrokenProcessPool:  # a worker died: the files not finished go to a new pool once
                        tries[task.rel] = tries.get(task.rel, 0) + 1
                        if tries[task.rel] < 2:
                            pending.append(task)
                            continue
                        entry = {"path": task.rel, "status": "error",
                                 "message": "the worker process judging it ended without an answer (killed?)"}
                    done(entry)
            pool.shutdown(wait=True)
        except BaseException:
            _kill(pool, others)
            raise


def _kill(pool: ProcessPoolExecutor, others: set) -> None:
    """End the pool's workers now (a worker in the middle of a file is not waited for); ``others``
    are the child processes that were there before the pool, left alone."""
    workers = [p for p in multiprocessing.active_children() if p.pid not in others]
    pool.shutdown(wait=False, cancel_futures=True)
    for proc in workers:
        proc.kill()
    for proc in workers:
        proc.join(timeout=5)
