"""Ctrl-C during REBOUND runs that are made of many ``integrate`` calls.

REBOUND installs its own SIGINT handler when it integrates and never gives Python's back; the handler
only counts (the C global ``reb_sigint``), the integration loop stops when the count is non-zero, and
every ``integrate`` call starts by zeroing it. A run that calls ``integrate`` once per output time
would thus lose a Ctrl-C landing between two calls (or in the last step of one);
:func:`integrate_interruptibly` reads the count before and after each call (a window of one ctypes
call remains).
"""

from __future__ import annotations

import ctypes

import rebound

__all__ = ["integrate_interruptibly", "step_interruptibly"]

_REB_SIGINT = ctypes.c_int.in_dll(rebound.clibrebound, "reb_sigint")


def _raise_if_interrupted() -> None:
    if _REB_SIGINT.value:
        _REB_SIGINT.value = 0
        raise KeyboardInterrupt


def integrate_interruptibly(sim, t) -> None:
    """``sim.integrate(t)``, raising ``KeyboardInterrupt`` for a Ctrl-C that REBOUND's handler absorbed.

    The simulation is then somewhere between its old time and ``t`` (as after REBOUND's own
    KeyboardInterrupt): stop the run, or resume from a checkpoint.

    Parameters
    ----------
    sim : rebound.Simulation
    t : float
        Time to integrate to, in the simulation's time unit (TDB days since J2000 for DE421 simulations).
    """
    _raise_if_interrupted()  # arrived since the last call, while REBOUND's handler was installed
    try:
        sim.integrate(t)
    except KeyboardInterrupt:
        _REB_SIGINT.value = 0  # REBOUND leaves the count set; the next call would stop at once
        raise
    _raise_if_interrupted()  # arrived during the last step, after REBOUND's final check


def step_interruptibly(sim) -> None:
    """One step of ``sim``'s integrator (``sim.steps(1)``: no output time, so BS's step is its own).

    A Ctrl-C that REBOUND's handler absorbed during an earlier ``integrate`` raises
    ``KeyboardInterrupt`` here, as in :func:`integrate_interruptibly`.
    """
    _raise_if_interrupted()
    sim.steps(1)
    _raise_if_interrupted()
