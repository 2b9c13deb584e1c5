"""Where cases run: small adapters with one calling convention (as pymoo's runners).

A runner is any callable ``runner(function, payloads)`` that returns an iterator of
``function(payload)`` results in the order they finish.  It pulls payloads lazily (a few
per worker in flight), so the driver's memory does not grow with the number of cases and
a Monte Carlo stopping rule can end the stream.  Closing the iterator (the driver does
on Ctrl-C or an error) cancels what has not started and stops the workers.

=================  ==================================================================
runner             where
=================  ==================================================================
``SerialRunner``   this process, one case after the other (``workers=1``)
``LocalPool``      a pool of worker processes on this machine (default: all cores)
``DaskRunner``     a Dask distributed cluster: a ``Client`` or a scheduler address
=================  ==================================================================

The driver code is the same for all three; only the adapter changes.  Worker processes
live for the whole study, so each compiles its kernels once (see
:mod:`torquesplit.study.case`).
"""

from __future__ import annotations

import contextlib
import logging
import os
import signal
from concurrent.futures import FIRST_COMPLETED, wait
from typing import Callable, Iterable, Iterator

from ..errors import HeldInterrupt, OptionError

log = logging.getLogger(__name__)


class SerialRunner:
    """Run the cases in this process, in order."""

    workers = 1

    def __call__(self, function: Callable, payloads: Iterable) -> Iterator:
        """Each case's result; a Ctrl-C stops the cases even where it landed inside
        compiled code and came out of the case as another error (numba's
        '_get_wrapper_address() missing ... sig', recorded as the case's error while the
        study ran on and exited 0: a reliability reviewer): the case's result is then
        dropped (it runs again on --resume) and KeyboardInterrupt raised."""
        with _noting_interrupts() as seen:
            for p in payloads:
                result = function(p)
                if seen:
                    raise KeyboardInterrupt
                yield result

    def __repr__(self) -> str:
        return "SerialRunner()"


@contextlib.contextmanager
def _noting_interrupts():
    """Within the block, a SIGINT is noted before the handler in force runs (Python's
    raises KeyboardInterrupt as ever).  Main thread only, and only where a handler of
    Python's is installed; elsewhere nothing is noted."""
    import threading

    seen = HeldInterrupt()  # (true once a SIGINT came)
    current = (signal.getsignal(signal.SIGINT)
               if threading.current_thread() is threading.main_thread() else None)
    if not callable(current):
        yield seen
        return

    def note(signum, frame):
        seen.hit = True
        current(signum, frame)

    signal.signal(signal.SIGINT, note)
    try:
        yield seen
    finally:
        signal.signal(signal.SIGINT, current)


def worker_start() -> None:  # pragma: no cover - runs in the worker processes
    """A worker's set-up: Ctrl-C, SIGHUP and SIGTERM ignored (they go to the whole process
    group: the driver stops the workers itself), the heap frozen after the first case
    (:data:`.case.FREEZE_HEAP`), and an exit as soon as the driver is gone.  A driver
    killed outright (SIGKILL, the out-of-memory killer) cannot stop its pool, whose
    workers then waited for work forever: a daemon thread waits on the parent
    process's sentinel, which becomes ready when it dies."""
    import multiprocessing
    import threading
    from multiprocessing.connection import wait

    from . import case

    # Ctrl-C, a closed session's SIGHUP and a batch system's SIGTERM reach the whole
    # process group: the driver stops on them, and stops (kills) its workers
    for name in ("SIGINT", "SIGHUP", "SIGTERM"):
        if hasattr(signal, name):
            signal.signal(getattr(signal, name), signal.SIG_IGN)
    case.FREEZE_HEAP = True
    parent = multiprocessing.parent_process()
    if parent is None:
        return

    def watch():
        wait([parent.sentinel])
        os._exit(1)

    threading.Thread(target=watch, name="torquesplit-driver-watch", daemon=True).start()


def start_helpers() -> None:
    """Start multiprocessing's resource tracker (a helper process of every pool) with
    SIGHUP ignored, as the workers ignore it: a closed session's SIGHUP reaches the whole
    process group, and a tracker it killed left four tracebacks of leaked semaphores
    under the study's 'stopped' line.  An ignored signal stays ignored across the
    tracker's exec.  Main thread only (elsewhere the tracker starts as it would)."""
    import threading
    from multiprocessing import resource_tracker

    hup = getattr(signal, "SIGHUP", None)
    if hup is None or threading.current_thread() is not threading.main_thread():
        resource_tracker.ensure_running()
        return
    before = signal.signal(hup, signal.SIG_IGN)
    try:
        resource_tracker.ensure_running()
    finally:
        signal.signal(hup, before)


