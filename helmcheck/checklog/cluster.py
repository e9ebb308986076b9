"""The per-file tasks of an archive check on a Dask distributed scheduler (``--cluster``).

This module owns talking to a cluster: the scheduler's address, the connection, submitting
:func:`~.fleettask.judge_file` once per file and collecting the answers as they come. The task is
the one the local pool runs, with the same arguments, so the results are the same bytes.

* ``distributed`` is an optional extra (``pip install 'helmcheck[cluster]'``); without it
  ``--cluster`` is a usage error naming the extra (exit 64).
* The address is ``tcp://HOST:PORT`` (or ``tls://HOST:PORT``); anything else is a usage error. A
  scheduler that cannot be reached within :data:`CONNECT_TIMEOUT_S` is a path failure (exit 64,
  like a port that cannot be opened): nothing is judged.
* The workers must see the archive, the report directory and the missions directory at the same
  paths as this machine (a shared file system), and run the same helmcheck version (a worker on
  another version answers ``error`` for each file instead of judging it).
* Each task is submitted with ``pure=False`` (judging has the side effect of writing the results
  directory) and ``retries=0``; a task whose worker dies is reported ``error``.
* An interruption cancels the tasks not yet finished and closes the connection. A task already
  running on a worker finishes there (Dask does not stop a running task): it writes a complete
  results directory, key last, which the summary of this run lists as not judged and the next
  run finds cached.
"""

from __future__ import annotations

import uuid
from typing import Any, Callable, Sequence
from urllib.parse import urlsplit

from ..failures import PathError, UsageError
from .fleettask import FileTask, Options, judge_file

__all__ = ["run_on_cluster", "check_address", "require_distributed", "CONNECT_TIMEOUT_S", "EXTRA_HINT"]

CONNECT_TIMEOUT_S = 10
EXTRA_HINT = "pip install 'helmcheck[cluster]'"


def require_distributed() -> None:
    """``UsageError`` naming the extra when Dask distributed is not installed."""
    try:
        import distributed  # noqa: F401
    except ImportError:
        raise UsageError(f"--cluster needs Dask distributed, the optional extra 'cluster': {EXTRA_HINT}") from None


def check_address(url: str) -> str:
    """The scheduler address, checked: ``tcp://HOST:PORT`` or ``tls://HOST:PORT``."""
    try:
        parts = urlsplit(url)
        port = parts.port
    except ValueError:
        port = None
        parts = None
    if (parts is None or parts.scheme not in ("tcp", "tls") or not parts.hostname or port is None
            or parts.path not in ("", "/") or parts.query or parts.fragment):
        raise UsageError(f"--cluster {url}: not a scheduler address; expected tcp://HOST:PORT "
                         f"(e.g. tcp://10.0.0.5:8786)")
    return f"{parts.scheme}://{parts.netloc}"


def run_on_cluster(url: str, tasks: Sequence[FileTask], opts: Options,
                   done: Callable[[dict[str, Any]], None]) -> None:
    """Every task on the scheduler at ``url``; ``done(entry)`` as each finishes."""
    address = check_address(url)
    require_distributed()
    from distributed import Client, as_completed

    try:
        client = Client(address, timeout=CONNECT_TIMEOUT_S, set_as_default=False)
    except (OSError, TimeoutError) as e:
        raise PathError(f"--cluster: cannot connect to the scheduler at {address}: {e}") from None
    futures: dict = {}
    try:
        run = uuid.uuid4().hex  # a key of its own: the scheduler never hands back an earlier run's answer
        for i, t in enumerate(tasks):
            fut = client.submit(judge_file, t, opts, pure=False, retries=0, key=f"helmcheck-check-{run}-{i}")
            futures[fut] = t
        for fut in as_completed(list(futures), loop=client.loop):
            task = futures[fut]
            try:
                entry = fut.result()
            except Exception as e:  # noqa: BLE001 - a worker lost, or the task could not run there
                entry = {"path": task.rel, "status": "error",
                         "message": f"cluster: the task failed: {type(e).__name__}: {e}"}
            done(entry)
    except BaseException:
        if futures:
            try:
                client.cancel(list(futures))
            except Exception:  # noqa: BLE001 - the connection may be gone already
                pass
        raise
    finally:
        client.close()
