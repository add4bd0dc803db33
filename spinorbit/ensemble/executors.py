"""Where an ensemble's chunks run: in this process, a process pool, any concurrent.futures.Executor, or Dask.

:func:`open_executor` turns the ``executor`` argument of :meth:`~spinorbit.ensemble.Ensemble.run`
into a :class:`concurrent.futures.Executor` (or None: in this process) for the length of a run:

- ``None``: in this process when one core is available to it, else a ``ProcessPoolExecutor`` with
  one worker per available core (``os.sched_getaffinity``), as for an ``int``;
- ``"serial"``: in this process;
- an ``int`` K: a ``ProcessPoolExecutor`` of K workers (:func:`~spinorbit.ensemble.workers.process_pool`:
  they die with this process and are stopped at once when the run is, :mod:`spinorbit.ensemble.workers`);
- ``"dask"``: an embedded ``dask.distributed.LocalCluster(processes=True)`` (one single-threaded
  worker per core, its dashboard on a free port) and its ``Client``, closed after the run;
- a ``dask.distributed.Client`` (e.g. one connected to a scheduler address, or to a dask-jobqueue
  cluster), through :class:`DaskExecutor`;
- any other ``concurrent.futures.Executor`` (e.g. mpi4py's ``MPIPoolExecutor``): used as it is.

The executor only decides where a chunk runs, never what it computes: the chunks are fixed by the
ensemble, so the results are the same bits whichever executor ran them.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import os
import threading
import time

from spinorbit.core.errors import SpinorbitError
from spinorbit.ensemble.workers import process_pool, stop_pool

__all__ = ["NO_WORKERS_SECONDS", "DaskExecutor", "ExecutorError", "NoWorkersError", "available_cores", "dask_client",
           "open_executor", "owns_workers"]


class ExecutorError(SpinorbitError, ValueError):
    """The executor argument is of an unknown kind, or Dask is not installed."""


def available_cores():
    """Cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def _is_dask_client(executor):
    try:
        from distributed import Client
    except ImportError:
        return False
    return isinstance(executor, Client)


#: How long a Dask run waits with no worker connected to its scheduler before its chunks fail (seconds).
NO_WORKERS_SECONDS = 60.0


class NoWorkersError(SpinorbitError, RuntimeError):
    """The Dask scheduler had no worker for longer than the executor waits: the chunks cannot run."""


class DaskExecutor(concurrent.futures.Executor):
    """A ``dask.distributed.Client`` as a concurrent.futures.Executor that forgets each result once read.

    Unlike ``client.get_executor()``: every submission is a new task (``pure=False``: a chunk sent
    again after its worker died is not the erred task the scheduler remembers), and the remote result
    is released as soon as it has arrived, so a worker that dies later does not make the scheduler
    compute it again behind the ensemble's back. A chunk cancelled here is cancelled on the cluster.

    A scheduler whose workers are all gone keeps its tasks waiting for ever. While chunks are out, a
    watching thread asks the scheduler for its worker count once a second; when it has been zero for
    ``no_workers_seconds``, every chunk still out fails with :class:`NoWorkersError` saying so (the
    ensemble then stops with the finished chunks kept). ``no_workers_seconds=None`` waits for ever,
    e.g. for an adaptive cluster whose workers come from a batch queue.
    """

    def __init__(self, client, no_workers_seconds=NO_WORKERS_SECONDS):
        self.client, self.no_workers_seconds = client, no_workers_seconds
        self._out, self._lock, self._watch = {}, threading.Lock(), None

    def submit(self, fn, /, *args, **kwargs):
        """Run ``fn`` with the arguments on the cluster; a concurrent.futures.Future of its result."""
        remote = self.client.submit(fn, *args, pure=False, **kwargs)
        local = concurrent.futures.Future()

        def arrived(remote):
            try:
                result = remote.result()
            except BaseException as error:  # noqa: BLE001 — handed to the caller through the future
                _settle(local, error=error)
            else:
                _settle(local, result=result)
            finally:
                remote.release()

        def settled(local):
            with self._lock:
                self._out.pop(id(local), None)
            if local.cancelled():
                remote.cancel()

        with self._lock:
            self._out[id(local)] = (local, remote)
        local.add_done_callback(settled)
        remote.add_done_callback(arrived)
        self._start_watch()
        return local

    def _start_watch(self):
        if self.no_workers_seconds is None or (self._watch is not None and self._watch.is_alive()):
            return
        self._watch = threading.Thread(target=self._watch_workers, name="spinorbit-dask-workers", daemon=True)
        self._watch.start()

    def _worker_count(self):
        try:
            return self.client.scheduler_info(n_workers=0)["n_workers"]
        except Exception:  # noqa: BLE001 — scheduler unreachable: the lost connection fails the chunks itself
            return None

    def _watch_workers(self):
        since = None
        while True:
            with self._lock:
                out = list(self._out.values())
            if not out:
                return
            count = self._worker_count()
            now = time.monotonic()
            since = (since or now) if count == 0 else None
            if since is not None and now - since >= self.no_workers_seconds:
                error = NoWorkersError(
                    f"the Dask scheduler {self.client.scheduler.address} has had no worker for "
                    f"{self.no_workers_seconds:g} s, so {len(out)} chunks cannot run; start workers for it "
                    "(dask worker ADDRESS) and run again with the same checkpoint")
                for local, remote in out:
                    remote.cancel()
                    _settle(local, error=error)
                return
            time.sleep(min(1.0, self.no_workers_seconds / 4))


