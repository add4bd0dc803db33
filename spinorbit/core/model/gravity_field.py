"""The body's figure as a source of the force function U, its gradient and the torque.

One definition: every quantity below comes from the same mutual force function of the rigid body
(mass m_b, principal moments A ≤ B ≤ C on the body x, y, z axes) and a point mass with
gravitational parameter μ = G M_p at body-frame position r (from the body's centre of mass to the
point mass, components on the principal axes)::

    U(r) = μ ∫ dm / |r − ρ|        (force function = minus the mutual potential energy)

Units: U is an energy (μ · mass / length). With μ in length³/time², moments in mass·length², m_b in
mass and r in length, U is in mass·length²/time² and the torque in the same unit, which is what
Euler's equations I ω̇ = Iω × ω + N need. No gravitational constant appears anywhere: G M_p m_b = μ m_b.

Expansion used (truncated at degree 4):

- degree 0: μ m_b / R (no torque; kept so that the force on the perturber is complete);
- degree 1: zero (the origin is the centre of mass);
- degree 2 from the inertia tensor (MacCullagh): (μ / 2R³)(A + B + C − 3 r̂ᵀ I r̂);
- degrees 3 and 4 from unnormalised Stokes coefficients C_nm, S_nm (geodesy convention, no
  Condon–Shortley phase) with reference radius R_ref:
  (μ m_b / R) Σ (R_ref/R)ⁿ P_nm(sin φ)(C_nm cos mλ + S_nm sin mλ), evaluated with Cunningham's
  recursion for the solid harmonics V_nm, W_nm (Montenbruck & Gill 2000, Satellite Orbits, §3.2.4–5,
  eqs. 3.29–3.33), which gives the Cartesian gradient without a pole singularity.
  Degree-2 Stokes entries are ignored: degree 2 comes from the moments only, so that U and the
  moments in Euler's equations cannot disagree.

Signs (derived in ``docs/torques.md``):

- ∂U/∂r is the force on the perturber divided by nothing: F_perturber = ∂U/∂r, F_body = −∂U/∂r.
- Torque on the body about its centre of mass, body frame: **N = (∂U/∂r) × r = −r × ∂U/∂r**.
  Equivalently, an infinitesimal active rotation δθ of the body moves the perturber's body-frame
  position by −δθ × r and changes U by δU = N · δθ: the torque is the derivative of the force function
  with respect to the body's rotation angle (a generalised force, + sign because U = −V).
- Degree 2 alone: N = (3μ/R⁵) r × (I r).

The body model is ONE flat float64 array, the ``figure`` (no jitclass: it cannot be cached; and one
array rather than a tuple of arrays because every array that crosses a numba call boundary costs two
atomic reference-count updates, measured at ~130 ns per RHS call with an 8-array tuple)::

    figure[0:6]   = [A, B, C, m_b, R_ref, n_max]
    figure[6:31]  = C_nm (unnormalised), row-major [n, m], n, m < STOKES_SIZE
    figure[31:56] = S_nm
    figure[56]    = absolute offset of the thermal block in the model array, 0 for none
                    (:mod:`spinorbit.core.model.thermal`; written by ``make_model``)

``n_max`` ∈ {2, 3, 4} is the highest degree evaluated. Any array that *starts* with a figure is
accepted (the dynamics' model array does), so the kernels take the model directly.
"""

import math

import numpy as np

from spinorbit.core.errors import require_finite
from spinorbit.core.jit import jit

#: Highest Stokes degree supported. Degree 4 is what the Moon-class problems need (DE421 stops at 4
#: for the Moon's figure torques); raising it only changes this constant and the array sizes.
STOKES_MAX_DEGREE = 4
#: Side of the Stokes coefficient arrays; the recursion needs V_nm up to degree n_max + 1.
STOKES_SIZE = STOKES_MAX_DEGREE + 1

# Layout of the flat ``figure`` array (float64): named offsets so that kernels read like the physics.
BODY_A, BODY_B, BODY_C, BODY_MASS, BODY_RADIUS, BODY_NMAX = 0, 1, 2, 3, 4, 5
BODY_SIZE = 6
FIG_STOKES_C = BODY_SIZE  # C_nm at FIG_STOKES_C + n·STOKES_SIZE + m
FIG_STOKES_S = FIG_STOKES_C + STOKES_SIZE * STOKES_SIZE
#: Where the model array's thermal block starts (0: no sunlight recoil); make_body leaves it at 0.
FIG_THERMAL = FIG_STOKES_S + STOKES_SIZE * STOKES_SIZE
FIGURE_SIZE = FIG_THERMAL + 1


