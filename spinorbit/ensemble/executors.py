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

from spinorbit.core.errors import SpinorbitError
from spinorbit.ensemble.workers import process_pool, stop_pool

__all__ = ["DaskExecutor", "ExecutorError", "available_cores", "dask_client", "open_executor", "owns_workers"]


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


class DaskExecutor(concurrent.futures.Executor):
    """A ``dask.distributed.Client`` as a concurrent.futures.Executor that forgets each result once read.

    Unlike ``client.get_executor()``: every submission is a new task (``pure=False``: a chunk sent
    again after its worker died is not the erred task the scheduler remembers), and the remote result
    is released as soon as it has arrived, so a worker that dies later does not make the scheduler
    compute it again behind the ensemble's back.
    """

    def __init__(self, client):
        self.client = client

    def submit(self, fn, /, *args, **kwargs):
        """Run ``fn`` with the arguments on the cluster; a concurrent.futures.Future of its result."""
        remote = self.client.submit(fn, *args, pure=False, **kwargs)
        local = concurrent.futures.Future()

        def arrived(remote):
            try:
                local.set_result(remote.result())
            except BaseException as error:  # noqa: BLE001 — handed to the caller through the future
                local.set_exception(error)
            finally:
                remote.release()

        remote.add_done_callback(arrived)
        return local


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
