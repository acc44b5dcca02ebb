"""Running independent tasks in this process or on Dask (``dask.distributed``).

:func:`run_tasks` maps a picklable function over a list of items and returns the results in
the items' order, whatever order they finish in:

- in-process (the default): one after the other;
- on a Dask ``LocalCluster`` of ``workers`` processes (one thread each) that it starts and
  stops itself;
- on an existing Dask cluster (``scheduler="tcp://HOST:PORT"``, started with ``dask
  scheduler`` and ``dask worker tcp://HOST:PORT``), or on a ``dask.distributed.Client`` the
  caller passes (then the caller owns it).

A worker that dies while running a task costs a retry on another worker (Dask reschedules
the tasks of a lost worker; ``distributed.scheduler.allowed-failures``, 3 by default), not a
result: a task that kills every worker it runs on becomes the result ``lost(item, message)``.
The limits in force here (``--limit``) are applied in the workers for each task, so a
distributed run refuses exactly what the serial run refuses. Ctrl-C cancels the tasks and
stops the cluster this module started.

Dask is an extra (``pip install 'obsdesign[distributed]'``); without it, asking for workers
is an :class:`InputError` that says how to install it (exit 2).
"""

from __future__ import annotations

import dataclasses
import functools
import logging
import numbers
import os
import time
import uuid
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from typing import Any, TypeVar

from obsdesign.errors import InputError, value_text

T = TypeVar("T")
R = TypeVar("R")

#: what to run to get Dask
INSTALL_HINT = (
    "Dask is not installed: pip install 'obsdesign[distributed]' "
    "(or pip install 'dask[distributed]'), or run without --workers/--scheduler"
)


#: the log level of Dask's "distributed" loggers here and in the workers obsdesign starts
QUIET = logging.CRITICAL


def dask_available() -> bool:
    """Whether ``dask.distributed`` can be imported."""
    try:
        import dask.distributed  # noqa: F401
    except ImportError:
        return False
    return True


def _require_dask() -> None:
    if not dask_available():
        raise InputError(INSTALL_HINT)


#: the most local worker processes ``--workers`` may start
MAX_LOCAL_WORKERS = max(64, 4 * (os.cpu_count() or 1))


#: the address schemes of dask.distributed's comm backends
SCHEMES = ("tcp", "tls", "inproc", "ucx", "ws", "wss")


def check_workers(workers: int | None, scheduler: str | None) -> None:
    """Refuse (exit 2) a bad ``--workers``/``--scheduler`` pair, or Dask missing, before any
    work starts."""
    if workers is not None and scheduler is not None:
        raise InputError("--workers and --scheduler exclude each other (a scheduler has its own)")
    if workers is not None and (
        isinstance(workers, bool) or not isinstance(workers, numbers.Integral)
    ):
        # workers='2' from the API: a bare TypeError (hostile-input trial, session 38)
        raise InputError(f"--workers: expected a whole number of processes, got {workers!r}")
    if scheduler is not None and not isinstance(scheduler, str):
        raise InputError(
            f"--scheduler: expected an address such as tcp://HOST:8786, got {scheduler!r}"
        )
    if workers is not None and workers < 1:
        raise InputError(
            f"--workers: expected a positive number of processes, got {value_text(workers)}"
        )
    if workers is not None and workers > MAX_LOCAL_WORKERS:
        # 100,000 local processes were still starting after 120 s (CLI fuzzer)
        raise InputError(
            f"--workers: {value_text(workers)} processes on this machine is above "
            f"{MAX_LOCAL_WORKERS} "
            f"(4 × its {os.cpu_count() or 1} CPUs, at least 64); for more, start a Dask "
            "cluster and give --scheduler"
        )
    if scheduler is not None and (
        "://" not in scheduler or scheduler.split("://", 1)[0] not in SCHEMES
    ):
        # junk://x reached distributed's "unknown address scheme" (exit 3; hostile-input
        # trial, session 24)
        raise InputError(
            f"--scheduler: expected an address such as tcp://HOST:8786 (schemes: "
            f"{', '.join(SCHEMES)}), got {scheduler!r}"
        )
    if scheduler is not None:
        _check_port(scheduler)
    if workers is not None:
        try:
            os.getcwd()
        except FileNotFoundError:
            # the Nanny processes start with multiprocessing's spawn, which needs the working
            # folder: exit 3 "Nanny failed to start" (re-check review 45)
            raise InputError(
                "the working folder no longer exists: cd to an existing folder (--workers "
                "starts its processes there)"
            ) from None
    if workers is not None or scheduler is not None:
        _require_dask()


