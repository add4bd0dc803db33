"""Mean-element equations: the perturbation averaged over the torque-free motion (paper eqs. 10–12).

With K = ½ a S² − U (eq. 10) the free motion moves s only (eq. 12). Along it the attitude is
quasi-periodic on a 2-torus: the body phase (s modulo one period P of the body-frame momentum) and
the precession phase about the angular momentum (g advances by Δg, not commensurate with 2π, per
period of s). For non-resonant motion the time average of U is the average over that torus, i.e.
over (s, z) uniformly; it depends on (S, Z, H, h, t) only. The mean equations (eq. 11 with ⟨U⟩)::

    dS/dt = ∂⟨U⟩/∂s = 0,   dZ/dt = ∂⟨U⟩/∂z = 0,   dH/dt = ∂⟨U⟩/∂h,
    ds/dt = a S − ∂⟨U⟩/∂S,  dz/dt = −∂⟨U⟩/∂Z,      dh/dt = −∂⟨U⟩/∂H.

Two ways to evaluate the right-hand side:

* **quadrature along the exact flow** (:func:`torus_mean_rhs`, any force function, degrees 2–4):
  eq. (11)'s right-hand side (:func:`spinorbit.core.elements.equations.elements_rhs_into`) averaged by
  the trapezoidal rule over a uniform (s, z) grid covering one period of s and 2π of z. The grid is
  a fundamental cell of the torus lattice ((s, z) → (s + P, z − Δg) is the same state), the
  integrand is smooth and periodic on it, so the rule converges geometrically; a harmonic k of the
  precession phase is integrated exactly with more than |k| points in z (degree n has |k| ≤ n).
  Terms of ∂U/∂S proportional to s (from ∂g/∂S) multiply ∂U/∂g, whose z-average is zero exactly.
* **closed form for the degree-2 (MacCullagh) torque of point masses** (:func:`degree2_mean_rhs`):
  U = −(3μ/2r³) r̂ᵀ(Rᵀ I R) r̂ + terms without attitude. The precession average makes the
  inertial-frame tensor axisymmetric about l = L/|L|: ⟨Rᵀ I R⟩ = α 1 + β l lᵀ with
  α + β = Q = ⟨m̂ᵀ I m̂⟩ (m̂ the body-frame unit momentum, averaged over the polhode) and
  3α + β = A + B + C. So ⟨U⟩ = −(3μ/2r³)[α + β (r̂·l)²]: (S, Z) are constant in the mean, l
  precesses, and only Q(d) (d = a S²/Z²) is needed. Q is computed by quadrature along the exact
  flow (:func:`polhode_mean_inertia`); the tests check it against the elliptic-integral closed form
  ⟨sn²⟩ = (K − E)/(mK), ⟨dn²⟩ = E/K. Averaging over a Keplerian orbit as well
  (⟨r̂ r̂ᵀ/r³⟩ = (1 − n nᵀ)/(2a³(1 − e²)^{3/2}), n the orbit normal) gives the doubly averaged
  ⟨⟨U⟩⟩ = −(3μ/(4a³η³))[2α + β − β (n·l)²]: uniform precession of l about n.

The reference frame of (H, h) is any inertial → reference rotation F (perturber positions are
inertial). l in the reference frame is (sin I sin h, −sin I cos h, cos I), cos I = H/Z.
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.elements.canonical import (
    MO_ARG_PER_S,
    MO_G_PER_S,
    MO_MODE,
    MO_PARAM_C,
    MO_PN_COEFF,
    MO_S_RATE,
    MODE_UNIFORM,
    body_from_argument,
    elliptic_constants,
    motion_from_elements,
)
from spinorbit.core.dynamics.equations import MODEL_PERTURBERS
from spinorbit.core.elements.equations import elements_rhs_into, force_function_of_elements
from spinorbit.core.math.elliptic import MK_K_HI, MK_K_LO, NK_COMPLETE
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C
from spinorbit.core.model.perturbers import (
    K_A,
    K_E,
    K_MEAN_MOTION,
    K_P,
    K_Q,
    K_ROOT,
    KIND_KEPLER,
    PERTURBER_ROW,
    perturber_position_xyz,
)

#: Points per period of s of the polhode quadrature. The integrand m̂ᵀ I m̂ is analytic in s; the
#: trapezoidal rule's error falls like the nome q^N (q ≈ 0.01–0.2 away from the separatrix), so 64
#: points give rounding-level Q unless |1 − m| < ~1e-3 (the validity check refuses those states).
POLHODE_POINTS = 64
#: Relative step of the central difference ∂Q/∂S (error ~ step² ≈ 1e-12, rounding ~ ε/step ≈ 1e-10).
DQ_RELATIVE_STEP = 1e-6

# Layout of the "mean constants" array of the degree-2 fast path.
MC_S, MC_Z, MC_A, MC_Q, MC_DQ_DS, MC_DQ_DZ, MC_TRACE = range(7)
MC_SIZE = 7


@jit
def torus_frequencies(big_s, big_z, ic):
    """(P, ν, ṡ_w) of the free motion of (S, Z): period of the working s, g advance per unit
    working s (averaged), and d s_w/dt = a|S| (time⁻¹). P = 4K/κ, ν = Δg/P (see
    :func:`spinorbit.core.elements.equations.reduce_phase`). Returns P = inf for a uniform rotation."""
    mo = motion_from_elements(abs(big_s), big_z, ic)
    if mo[MO_MODE] == MODE_UNIFORM or not (mo[MO_PARAM_C] > 0.0):
        return np.inf, 0.0, mo[MO_S_RATE]
    mk, pk = elliptic_constants(mo)
    period = 4.0 * (mk[MK_K_HI] + mk[MK_K_LO]) / mo[MO_ARG_PER_S]
    advance_g = mo[MO_G_PER_S] * period + mo[MO_PN_COEFF] * 4.0 * pk[NK_COMPLETE]
    return period, advance_g / period, mo[MO_S_RATE]


@jit
def polhode_mean_inertia(big_s, big_z, ic, moments, n_points):
    """Q = ⟨m̂ᵀ I m̂⟩ (mass·length²): the body-frame unit momentum's inertia averaged over one period
    of s along the exact free motion (eqs. 7, 12), trapezoidal rule on n_points equally spaced s."""
    mo = motion_from_elements(abs(big_s), big_z, ic)
    mk, _ = elliptic_constants(mo)
    four_k = 4.0 * (mk[MK_K_HI] + mk[MK_K_LO])
    acc = 0.0
    for j in range(n_points):
        mx, my, mz, _, _ = body_from_argument(four_k * j / n_points, mo, mk)
        acc += moments[0] * mx * mx + moments[1] * my * my + moments[2] * mz * mz
    return acc / (n_points * big_z * big_z)


@jit
def mean_constants(big_s, big_z, ic, moments):
    """The degree-2 fast path's constants (MC_* layout): S, Z, a, Q, ∂Q/∂S, ∂Q/∂Z, A + B + C.

    Q depends on (S, Z) through d = a S²/Z² only, so ∂Q/∂Z = −(S/Z) ∂Q/∂S.
    """
    out = np.empty(MC_SIZE)
    step = DQ_RELATIVE_STEP * abs(big_s)
    q_hi = polhode_mean_inertia(abs(big_s) + step, big_z, ic, moments, POLHODE_POINTS)
    q_lo = polhode_mean_inertia(abs(big_s) - step, big_z, ic, moments, POLHODE_POINTS)
    dq = (q_hi - q_lo) / (2.0 * step) * (1.0 if big_s >= 0.0 else -1.0)
    out[MC_S] = big_s
    out[MC_Z] = big_z
    a, _b, _c, _a_b, _b_c, _a_c = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    out[MC_A] = a
    out[MC_Q] = polhode_mean_inertia(big_s, big_z, ic, moments, POLHODE_POINTS)
    out[MC_DQ_DS] = dq
    out[MC_DQ_DZ] = -big_s / big_z * dq
    out[MC_TRACE] = moments[0] + moments[1] + moments[2]
    return out


@jit(inline="always")
def _axisymmetric_term(weight, c0, c0_s, c0_z, c1, c1_s, c1_z, dx, dy, dz, big_z, big_h, h):
    """weight·(c0 + c1 p²), p = d·l (d a reference-frame unit vector), and its partials in
    (S, Z, H, h): five floats (inlined: no array crosses a call on the hot path)."""
    cos_i = big_h / big_z
    sin_i = math.sqrt(max((big_z - big_h) * (big_z + big_h), 0.0)) / big_z
    sh, ch = math.sin(h), math.cos(h)
    along = dx * sh - dy * ch  # ∂p/∂(sin I)
    p = sin_i * along + dz * cos_i
    dp_dh = sin_i * (dx * ch + dy * sh)
    dp_dbig_h = -along * cos_i / (big_z * sin_i) + dz / big_z
    dp_dz = along * cos_i * cos_i / (big_z * sin_i) - dz * cos_i / big_z
    return (weight * (c0 + c1 * p * p), weight * (c0_s + c1_s * p * p),
            weight * (c0_z + c1_z * p * p + 2.0 * c1 * p * dp_dz), weight * 2.0 * c1 * p * dp_dbig_h,
            weight * 2.0 * c1 * p * dp_dh)


@jit(inline="always")
def _alpha_beta(mc):
    """(α, ∂α/∂S, ∂α/∂Z, β, ∂β/∂S, ∂β/∂Z) of ⟨Rᵀ I R⟩ = α 1 + β l lᵀ (module docstring)."""
    q, q_s, q_z, trace = mc[MC_Q], mc[MC_DQ_DS], mc[MC_DQ_DZ], mc[MC_TRACE]
    return 0.5 * (trace - q), -0.5 * q_s, -0.5 * q_z, 0.5 * (3.0 * q - trace), 1.5 * q_s, 1.5 * q_z


@jit(inline="always")
def _point_mass_term(mu, ix, iy, iz, elements, mc, frame):
    """Degree-2 ⟨U⟩ of one point mass μ at inertial position (ix, iy, iz) and its partials in
    (S, Z, H, h): five floats."""
    alpha, alpha_s, alpha_z, beta, beta_s, beta_z = _alpha_beta(mc)
    norm = math.sqrt(ix * ix + iy * iy + iz * iz)
    weight = -1.5 * mu / norm ** 3
    dx = (frame[0, 0] * ix + frame[0, 1] * iy + frame[0, 2] * iz) / norm
    dy = (frame[1, 0] * ix + frame[1, 1] * iy + frame[1, 2] * iz) / norm
    dz = (frame[2, 0] * ix + frame[2, 1] * iy + frame[2, 2] * iz) / norm
    return _axisymmetric_term(weight, alpha, alpha_s, alpha_z, beta, beta_s, beta_z, dx, dy, dz,
                              elements[1], elements[2], elements[5])


@jit
def degree2_mean_partials(t, elements, mc, model, frame, orbit_averaged):
    """(⟨U⟩, ∂⟨U⟩/∂(S, Z, H, h)) of the degree-2 torque of every perturber (module docstring).

    orbit_averaged: also average over each perturber's Keplerian orbit (elliptic KIND_KEPLER rows
    only; others are used at their instantaneous position).
    """
    du = np.zeros(4)
    u = degree2_mean_partials_into(t, elements, mc, model, frame, orbit_averaged, du)
    return u, du


@jit
def degree2_mean_partials_into(t, elements, mc, model, frame, orbit_averaged, du):
    """:func:`degree2_mean_partials` writing ∂⟨U⟩/∂(S, Z, H, h) into du (4,), returning ⟨U⟩; no
    allocation (the mean equations' inner call)."""
    alpha, alpha_s, alpha_z, beta, beta_s, beta_z = _alpha_beta(mc)
    for i in range(4):
        du[i] = 0.0
    u = 0.0
    for k in range(int(model[MODEL_PERTURBERS])):
        row = MODEL_PERTURBERS + 1 + k * PERTURBER_ROW
        mu = model[row + 1]
        par = row + 2
        if orbit_averaged and model[row] == KIND_KEPLER and model[par + K_E] < 1.0:
            semi, ecc = model[par + K_A], model[par + K_E]
            px, py, pz = model[par + K_P], model[par + K_P + 1], model[par + K_P + 2]
            qx, qy, qz = model[par + K_Q], model[par + K_Q + 1], model[par + K_Q + 2]
            ix, iy, iz = py * qz - pz * qy, pz * qx - px * qz, px * qy - py * qx  # orbit normal
            weight = -3.0 * mu / (4.0 * semi ** 3 * (1.0 - ecc * ecc) ** 1.5)
            dx = frame[0, 0] * ix + frame[0, 1] * iy + frame[0, 2] * iz
            dy = frame[1, 0] * ix + frame[1, 1] * iy + frame[1, 2] * iz
            dz = frame[2, 0] * ix + frame[2, 1] * iy + frame[2, 2] * iz
            term = _axisymmetric_term(weight, 2.0 * alpha + beta, 2.0 * alpha_s + beta_s, 2.0 * alpha_z + beta_z,
                                      -beta, -beta_s, -beta_z, dx, dy, dz, elements[1], elements[2], elements[5])
        else:
            ix, iy, iz = perturber_position_xyz(t, model, row)
            term = _point_mass_term(mu, ix, iy, iz, elements, mc, frame)
        u += term[0]
        for i in range(4):
            du[i] += term[1 + i]
    return u


@jit
def degree2_mean_rhs(t, elements, mc, model, frame, orbit_averaged, dy):
    """Mean eq. (11) with the closed-form degree-2 ⟨U⟩: writes d(S, Z, H, s, z, h)/dt into dy."""
    du = dy[2:6]  # scratch: the four partials, written before the rates that overwrite them
    degree2_mean_partials_into(t, elements, mc, model, frame, orbit_averaged, du)
    d_s, d_z, d_h_big, d_h = du[0], du[1], du[2], du[3]
    dy[0] = 0.0
    dy[1] = 0.0
    dy[2] = d_h
    dy[3] = mc[MC_A] * elements[0] - d_s
    dy[4] = -d_z
    dy[5] = -d_h_big


@jit(inline="always")
def anomaly_position_xyz(f, model, par):
    """(x, y, z, dt/df) of the elliptic KIND_KEPLER row with parameters at model[par:] at true anomaly
    f: r = a(1 − e²)/(1 + e cos f) along P cos f + Q sin f, and dt/df = r²/(n a² √(1 − e²)) (the
    areal velocity is constant). No Kepler equation to solve."""
    ecc, semi = model[par + K_E], model[par + K_A]
    cf, sf = math.cos(f), math.sin(f)
    r = semi * (1.0 - ecc) * (1.0 + ecc) / (1.0 + ecc * cf)
    px, py = r * cf, r * sf
    dt_df = r * r / (model[par + K_MEAN_MOTION] * semi * semi * model[par + K_ROOT])
    return (model[par + K_P] * px + model[par + K_Q] * py, model[par + K_P + 1] * px + model[par + K_Q + 1] * py,
            model[par + K_P + 2] * px + model[par + K_Q + 2] * py, dt_df)


@jit(inline="always")
def degree2_mean_rhs_anomaly(f, elements, mc, model, frame, dy):
    """Mean eq. (11), degree-2 ⟨U⟩ of the one perturber of ``model`` (an elliptic Kepler orbit),
    with its true anomaly f as the independent variable: writes d(S, Z, H, s, z, h)/df into dy,
    *without* the free rate a S of s (which the caller adds exactly as a S Δt).

    In f the torque is (dt/df)/r³ · r̂ r̂ᵀ ∝ (1 + e cos f) r̂ r̂ᵀ: a trigonometric polynomial of
    degree 3 in f, so a step spans the perihelion passage as well as the aphelion one.
    """
    row = MODEL_PERTURBERS + 1
    ix, iy, iz, dt_df = anomaly_position_xyz(f, model, row + 2)
    _, d_s, d_z, d_h_big, d_h = _point_mass_term(model[row + 1], ix, iy, iz, elements, mc, frame)
    dy[0] = 0.0
    dy[1] = 0.0
    dy[2] = d_h * dt_df
    dy[3] = -d_s * dt_df
    dy[4] = -d_z * dt_df
    dy[5] = -d_h_big * dt_df


@jit
def torus_mean_force_function(t, elements, model, frame, ic, n_s, n_z):
    """⟨U⟩(S, Z, H, h; t) by quadrature along the exact flow: U averaged over an n_s × n_z trapezoidal
    grid of the torus (s over one period of the working s, z over 2π), energy units."""
    period, _, _ = torus_frequencies(elements[0], elements[1], ic)
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    point = elements.copy()
    acc = 0.0
    for j in range(n_s):
        point[3] = sign * period * j / n_s
        for k in range(n_z):
            point[4] = 2.0 * math.pi * k / n_z
            acc += force_function_of_elements(t, point, model, frame, ic)
    return acc / (n_s * n_z)


#: Relative step (of Z) of the central differences of ⟨U⟩ in S and Z of :func:`torus_mean_rhs`.
TORUS_DIFFERENCE_STEP = 1e-5


@jit
def torus_mean_rhs(t, elements, model, frame, ic, n_s, n_z, dy):
    """Mean eq. (11) by quadrature along the exact flow, any force function (degrees 2–4).

    dH/dt and dh/dt are eq. (11)'s ∂U/∂h and −∂U/∂H averaged over the torus grid (H and h do not
    move the torus lattice, so these averages are ∂⟨U⟩/∂h and ∂⟨U⟩/∂H). ∂⟨U⟩/∂S and ∂⟨U⟩/∂Z are
    central differences of :func:`torus_mean_force_function`: the grid average of ∂U/∂S at fixed s
    would not be ∂⟨U⟩/∂S, because the period P(S, Z) and advance Δg(S, Z) of the lattice depend on S
    and Z (the result would depend on which cell of s is sampled). n_z > the highest degree makes the
    z-average exact for the precession harmonics.
    """
    period, _, _ = torus_frequencies(elements[0], elements[1], ic)
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    point = elements.copy()
    buf = np.empty(6)
    dh_sum = 0.0
    dbig_h_sum = 0.0
    for j in range(n_s):
        point[3] = sign * period * j / n_s
        for k in range(n_z):
            point[4] = 2.0 * math.pi * k / n_z
            elements_rhs_into(t, point, model, frame, ic, buf)
            dbig_h_sum += buf[2]
            dh_sum += buf[5]
    step = TORUS_DIFFERENCE_STEP * elements[1]
    partial = np.empty(2)
    for i in range(2):
        point = elements.copy()
        point[i] += step
        hi = torus_mean_force_function(t, point, model, frame, ic, n_s, n_z)
        point[i] -= 2.0 * step
        lo = torus_mean_force_function(t, point, model, frame, ic, n_s, n_z)
        partial[i] = (hi - lo) / (2.0 * step)
    dy[0] = 0.0
    dy[1] = 0.0
    dy[2] = dbig_h_sum / (n_s * n_z)
    a, _b, _c, _a_b, _b_c, _a_c = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    dy[3] = a * elements[0] - partial[0]
    dy[4] = -partial[1]
    dy[5] = dh_sum / (n_s * n_z)


@jit
def fast_frequencies(elements, ic):
    """(ω_s, ω_g): angular rates (rad/time) of the body phase (2π/P per period of s) and of the mean
    precession (the averaged ġ) of the free motion of the elements' (S, Z)."""
    period, nu, s_rate = torus_frequencies(elements[0], elements[1], ic)
    return 2.0 * math.pi / period * s_rate, nu * s_rate


def element_differences(first, second, ic):
    """Differences first − second of signed elements (n, 6) as (ΔS, ΔZ, ΔH, Δθ, Δz, Δh).

    θ = 2π s/P is the body phase (rad). The two rows may sit in different cells of the torus lattice
    ((s, z) ~ (s + P, z − Δg)): the second is moved into the first's cell before subtracting, and
    angle differences are reduced to (−π, π].
    """
    first = np.atleast_2d(np.asarray(first, dtype=float))
    second = np.atleast_2d(np.asarray(second, dtype=float))
    out = np.empty_like(first)
    for i in range(first.shape[0]):
        period, nu, _ = torus_frequencies(first[i, 0], first[i, 1], ic)
        sign = 1.0 if first[i, 0] >= 0.0 else -1.0
        cells = np.rint(sign * (first[i, 3] - second[i, 3]) / period)
        s2 = second[i, 3] + sign * cells * period
        z2 = second[i, 4] - cells * nu * period
        out[i, :3] = first[i, :3] - second[i, :3]
        out[i, 3] = 2.0 * math.pi * sign * (first[i, 3] - s2) / period
        out[i, 4] = first[i, 4] - z2
        out[i, 5] = first[i, 5] - second[i, 5]
    out[:, 3:] = (out[:, 3:] + math.pi) % (2.0 * math.pi) - math.pi
    return out


def moments_of(model):
    """(A, B, C) of a model array as a float array."""
    return np.array([model[BODY_A], model[BODY_B], model[BODY_C]])
