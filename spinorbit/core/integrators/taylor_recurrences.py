"""Taylor coefficients of the Euler-parameter equations by automatic differentiation (Jorba & Zou 2005).

The series array and the recurrences that fill it, order by order, for the adaptive Taylor integrator
(:mod:`spinorbit.core.integrators.taylor`, which chooses the order and the step and evaluates the
polynomials). Every product a·b of the right-hand side becomes the Cauchy product
(ab)^[k] = Σⱼ a^[j] b^[k−j], the power u = a^α the recurrence
k a^[0] u^[k] = Σ_{j<k} (α(k − j) − j) a^[k−j] u^[j], and y^[k+1] = f^[k]/(k + 1).

**One definition.** The recurrences below are the right-hand side of ``dynamics.rhs_into`` written
term by term; the order-1 coefficient they produce *is* that right-hand side, and ``tests/test_integrate_taylor.py``
checks y^[1] == ``rhs_into`` (and y^[2] against a difference of ``rhs_into`` along the flow) for
random states and perturbers. Three exact rewritings are used, the first valid on the unit sphere
|q| = 1 on which the exact flow stays (the integrator renormalises q before each expansion):

- r_body = M(q)ᵀ r = r + 2 (u × c − q₀ c), c = u × r, u = (q₁, q₂, q₃) — the rotation by q* without
  the 1/|q|² of ``dynamics.body_frame_xyz`` (which is 1 on the sphere; its series would cost a
  division recurrence);
- (I r) × r components (C − B) r_y r_z etc. (the A r_x r_x terms cancel exactly);
- **Torque.** |r|⁻⁵ r_y r_z = ρ_y ρ_z of ρ = |r|⁻⁵ᐟ² r rotated to the body frame (rotation is linear):
  the |r|⁻⁵ᐟ² enters in the perturber's orbit series, which stop after a few orders (below), and the
  torque at the attitude's orders is the rotation and the pair products only.

**Four components in one register.** The series array is order-major: row k holds every quantity's
order-k coefficient, each quaternion or 3-vector in four consecutive doubles (a 3-vector's fourth is
zero), so one order of one quantity is one :mod:`~spinorbit.core.math.lanes` ``Quad``. A Cauchy
product of two 3-vectors component by component, or of a quaternion with one broadcast component, is
one fused multiply-add per term instead of three or four. Products that mix components (cross
products, Euler's ω_y ω_z, …) load copies stored in the order they need: ω as (ω_y, ω_z, ω_x) and
(ω_z, ω_x, ω_y), u = (q₁, q₂, q₃) and ρ and ρ_body likewise. A quaternion product is summed as the
Cauchy products of the whole quaternion with each broadcast component, and permuted with signs once
per order (a permutation is linear, so it commutes with the sum): q ⊗ (0, ω) = Σ_a P_a(q) ω_a for
the kinematics, and u × c − q₀ c = −vec((0, c) ⊗ q) for the rotation of ρ to the body frame. The
rewriting is measured in ``docs/performance.md`` (*Where the Taylor floor is*).

**Latency.** Each order needs the last one, so the step is one chain of dependent orders. Every Cauchy
sum therefore adds the terms with the newest coefficients (j = 0 and j = k) last, from registers: the
rest of the sum can run while the previous quantity of the chain is still being computed. Those other
terms of all of an order's products run in one pass per group (the attitude's four sums; each
perturber's five), so that each pass has independent chains of multiply-adds and the loops' set-up,
as long as their bodies at these orders, is paid once per group.

**Perturbers over a step.** A Keplerian perturber's relative position is carried as extra state
of the Taylor system, r̈ = −μ_orbit r / |r|³, advanced by its own Taylor polynomial and *re-seeded
every KEPLER_RESEED_INTERVAL steps* (by the driver) from the exact Kepler solution (``perturbers.kepler_perifocal``):
the series is that of the exact two-body motion (truncation error controlled like everything else)
and the drift between re-seeds stays ~0.1 tol relative. A fixed
perturber is a constant series. A sampled perturber's cubic Hermite piece is a polynomial of degree 3,
so its Taylor series is exact, and steps are clipped at sample times (the piecewise interpolant is
not smooth across them). The figure's degree-3/4 Stokes terms have no recurrence here: the Python
front end falls back to DOP853 with a warning (``taylor.TaylorFallbackWarning``).

**Truncated orbit series.** A Keplerian perturber's own series (position, velocity, |r|², |r|⁻⁵ᐟ², ρ)
stops at the first order m after which two consecutive terms, at the largest step allowed
(the driver's STEP_GROWTH × the previous step), are below its ORBIT_TOLERANCE_FRACTION × tol relative to |r| and |v|:
the higher ones are exactly zero in the products. The Sun seen from an asteroid moves ~300× slower
than the body turns, so m ≈ 6 where the attitude needs p = 13 (tol 1e-10), and the products with
the orbit cost m + 1 instead of k + 1 terms. The *torque* series is not truncated: in the body frame
it turns with the body (at twice the spin rate, being quadratic in the rotation), so its high
coefficients are what dominates ω's series (truncating it loses accuracy far above tol).
"""