def normalization_factor(n, m):
    """Factor N_nm with C_nm (unnormalised) = N_nm · C̄_nm (fully normalised, 4π convention).

    N_nm = sqrt((2 − δ_m0)(2n + 1)(n − m)! / (n + m)!)  (Kaula 1966; Montenbruck & Gill eq. 3.21).
    """
    delta = 1.0 if m == 0 else 0.0
    return math.sqrt((2.0 - delta) * (2 * n + 1) * math.factorial(n - m) / math.factorial(n + m))


def unnormalize_stokes(c_bar, s_bar):
    """Convert fully normalised Stokes coefficients (C̄_nm, S̄_nm) to unnormalised (C_nm, S_nm).

    Parameters
    ----------
    c_bar, s_bar : array_like, shape (n+1, n+1)
        Fully normalised coefficients indexed [degree, order] (dimensionless).

    Returns
    -------
    c, s : ndarray
        Unnormalised coefficients, same shape.
    """
    return _rescale_stokes(c_bar, s_bar, normalised=True)


def normalize_stokes(c, s):
    """Inverse of :func:`unnormalize_stokes`: unnormalised → fully normalised (Kaula 1966).

    Parameters
    ----------
    c, s : array_like, shape (n+1, n+1)
        Unnormalised coefficients C_nm, S_nm indexed [degree, order] (dimensionless).

    Returns
    -------
    c_bar, s_bar : ndarray
        Fully normalised coefficients (4π convention), same shape.
    """
    return _rescale_stokes(c, s, normalised=False)


def _rescale_stokes(c_in, s_in, normalised):
    """Multiply (``normalised``: input fully normalised) or divide by N_nm degree by degree."""
    c_in = np.asarray(c_in, dtype=float)
    s_in = np.asarray(s_in, dtype=float)
    c_out = np.zeros_like(c_in)
    s_out = np.zeros_like(s_in)
    for n in range(c_in.shape[0]):
        for m in range(n + 1):
            factor = normalization_factor(n, m)
            if normalised:
                c_out[n, m], s_out[n, m] = factor * c_in[n, m], factor * s_in[n, m]
            else:
                c_out[n, m], s_out[n, m] = c_in[n, m] / factor, s_in[n, m] / factor
    return c_out, s_out


