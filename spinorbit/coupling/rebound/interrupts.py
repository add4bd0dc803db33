"""Ctrl-C during and after REBOUND runs: Python's SIGINT handler given back after every ``integrate``.

REBOUND 5.2's ``reb_simulation_integrate`` installs its own C-level SIGINT handler
(``reb_sigint_handler``) and never gives Python's back. That handler only counts (the C global
``reb_sigint``); the integration loop stops when the count is non-zero, and every ``integrate``
call starts by zeroing it. Left installed, it swallows every later Ctrl-C: ``KeyboardInterrupt``
never reaches Python, and a command that ran REBOUND once and then loops (an ensemble waiting for
its workers) cannot be stopped.

:func:`integrate_interruptibly` therefore

- reads the signal action in force before the call (the raw ``struct sigaction``, whatever handler
  it names: Python's, ``SIG_IGN`` in a worker, a caller's own) and puts it back right after, from
  any thread (``signal.signal`` works in the main thread only);
- reads REBOUND's count before the call (a Ctrl-C its handler absorbed since an earlier call that
  did not pass through here) and after it (one that landed in the last step, after REBOUND's final
  check), raising ``KeyboardInterrupt`` for either. The action is put back *before* that last read,
  so no Ctrl-C can fall between the two handlers.

Every ``integrate`` in spinorbit goes through it. ``sim.steps`` does not install the handler
(checked in ``tests/test_interrupts.py``).
"""

from __future__ import annotations

import ctypes
import signal
import threading

import rebound

__all__ = ["integrate_interruptibly", "rebound_handler_installed", "step_interruptibly"]

_REB_SIGINT = ctypes.c_int.in_dll(rebound.clibrebound, "reb_sigint")
_REB_HANDLER = ctypes.cast(rebound.clibrebound.reb_sigint_handler, ctypes.c_void_p).value

#: Bytes for one ``struct sigaction`` (152 on Linux x86-64/aarch64, 16 on macOS): read and written
#: whole, never interpreted, except its first member, the handler's address (on every POSIX ABI).
_SIGACTION_BYTES = 512


def _libc_sigaction():
    try:
        libc = ctypes.CDLL(None)  # the process's own symbols: libc's among them on Linux and macOS
        function = libc.sigaction
    except (OSError, AttributeError):  # no POSIX sigaction (Windows): signal.signal from the main thread only
        return None
    function.argtypes = (ctypes.c_int, ctypes.c_void_p, ctypes.c_void_p)
    function.restype = ctypes.c_int
    return function


_SIGACTION = _libc_sigaction()
#: The last SIGINT action seen that was not REBOUND's: what to put back when REBOUND's is found in
#: force before a call (a direct ``sim.integrate`` elsewhere installed it).
_lock = threading.Lock()
_last_foreign = None


def _read_action():
    action = ctypes.create_string_buffer(_SIGACTION_BYTES)
    _SIGACTION(signal.SIGINT, None, action)
    return action


def _handler_address(action):
    return ctypes.c_void_p.from_buffer(action).value


def rebound_handler_installed() -> bool:
    """Whether REBOUND's C handler is the SIGINT action in force (so Ctrl-C would not reach Python)."""
    return _SIGACTION is not None and _handler_address(_read_action()) == _REB_HANDLER


def _action_to_restore():
    """The SIGINT action to put back after the next ``integrate`` (None: nothing to put back)."""
    global _last_foreign
    if _SIGACTION is None:
        return None
    with _lock:
        action = _read_action()
        if _handler_address(action) != _REB_HANDLER:
            _last_foreign = action
        return _last_foreign


def _restore(action) -> None:
    if action is not None:
        with _lock:
            if _handler_address(_read_action()) == _REB_HANDLER:  # leave a handler installed meanwhile alone
                _SIGACTION(signal.SIGINT, action, None)
    elif threading.current_thread() is threading.main_thread():  # no sigaction: Python's own call can do it
        handler = signal.getsignal(signal.SIGINT)
        if handler is not None:
            signal.signal(signal.SIGINT, handler)


def _raise_if_interrupted() -> None:
    if _REB_SIGINT.value:
        _REB_SIGINT.value = 0
        raise KeyboardInterrupt


def integrate_interruptibly(sim, t) -> None:
    """``sim.integrate(t)`` that leaves the SIGINT handler as it found it and loses no Ctrl-C.

    The action in force before the call (Python's handler, normally) is put back after it, so a
    Ctrl-C after the call raises ``KeyboardInterrupt`` as usual; one that REBOUND's handler absorbed
    (during the call, or since a direct ``sim.integrate`` elsewhere) raises it here. The simulation
    is then somewhere between its old time and ``t`` (as after REBOUND's own KeyboardInterrupt):
    stop the run, or resume from a checkpoint.

    Parameters
    ----------
    sim : rebound.Simulation
    t : float
        Time to integrate to, in the simulation's time unit (TDB days since J2000 for DE421 simulations).
    """
    action = _action_to_restore()
    _raise_if_interrupted()  # arrived since an earlier call, while REBOUND's handler was installed
    try:
        sim.integrate(t)
    except KeyboardInterrupt:
        _REB_SIGINT.value = 0  # REBOUND leaves the count set; the next call would stop at once
        raise
    finally:
        _restore(action)
    _raise_if_interrupted()  # arrived during the last step, after REBOUND's final check


def step_interruptibly(sim) -> None:
    """One step of ``sim``'s integrator (``sim.steps(1)``: no output time, so BS's step is its own).

    A Ctrl-C that REBOUND's handler absorbed during an earlier ``integrate`` raises
    ``KeyboardInterrupt`` here, as in :func:`integrate_interruptibly`.
    """
    _raise_if_interrupted()
    sim.steps(1)
    _raise_if_interrupted()