import math

import numpy as np

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.jit import FUSED_MULTIPLY_ADD, INLINE, jit
from spinorbit.core.math.ddouble import fma
from spinorbit.core.math.lanes import (
    choose,
    constant_like,
    load_broadcast_quad,
    load_quad,
    quad,
    quad_lane,
    quad_shuffle,
    store_quad,
)
from spinorbit.core.math.lanes_generic import (
    all_above,
    any_below,
    first_member,
    largest,
    load_one,
    member_rows,
    order_like,
    quad_zero,
    store_one,
)
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C
from spinorbit.core.model.perturbers import (
    K_A,
    K_E,
    K_M0,
    K_MEAN_MOTION,
    K_MU,
    K_P,
    K_Q,
    K_ROOT,
    K_T0,
    KIND_FIXED,
    KIND_KEPLER,
    KIND_SAMPLED,
    PERTURBER_ROW,
    find_interval,
    kepler_perifocal,
)

#: Highest Taylor order the series array is made for (tol ≥ 1e-16 with order_factor ≤ 2 needs ≤ 40).
MAX_ORDER = 48
# 1/(k + 1) for every order: a division would sit on the chain of dependent orders.
_RECIPROCALS = 1.0 / np.arange(1, MAX_ORDER + 2, dtype=np.float64)

# Columns of the series array, four per quantity. The state first, in the order of y (q, ω), then the
# copies the products load, then the summed torque; then one block per perturber.
_Q, _W, _W_YZX, _W_ZXY, _U_YZX, _U_ZXY, _N = 0, 4, 8, 12, 16, 20, 24
_HEAD_COLUMNS = 28
# Perturber block: position, velocity, the scalars (|r|², |r|⁻⁵ᐟ², |r|⁻³), ρ = |r|⁻⁵ᐟ² r with its two
# rotated copies, c = u × ρ, and ρ_body with its two rotated copies.
_X, _V, _SCALARS, _RHO, _C, _B = 0, 4, 8, 12, 24, 28
_R2, _S52, _S3 = _SCALARS, _SCALARS + 1, _SCALARS + 2
_BLOCK_COLUMNS = 40
_YZX, _ZXY = 4, 8  # offsets of a 3-vector's rotated copies from the vector itself

_yzx = quad_shuffle((1, 2, 0, 4))  # (x, y, z, ·) → (y, z, x, 0)
_zxy = quad_shuffle((2, 0, 1, 4))
_u_yzx = quad_shuffle((2, 3, 1, 4))  # (q0, q1, q2, q3) → (q2, q3, q1, 0): u = (q1, q2, q3) rotated
_u_zxy = quad_shuffle((3, 1, 2, 4))
_lane_x, _lane_y, _lane_z = quad_shuffle((0, 0, 0, 0)), quad_shuffle((1, 1, 1, 1)), quad_shuffle((2, 2, 2, 2))
# q ⊗ (0, ω) = P_x(q) ω_x + P_y(q) ω_y + P_z(q) ω_z with P_x(q) = (−q1, q0, q3, −q2),
# P_y(q) = (−q2, −q3, q0, q1), P_z(q) = (−q3, q2, −q1, q0): a permutation, then signs.
_p_x = quad_shuffle((1, 0, 3, 2))
_p_y = quad_shuffle((2, 3, 0, 1))
_p_z = quad_shuffle((3, 2, 1, 0))
# u × c − q₀ c = −vec((0, c) ⊗ q) = −Σ_a c_a vec(e_a ⊗ q), vec(e_x ⊗ q) = (q0, −q3, q2),
# vec(e_y ⊗ q) = (q3, q0, −q1), vec(e_z ⊗ q) = (−q2, q1, q0): a permutation, then signs.
_e_x = quad_shuffle((0, 3, 2, 4))
_e_y = quad_shuffle((3, 0, 1, 4))
_e_z = quad_shuffle((2, 1, 0, 4))