def make_body(moments, mass=0.0, reference_radius=1.0, stokes_c=None, stokes_s=None, normalized=False):
    """Pack a body's figure into the arrays the kernels take, validating it.

    Parameters
    ----------
    moments : sequence of 3 floats
        Principal moments (A, B, C), A ≤ B ≤ C, mass·length², on the body x, y, z axes.
    mass : float
        Body mass m_b (mass unit). Enters only the degree-0 term and the Stokes terms; 0 is allowed
        when no Stokes coefficients are given (then U has no monopole part; torques are unaffected).
    reference_radius : float
        R_ref of the Stokes coefficients (length).
    stokes_c, stokes_s : array_like, shape (k, k) with k ≤ STOKES_SIZE, optional
        Stokes coefficients [n, m] in the principal-axis frame. Only degrees 3..4 are used.
    normalized : bool
        True if the coefficients are fully normalised (converted here with :func:`unnormalize_stokes`).

    Returns
    -------
    figure : ndarray, shape (FIGURE_SIZE,)
        [A, B, C, m_b, R_ref, n_max, C_nm…, S_nm…] (unnormalised, zero at degrees < 3).

    Raises
    ------
    ValueError
        Non-positive or unordered moments, negative mass,
        non-positive radius, Stokes terms without a positive mass, or arrays of the wrong shape.
    """
    moments = np.asarray(moments, dtype=float)
    require_finite("moments", moments, "3 finite principal moments (A, B, C)")
    if moments.shape != (3,) or not np.all(np.isfinite(moments)):
        raise ValueError(f"moments: expected 3 finite principal moments (A, B, C), got {moments!r}.")
    if np.any(moments <= 0):
        raise ValueError(
            f"moments: expected positive principal moments, got {tuple(moments)}; "
            "pass the moments of inertia in mass·length² (any consistent unit)."
        )
    a_mom, b_mom, c_mom = moments
    if not (a_mom <= b_mom <= c_mom):
        raise ValueError(
            f"moments: expected A ≤ B ≤ C on the body x, y, z axes, got {tuple(moments)}; "
            "map your body axes onto the principal-axis convention first (docs/conventions.md)."
        )
    # The triangle inequality C ≤ A + B of a real mass distribution is deliberately *not* enforced:
    # standard test bodies violate it (Hairer–Lubich–Wanner's I = (2, 1, 2/3)) and the equations of
    # motion do not need it.
    require_finite("mass", float(mass), "a finite mass ≥ 0")
    require_finite("reference_radius", float(reference_radius), "a finite positive length")
    if not (np.isfinite(mass) and mass >= 0):
        raise ValueError(f"mass: expected a finite mass ≥ 0, got {mass!r}.")
    if not (np.isfinite(reference_radius) and reference_radius > 0):
        raise ValueError(f"reference_radius: expected a positive length, got {reference_radius!r}.")
    c_out = np.zeros((STOKES_SIZE, STOKES_SIZE))
    s_out = np.zeros((STOKES_SIZE, STOKES_SIZE))
    n_max = 2
    if stokes_c is not None or stokes_s is not None:
        given_c = np.zeros((1, 1)) if stokes_c is None else np.asarray(stokes_c, dtype=float)
        given_s = np.zeros_like(given_c) if stokes_s is None else np.asarray(stokes_s, dtype=float)
        for name, arr in (("stokes_c", given_c), ("stokes_s", given_s)):
            if arr.ndim != 2 or arr.shape[0] != arr.shape[1] or arr.shape[0] > STOKES_SIZE:
                raise ValueError(
                    f"{name}: expected a square [degree, order] array of side ≤ {STOKES_SIZE}, "
                    f"got shape {arr.shape}."
                )
            if not np.all(np.isfinite(arr)):
                raise ValueError(f"{name}: expected finite coefficients, got NaN or inf.")
        if normalized:
            given_c, given_s = unnormalize_stokes(given_c, given_s)
        k_c, k_s = given_c.shape[0], given_s.shape[0]
        c_out[:k_c, :k_c] = np.tril(given_c)
        s_out[:k_s, :k_s] = np.tril(given_s)
        c_out[:3] = 0.0  # degrees 0..2 come from the mass and the moments (see module docstring)
        s_out[:3] = 0.0
        s_out[:, 0] = 0.0  # S_n0 does not exist
        nonzero = [n for n in range(3, STOKES_SIZE) if np.any(c_out[n]) or np.any(s_out[n])]
        if nonzero:
            n_max = max(nonzero)
            if mass <= 0:
                raise ValueError(
                    f"mass: Stokes coefficients of degree {n_max} need the body mass m_b > 0, got {mass!r}."
                )
    body = np.array([a_mom, b_mom, c_mom, float(mass), float(reference_radius), float(n_max)])
    return np.concatenate([body, c_out.ravel(), s_out.ravel(), [0.0]])


def pack_stokes(stokes_c, stokes_s, mass=1.0, reference_radius=1.0):
    """A figure array holding *all* given coefficients (any degree ≤ STOKES_MAX_DEGREE, also 0..2).

    For :func:`stokes_force_function_and_gradient` used on its own (tests with point-mass clouds);
    the moments are left at zero, so do not use it for the dynamics.
    """
    c = np.zeros((STOKES_SIZE, STOKES_SIZE))
    s = np.zeros((STOKES_SIZE, STOKES_SIZE))
    given_c = np.asarray(stokes_c, dtype=float)
    given_s = np.asarray(stokes_s, dtype=float)
    c[: given_c.shape[0], : given_c.shape[1]] = given_c
    s[: given_s.shape[0], : given_s.shape[1]] = given_s
    head = np.array([0.0, 0.0, 0.0, float(mass), float(reference_radius), float(STOKES_MAX_DEGREE)])
    return np.concatenate([head, c.ravel(), s.ravel(), [0.0]])


