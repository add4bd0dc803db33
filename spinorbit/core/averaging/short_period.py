"""First-order short-period corrections: mean ↔ osculating canonical elements.

Lie-series averaging of K = ½ a S² − U (paper eq. 10) about the free motion (eq. 12). The
generating function W solves the homological equation along the free flow

    a S ∂W/∂s|_z = U − ⟨U⟩,

single valued on the torus of the free motion. In torus coordinates (s_w, ψ), s_w the working s
(S ≥ 0) and ψ = z + ν s_w (ν = mean g advance per unit s_w), U − ⟨U⟩ = Σ c_jk e^{i(jω s_w + kψ)}
with ω = 2π/P, and

    W = Σ_{(j,k) ≠ 0} c_jk e^{i(jω s_w + kψ)} / (i Ω_jk),   Ω_jk = a|S| (jω + kν),

the c_jk from a 2-D FFT of U sampled on the torus grid (:func:`torus_u_grid`). The osculating
elements are x_osc = x_mean + {x, W}: ΔS = ∂W/∂s, ΔZ = ∂W/∂z, ΔH = ∂W/∂h, Δs = −∂W/∂S,
Δz = −∂W/∂Z, Δh = −∂W/∂H. ∂W/∂s = (U − ⟨U⟩)/(aS) and ∂W/∂z are spectral; the momentum partials are
central differences of W at fixed (s, z, h). U also moves with time t through the perturbers (orbital time scale, rate n ≪ Ω); the
homological equation is then a S ∂W/∂s + ∂W/∂t = U − ⟨U⟩, solved to third order in n/Ω:
Ŵ_jk = c_jk/(iΩ_jk) − ċ_jk/(iΩ_jk)² + c̈_jk/(iΩ_jk)³ − c⃛_jk/(iΩ_jk)⁴ (without the ċ term the
corrections keep an error ∝ the torque × n/Ω, measured as a first-order slope; the c̈ term removes
the next one, which at perihelion of the Toutatis-like orbit, n/Ω ≈ 1/9, left mean momenta off by
~1e-7 Z and hence a precession-phase drift; the c⃛ term cuts the remaining drift of z 5×, a c⁗ term
no further: TIME_DERIVATIVE_ORDER). Small divisors Ω_jk → 0 are the internal and spin–orbit resonances that
:mod:`spinorbit.core.averaging.propagate` refuses.
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.averaging.mean_equations import torus_frequencies
from spinorbit.core.elements.canonical import (
    elliptic_constants,
    motion_from_elements,
    state_from_elements_motion,
)
from spinorbit.core.dynamics.equations import force_function_and_torque_xyz
from spinorbit.core.elements.equations import inertial_quaternion, reduce_phase, working_elements
from spinorbit.core.model.gravity_field import BODY_NMAX

#: Torus grid (points per period of s, points in the precession phase ψ) by the figure's degree.
#: Degree 2 has ψ-harmonics |k| ≤ 2 (8 points resolve them exactly); 32 points in s leave 4e-12 of
#: corrections of ~1e-5 in the Apophis- and Toutatis-like scenes (measured against 128 × 16).
#: Degrees 3–4 (|k| ≤ 4): 64 × 16.
GRID_DEGREE2 = (32, 8)
GRID_DEGREE4 = (64, 16)
#: Relative size (to the largest harmonic of U − ⟨U⟩) below which a harmonic is rounding noise.
HARMONIC_NOISE = 1e-11
#: Highest time derivative of U kept in W (1: ċ; 2: ċ, c̈; 3: ċ, c̈, c⃛). The series in n/Ω is
#: asymptotic, so more terms help only up to a point. Measured on the Toutatis-like scene (Sun only,
#: n/Ω ≈ 1/9 at perihelion), 100 orbits against heyoka's mean elements (same map on both sides),
#: largest z error: order 2 3.5e-3 rad, order 3 7.1e-4 (7.6e-4 with 3-point ċ, c̈), order 4 (a
#: 5-point fourth difference) 9.0e-4; Apophis-like (Ω_min/n ≈ 20 at perihelion) 7.08e-6 (order 2),
#: 7.05e-6 (order 3).
TIME_DERIVATIVE_ORDER = 3
#: The c⃛ term is kept only for harmonics above this fraction of the largest: on the small ones its
#: third difference, divided by Ω_jk⁴, is rounding noise that the central differences of W amplify
#: (measured, Apophis-like: the 3-step osculating → mean → osculating round trip at 10× / 100× /
#: 1000× the solar torque erred by 1.3e-9 / 1.2e-8 / 3.9e-7 with the term on every harmonic where it
#: is smaller than the c̈ term, 8.4e-11 / 9.3e-10 / 3.6e-8 with this floor, 2.3e-11 / 6.1e-10 /
#: 3.2e-8 at order 2). The Toutatis-like gain (TIME_DERIVATIVE_ORDER) is the same with the floor.
THIRD_TERM_FLOOR = 1e-6
#: Time step of ∂U/∂t, as a fraction of the fastest period of the free motion. The truncation error
#: of the differences is ~ (n δt)² ≈ 1e-5 relative; 1e-2 was measured worse (the second difference
#: then amplifies the grid's rounding: round trips of 2e-7 instead of 3e-9 at 100× the solar torque).
TIME_DIFFERENCE_FRACTION = 0.1
#: Relative step (of Z) of the central differences of W in S, Z, H; absolute step (rad) in h.
W_DIFFERENCE_STEP = 1e-5


@jit
def torus_u_grid(times, elements, model, frame, ic, n_s, n_psi):
    """U (energy) on the (s_w, ψ) grid s_w = P j/n_s, ψ = 2π k/n_psi at the elements' (S, Z, H, h),
    at each of ``times``: shape (len(times), n_s, n_psi). The attitude of each grid point is built
    once for all times."""
    period, nu, _ = torus_frequencies(elements[0], elements[1], ic)
    work, flip = working_elements(elements)
    # The motion and elliptic constants of (S, Z) once for the whole grid (they cost as much as the
    # rest of a backward map).
    mo = motion_from_elements(work[0], work[1], ic)
    mk, pk = elliptic_constants(mo)
    out = np.empty((times.shape[0], n_s, n_psi))
    for j in range(n_s):
        s_w = period * j / n_s
        work[3] = s_w
        for k in range(n_psi):
            work[4] = 2.0 * math.pi * k / n_psi - nu * s_w
            attitude, _ = state_from_elements_motion(work, flip, mo, mk, pk)
            q = inertial_quaternion(attitude, frame)
            for i in range(times.shape[0]):
                out[i, j, k] = force_function_and_torque_xyz(times[i], q[0], q[1], q[2], q[3], model)[0]
    return out


def _generating_coefficients(t, elements, model, frame, ic, n_s, n_psi):
    """(Ŵ, jω + kν per unit s_w, k, ν, mean U) of W's Fourier series at the elements' momenta."""
    period, nu, s_rate = torus_frequencies(elements[0], elements[1], ic)
    # ∂U/∂t and ∂²U/∂t² through the perturbers' motion: central differences over a fraction of the
    # fastest torus period (the grid varies on the orbital time scale).
    omega_fast = max(2.0 * math.pi / period, abs(nu)) * s_rate
    dt = TIME_DIFFERENCE_FRACTION * 2.0 * math.pi / omega_fast
    five = TIME_DERIVATIVE_ORDER > 2  # c⃛ needs t ± 2δt; ċ, c̈ then take the 4th-order stencils
    offsets = (0.0, 1.0, -1.0, 2.0, -2.0) if five else (0.0, 1.0, -1.0)
    grids = torus_u_grid(np.array([t + m * dt for m in offsets]), elements, model, frame, ic, n_s, n_psi)
    c = [np.fft.fft2(g) / (n_s * n_psi) for g in grids]
    coeff = c[0]
    if five:
        c_dot = (8.0 * (c[1] - c[2]) - (c[3] - c[4])) / (12.0 * dt)
        c_ddot = (16.0 * (c[1] + c[2]) - (c[3] + c[4]) - 30.0 * coeff) / (12.0 * dt * dt)
        c_dddot = ((c[3] - c[4]) - 2.0 * (c[1] - c[2])) / (2.0 * dt**3)
    else:
        c_dot = (c[1] - c[2]) / (2.0 * dt)
        c_ddot = (c[1] - 2.0 * coeff + c[2]) / (dt * dt)
        c_dddot = 0.0
    j = np.fft.fftfreq(n_s, 1.0 / n_s)[:, None]
    k = np.fft.fftfreq(n_psi, 1.0 / n_psi)[None, :]
    rate = j * (2.0 * math.pi / period) + k * nu  # d(phase)/d s_w
    mean_u = coeff[0, 0].real
    # Harmonics at the rounding level of the grid are dropped: with a small divisor Ω_jk (some
    # jω + kν is always close to 0 on a large grid) their noise, divided by Ω³ in the c̈ term, would
    # dominate the corrections.
    coeff[0, 0] = 0.0
    significant = np.abs(coeff) > HARMONIC_NOISE * np.abs(coeff).max()
    with np.errstate(divide="ignore", invalid="ignore"):
        i_omega = 1j * s_rate * rate
        third = c_dddot / i_omega**4 if TIME_DERIVATIVE_ORDER > 2 else np.zeros_like(coeff)
        third = np.where(np.abs(coeff) > THIRD_TERM_FLOOR * np.abs(coeff).max(), third, 0.0)
        w_hat = np.where(~significant, 0.0, coeff / i_omega - c_dot / i_omega**2
                         + (c_ddot / i_omega**3 if TIME_DERIVATIVE_ORDER > 1 else 0.0) - third)
    return w_hat, rate, k, nu, mean_u


def _series(w_hat, rate, k, nu, elements, factor=None):
    """Real part of Σ Ŵ·factor e^{i(jω s_w + kψ)} at the elements' (s, z)."""
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    s_w = sign * elements[3]
    psi = elements[4] + nu * s_w
    j_omega = rate - k * nu
    phase = np.exp(1j * (j_omega * s_w + k * psi))
    terms = w_hat * phase if factor is None else w_hat * factor * phase
    return float(np.sum(terms).real)