@jit
def series_array(n_pert, order):
    """Zeroed series array for n_pert perturbers up to ``order``: row k holds the order-k coefficients,
    its first 7 columns the state (q, ω) in the order of y."""
    return np.zeros((order + 1, _HEAD_COLUMNS + n_pert * _BLOCK_COLUMNS))


@jit(inline=INLINE)
def _store_rotated(f, at, vector):
    """A 3-vector at column offset ``at`` of the flat series, with its (y, z, x) and (z, x, y) copies."""
    store_quad(f, at, vector)
    store_quad(f, at + _YZX, _yzx(vector))
    store_quad(f, at + _ZXY, _zxy(vector))


@jit(inline=INLINE)
def _store_attitude(f, row, q, w):
    """q and ω of one order at flat offset ``row``, with the copies the products load."""
    store_quad(f, row + _Q, q)
    store_quad(f, row + _U_YZX, _u_yzx(q))
    store_quad(f, row + _U_ZXY, _u_zxy(q))
    _store_rotated(f, row + _W, w)


@jit(inline=INLINE)
def _inner_sum(f, ncol, a, b, k, first):
    """Σ_{j=first}^{k−1} A^[j] ⊙ B^[k−j] of the quads at columns a and b (component by component). The terms
    with j = 0 and j = k, which hold the newest coefficients, are the caller's (module docstring, *Latency*)."""
    total = quad_zero(f)
    for j in range(first, k):
        total = fma(load_quad(f, j * ncol + a), load_quad(f, (k - j) * ncol + b), total)
    return total


@jit(inline=INLINE)
def _attitude_inner(f, ncol, k):
    """The terms j = 1 … k − 1 of q ω_x, q ω_y, q ω_z (the quaternion times one broadcast component of ω)
    and of Euler's (ω_y ω_z, ω_z ω_x, ω_x ω_y), in one pass: all the attitude's products of order k but
    those with the newest coefficients."""
    zero = quad_zero(f)
    x, y, z, euler = zero, zero, zero, zero
    for j in range(1, k):
        row, other = j * ncol, (k - j) * ncol
        q = load_quad(f, row + _Q)
        x = fma(q, load_broadcast_quad(f, other + _W), x)
        y = fma(q, load_broadcast_quad(f, other + _W + 1), y)
        z = fma(q, load_broadcast_quad(f, other + _W + 2), z)
        euler = fma(load_quad(f, row + _W_YZX), load_quad(f, other + _W_ZXY), euler)
    return x, y, z, euler


@jit(inline=INLINE)
def _perturber_inner(f, ncol, b, k, first_cross):
    """The terms j = 1 … k − 1 of perturber block b's q c_a (a = x, y, z) and of the pair products of
    ρ_body, and the terms j = first_cross … k − 1 of u × ρ, in one pass (ρ^[k−j] is zero before
    first_cross = k − m)."""
    zero = quad_zero(f)
    x, y, z, pairs, cross, cross_back = zero, zero, zero, zero, zero, zero
    for j in range(1, k):
        row, other = j * ncol, (k - j) * ncol
        q = load_quad(f, row + _Q)
        x = fma(q, load_broadcast_quad(f, other + b + _C), x)
        y = fma(q, load_broadcast_quad(f, other + b + _C + 1), y)
        z = fma(q, load_broadcast_quad(f, other + b + _C + 2), z)
        pairs = fma(load_quad(f, row + b + _B + _YZX), load_quad(f, other + b + _B + _ZXY), pairs)
        if j >= first_cross:
            cross = fma(load_quad(f, row + _U_YZX), load_quad(f, other + b + _RHO + _ZXY), cross)
            cross_back = fma(load_quad(f, row + _U_ZXY), load_quad(f, other + b + _RHO + _YZX), cross_back)
    return x, y, z, pairs, cross - cross_back


@jit(inline=INLINE)
def _with_newest(f, column, k, q, v, x, y, z):
    """q v_a sums (a = x, y, z, the 3-vector v at ``column``) completed with their j = 0 and j = k terms:
    the newest v^[k] and q^[k] come in registers (``v``, ``q``), not from memory. (Weights instead of a
    branch for k = 0, where the two terms are one: with one exit and no branch around the array reads
    numba drops the reference counting of ``f`` in the inlined code.)"""
    later = 1.0 if k > 0 else 0.0
    q0 = load_quad(f, _Q) * later
    x = fma(q, load_broadcast_quad(f, column) * later, fma(q0, _lane_x(v), x))
    y = fma(q, load_broadcast_quad(f, column + 1) * later, fma(q0, _lane_y(v), y))
    z = fma(q, load_broadcast_quad(f, column + 2) * later, fma(q0, _lane_z(v), z))
    first = 1.0 - later
    return fma(q * first, _lane_x(v), x), fma(q * first, _lane_y(v), y), fma(q * first, _lane_z(v), z)


