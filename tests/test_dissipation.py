"""Nutation damping (Burns & Safronov 1973 time scale) as a drift of the canonical elements.

The reference is the published formula τ_D = μQ/(ρ K₃² R² ω³) evaluated here in SI by hand, and the
exponential decay of the energy above the principal-axis state that the drift is defined to follow
(its integral in closed form); the test checks that the drift in (S, Z, H, h) realises both.
"""

import math

import numpy as np
import pytest

from spinorbit.core.averaging.dissipation import damping_constant, damping_time
from spinorbit.core.averaging.thermal_mean import propagate_mean_thermal
from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.elements.canonical import inertia_constants
from spinorbit.core.integrators.elements import elements_of_state
from spinorbit.core.model.perturbers import kepler_source

GM_SUN = 0.01720209895**2
MOMENTS = np.array([0.6, 0.92, 1.0]) * 1e16  # kg m², a 200 m-class body


def test_damping_time_is_the_published_formula():
    mu_q, rho, radius, k3 = 5e12, 2000.0, 500.0, 0.01
    omega_si = 2 * math.pi / (6 * 3600.0)
    ic = inertia_constants(*MOMENTS)
    big_z = MOMENTS[2] * omega_si * 86400.0  # kg m² rad/day, rotation about C at ω
    tau_days = damping_time(big_z, ic, damping_constant(mu_q, rho, radius, k3))
    tau_si = mu_q / (rho * k3 * radius**2 * omega_si**3)  # Burns & Safronov 1973, in seconds
    assert tau_days * 86400.0 == pytest.approx(tau_si, rel=1e-13)
    with pytest.raises(ValueError, match="mu_q"):
        damping_constant(-1.0, rho, radius, k3)


def test_drift_relaxes_the_energy_excess_with_the_published_time():
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, sign=-1.0)
    model = make_model(MOMENTS, [sun])
    frame = np.diag([-1.0, -1.0, 1.0])
    omega = 2 * math.pi / 0.25
    q = np.array([0.9, 0.2, -0.3, 0.25])
    y0 = np.array([*(q / np.linalg.norm(q)), 0.1 * omega, 0.1 * omega, omega])  # a SAM tumbler near C
    el0 = elements_of_state(y0, model, frame)
    ic = inertia_constants(*MOMENTS)
    a, _, c, _, _, _ = ic
    k = 1e9  # day⁻²: τ_D ~ k/ω³ ≈ 60 days for this spin
    tau = damping_time(el0[1], ic, k)
    times = tau * np.array([0.25, 0.5, 1.0, 2.0])
    out, _ = propagate_mean_thermal(el0, 0.0, times, model, frame, step=tau / 50, with_gravity=False,
                                    damping_constant=k)
    excess0 = 0.5 * a * el0[0] ** 2 - 0.5 * c * el0[1] ** 2
    excess = 0.5 * a * out[:, 0] ** 2 - 0.5 * c * out[:, 1] ** 2
    np.testing.assert_allclose(excess / excess0, np.exp(-2 * times / tau), rtol=1e-9)
    np.testing.assert_array_equal(out[:, 1:3], np.broadcast_to(el0[1:3], (4, 2)))  # L is conserved
    assert out[-1, 5] == el0[5]


def test_long_axis_tumbler_relaxes_through_the_separatrix():
    """Damping alone needs no torus average: the drift of S is smooth across the separatrix (d = b)."""
    sun = kepler_source(GM_SUN, 1.0, 0.1, 0.0, 0.0, 0.0, 0.0, sign=-1.0)
    model = make_model(MOMENTS, [sun])
    frame = np.diag([-1.0, -1.0, 1.0])
    omega = 2 * math.pi / 0.25
    y0 = np.array([1.0, 0.0, 0.0, 0.0, omega, 0.2 * omega, 0.2 * omega])  # LAM: energy above the separatrix
    el0 = elements_of_state(y0, model, frame)
    ic = inertia_constants(*MOMENTS)
    a, b, c, _, _, _ = ic
    assert a * el0[0] ** 2 / el0[1] ** 2 > b  # d > b: long-axis mode at the start
    tau = damping_time(el0[1], ic, 1e9)
    times = tau * np.array([1.0, 3.0, 6.0])
    out, _ = propagate_mean_thermal(el0, 0.0, times, model, frame, step=tau / 50, with_gravity=False,
                                    damping_constant=1e9)
    d = a * out[:, 0] ** 2 / out[:, 1] ** 2
    assert d[-1] < b  # short-axis mode at the end, relaxing toward C (d → c)
    excess = (d - c) / (a * el0[0] ** 2 / el0[1] ** 2 - c)
    np.testing.assert_allclose(excess, np.exp(-2 * times / tau), rtol=1e-9)
    with pytest.raises(ValueError, match="damping_constant"):
        propagate_mean_thermal(el0, 0.0, [1.0], model, frame, step=1.0, damping_constant=-1.0)
    with pytest.raises(ValueError, match="it has none"):
        propagate_mean_thermal(el0, 0.0, [1.0], model, frame, step=1.0)