@jit
def solid_harmonics(r, reference_radius, degree_max):
    """Cunningham's V_nm, W_nm = (R_ref/R)^(n+1) P_nm(sin φ) (cos mλ, sin mλ) for n ≤ degree_max.

    Parameters
    ----------
    r : ndarray, shape (3,)
        Body-frame position (length).
    reference_radius : float
        R_ref (length).
    degree_max : int
        Highest degree computed.

    Returns
    -------
    v, w : ndarray, shape (degree_max + 1, degree_max + 1)
        Indexed [n, m]; unnormalised P_nm without the Condon–Shortley phase.
    """
    x, y, z = r[0], r[1], r[2]
    rr = x * x + y * y + z * z
    x0 = reference_radius * x / rr
    y0 = reference_radius * y / rr
    z0 = reference_radius * z / rr
    rho = reference_radius * reference_radius / rr
    size = degree_max + 1
    v = np.zeros((size, size))
    w = np.zeros((size, size))
    v[0, 0] = reference_radius / math.sqrt(rr)
    for m in range(size):
        if m > 0:
            # Sectorial terms (M&G eq. 3.30).
            v[m, m] = (2 * m - 1) * (x0 * v[m - 1, m - 1] - y0 * w[m - 1, m - 1])
            w[m, m] = (2 * m - 1) * (x0 * w[m - 1, m - 1] + y0 * v[m - 1, m - 1])
        if m + 1 < size:
            v[m + 1, m] = (2 * m + 1) * z0 * v[m, m]
            w[m + 1, m] = (2 * m + 1) * z0 * w[m, m]
        for n in range(m + 2, size):
            # Zonal/tesseral recursion (M&G eq. 3.29).
            v[n, m] = ((2 * n - 1) * z0 * v[n - 1, m] - (n + m - 1) * rho * v[n - 2, m]) / (n - m)
            w[n, m] = ((2 * n - 1) * z0 * w[n - 1, m] - (n + m - 1) * rho * w[n - 2, m]) / (n - m)
    return v, w


@jit
def stokes_force_function_and_gradient(r, mu, figure, degree_min, degree_max):
    """U and ∂U/∂r of the Stokes terms of degrees degree_min..degree_max of a figure array.

    U = (μ m_b / R_ref) Σ (C_nm V_nm + S_nm W_nm); the gradient is M&G eq. 3.33 times μ m_b / R_ref².
    Low-level: used for degrees 3..4 by :func:`figure_force_function_and_gradient` and by the tests
    with arbitrary degrees (including 0..2 from a point-mass cloud, see :func:`pack_stokes`).
    """
    mass = figure[BODY_MASS]
    reference_radius = figure[BODY_RADIUS]
    v, w = solid_harmonics(r, reference_radius, degree_max + 1)
    u_sum = 0.0
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for n in range(degree_min, degree_max + 1):
        for m in range(n + 1):
            c = figure[FIG_STOKES_C + n * STOKES_SIZE + m]
            s = figure[FIG_STOKES_S + n * STOKES_SIZE + m]
            if c == 0.0 and s == 0.0:
                continue
            u_sum += c * v[n, m] + s * w[n, m]
            if m == 0:
                gx -= c * v[n + 1, 1]
                gy -= c * w[n + 1, 1]
            else:
                fac = (n - m + 2) * (n - m + 1)
                gx += 0.5 * ((-c * v[n + 1, m + 1] - s * w[n + 1, m + 1])
                             + fac * (c * v[n + 1, m - 1] + s * w[n + 1, m - 1]))
                gy += 0.5 * ((-c * w[n + 1, m + 1] + s * v[n + 1, m + 1])
                             + fac * (-c * w[n + 1, m - 1] + s * v[n + 1, m - 1]))
            gz += (n - m + 1) * (-c * v[n + 1, m] - s * w[n + 1, m])
    scale_u = mu * mass / reference_radius
    scale_g = scale_u / reference_radius
    grad = np.empty(3)
    grad[0] = scale_g * gx
    grad[1] = scale_g * gy
    grad[2] = scale_g * gz
    return scale_u * u_sum, grad


@jit(inline="always")  # RHS hot path: no array crosses a call boundary (see perturbers.py)
def figure_force_function_and_gradient_xyz(x, y, z, mu, body):
    """Scalar form of :func:`figure_force_function_and_gradient`: returns (U, ∂U/∂x, ∂U/∂y, ∂U/∂z).

    The hot path of the right-hand side; allocates nothing unless Stokes terms (degree ≥ 3) are on.
    Degree 0 (μ m_b / R) plus :func:`figure_field_without_monopole_xyz`.
    """
    u, gx, gy, gz = figure_field_without_monopole_xyz(x, y, z, mu, body)
    rr = x * x + y * y + z * z
    dist = math.sqrt(rr)
    radial = -mu * body[BODY_MASS] / (rr * dist)
    return u + mu * body[BODY_MASS] / dist, gx + radial * x, gy + radial * y, gz + radial * z