@jit(inline=INLINE)
def _pairs_with_newest(f, column, k, v, total):
    """(v_y v_z, v_z v_x, v_x v_y) sums of the 3-vector at ``column`` (rotated copies stored) completed with
    their j = 0 and j = k terms, the newest order ``v`` in a register (weights as in :func:`_with_newest`)."""
    later = 1.0 if k > 0 else 0.0
    total = fma(load_quad(f, column + _YZX) * later, _zxy(v), total)
    total = fma(_yzx(v) * later, load_quad(f, column + _ZXY), total)
    return fma(_yzx(v) * (1.0 - later), _zxy(v), total)


@jit(inline=INLINE)
def _perturber_pairs(f, ncol, b, k, m, q):
    """Order k of (ρ_y ρ_z, ρ_z ρ_x, ρ_x ρ_y) of perturber block b's body-frame ρ, storing c and ρ_body.

    c = u × ρ (ρ truncated at order m, so the sum is short), then ρ_body = ρ + 2 (u × c − q₀ c) as
    ρ − 2 vec((0, c) ⊗ q); q^[k] comes in a register.
    """
    top = largest(m)  # m itself; in lanes the largest member's (ρ is zero above each member's own m)
    lo = max(0, k - top)  # ρ is zero above order m
    x, y, z, pairs, cross = _perturber_inner(f, ncol, b, k, lo)
    if lo == 0 and k > 0:
        cross = fma(load_quad(f, _U_YZX), load_quad(f, k * ncol + b + _RHO + _ZXY), cross)
        cross = fma(-load_quad(f, _U_ZXY), load_quad(f, k * ncol + b + _RHO + _YZX), cross)
    cross = fma(_u_yzx(q), load_quad(f, b + _RHO + _ZXY), cross)
    cross = fma(-_u_zxy(q), load_quad(f, b + _RHO + _YZX), cross)
    store_quad(f, k * ncol + b + _C, cross)
    x, y, z = _with_newest(f, b + _C, k, q, cross, x, y, z)
    product = quad(1.0, -1.0, 1.0, 0.0) * _e_x(x) + quad(1.0, 1.0, -1.0, 0.0) * _e_y(y) \
        + quad(-1.0, 1.0, 1.0, 0.0) * _e_z(z)
    if k <= top:
        body = choose(k <= m, load_quad(f, k * ncol + b + _RHO) - 2.0 * product, -2.0 * product)
    else:
        body = -2.0 * product
    _store_rotated(f, k * ncol + b + _B, body)
    return _pairs_with_newest(f, b + _B, k, body, pairs)


@jit(inline=INLINE)
def _dot(a, b):
    """a · b of two 3-vector quads (fourth lanes zero)."""
    product = a * b
    return quad_lane(product, 0) + quad_lane(product, 1) + quad_lane(product, 2)