def _check_port(scheduler: str) -> None:
    """Refuse (exit 2) a TCP-family address whose port is outside 1–65535: distributed retried
    tcp://127.0.0.1:99999 until the :data:`CONNECT_S` probe gave up, 20 s later, blaming the
    service (CLI review 44)."""
    scheme, location = scheduler.split("://", 1)
    if scheme not in ("tcp", "tls", "ws", "wss") or ":" not in location:
        return
    host_port = location.split("/", 1)[0]
    if host_port.endswith("]") or ":" not in host_port:  # [::1] with no port: Dask says so
        return
    port = host_port.rsplit(":", 1)[1]
    if not (port.isascii() and port.isdigit()):
        # -1, +99999, 9_9999 passed to the 20 s probe (CLI review 45)
        raise InputError(f"--scheduler {scheduler}: port {port!r} is not a number from 1 to 65535")
    digits = port.lstrip("0")
    if len(digits) > 5 or not 0 < int(digits or 0) <= 65535:
        raise InputError(f"--scheduler {scheduler}: port {port} is outside 1-65535")


def _quiet_logs() -> None:
    """distributed's loggers at CRITICAL: the parent and every child that has its own level
    (``distributed.client`` is set to WARNING by dask's config, so a scheduler killed mid-run
    printed ~35 lines of traceback through it; distributed trial, session 27), and asyncio's:
    a Ctrl-C or SIGTERM while LocalCluster starts its nannies left a failed task that asyncio
    reported at exit as "Task exception was never retrieved … Nanny failed to start" (22
    lines after "terminated", session 28)."""
    import distributed  # noqa: F401 - its loggers exist once it is imported

    for name in ["distributed", "asyncio", *logging.root.manager.loggerDict]:
        if name in ("distributed", "asyncio") or name.startswith("distributed."):
            logging.getLogger(name).setLevel(QUIET)


