"""The model of a fit: states at the observation epochs and their STM, from one back end.

``exact``: the torque-free flow with its exact STM (:func:`spinorbit.core.free_motion.stm.free_flow_stm`);
``dop853``: the quaternion integrator with its variational equations
(:func:`spinorbit.core.integrators.variational.integrate_variational`), with or without torques;
``taylor``: the Taylor integrator with the recurrences of its variational equations
(:func:`spinorbit.core.integrators.taylor_variational.integrate_taylor_variational`, tol = rtol). Times
are TDB days since the fit's epoch, on both sides of it (the integrator runs each way from t = 0).
"""

import numpy as np

from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.free_motion.stm import free_flow_stm
from spinorbit.core.integrators.taylor_variational import integrate_taylor_variational
from spinorbit.core.integrators.variational import integrate_variational

BACKENDS = ("exact", "dop853", "taylor")


def propagate_with_stm(backend, q0, omega0, moments, times, sources=(), rtol=1e-11):
    """(q (T, 4), ω (T, 3), Φ (T, 6, 6), Ψ (T, 6, 2)) at ``times`` (days since the epoch, any order)."""
    times = np.asarray(times, dtype=float)
    if backend == "exact":
        q, w, phi, psi = free_flow_stm(q0, omega0, moments, times)
        return q, w, phi, psi
    model = make_model(np.asarray(moments, dtype=float), list(sources))
    n = times.size
    q = np.empty((n, 4))
    w = np.empty((n, 3))
    phi = np.empty((n, 6, 6))
    psi = np.empty((n, 6, 2))
    y0 = np.concatenate([q0, omega0])
    at_epoch = times == 0.0
    q[at_epoch], w[at_epoch], phi[at_epoch], psi[at_epoch] = q0, omega0, np.eye(6), 0.0
    for sign in (1.0, -1.0):
        chosen = np.flatnonzero(sign * times > 0.0)
        if chosen.size == 0:
            continue
        order = chosen[np.argsort(sign * times[chosen])]
        unique, inverse = np.unique(sign * times[order], return_inverse=True)
        if backend == "taylor":
            ys, phis, psis = integrate_taylor_variational(y0, 0.0, sign * unique, model, tol=rtol)
        else:
            ys, phis, psis = integrate_variational(y0, 0.0, sign * unique, model, rtol=rtol)
        q[order], w[order] = ys[inverse, :4], ys[inverse, 4:]
        phi[order], psi[order] = phis[inverse], psis[inverse]
    return q, w, phi, psi