@jit(inline=INLINE)
def _orbit_series_into(f, ncol, b, kind, order, mu_orbit, h_bound, orbit_tol_sq):
    """A perturber's orbit columns (r, |r|², |r|⁻⁵ᐟ², ρ = |r|⁻⁵ᐟ² r) to its truncation order m, which it returns.

    Independent of the attitude, so computed before it. A Kepler perturber's two-body motion
    r'' = −μ_orbit r |r|⁻³ fills r and v up to m (module docstring, *Truncated orbit series*); a
    sampled one's r rows are given (cubic), m = order; a fixed one has m = 0. ρ carries the torque's
    |r|⁻⁵ as the square of its |r|⁻⁵ᐟ², so that the torque needs no product with a |r|⁻⁵ series at
    the attitude's orders (module docstring, *Torque*). The powers u = |r|^α follow
    k |r|²^[0] u^[k] = Σ_{j<k} (α(k − j) − j) |r|²^[k−j] u^[j]; each order's newest r and v stay in
    registers, and every sum adds its newest terms last (module docstring, *Latency*).
    """
    m = order_like(h_bound, 0 if kind == KIND_FIXED else order)
    kepler = kind == KIND_KEPLER
    r0 = load_quad(f, b + _X)
    v = load_quad(f, b + _V)
    r2_0 = _dot(r0, r0)
    inv_r2 = 1.0 / r2_0
    inv_v2 = 1.0 / _dot(v, v)
    root = math.sqrt(r2_0)
    s52_0 = 1.0 / (r2_0 * math.sqrt(root))  # |r|⁻⁵ᐟ² and |r|⁻³ without a power function
    s3_0 = 1.0 / (r2_0 * root)
    store_one(f, b + _R2, r2_0)
    store_one(f, b + _S52, s52_0)
    store_one(f, b + _S3, s3_0)
    r = r0
    s52, s3 = s52_0, s3_0
    h_pow_sq = constant_like(h_bound, 1.0)  # h_bound^(2k), by one product per order (no power function)
    for k in range(order):
        if all_above(k, m):
            break
        row = k * ncol + b
        if not kepler:
            r = load_quad(f, row + _X)  # given (sampled) or constant (fixed)
        rho = quad_zero(f)
        acceleration = quad_zero(f)
        if k > 0:
            r2 = 2.0 * _dot(r0, r) + _dot(_inner_sum(f, ncol, b + _X, b + _X, k, 1), quad(1.0, 1.0, 1.0, 0.0))
            power52 = constant_like(r2_0, 0.0)
            power3 = constant_like(r2_0, 0.0)
            for j in range(1, k):
                r2_j = load_one(f, (k - j) * ncol + b + _R2)
                power52 += (-1.25 * (k - j) - j) * r2_j * load_one(f, j * ncol + b + _S52)
                power3 += (-1.5 * (k - j) - j) * r2_j * load_one(f, j * ncol + b + _S3)
                r_j = load_quad(f, (k - j) * ncol + b + _X)
                rho = fma(load_broadcast_quad(f, j * ncol + b + _S52), r_j, rho)
                acceleration = fma(load_broadcast_quad(f, j * ncol + b + _S3), r_j, acceleration)
            inverse_k_a0 = inv_r2 * _RECIPROCALS[k - 1]
            s52 = (power52 - 1.25 * k * r2 * s52_0) * inverse_k_a0
            s3 = (power3 - 1.5 * k * r2 * s3_0) * inverse_k_a0
            store_one(f, row + _R2, r2)
            store_one(f, row + _S52, s52)
            store_one(f, row + _S3, s3)
            rho = fma(quad(s52_0, s52_0, s52_0, s52_0), r, rho)
            acceleration = fma(quad(s3_0, s3_0, s3_0, s3_0), r, acceleration)
        rho = fma(quad(s52, s52, s52, s52), r0, rho)
        # zero above a member's own m (in lanes, where another member's m is larger), as the products read it
        _store_rotated(f, row + _RHO, choose(k <= m, rho, quad_zero(f)))
        if kepler and any_below(k, m):
            acceleration = fma(quad(s3, s3, s3, s3), r0, acceleration)
            inverse = _RECIPROCALS[k]
            r_next = v * inverse
            v_next = acceleration * (-mu_orbit * inverse)
            store_quad(f, row + ncol + _X, r_next)
            store_quad(f, row + ncol + _V, v_next)
            h_pow_sq_next = h_pow_sq * h_bound * h_bound
            if k >= 1:
                m = choose((k < m) & (_orbit_term_sq(r, v, inv_r2, inv_v2) * h_pow_sq < orbit_tol_sq)
                           & (_orbit_term_sq(r_next, v_next, inv_r2, inv_v2) * h_pow_sq_next < orbit_tol_sq),
                           order_like(h_bound, k + 1), m)
            r, v = r_next, v_next
            h_pow_sq = h_pow_sq_next
    return m