class LocalPool:
    """A pool of ``workers`` processes (default: all cores), started with ``spawn``.

    ``spawn`` (not ``fork``): a worker starts from a clean interpreter, safe with the
    threads of numba, llvmlite and Dask in the parent.  Each worker imports torquesplit
    and loads the compiled kernels once (about a second), then serves cases until the
    study ends.
    """

    def __init__(self, workers: int | None = None, *, start_method: str = "spawn",
                 in_flight: int = 2):
        self.workers = int(workers or os.cpu_count() or 1)
        if self.workers < 1:
            raise OptionError("workers must be >= 1; give e.g. workers=2")
        self.start_method = start_method
        self.in_flight = in_flight

    def __call__(self, function: Callable, payloads: Iterable) -> Iterator:
        import multiprocessing
        from concurrent.futures import ProcessPoolExecutor

        ctx = multiprocessing.get_context(self.start_method)
        start_helpers()
        pool = ProcessPoolExecutor(self.workers, mp_context=ctx, initializer=worker_start)
        items = iter(payloads)
        pending: set = set()
        finished = False
        try:
            def refill():
                while len(pending) < self.in_flight * self.workers:
                    try:
                        p = next(items)
                    except StopIteration:
                        return
                    pending.add(pool.submit(function, p))

            refill()
            while pending:
                done, rest = wait(pending, return_when=FIRST_COMPLETED)
                pending.clear()
                pending.update(rest)
                for f in done:
                    yield f.result()
                refill()
            finished = True
        finally:
            for f in pending:
                f.cancel()
            if not finished:
                # stop at once: running cases are lost (they were not committed) and will
                # run again on --resume.  ProcessPoolExecutor has no public terminate.
                for proc in list(getattr(pool, "_processes", {}).values()):
                    proc.kill()  # (SIGKILL: they ignore SIGTERM, see worker_start)
            pool.shutdown(wait=finished, cancel_futures=True)

    def __repr__(self) -> str:
        return f"LocalPool(workers={self.workers})"


class DaskRunner:
    """Cases on a Dask distributed cluster, through ``client`` or a scheduler ``address``.

    Each case is one task (``pure=False``); a task whose worker dies is rescheduled by
    the scheduler on another worker, and ``retries`` more attempts are allowed for a task
    that raises (``run_case`` records failures itself, so this is rare).
    """

    def __init__(self, client=None, address: str | None = None, *, retries: int = 2,
                 in_flight: int = 2):
        if (client is None) == (address is None):
            raise OptionError("give a dask.distributed Client or a scheduler address "
                             "('tcp://host:8786'), not both")
        self.client = client
        self.address = address
        self.retries = retries
        self.in_flight = in_flight

    @property
    def workers(self) -> int:
        if self.client is None:
            return 0
        return sum(self.client.nthreads().values())

    def __call__(self, function: Callable, payloads: Iterable) -> Iterator:
        try:
            from distributed import Client, as_completed
        except ImportError:  # pragma: no cover - depends on the installation
            raise ImportError("running on Dask needs dask.distributed; install it with "
                              "pip install 'torquesplit[study]'") from None
        own = self.client is None
        try:
            client = Client(self.address) if own else self.client
        except ValueError as exc:  # (distributed's own 'missing port number in address')
            raise OptionError(f"scheduler address {self.address!r}: {exc}; give e.g. "
                              f"'tcp://host:8786'") from None
        items = iter(payloads)
        window = self.in_flight * max(1, sum(client.nthreads().values()))
        queue = as_completed()
        live: set = set()

        def submit() -> bool:
            try:
                p = next(items)
            except StopIteration:
                return False
            fut = client.submit(function, p, pure=False, retries=self.retries)
            live.add(fut)
            queue.add(fut)
            return True

        try:
            for _ in range(window):
                if not submit():
                    break
            for fut in queue:
                live.discard(fut)
                result = fut.result()
                fut.release()
                yield result
                submit()
        finally:
            if live:
                client.cancel(list(live))
            if own:
                client.close()

    def __repr__(self) -> str:
        return f"DaskRunner({self.address or self.client!r})"


def make_runner(workers: int | None = None, *, client=None, scheduler: str | None = None,
                runner=None):
    """The runner for the given options: an explicit ``runner``, else Dask for a
    ``client`` or ``scheduler`` address, else a local pool (one worker: this process)."""
    given = [x is not None for x in (runner, client, scheduler)]
    if sum(given) > 1:
        raise OptionError("give only one of runner, client and scheduler")
    if runner is not None:
        return runner
    if client is not None:
        return DaskRunner(client=client)
    if scheduler is not None:
        return DaskRunner(address=scheduler)
    n = int(workers or os.cpu_count() or 1)
    if n < 1:
        raise OptionError(f"workers must be at least 1, got {workers}; give e.g. workers=2 "
                         "(on the command line: --workers 2)")
    return SerialRunner() if n == 1 else LocalPool(n)
