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
Δz = −∂W/∂Z, Δh = −∂W/∂H. ∂W/∂s = (U − ⟨U⟩)/(aS) and ∂W/∂z are spectral; ∂W/∂H and ∂W/∂h are the same
series of ∂U/∂H, ∂U/∂h (from the torque: H, h leave the free motion unchanged); ∂W/∂S is a
central difference of W at fixed (s, z, H, h), ∂W/∂Z follows from Euler's relation for W's terms,
which are homogeneous in the momenta (:func:`_short_period_offsets`). U also moves with time t through the perturbers (orbital time scale, rate n ≪ Ω); the
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
    body_part_of_elements,
    elliptic_constants,
    motion_from_elements,
    state_from_body_part,
)
from spinorbit.core.dynamics.equations import (
    MODEL_PERTURBERS,
    body_frame_xyz,
    perturber_force_function_and_torque_xyz,
)
from spinorbit.core.elements.equations import (
    andoyer_h_partials,
    inertial_quaternion,
    reduce_phase,
    working_elements,
)
from spinorbit.core.model.gravity_field import BODY_NMAX
from spinorbit.core.model.perturbers import PERTURBER_ROW, perturber_position_xyz
from spinorbit.core.math.rotations import qmul_parts

#: Torus grid (points per period of s, points in the precession phase ψ) by the figure's degree.
#: Degree 2 has ψ-harmonics |k| ≤ 2 (8 points resolve them exactly); 32 points in s leave 4e-12 of
#: corrections of ~1e-5 in the Apophis- and Toutatis-like scenes (measured against 128 × 16).
#: Degrees 3–4 (|k| ≤ 4): 64 × 16.
GRID_DEGREE2 = (32, 8)
GRID_DEGREE4 = (64, 16)
#: Grid of the first osculating → mean iteration (of two or more), degree-2 figures. Its error η
#: reaches the result only through the next one, as ∂{x, W}/∂x · η ~ ε η (ε ≈ 0.0025 for the
#: Apophis-like scene), so a coarser grid costs nothing visible and halves that iteration's cost
#: (the round trip of test_mean_osculating_round_trip, 3 iterations, stays at its floor of
#: 1e-8 … 1e-6 of the correction, set by the central differences of W, at × 1 … × 100 the torque;
#: coarse in the first two iterations it reached 2.4e-6 at × 100).
#: Measured against 32 × 8 throughout (Apophis- and Toutatis-like, t = 0 and 150 d, torque × 1 and
#: × 10): 16 × 8 changes the mean elements by ≤ 2e-13 Z and ≤ 1.2e-10 rad (× 1: ≤ 2e-15 Z,
#: 3e-12 rad, the size of the last iteration's own step from the fixed point); 12 × 8 by up to
#: 7e-10 rad at × 10 (tests/test_averaged.py, test_coarse_first_iteration).
FIRST_ITERATION_GRID_DEGREE2 = (16, 8)
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
#: Relative step (of Z) of the central differences of W in S and Z (∂W/∂H, ∂W/∂h come from the torque).
W_DIFFERENCE_STEP = 1e-5


# Fields of the torus grids: U and its partials in H and h at fixed (S, Z, s, z), from the torque.
FIELD_U, FIELD_DU_DH, FIELD_DU_DSMALL_H = range(3)