@jit(fastmath=FUSED_MULTIPLY_ADD)
def taylor_coefficients_into(t, model, s, n_pert, order, h_bound, orbit_tol, orbit_orders):
    """Fill the series array s (≥ order+1 rows, :func:`series_array`) with the Taylor coefficients at t.

    On entry s[0, 0:7] holds the state (unit q, ω) and the perturbers' order-0 columns are seeded
    (:func:`seed_perturbers`). Attitude and torque get orders 0..order. A Keplerian perturber's orbit
    series (position, |r|², |r|⁻⁵ᐟ², ρ) stops at the first order m after which two consecutive terms,
    at the largest step ``h_bound``, are below ``orbit_tol`` relative to |r| and |v|: the Sun's orbit
    varies ~300× slower than the attitude, so m ≈ 5 instead of p (module docstring).
    ``orbit_orders[p]`` receives m (``order`` for a sampled perturber, 0 for a fixed one); 0 < orbit_tol.

    The orbit series do not depend on the attitude, so they are computed first, each to its own m
    (:func:`_orbit_series_into`); then order by order the torque and the attitude.
    """
    ncol = s.shape[1]
    f = member_rows(s)
    a_mom, b_mom, c_mom = load_one(model, BODY_A), load_one(model, BODY_B), load_one(model, BODY_C)
    inverse_moments = quad(1.0 / a_mom, 1.0 / b_mom, 1.0 / c_mom, 0.0)
    euler_factors = quad(b_mom - c_mom, c_mom - a_mom, a_mom - b_mom, 0.0)
    torque_factors = quad(c_mom - b_mom, a_mom - c_mom, b_mom - a_mom, 0.0)
    signs_x, signs_y, signs_z = quad(-1.0, 1.0, 1.0, -1.0), quad(-1.0, -1.0, 1.0, 1.0), quad(-1.0, 1.0, -1.0, 1.0)
    zero = quad_zero(f)
    q = load_quad(f, _Q)
    # fourth lane zero: callers write only y's seven columns
    w = quad(load_one(f, _W), load_one(f, _W + 1), load_one(f, _W + 2), 0.0)
    _store_attitude(f, 0, q, w)
    orbit_tol_sq = orbit_tol * orbit_tol
    for p in range(n_pert):
        row = MODEL_PERTURBERS + 1 + p * PERTURBER_ROW
        kind = int(first_member(model, row))  # the same for every member in lanes (the caller's grouping)
        store_one(orbit_orders, p, _orbit_series_into(f, ncol, _HEAD_COLUMNS + p * _BLOCK_COLUMNS, kind, order,
                                                      load_one(model, row + 2 + K_MU), h_bound, orbit_tol_sq))
    for k in range(order):
        # --- torque N^[k] = Σ 3μ ((C − B) ρ_y ρ_z, (A − C) ρ_z ρ_x, (B − A) ρ_x ρ_y) of each ρ_body
        torque = zero
        for p in range(n_pert):
            mu = load_one(model, MODEL_PERTURBERS + 1 + p * PERTURBER_ROW + 1)
            pairs = _perturber_pairs(f, ncol, _HEAD_COLUMNS + p * _BLOCK_COLUMNS, k, load_one(orbit_orders, p), q)
            torque = fma(torque_factors * (3.0 * mu), pairs, torque)
        store_quad(f, k * ncol + _N, torque)
        # --- Euler: A ω̇x = (B − C) ωy ωz + Nx, cyclic; and q̇ = ½ q ⊗ (0, ω) = ½ Σ_a P_a(q ω_a)
        sx, sy, sz, euler = _attitude_inner(f, ncol, k)
        sx, sy, sz = _with_newest(f, _W, k, q, w, sx, sy, sz)
        inverse = _RECIPROCALS[k]
        w_next = fma(euler_factors, _pairs_with_newest(f, _W, k, w, euler), torque) * inverse_moments * inverse
        q_next = (signs_x * _p_x(sx) + signs_y * _p_y(sy) + signs_z * _p_z(sz)) * (0.5 * inverse)
        _store_attitude(f, (k + 1) * ncol, q_next, w_next)
        q, w = q_next, w_next