@functools.cache
def code_fingerprint() -> str:
    """sha256 of the obsdesign package's Python sources (relative path and bytes of each
    ``*.py``, sorted): what a worker must share with the caller."""
    import hashlib
    from pathlib import Path

    root = Path(__file__).resolve().parent
    h = hashlib.sha256()
    for f in sorted(root.rglob("*.py")):
        h.update(str(f.relative_to(root)).encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def _same_code(c: Any, scheduler: str) -> None:
    """Refuse (exit 2) a cluster whose workers run other obsdesign code than this process: a
    worker on an older checkout (the same version number) gave 5 of 13 check rows different
    from the serial run, silently (distributed trial, session 27)."""
    mine = code_fingerprint()
    try:
        theirs = c.run(code_fingerprint)
    except Exception as e:  # noqa: BLE001 - a worker without this function runs other code
        raise InputError(
            f"--scheduler {scheduler}: a worker cannot report its obsdesign code "
            f"({type(e).__name__}); start the workers from this installation"
        ) from None
    other = sorted(w for w, fp in theirs.items() if fp != mine)
    if other:
        raise InputError(
            f"--scheduler {scheduler}: {len(other)} of {len(theirs)} worker(s) run other "
            f"obsdesign code than this one (e.g. {other[0]}); start them from this installation"
        )


def _probe(scheduler: str) -> None:
    """Refuse (exit 2) an address that does not complete Dask's handshake within
    :data:`CONNECT_S`: Client's timeout bounds the TCP connect only, and distributed's
    ``connect`` reads the handshake with no timeout, so a TCP service that is not Dask
    (python3 -m http.server) hung forever (distributed trial, session 27). The probe runs on
    its own event loop in a daemon thread, and is bounded there: a Client interrupted while
    it is made is left half-made, and its finalizer later deadlocked the next cluster's start
    in the same process. Errors of the connection itself are raised as they are."""
    import asyncio
    import threading

    from distributed.comm import connect

    err: list[BaseException] = []

    async def handshake() -> None:
        comm = await asyncio.wait_for(connect(scheduler, timeout=CONNECT_S), CONNECT_S)
        await comm.close()

    def run() -> None:
        try:
            asyncio.run(handshake())
        except BaseException as e:  # noqa: BLE001 - handed to the caller's thread
            err.append(e)

    t = threading.Thread(target=run, name="obsdesign-dask-probe", daemon=True)
    t.start()
    t.join(CONNECT_S + 5)
    if t.is_alive() or (err and isinstance(err[0], TimeoutError)):
        raise InputError(
            f"--scheduler {scheduler}: no Dask scheduler answered within {CONNECT_S:g} s "
            "(is it a Dask scheduler's address?)"
        )
    if err:
        raise err[0]


#: seconds a --scheduler address has to complete Dask's handshake
CONNECT_S = 20.0


@contextmanager
def dask_client(
    workers: int | None = None, scheduler: str | None = None, client: Any = None
) -> Iterator[Any]:
    """A ``dask.distributed.Client``: ``client`` as given (not closed here), else one
    connected to ``scheduler``, else one on a new ``LocalCluster`` of ``workers`` processes
    with one thread each. What this function starts, it closes (also on Ctrl-C)."""
    if client is not None:
        if not callable(getattr(client, "submit", None)):
            # client=object() was a bare AttributeError (API review 45)
            raise InputError(
                f"client: expected a dask.distributed.Client, got {type(client).__name__}"
            )
        yield client
        return
    _require_dask()
    from dask.distributed import Client, LocalCluster

    # CRITICAL, not ERROR: a worker's "Failed to communicate with scheduler during heartbeat"
    # (CommClosedError, ~30 lines) reached stderr at cluster shutdown in 1 of 3 runs of
    # `check --workers 2` (docs audit); failures that matter come back as task results
    _quiet_logs()
    if scheduler is not None:
        try:
            _probe(scheduler)
            c = Client(scheduler, timeout="10s")
        except (OSError, ValueError, TypeError, MemoryError) as e:
            # ValueError: an address distributed cannot parse, e.g. tcp:// without a port
            # (exit 3 "missing port number"; hostile-input trial, session 24); TypeError: a
            # tls:// or ucx:// address without its setup; MemoryError: a service that answers
            # bytes read as a frame length of exabytes (an HTTP server; session 27)
            why = (
                "the service there does not speak Dask's protocol (its answer read as a "
                "message of impossible size)"
                if isinstance(e, MemoryError)
                else f"{type(e).__name__}: {e}"
            )
            raise InputError(f"--scheduler {scheduler}: cannot connect ({why})") from None
        try:
            try:
                # a scheduler without workers took the tasks and waited forever, silently
                # (distributed trial, session 27)
                c.wait_for_workers(1, timeout=CONNECT_S)
            except TimeoutError:
                raise InputError(
                    f"--scheduler {scheduler}: no worker joined within {CONNECT_S:g} s "
                    "(start some: dask worker ADDRESS)"
                ) from None
            _same_code(c, scheduler)
            yield c
        finally:
            c.close()
        return
    import dask

    # one task per worker thread at a time: when a worker dies, only the task it was running
    # is suspected (and retried), not a queued one; no statistical profiler in the workers
    # (it samples the running task every 10 ms for a dashboard we do not start)
    cfg = {
        "distributed.scheduler.worker-saturation": 1.0,
        "distributed.worker.profile.enabled": False,
    }
    from obsdesign import WORKER_ENV

    # the worker processes inherit this: they ignore Ctrl-C (obsdesign/__init__.py), which
    # stops the command here, and cluster.close() ends them
    before = os.environ.get(WORKER_ENV)
    os.environ[WORKER_ENV] = "1"
    try:
        from distributed.deploy.spec import SpecCluster

        started = set(SpecCluster._instances)
        try:
            with dask.config.set(cfg):
                cluster = LocalCluster(
                    n_workers=workers or 1,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=None,
                    silence_logs=QUIET,
                )
        except BaseException:
            _abandon(set(SpecCluster._instances) - started)
            raise
        try:
            c = Client(cluster)
            try:
                yield c
            finally:
                c.close()
        finally:
            cluster.close()
    finally:
        if before is None:
            os.environ.pop(WORKER_ENV, None)
        else:
            os.environ[WORKER_ENV] = before


def _abandon(clusters: set[Any]) -> None:
    """Close clusters whose start was interrupted (Ctrl-C, SIGTERM while ``LocalCluster``
    starts its workers), and take them out of Dask's registry: left there, Dask's exit hook
    closed them again and printed a 29-line AssertionError traceback (a worker still
    "starting") after "interrupted" (session 27's note)."""
    from distributed.deploy.spec import SpecCluster

    for cluster in clusters:
        try:
            cluster.close(timeout=10)
        except BaseException:  # noqa: BLE001, S110 - best effort; the interrupt goes on
            pass
        finally:
            SpecCluster._instances.discard(cluster)


def _limits_state() -> tuple[Any, tuple[str, ...]]:
    from obsdesign import limits as lim

    return lim.limits(), tuple(sorted(lim._overridden))


def _call(fn: Callable[[T], R], state: tuple[Any, tuple[str, ...]], item: T) -> R:
    """Run ``fn(item)`` in a worker with the caller's limits in force, for this task's
    thread only (:func:`obsdesign.limits.applied`)."""
    from obsdesign import limits as lim

    values, overridden = state
    given = {k: getattr(values, k) for k in overridden}
    with lim.applied(dataclasses.replace(lim.Limits(), **given), frozenset(overridden)):
        return fn(item)


def _call_many(
    fn: Callable[[T], R], state: tuple[Any, tuple[str, ...]], items: list[T]
) -> tuple[str, list[R]]:
    """``[fn(x) for x in items]`` in a worker, with the caller's limits in force, beside the
    worker's :func:`code_fingerprint`: a worker that joins after :func:`_same_code` checked
    the cluster is checked by its results (:func:`_own_code`)."""
    return code_fingerprint(), [_call(fn, state, it) for it in items]


def _own_code(out: Any, where: str) -> list[Any]:
    """The results of a :func:`_call_many` task, refused (exit 2) when the worker that ran it
    has other obsdesign code than this process: a worker that joined a ``--scheduler``
    cluster after the check at the start ran the tasks it got with its own code, silently
    (session 27's note). A worker with code older than this check returns a bare list.

    :param out: the task's result; :param where: the cluster, for the message."""
    if isinstance(out, tuple) and len(out) == 2 and out[0] == code_fingerprint():
        return list(out[1])
    raise InputError(
        f"{where}: a worker (one that joined after the check at the start) ran other obsdesign "
        "code than this one; start the workers from this installation"
    )


#: chunks per worker thread when ``chunk`` is not given: enough to balance uneven tasks,
#: few enough that the scheduler's per-task cost (a few ms) stays small beside the work
CHUNKS_PER_THREAD = 8


def _lost_message(e: BaseException) -> str:
    """The one-line message of a row whose task was lost (a scheduler's multi-line error
    text kept its raw newline in the row: distributed trial, session 27)."""
    from obsdesign.errors import one_line

    name = type(e).__name__
    if name == "KilledWorker":
        return one_line(f"internal failure: the task killed every worker it ran on ({e})")
    return one_line(f"internal failure: {name}: {e}")


def run_tasks(
    fn: Callable[[T], R],
    items: Sequence[T],
    *,
    workers: int | None = None,
    scheduler: str | None = None,
    client: Any = None,
    on_result: Callable[[int, R], None] | None = None,
    lost: Callable[[T, str], R] | None = None,
    chunk: int | None = None,
) -> list[R]:
    """``[fn(x) for x in items]``, in this process or on Dask (see the module docstring).

    ``on_result(i, result)`` is called as each result arrives (in completion order: for a
    progress bar); the returned list is in the items' order. ``fn`` should not raise (return
    a result that records the failure); if it does, or if its task kills the workers it runs
    on, the result is ``lost(item, message)`` (the exception is raised when ``lost`` is
    None).

    On Dask, consecutive items go together in tasks of ``chunk`` items (default: about
    :data:`CHUNKS_PER_THREAD` tasks per worker thread), which keeps the scheduler's cost per
    task small beside short items; a chunk whose task fails is run again item by item, so
    only the item that fails gets a ``lost`` result."""
    items = list(items)
    results: list[Any] = [None] * len(items)
    if workers is None and scheduler is None and client is None:
        for i, it in enumerate(items):
            r = fn(it)
            results[i] = r
            if on_result is not None:
                on_result(i, r)
        return results
    check_workers(workers, scheduler)
    if chunk is not None and chunk < 1:
        raise InputError(f"chunk: expected a positive number of items, got {chunk}")
    from dask.distributed import as_completed

    state = _limits_state()
    tag = uuid.uuid4().hex[:12]
    with dask_client(workers, scheduler, client) as c:
        if chunk is None:
            threads = max(1, sum(c.nthreads().values()))
            chunk = max(1, -(-len(items) // (threads * CHUNKS_PER_THREAD)))
        spans = {}
        futures = []
        for a in range(0, len(items), chunk):
            b = min(len(items), a + chunk)
            f = c.submit(
                _call_many, fn, state, items[a:b], key=f"obsdesign-{tag}-{a}-{b}", pure=False
            )
            spans[f.key] = (a, b, False)
            futures.append(f)
        ac = as_completed(futures)
        watch = _Workers(c)
        try:
            for fut in _arrivals(ac, watch):
                a, b, single = spans[fut.key]
                try:
                    got = fut.result()
                except Exception as e:  # noqa: BLE001 - KilledWorker, or fn raised
                    _scheduler_gone(e)
                    if not single and b - a > 1:  # again item by item: only the bad one is lost
                        for i in range(a, b):
                            f = c.submit(
                                _call_many,
                                fn,
                                state,
                                [items[i]],
                                key=f"obsdesign-{tag}-retry-{i}",
                                pure=False,
                            )
                            spans[f.key] = (i, i + 1, True)
                            futures.append(f)
                            ac.add(f)
                        continue
                    if lost is None:
                        raise
                    out = [lost(items[a], _lost_message(e))]
                else:
                    out = _own_code(got, f"--scheduler {scheduler}" if scheduler else "the cluster")
                for i, r in zip(range(a, b), out, strict=True):
                    results[i] = r
                    if on_result is not None:
                        on_result(i, r)
        except BaseException:
            c.cancel(futures)
            raise
    return results


def _scheduler_gone(e: Exception) -> None:
    """A SolverError (exit 3, one message for the run) when a task's future was cancelled:
    this code cancels none while it waits, so the scheduler went away (killed, restarted).
    Each row not done was an exit-3 row of its own, "internal failure: FutureCancelledError
    … cancelled for reason: unknown", blaming the specs (Dask review 47)."""
    from concurrent.futures import CancelledError

    from obsdesign.errors import SolverError

    if isinstance(e, CancelledError):
        raise SolverError(
            "the Dask scheduler went away (its tasks were cancelled): the rows not done are "
            "lost (restart it and run again)"
        ) from None


#: seconds a run may go on with no worker at all before it stops
NO_WORKERS_S = 60.0


#: worker states that take tasks (a worker without a ``status`` counts as one)
WORKING = frozenset({"running", "init"})


class _Workers:
    """The scheduler's count of workers that take tasks, asked at most once a second, and
    since when it is 0. A paused worker (Dask pauses one past 80 % of its memory limit) takes
    none: counted as one, a cluster of paused workers left ``check --scheduler`` waiting
    forever with no word (Dask review 47)."""

    def __init__(self, client: Any) -> None:
        self.client = client
        self.asked = 0.0
        self.none_since: float | None = None
        self.paused = 0

    def gone_for(self) -> float:
        """Seconds the scheduler has had no worker that takes tasks (0 while it has one)."""
        now = time.monotonic()
        if now - self.asked >= 1.0:
            self.asked = now
            try:
                workers = self.client.scheduler_info().get("workers", {})
                states = [str(w.get("status", "running")) for w in workers.values()]
                n = sum(st in WORKING for st in states)
                self.paused = sum(st == "paused" for st in states)
            except Exception:  # noqa: BLE001 - a scheduler that went away: as_completed says so
                n = 1
            self.none_since = None if n else (self.none_since or now)
        return 0.0 if self.none_since is None else now - self.none_since


def _arrivals(ac: Any, watch: _Workers) -> Iterator[Any]:
    """The futures of ``ac`` as they complete; :class:`obsdesign.errors.SolverError` (exit 3)
    when the scheduler has had no worker for :data:`NO_WORKERS_S` (the last worker of an
    external cluster died, and the run waited forever with no message: distributed trial,
    session 27). A LocalCluster's nanny restarts its workers, so this is an external
    cluster's case."""
    from obsdesign.errors import SolverError

    while not ac.is_empty():
        batch = ac.next_batch(block=False)
        if batch:
            yield from batch
            continue
        if watch.gone_for() > NO_WORKERS_S:
            if watch.paused:
                raise SolverError(
                    f"the Dask scheduler's {watch.paused} worker(s) have been paused for "
                    f"{NO_WORKERS_S:g} s (Dask pauses a worker past 80 % of its memory "
                    "limit): the rows not done are lost (give the workers more memory, "
                    "--memory-limit, and run again)"
                )
            raise SolverError(
                f"the Dask scheduler has had no worker for {NO_WORKERS_S:g} s: the rows not "
                "done are lost (start workers and run again)"
            )
        time.sleep(0.02)


@contextmanager
def progress_bar(total: int, label: str, quiet: bool = False) -> Iterator[Callable[[bool], None]]:
    """A rich progress bar on stderr (rows done / total, failures, ETA); yields
    ``advance(failed)``, called once per finished row. Nothing is shown with ``quiet``."""
    if quiet or total <= 0:
        yield lambda failed: None
        return
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    from obsdesign.report.render import stderr_console

    bar = Progress(
        TextColumn("{task.description}"),
        BarColumn(),
        MofNCompleteColumn(),
        TextColumn("failures {task.fields[failures]}"),
        TimeElapsedColumn(),
        TextColumn("ETA"),
        TimeRemainingColumn(),
        console=stderr_console(),
        transient=False,
    )
    task = bar.add_task(label, total=total, failures=0)
    failures = 0

    def advance(failed: bool) -> None:
        nonlocal failures
        failures += bool(failed)
        bar.update(task, advance=1, failures=failures)

    with bar:
        yield advance


__all__ = [
    "INSTALL_HINT",
    "check_workers",
    "dask_available",
    "dask_client",
    "progress_bar",
    "run_tasks",
]
