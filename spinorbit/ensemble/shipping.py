"""``make_scene`` sent to the workers as bytes, loaded where it runs, so a failure to load it has its cause.

When an executor unpickles a task's function itself and fails (the worker cannot import the module
``make_scene`` lives in, or finds no such name in it), Dask reports a generic deserialisation error
and keeps the cause (``ModuleNotFoundError``, ``AttributeError``) in the scheduler's log; the
ensemble could only call the run "interrupted", and running it again cannot help. So the ensemble
pickles ``make_scene`` once, here, and the chunk (:func:`spinorbit.ensemble.ensemble.run_chunk`, a
function every worker can import) loads it: a failure is then recorded for each member of the chunk
with its own type and message, and the run goes on.

The serialiser follows the executor: Dask's own, cloudpickle (a function of ``__main__`` goes by
value, with what it refers to, as Dask sends it), for a :class:`~spinorbit.ensemble.executors.DaskExecutor`;
the standard pickle (by reference) for a process pool, whose forked or spawned workers have the
parent's ``__main__``. What a function carries by value (an orbit cached in a dict) crosses as its
own pickling says: an :class:`~spinorbit.scene.Orbit` as its description (``Orbit.__reduce__``).
"""

from __future__ import annotations

import os
import pickle
import socket

from spinorbit.ensemble.errors import EnsembleError

__all__ = ["ShippedFunction", "load_failure_record", "load_where_run", "shipped_for"]


def _qualified(function):
    return f"{getattr(function, '__module__', '?')}.{getattr(function, '__qualname__', repr(function))}"


class ShippedFunction:
    """A function pickled in this process, to be loaded (:meth:`load`) in the process that calls it.

    Parameters
    ----------
    function : callable
    by_value : bool
        Pickle with cloudpickle (functions of ``__main__`` by value, as Dask does) instead of pickle.

    Raises
    ------
    EnsembleError
        ``function`` cannot be pickled here (a lambda or a local function with the standard pickle).
    """

    def __init__(self, function, by_value=False):
        self.name = _qualified(function)
        try:
            if by_value:
                import cloudpickle  # Dask's own serialiser: installed with it

                self.payload = cloudpickle.dumps(function)
            else:
                self.payload = pickle.dumps(function)
        except Exception as error:  # noqa: BLE001 — any pickling failure, with its cause
            raise EnsembleError(f"make_scene ({self.name}) cannot be sent to the worker processes "
                                f"({type(error).__name__}: {error}); define it at module level in an importable "
                                "module, or run with executor='serial'.") from None

    def load(self):
        """The function (raises what unpickling raises: ModuleNotFoundError, AttributeError, …)."""
        return pickle.loads(self.payload)


def load_failure_record(index, parameters, shipped, error):
    """The failure of member ``index`` whose make_scene could not be loaded in this (worker) process."""
    return {"index": int(index), "parameters": {k: repr(v) for k, v in parameters.items()},
            "type": type(error).__name__,
            "message": f"make_scene ({shipped.name}) could not be loaded in the worker process {os.getpid()} on "
                       f"{socket.gethostname()}: {error}. The workers import it by its module: put it in a module "
                       "they can import (installed, or on their PYTHONPATH), then rerun these members."}


def shipped_for(function, pool):
    """``function`` as a :class:`ShippedFunction` for ``pool`` (cloudpickle for Dask), or None in this process."""
    from spinorbit.ensemble.executors import DaskExecutor

    return None if pool is None else ShippedFunction(function, by_value=isinstance(pool, DaskExecutor))


def load_where_run(make_scene, members):
    """(make_scene loaded, {}) — or (None, a failure record per member of ``members``) when it cannot be."""
    if not isinstance(make_scene, ShippedFunction):
        return make_scene, {}
    try:
        return make_scene.load(), {}
    except Exception as error:  # noqa: BLE001 — every member of the chunk fails with that cause
        return None, {i: load_failure_record(i, p, make_scene, error) for i, p in members}