@jit
def seed_perturbers(t, model, s, n_pert, t_stop, direction, h_last, orbit_orders, kepler_exact):
    """Order-0 columns of each perturber at time t (all orders of a sampled one); returns the step limit.

    Sampled perturbers write their whole (cubic) series and limit the step to the boundary of their
    Hermite interval in the direction of integration; Kepler and fixed ones impose no limit
    (``t_stop`` returned unchanged). With ``kepler_exact`` False a Kepler perturber is advanced by its
    own Taylor polynomial of the last step (length h_last, orders ≤ orbit_orders[p]) instead of a
    Kepler solve (module docstring: KEPLER_RESEED_INTERVAL). A Kepler perturber's higher orders need no
    clearing: the recurrences write every order they read.
    """
    ncol = s.shape[1]
    flat = s.reshape(-1)
    for p in range(n_pert):
        row = MODEL_PERTURBERS + 1 + p * PERTURBER_ROW
        kind = int(model[row])
        off = row + 2
        base = _HEAD_COLUMNS + p * _BLOCK_COLUMNS
        if kind == KIND_KEPLER and not kepler_exact:
            m = orbit_orders[p]
            position = load_quad(flat, m * ncol + base + _X)
            velocity = load_quad(flat, m * ncol + base + _V)
            for k in range(m - 1, -1, -1):
                position = fma(position, h_last, load_quad(flat, k * ncol + base + _X))
                velocity = fma(velocity, h_last, load_quad(flat, k * ncol + base + _V))
            store_quad(flat, base + _X, position)
            store_quad(flat, base + _V, velocity)
            continue
        if kind != KIND_KEPLER:
            for k in range(s.shape[0]):
                for i in range(8):
                    s[k, base + _X + i] = 0.0
        if kind == KIND_KEPLER:
            px, py, vx, vy = kepler_perifocal(t, model[off + K_A], model[off + K_E], model[off + K_M0],
                                               model[off + K_T0], model[off + K_MEAN_MOTION], model[off + K_ROOT])
            for i in range(3):
                s[0, base + _X + i] = model[off + K_P + i] * px + model[off + K_Q + i] * py
                s[0, base + _V + i] = model[off + K_P + i] * vx + model[off + K_Q + i] * vy
        elif kind == KIND_SAMPLED:
            first, count, xv_first = int(model[off]), int(model[off + 1]), int(model[off + 2])
            lo = find_interval(t, model, first, count)
            if direction < 0.0 and t == model[lo] and lo > first:
                lo -= 1  # going backwards from a sample time: use the interval below it
            t_lo = model[lo]
            h = model[lo + 1] - t_lo
            i0 = xv_first + 6 * (lo - first)
            i1 = i0 + 6
            x = (t - t_lo) / h
            for i in range(3):
                # Hermite cubic in x ∈ [0, 1]: p(x) = c0 + c1 x + c2 x² + c3 x³, re-expanded about x.
                p0, p1, d0, d1 = model[i0 + i], model[i1 + i], h * model[i0 + 3 + i], h * model[i1 + 3 + i]
                c1, c2, c3 = d0, 3.0 * (p1 - p0) - 2.0 * d0 - d1, 2.0 * (p0 - p1) + d0 + d1
                s[0, base + _X + i] = p0 + x * (c1 + x * (c2 + x * c3))
                s[1, base + _X + i] = (c1 + x * (2.0 * c2 + x * 3.0 * c3)) / h
                s[2, base + _X + i] = (c2 + 3.0 * c3 * x) / (h * h)
                s[3, base + _X + i] = c3 / (h * h * h)
            end = model[lo + 1] if direction > 0.0 else t_lo
            if direction * (end - t) > 0.0 and direction * (end - t_stop) < 0.0:
                t_stop = end
        else:  # KIND_FIXED
            for i in range(3):
                s[0, base + _X + i] = model[off + i]
    return t_stop


@jit(inline=INLINE)
def _orbit_term_sq(r, v, inv_r2, inv_v2):
    """The largest of (r_i^[k])²/|r|² and (v_i^[k])²/|v|² over the components i of one order's position and
    velocity: its k-th coefficient, relative, squared.

    ``inv_r2``, ``inv_v2``: 1/|r|², 1/|v|² of the order-0 position and velocity, computed once per step.

    Squared, so that the truncation test (times h^2k against orbit_tol²) needs no square root and
    no power function (the square roots and h**k were ~15 % of a Taylor step in scenes (a)–(c)).
    """
    scaled = r * r * inv_r2
    speeds = v * v * inv_v2
    return max(max(quad_lane(scaled, 0), quad_lane(scaled, 1), quad_lane(scaled, 2)),
               max(quad_lane(speeds, 0), quad_lane(speeds, 1), quad_lane(speeds, 2)))


@jit
def scaled_norm(s, k, w_scale):
    """Max over the scaled components of the order-k coefficients (see the module docstring)."""
    norm = 0.0
    for i in range(4):
        norm = max(norm, abs(s[k, _Q + i]))
    for i in range(3):
        norm = max(norm, abs(s[k, _W + i]) / w_scale)
    return norm