@jit
def torus_grids(times, elements, model, frame, ic, n_s, n_psi, n_fields):
    """U (energy), and for ``n_fields`` = 3 also ∂U/∂H, ∂U/∂h, on the (s_w, ψ) grid s_w = P j/n_s,
    ψ = 2π k/n_psi at the elements' (S, Z, H, h), at each of ``times``: shape
    (len(times), n_fields, n_s, n_psi) (FIELD_*).

    The free motion's body part (one sn/cn/dn and one pn) and the backward map are evaluated once
    per s_w: along ψ only z, hence g, moves (:func:`.canonical.body_part_of_elements`), and z is the
    angle about the angular momentum, so a step δ in z turns the body by δ about the (inertial,
    constant) momentum direction: each point of the row is that turn of its first point (one
    quaternion product instead of a backward map; checked against it in tests/test_averaged.py).
    ∂U/∂H and ∂U/∂h are the Andoyer partials from the torque
    (:func:`.equations.andoyer_h_partials`: they need only the reference-frame momentum, the same on
    the whole grid, and the reference-frame torque): H and h are both an Andoyer and a canonical
    pair, so they are the canonical partials too, exactly, with no difference step.
    """
    period, nu, _ = torus_frequencies(elements[0], elements[1], ic)
    work, flip = working_elements(elements)
    # The motion and elliptic constants of (S, Z) once for the whole grid (they cost as much as the
    # rest of a backward map).
    mo = motion_from_elements(work[0], work[1], ic)
    mk, pk = elliptic_constants(mo)
    # the perturbers' positions once per time, not once per grid point (a Kepler solve each)
    n_perturbers = int(model[MODEL_PERTURBERS])
    n_times = times.shape[0]
    positions = np.empty((n_times, n_perturbers, 3))
    mus = np.empty(n_perturbers)
    for p in range(n_perturbers):
        row = MODEL_PERTURBERS + 1 + p * PERTURBER_ROW
        mus[p] = model[row + 1]
        for i in range(n_times):
            positions[i, p, 0], positions[i, p, 1], positions[i, p, 2] = perturber_position_xyz(times[i], model, row)
    out = np.empty((n_times, n_fields, n_s, n_psi))
    m0, m1 = 0.0, 0.0  # reference-frame angular momentum (x, y): the same at every grid point
    for j in range(n_s):
        s_w = period * j / n_s
        work[3] = s_w
        work[4] = -nu * s_w  # ψ = 0
        attitude, momentum = state_from_body_part(work, flip, body_part_of_elements(s_w, mo, mk, pk))
        q_first = inertial_quaternion(attitude, frame)
        axis = inertial_direction(q_first, momentum)
        if j == 0:
            m0 = attitude[0, 0] * momentum[0] + attitude[1, 0] * momentum[1] + attitude[2, 0] * momentum[2]
            m1 = attitude[0, 1] * momentum[0] + attitude[1, 1] * momentum[1] + attitude[2, 1] * momentum[2]
        for k in range(n_psi):
            half = math.pi * k / n_psi
            sin_half = math.sin(half)
            q0, q1, q2, q3 = qmul_parts(math.cos(half), sin_half * axis[0], sin_half * axis[1], sin_half * axis[2],
                                        q_first[0], q_first[1], q_first[2], q_first[3])
            for i in range(n_times):
                u, nx, ny, nz = 0.0, 0.0, 0.0, 0.0
                for p in range(n_perturbers):
                    u_p, nx_p, ny_p, nz_p = perturber_force_function_and_torque_xyz(
                        q0, q1, q2, q3, positions[i, p, 0], positions[i, p, 1], positions[i, p, 2], mus[p], model)
                    u, nx, ny, nz = u + u_p, nx + nx_p, ny + ny_p, nz + nz_p
                out[i, FIELD_U, j, k] = u
                if n_fields > 1:
                    # body torque → inertial (the conjugate's body-frame map) → reference frame
                    ex, ey, ez = body_frame_xyz(q0, -q1, -q2, -q3, nx, ny, nz)
                    n0 = frame[0, 0] * ex + frame[0, 1] * ey + frame[0, 2] * ez
                    n1 = frame[1, 0] * ex + frame[1, 1] * ey + frame[1, 2] * ez
                    n2 = frame[2, 0] * ex + frame[2, 1] * ey + frame[2, 2] * ez
                    out[i, FIELD_DU_DH, j, k], out[i, FIELD_DU_DSMALL_H, j, k] = andoyer_h_partials(m0, m1, n0, n1, n2)
    return out


@jit
def inertial_direction(q, body_vector):
    """Unit vector (3,) along q ⊗ v ⊗ q* (body → inertial) of a body-frame vector."""
    w, x, y, z = q[0], q[1], q[2], q[3]
    vx, vy, vz = body_vector[0], body_vector[1], body_vector[2]
    out = np.empty(3)
    out[0] = (w * w + x * x - y * y - z * z) * vx + 2.0 * (x * y - w * z) * vy + 2.0 * (x * z + w * y) * vz
    out[1] = 2.0 * (x * y + w * z) * vx + (w * w - x * x + y * y - z * z) * vy + 2.0 * (y * z - w * x) * vz
    out[2] = 2.0 * (x * z - w * y) * vx + 2.0 * (y * z + w * x) * vy + (w * w - x * x - y * y + z * z) * vz
    return out / math.sqrt(out[0] ** 2 + out[1] ** 2 + out[2] ** 2)


@jit
def torus_u_grid(times, elements, model, frame, ic, n_s, n_psi):
    """U (energy) on the torus grid of :func:`torus_grids` at each of ``times``: (len(times), n_s, n_psi)."""
    return torus_grids(times, elements, model, frame, ic, n_s, n_psi, 1)[:, FIELD_U]


