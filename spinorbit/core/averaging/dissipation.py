"""Nutation damping: anelastic dissipation drives a tumbler toward rotation about its axis of largest moment.

Internal friction conserves the angular momentum L (so Z, H and h are constant) and removes the
rotational energy E = ½ a S² (the free Hamiltonian, eq. 10: S = √(d/a) Z, 2E = d Z²) down to the
minimum E_min = ½ c Z² of rotation about C. The published time scale is Burns & Safronov's
(1973, MNRAS 165, 403; used by Harris 1994, Icarus 107, 209, and revisited by Sharma, Burns & Hui
2005, MNRAS 359, 79)::

    τ_D = μ Q / (ρ K₃² R² ω³)

with μ the rigidity, Q the quality factor, ρ the density, R the mean radius, ω the spin rate and
K₃² Burns & Safronov's dimensionless shape factor.
It is the e-folding time of the nutation angle θ; the energy above E_min goes as θ², so here

    d(E − E_min)/dt = −2 (E − E_min) / τ_D,   dS/dt = (dE/dt) / (a S)    (Z, H, h fixed),

with ω = c Z (the spin rate of the principal-axis state the body relaxes to). The form of the decay
(exponential in the excess energy) is this model's choice; its time scale is the published one. The
units layer supplies k = μQ/(ρ K₃² R²) in the model's time⁻², so that τ_D = k / ω³.
"""

from spinorbit.core.jit import jit

__all__ = ["damping_time", "damping_rate_of_s", "damping_constant"]


def damping_constant(mu_q, density, radius, k3_squared, time_unit=86400.0):
    """k = μQ/(ρ K₃² R²) in the model's time⁻² from SI values, so that τ_D = k/ω³ (ω in rad per time unit).

    Parameters
    ----------
    mu_q : float
        Rigidity times quality factor, μQ (Pa).
    density : float
        ρ (kg/m³).
    radius : float
        Mean radius R (m).
    k3_squared : float
        Burns & Safronov's shape factor K₃² (dimensionless).
    time_unit : float
        Seconds per model time unit (86400: days).
    """
    for name, value in (("mu_q", mu_q), ("density", density), ("radius", radius), ("k3_squared", k3_squared)):
        if not (value > 0.0 and value < float("inf")):
            raise ValueError(f"{name}: expected a positive finite number (SI); got {value!r}.")
    return mu_q / (density * k3_squared * radius * radius) * time_unit * time_unit


@jit
def damping_time(big_z, ic, damping_constant):
    """τ_D = k / ω³ with ω = c Z (time): Burns & Safronov's nutation damping time (module docstring)."""
    _, _, c, _, _, _ = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    omega = c * big_z
    return damping_constant / (omega * omega * omega)


@jit
def damping_rate_of_s(big_s, big_z, ic, damping_constant):
    """dS/dt of the damping (S drifts toward √(c/a) Z, rotation about C; the sign of S is kept)."""
    a, _, c, _, _, _ = ic
    excess = 0.5 * a * big_s * big_s - 0.5 * c * big_z * big_z
    if excess <= 0.0 or damping_constant <= 0.0:
        return 0.0
    return -2.0 * excess / damping_time(big_z, ic, damping_constant) / (a * big_s)