@jit
def orbit_radius(s, n_pert, orbit_orders, order):
    """Radius of convergence of the Kepler perturbers' series from their last two orders (inf if none).

    A series truncated below ``order`` is skipped: its terms are already below the orbit tolerance at
    the largest step allowed, so it cannot limit the step.
    """
    rho = np.inf
    for p in range(n_pert):
        m = orbit_orders[p]
        if m < 2 or m < order:
            continue
        b = _HEAD_COLUMNS + p * _BLOCK_COLUMNS
        r = math.sqrt(s[0, b + _X] ** 2 + s[0, b + _X + 1] ** 2 + s[0, b + _X + 2] ** 2)
        v = math.sqrt(s[0, b + _V] ** 2 + s[0, b + _V + 1] ** 2 + s[0, b + _V + 2] ** 2)
        if v == 0.0:
            continue
        for k in (m - 1, m):
            nk = 0.0
            for i in range(3):
                nk = max(nk, abs(s[k, b + _X + i]) / r, abs(s[k, b + _V + i]) / v)
            if nk > 0.0:
                rho = min(rho, nk ** (-1.0 / k))
    return rho


@jit(fastmath=FUSED_MULTIPLY_ADD)
def state_at(s, order, dt, out):
    """out[0:7] = the state's Taylor polynomial at t + dt: Σ_k s[k, 0:7] dt^k (q and ω as two Horner chains)."""
    ncol = s.shape[1]
    f = s.reshape(-1)
    q = load_quad(f, order * ncol + _Q)
    w = load_quad(f, order * ncol + _W)
    for k in range(order - 1, -1, -1):
        q = fma(q, dt, load_quad(f, k * ncol + _Q))
        w = fma(w, dt, load_quad(f, k * ncol + _W))
    for i in range(4):
        out[i] = quad_lane(q, i)
    for i in range(3):
        out[4 + i] = quad_lane(w, i)


@jit(fastmath=FUSED_MULTIPLY_ADD)
def horner(s, rows, order, dt, out):
    """out[i] = Σ_k s[i, k] dt^k for i < rows of a row-major series (the variational equations' own
    series: row i, order k); ``out`` is not a view of s.

    Four rows' Horner sums in one loop: each is a chain of ``order`` dependent multiply-adds, and four
    independent chains side by side take about the time of one (one row after the other, the chains
    were half of the evaluation's time: 42 → 23 ns for the 7 state rows at order 11, same bits). The
    last group of four is shifted back to end at the last row; a row evaluated twice gets the same value.
    """
    if rows < 4:
        for i in range(rows):
            acc = s[i, order]
            for k in range(order - 1, -1, -1):
                acc = acc * dt + s[i, k]
            out[i] = acc
        return
    i = 0
    while i < rows:
        i = min(i, rows - 4)
        a0, a1, a2, a3 = s[i, order], s[i + 1, order], s[i + 2, order], s[i + 3, order]
        for k in range(order - 1, -1, -1):
            a0 = a0 * dt + s[i, k]
            a1 = a1 * dt + s[i + 1, k]
            a2 = a2 * dt + s[i + 2, k]
            a3 = a3 * dt + s[i + 3, k]
        out[i], out[i + 1], out[i + 2], out[i + 3] = a0, a1, a2, a3
        i += 4


@jit
def taylor_series(t, y, model, order):
    """The (7, order+1) Taylor coefficients of the attitude state at (t, y) (q normalised first).

    For tests and diagnostics: row i, column k is y_i^(k)(t)/k!, with untruncated orbit series.
    """
    n_pert = int(model[MODEL_PERTURBERS])
    s = series_array(n_pert, order)
    for i in range(STATE_SIZE):
        s[0, i] = y[i]
    norm = math.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2 + y[3] ** 2)
    for i in range(4):
        s[0, i] /= norm
    seed_perturbers(t, model, s, n_pert, np.inf, 1.0, 0.0, np.zeros(max(n_pert, 1), dtype=np.int64), True)
    taylor_coefficients_into(t, model, s, n_pert, order, 0.0, 0.0, np.zeros(max(n_pert, 1), dtype=np.int64))
    return s[:, :STATE_SIZE].T.copy()


#: Layout of the series array, for modules that read the columns this one fills: the state's ω starts
#: at OMEGA_COLUMN (q in columns 0–3, as in y), perturber p's block at SERIES_HEAD_COLUMNS +
#: p·PERTURBER_BLOCK_COLUMNS, and its body-frame ρ = |r|⁻⁵ᐟ² r_body (x, y, z) at SCALED_BODY_POSITION_OFFSET
#: in the block (the Taylor variational equations build the tidal tensor from it).
OMEGA_COLUMN = _W
SERIES_HEAD_COLUMNS = _HEAD_COLUMNS
PERTURBER_BLOCK_COLUMNS = _BLOCK_COLUMNS
SCALED_BODY_POSITION_OFFSET = _B