@jit
def _dft_matrix(n):
    """The n × n matrix of the forward DFT, exp(−2πi jk/n) (numpy.fft's sign convention)."""
    out = np.empty((n, n), dtype=np.complex128)
    for j in range(n):
        for k in range(n):
            out[j, k] = np.exp(-2j * math.pi * ((j * k) % n) / n)
    return out


#: Matrix products of the DFTs are kept below this m·n·k: from 65536 on OpenBLAS (numba's np.dot)
#: runs a gemm on several threads, which on a loaded machine wait for a core (measured on the
#: shared 2-core machine: a 32 × 32 by 32 × 96 product 23 µs median, stalls of 8–36 ms; split, no stall).
SINGLE_THREAD_GEMM = 65536


@jit
def _single_thread_dot(a, b):
    """a @ b (complex, 2-D) in blocks of rows of a and columns of b, each product below
    SINGLE_THREAD_GEMM (multiply-adds) so that BLAS keeps it on the calling thread."""
    m, k = a.shape
    n = b.shape[1]
    if m * n * k < SINGLE_THREAD_GEMM:
        return np.dot(a, b)
    out = np.empty((m, n), dtype=np.complex128)
    rows = max(1, (SINGLE_THREAD_GEMM - 1) // (n * k))
    cols = max(1, (SINGLE_THREAD_GEMM - 1) // (min(rows, m) * k))
    for r in range(0, m, rows):
        block = np.ascontiguousarray(a[r:r + rows])
        for c in range(0, n, cols):
            out[r:r + rows, c:c + cols] = np.dot(block, np.ascontiguousarray(b[:, c:c + cols]))
    return out


@jit
def _dft2_many(stack, matrix_s, matrix_psi):
    """numpy.fft.fft2 / size of each grid stack[:, m, :] (stack (n_s, M, n_psi), real) for the small
    torus grids, as two matrix products with the DFT matrices of :func:`_dft_matrix` for all M grids
    at once (numba has no FFT; 32 × 8 and 64 × 16 points, where a call's overhead is most of its
    cost): (n_s, M, n_psi) complex."""
    n_s, many, n_psi = stack.shape
    rows = _single_thread_dot(stack.reshape(n_s * many, n_psi).astype(np.complex128), matrix_psi)
    full = _single_thread_dot(matrix_s, rows.reshape(n_s, many * n_psi))
    return full.reshape(n_s, many, n_psi) / (n_s * n_psi)


@jit
def _fft_frequencies(n):
    """numpy.fft.fftfreq(n, 1/n): 0, 1, …, ⌈n/2⌉ − 1, −⌊n/2⌋, …, −1."""
    out = np.empty(n)
    for i in range(n):
        out[i] = i if i < (n + 1) // 2 else i - n
    return out


@jit
def _generating_coefficients(t, elements, model, frame, ic, matrix_s, matrix_psi, n_fields):
    """(Ŵ, jω + kν per unit s_w, k, ν, mean U) of W's Fourier series at the elements' momenta, on the
    torus grid of the DFT matrices ``matrix_s``, ``matrix_psi`` (:func:`_dft_matrix` of n_s, n_psi).

    Ŵ has shape (n_fields, n_s, n_psi): the series of W and, for ``n_fields`` = 3, of ∂W/∂H and
    ∂W/∂h (the same linear map applied to ∂U/∂H, ∂U/∂h, which leave ω, ν and the grid unchanged;
    the harmonics kept are those significant in U).
    """
    n_s, n_psi = matrix_s.shape[0], matrix_psi.shape[0]
    period, nu, s_rate = torus_frequencies(elements[0], elements[1], ic)
    # ∂U/∂t and ∂²U/∂t² through the perturbers' motion: central differences over a fraction of the
    # fastest torus period (the grid varies on the orbital time scale).
    omega_fast = max(2.0 * math.pi / period, abs(nu)) * s_rate
    dt = TIME_DIFFERENCE_FRACTION * 2.0 * math.pi / omega_fast
    five = TIME_DERIVATIVE_ORDER > 2  # c⃛ needs t ± 2δt; ċ, c̈ then take the 4th-order stencils
    if five:
        offsets = np.array([0.0, 1.0, -1.0, 2.0, -2.0])
    else:
        offsets = np.array([0.0, 1.0, -1.0])
    grids = torus_grids(t + offsets * dt, elements, model, frame, ic, n_s, n_psi, n_fields)
    j = _fft_frequencies(n_s)
    k = _fft_frequencies(n_psi)
    rate = np.empty((n_s, n_psi))
    for a in range(n_s):
        for b in range(n_psi):
            rate[a, b] = j[a] * (2.0 * math.pi / period) + k[b] * nu  # d(phase)/d s_w
    # the differences in t are linear, so they are taken on the grids before the transform; all
    # fields and orders in one transform (stack index 4·field + order)
    stack = np.empty((n_s, 4 * n_fields, n_psi))
    for field in range(n_fields):
        g = grids[:, field]
        for a in range(n_s):
            for b in range(n_psi):
                if five:
                    g1, g2, g3, g4 = g[1, a, b], g[2, a, b], g[3, a, b], g[4, a, b]
                    stack[a, 4 * field, b] = g[0, a, b]
                    stack[a, 4 * field + 1, b] = (8.0 * (g1 - g2) - (g3 - g4)) / (12.0 * dt)
                    stack[a, 4 * field + 2, b] = (16.0 * (g1 + g2) - (g3 + g4) - 30.0 * g[0, a, b]) / (12.0 * dt * dt)
                    stack[a, 4 * field + 3, b] = ((g3 - g4) - 2.0 * (g1 - g2)) / (2.0 * dt**3)
                else:
                    stack[a, 4 * field, b] = g[0, a, b]
                    stack[a, 4 * field + 1, b] = (g[1, a, b] - g[2, a, b]) / (2.0 * dt)
                    stack[a, 4 * field + 2, b] = (g[1, a, b] - 2.0 * g[0, a, b] + g[2, a, b]) / (dt * dt)
                    stack[a, 4 * field + 3, b] = 0.0
    spectra = _dft2_many(stack, matrix_s, matrix_psi)
    # Harmonics at the rounding level of the grid are dropped: with a small divisor Ω_jk (some
    # jω + kν is always close to 0 on a large grid) their noise, divided by Ω³ in the c̈ term, would
    # dominate the corrections.
    mean_u = spectra[0, 4 * FIELD_U, 0].real
    spectra[0, 4 * FIELD_U, 0] = 0.0
    size = np.abs(spectra[:, 4 * FIELD_U, :])
    largest = size.max()
    w_hat = np.zeros((n_fields, n_s, n_psi), dtype=np.complex128)
    # Σ_m (m + 1) W_m of W's terms W_m = (−1)^m c^(m)/(iΩ)^{m+1}, homogeneous of degree −(m + 1) in
    # the momenta (S, Z, H) (see _short_period_offsets)
    w_degree = np.zeros((n_s, n_psi), dtype=np.complex128)
    for field in range(n_fields):
        for a in range(n_s):
            for b in range(n_psi):
                if not size[a, b] > HARMONIC_NOISE * largest:
                    continue
                i_omega = 1j * s_rate * rate[a, b]
                term0 = spectra[a, 4 * field, b] / i_omega
                term1 = -spectra[a, 4 * field + 1, b] / i_omega**2
                term2, term3 = 0.0j, 0.0j
                if TIME_DERIVATIVE_ORDER > 1:
                    term2 = spectra[a, 4 * field + 2, b] / i_omega**3
                if TIME_DERIVATIVE_ORDER > 2 and size[a, b] > THIRD_TERM_FLOOR * largest:
                    term3 = -spectra[a, 4 * field + 3, b] / i_omega**4
                w_hat[field, a, b] = term0 + term1 + term2 + term3
                if field == FIELD_U:
                    w_degree[a, b] = term0 + 2.0 * term1 + 3.0 * term2 + 4.0 * term3
    return w_hat, rate, k, nu, mean_u, w_degree


# What :func:`_series` sums: W itself, ∂W/∂s_w (factor i(jω + kν)) or ∂W/∂z (factor i k).
SERIES_W, SERIES_D_S, SERIES_D_Z = 0, 1, 2


@jit
def _series(w_hat, rate, k, nu, elements, which):
    """Real part of Σ Ŵ·factor e^{i(jω s_w + kψ)} at the elements' (s, z), factor by ``which``."""
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    s_w = sign * elements[3]
    psi = elements[4] + nu * s_w
    # e^{i(jω s_w + kψ)} = e^{ijω s_w} e^{ikψ}: n_s + n_psi exponentials instead of n_s · n_psi
    # (jω = rate[a, 0], as k[0] = 0)
    along_s = np.exp(1j * rate[:, 0] * s_w)
    along_psi = np.exp(1j * k * psi)
    total = 0.0
    for a in range(w_hat.shape[0]):
        for b in range(w_hat.shape[1]):
            term = w_hat[a, b] * along_s[a] * along_psi[b]
            if which == SERIES_D_S:
                term *= 1j * rate[a, b]
            elif which == SERIES_D_Z:
                term *= 1j * k[b]
            total += term.real
    return total


def torus_grid_for(model):
    """(n_s, n_psi) of the short-period grid for a model's figure degree."""
    return GRID_DEGREE2 if model[BODY_NMAX] <= 2 else GRID_DEGREE4


@jit
def _generating_function(t, elements, model, frame, ic, matrix_s, matrix_psi):
    w_hat, rate, k, nu, _, _ = _generating_coefficients(t, elements, model, frame, ic, matrix_s, matrix_psi, 1)
    return _series(w_hat[FIELD_U], rate, k, nu, elements, SERIES_W)


def generating_function(t, elements, model, frame, ic, n_s=None, n_psi=None):
    """W(t, elements) (energy·time): the first-order generating function (module docstring)."""
    if n_s is None or n_psi is None:
        n_s, n_psi = torus_grid_for(model)
    elements = np.ascontiguousarray(elements, dtype=float)
    return _generating_function(float(t), elements, model, frame, ic, _dft_matrix(n_s), _dft_matrix(n_psi))


@jit
def _short_period_offsets(t, elements, model, frame, ic, n_s, n_psi):
    """Kernel of :func:`short_period_offsets` (compiled: the map is the averaged propagator's fixed cost)."""
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    matrix_s, matrix_psi = _dft_matrix(n_s), _dft_matrix(n_psi)
    w_hat, rate, k, nu, _, w_degree = _generating_coefficients(t, elements, model, frame, ic, matrix_s, matrix_psi, 3)
    out = np.empty(6)
    out[0] = sign * _series(w_hat[FIELD_U], rate, k, nu, elements, SERIES_D_S)  # ∂W/∂s = sign ∂W/∂s_w
    out[1] = _series(w_hat[FIELD_U], rate, k, nu, elements, SERIES_D_Z)  # ∂W/∂z
    d_big_h = _series(w_hat[FIELD_DU_DH], rate, k, nu, elements, SERIES_W)  # ∂W/∂H
    d_h = _series(w_hat[FIELD_DU_DSMALL_H], rate, k, nu, elements, SERIES_W)  # ∂W/∂h
    # S moves the free motion itself (the grid, ω, ν): a central difference of W, step ∝ Z
    step = W_DIFFERENCE_STEP * elements[1]
    shifted = elements.copy()
    shifted[0] += step
    w_plus = _generating_function(t, shifted, model, frame, ic, matrix_s, matrix_psi)
    shifted[0] = elements[0] - step
    w_minus = _generating_function(t, shifted, model, frame, ic, matrix_s, matrix_psi)
    d_big_s = (w_plus - w_minus) / (2.0 * step)
    # ∂W/∂Z from Euler's relation: the free motion is homogeneous (λM(λt) solves Euler's equations
    # when M(t) does, and ds/dt = aS), so at fixed angles (s, z, h) the attitude, the grid, ω and ν
    # depend on (S, Z, H) through ratios only, while Ω_jk ∝ the momenta: W_m is homogeneous of
    # degree −(m + 1), so S W_S + Z W_Z + H W_H = −Σ (m + 1) W_m (two grids instead of a central
    # difference in Z; tests/test_averaged.py checks it against that difference).
    d_big_z = -(_series(w_degree, rate, k, nu, elements, SERIES_W) + elements[2] * d_big_h
                + elements[0] * d_big_s) / elements[1]
    out[2] = d_h
    out[3] = -d_big_s
    out[4] = -d_big_z
    out[5] = -d_big_h
    return out


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
    return _short_period_offsets(float(t), elements, model, frame, ic, n_s, n_psi)


def mean_to_osculating(t, mean, model, frame, ic):
    """Osculating elements of mean elements at time t (first order): x + {x, W}(x)."""
    osc = np.asarray(mean, dtype=float) + short_period_offsets(t, mean, model, frame, ic)
    reduce_phase(osc, ic)
    return osc


def osculating_to_mean(t, osc, model, frame, ic, iterations=2):
    """Mean elements of osculating elements at time t: the inverse of :func:`mean_to_osculating`,
    solved by fixed-point iteration x ← x_osc − {x, W}(x) (each iteration gains one order; the first
    of two or more on the coarser FIRST_ITERATION_GRID_DEGREE2 for degree-2 figures)."""
    osc = np.ascontiguousarray(osc, dtype=float).copy()
    reduce_phase(osc, ic)
    mean = osc.copy()
    last = torus_grid_for(model)
    first = FIRST_ITERATION_GRID_DEGREE2 if model[BODY_NMAX] <= 2 and iterations > 1 else last
    for i in range(iterations):
        mean = osc - short_period_offsets(t, mean, model, frame, ic, *(first if i == 0 else last))
    reduce_phase(mean, ic)
    return mean