@jit(inline="always")
def figure_field_without_monopole_xyz(x, y, z, mu, body):
    """(U, ∂U/∂x, ∂U/∂y, ∂U/∂z) of degrees 2..n_max only, i.e. without μ m_b / R.

    What the torque must be computed from: the monopole gradient is radial, so its torque is zero
    analytically, but in floating point (∂U₀/∂r) × r leaves rounding noise of ε·μ m_b / R, which for
    the Sun acting on the Moon is ~1e-3 of the true solar torque and made an adaptive integrator
    shrink its steps 100-fold. It is also the back-reaction an N-body code adds to its point masses.
    """
    return figure_field_to_degree_xyz(x, y, z, mu, body, int(body[BODY_NMAX]))


@jit(inline="always")
def figure_field_to_degree_xyz(x, y, z, mu, body, n_max):
    """:func:`figure_field_without_monopole_xyz` truncated at degree ``min(n_max, figure's n_max)``.

    For distant perturbers whose degree ≥ 3 torque is negligible (the Sun on the Moon: (R/r) ~ 1e-5
    of its own degree-2 torque), so that the allocating Stokes recursion is skipped for them.
    """
    a_mom, b_mom, c_mom = body[BODY_A], body[BODY_B], body[BODY_C]
    rr = x * x + y * y + z * z
    dist = math.sqrt(rr)
    inv_r3 = 1.0 / (rr * dist)
    inv_r5 = inv_r3 / rr
    # Degree 2 (MacCullagh): U2 = μ/(2R³) tr I − (3μ/2R⁵) rᵀ I r;
    # ∂U2/∂r = [−(3μ/2R⁵) tr I + (15μ/2R⁷) rᵀIr] r − (3μ/R⁵) I r.
    ix, iy, iz = a_mom * x, b_mom * y, c_mom * z
    r_i_r = x * ix + y * iy + z * iz
    trace = a_mom + b_mom + c_mom
    u = 0.5 * mu * trace * inv_r3 - 1.5 * mu * r_i_r * inv_r5
    radial = -1.5 * mu * trace * inv_r5 + 7.5 * mu * r_i_r * inv_r5 / rr
    k = -3.0 * mu * inv_r5
    gx = radial * x + k * ix
    gy = radial * y + k * iy
    gz = radial * z + k * iz
    n_max = min(n_max, int(body[BODY_NMAX]))
    if n_max >= 3:
        r = np.array([x, y, z])
        u_s, g_s = stokes_force_function_and_gradient(r, mu, body, 3, n_max)
        u += u_s
        gx += g_s[0]
        gy += g_s[1]
        gz += g_s[2]
    return u, gx, gy, gz


@jit
def figure_force_function_and_gradient(r, mu, figure):
    """Force function U (energy) and its gradient ∂U/∂r (energy/length) of the body and a point mass.

    Parameters
    ----------
    r : ndarray, shape (3,)
        Position of the point mass relative to the body's centre of mass, body principal axes (length).
    mu : float
        G M_p of the point mass (length³/time²).
    figure : ndarray
        From :func:`make_body` (or any array starting with a figure, e.g. a dynamics model).

    Returns
    -------
    u : float
        μ ∫ dm/|r − ρ| truncated at degree n_max (energy).
    grad : ndarray, shape (3,)
        ∂U/∂r: the force on the point mass (the body feels −grad).
    """
    u, gx, gy, gz = figure_force_function_and_gradient_xyz(r[0], r[1], r[2], mu, figure)
    return u, np.array([gx, gy, gz])


@jit
def torque_from_gradient(r, grad):
    """Body-frame torque N = (∂U/∂r) × r (see the module docstring for the derivation of the sign)."""
    n = np.empty(3)
    n[0] = grad[1] * r[2] - grad[2] * r[1]
    n[1] = grad[2] * r[0] - grad[0] * r[2]
    n[2] = grad[0] * r[1] - grad[1] * r[0]
    return n


@jit
def figure_torque(r, mu, figure):
    """Torque (energy units, body frame) exerted on the body by a point mass μ at body-frame r."""
    _, grad = figure_force_function_and_gradient(r, mu, figure)
    return torque_from_gradient(r, grad)


@jit
def degree2_torque_closed_form(r, mu, a_mom, b_mom, c_mom):
    """N = (3μ/R⁵) r × (I r): the textbook MacCullagh torque, kept as an independent check."""
    rr = r[0] * r[0] + r[1] * r[1] + r[2] * r[2]
    k = 3.0 * mu / (rr * rr * math.sqrt(rr))
    ix, iy, iz = a_mom * r[0], b_mom * r[1], c_mom * r[2]
    n = np.empty(3)
    n[0] = k * (r[1] * iz - r[2] * iy)
    n[1] = k * (r[2] * ix - r[0] * iz)
    n[2] = k * (r[0] * iy - r[1] * ix)
    return n