def _settle(future, result=None, error=None):
    """Give ``future`` its result or error unless it has one already (the watch and Dask may race)."""
    try:
        future.set_exception(error) if error is not None else future.set_result(result)
    except concurrent.futures.InvalidStateError:
        pass


def dask_client(address=None, workers=None):
    """A ``dask.distributed.Client``: of the scheduler at ``address``, or of a new LocalCluster of ``workers``
    single-threaded worker processes (default: the available cores)."""
    try:
        from distributed import Client, LocalCluster
    except ImportError:
        raise ExecutorError("executor='dask' needs dask.distributed; install it with: "
                            "pip install 'spinorbit[distributed]'") from None
    if address is not None:
        return Client(address)
    # The scheduler's HTTP server starts whatever dashboard_address says; None means the default port
    # 8787, which another cluster on the machine may hold (then the start fails). ':0' takes a free one.
    cluster = LocalCluster(n_workers=workers or available_cores(), threads_per_worker=1, processes=True,
                           dashboard_address=":0")
    return Client(cluster)


def owns_workers(executor):
    """Whether :func:`open_executor` makes (and so stops) the workers of ``executor``: None, an int, "dask"."""
    return executor is None or executor == "dask" or (isinstance(executor, int) and not isinstance(executor, bool))


@contextlib.contextmanager
def open_executor(executor):
    """Yield (Executor or None, description) for ``executor`` (module docstring); owned ones are shut down after."""
    if executor is None:
        cores = available_cores()
        executor = "serial" if cores == 1 else cores
    if executor == "serial":
        yield None, "in this process"
    elif isinstance(executor, (int,)) and not isinstance(executor, bool):
        if executor < 1:
            raise ExecutorError(f"executor expects a positive number of worker processes; got {executor}.")
        pool = process_pool(executor)
        try:
            yield pool, f"a process pool of {executor} workers"
        except BaseException:  # Ctrl-C, SIGTERM, an error: stop now, not after every submitted chunk
            stop_pool(pool)
            raise
        pool.shutdown(wait=True)
    elif executor == "dask":
        client = dask_client()
        try:
            yield DaskExecutor(client), f"an embedded Dask LocalCluster of {len(client.scheduler_info()['workers'])} workers"
        finally:
            cluster = client.cluster
            client.close()
            if cluster is not None:
                cluster.close()
    elif _is_dask_client(executor):
        yield DaskExecutor(executor), f"the Dask client {executor.scheduler.address}"
    elif isinstance(executor, concurrent.futures.Executor):
        yield executor, type(executor).__name__
    else:
        raise ExecutorError(f"executor expects None, 'serial', 'dask', a number of worker processes, a "
                            f"dask.distributed.Client or a concurrent.futures.Executor; got {executor!r}.")