def torus_grid_for(model):
    """(n_s, n_psi) of the short-period grid for a model's figure degree."""
    return GRID_DEGREE2 if model[BODY_NMAX] <= 2 else GRID_DEGREE4


def generating_function(t, elements, model, frame, ic, n_s=None, n_psi=None):
    """W(t, elements) (energy·time): the first-order generating function (module docstring)."""
    if n_s is None or n_psi is None:
        n_s, n_psi = torus_grid_for(model)
    w_hat, rate, k, nu, _ = _generating_coefficients(t, elements, model, frame, ic, n_s, n_psi)
    return _series(w_hat, rate, k, nu, elements)


def short_period_offsets(t, elements, model, frame, ic, n_s=None, n_psi=None):
    """{x, W} at the elements: (ΔS, ΔZ, ΔH, Δs, Δz, Δh) with osculating = mean + Δ to first order.

    Parameters
    ----------
    t : float
        Time (model unit).
    elements : (6,) ndarray
        Signed (S, Z, H, s, z, h) referred to ``frame``.
    model, frame, ic
        As for :func:`spinorbit.core.elements.equations.elements_rhs_into`.
    n_s, n_psi : int, optional
        Torus grid; default :func:`torus_grid_for`.

    Returns
    -------
    (6,) ndarray
        Momenta in the momentum unit, angles in rad (s in its own unit).
    """
    if n_s is None or n_psi is None:
        n_s, n_psi = torus_grid_for(model)
    elements = np.ascontiguousarray(elements, dtype=float)
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    w_hat, rate, k, nu, _ = _generating_coefficients(t, elements, model, frame, ic, n_s, n_psi)
    out = np.empty(6)
    out[0] = sign * _series(w_hat, rate, k, nu, elements, 1j * rate)  # ∂W/∂s = sign ∂W/∂s_w
    out[1] = _series(w_hat, rate, k, nu, elements, 1j * k)  # ∂W/∂z
    steps = (W_DIFFERENCE_STEP * elements[1],) * 3 + (W_DIFFERENCE_STEP,)
    partial = []
    for index, step in zip((0, 1, 2, 5), steps):
        values = []
        for delta in (step, -step):
            shifted = elements.copy()
            shifted[index] += delta
            values.append(generating_function(t, shifted, model, frame, ic, n_s, n_psi))
        partial.append((values[0] - values[1]) / (2.0 * step))
    d_big_s, d_big_z, d_big_h, d_h = partial
    out[2] = d_h
    out[3] = -d_big_s
    out[4] = -d_big_z
    out[5] = -d_big_h
    return out


def mean_to_osculating(t, mean, model, frame, ic):
    """Osculating elements of mean elements at time t (first order): x + {x, W}(x)."""
    osc = np.asarray(mean, dtype=float) + short_period_offsets(t, mean, model, frame, ic)
    reduce_phase(osc, ic)
    return osc


def osculating_to_mean(t, osc, model, frame, ic, iterations=2):
    """Mean elements of osculating elements at time t: the inverse of :func:`mean_to_osculating`,
    solved by fixed-point iteration x ← x_osc − {x, W}(x) (each iteration gains one order)."""
    osc = np.ascontiguousarray(osc, dtype=float).copy()
    reduce_phase(osc, ic)
    mean = osc.copy()
    for _ in range(iterations):
        mean = osc - short_period_offsets(t, mean, model, frame, ic)
    reduce_phase(mean, ic)
    return mean
