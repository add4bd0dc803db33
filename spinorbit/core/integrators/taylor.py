"""Adaptive Taylor-series integration of the Euler-parameter equations, entirely in numba.

The equations are those of :mod:`spinorbit.core.dynamics.equations` (q̇ = ½ q ⊗ (0, ω), I ω̇ = Iω × ω + N) with
the degree-2 (MacCullagh) torque of point masses, N = (3μ/R⁵) r × (I r) (``gravity_field.py``,
``docs/torques.md``). Instead of evaluating the right-hand side at stages, the Taylor coefficients
y^[k] = y⁽ᵏ⁾(t)/k! of the solution are generated order by order by automatic differentiation
(Jorba & Zou 2005, Exp. Math. 14, 99): every product a·b of the right-hand side becomes the Cauchy
product (ab)^[k] = Σⱼ a^[j] b^[k−j], the power u = a^α the recurrence
k a^[0] u^[k] = Σ_{j<k} (α(k − j) − j) a^[k−j] u^[j], and y^[k+1] = f^[k]/(k + 1).

**One definition.** The recurrences below are the right-hand side of ``dynamics.rhs_into`` written
term by term; the order-1 coefficient they produce *is* that right-hand side, and ``tests/test_integrate_taylor.py``
checks y^[1] == ``rhs_into`` (and y^[2] against a difference of ``rhs_into`` along the flow) for
random states and perturbers. Two exact rewritings are used, both valid on the unit sphere |q| = 1
on which the exact flow stays (the integrator renormalises q before each expansion):

- r_body = M(q)ᵀ r = r + 2 (u × c − q₀ c), c = u × r, u = (q₁, q₂, q₃) — the rotation by q* without
  the 1/|q|² of ``dynamics.body_frame_xyz`` (which is 1 on the sphere; its series would cost a
  division recurrence);
- (I r) × r components (C − B) r_y r_z etc. (the A r_x r_x terms cancel exactly).

**Perturbers over a step.** A Keplerian perturber's relative position is carried as extra state
of the Taylor system, r̈ = −μ_orbit r / |r|³, advanced by its own Taylor polynomial and *re-seeded
every KEPLER_RESEED_INTERVAL steps* from the exact Kepler solution (``perturbers.kepler_perifocal``):
the series is that of the exact two-body motion (truncation error controlled like everything else)
and the drift between re-seeds stays ~0.1 tol relative. A fixed
perturber is a constant series. A sampled perturber's cubic Hermite piece is a polynomial of degree 3,
so its Taylor series is exact, and steps are clipped at sample times (the piecewise interpolant is
not smooth across them). The figure's degree-3/4 Stokes terms have no recurrence here: the Python
front end falls back to DOP853 with a warning (:class:`TaylorFallbackWarning`).

**Order and step (heyoka's rule, Biscani & Izzo 2021, MNRAS 504, 2614, after Jorba & Zou).** Order
p = ⌈−ln(tol)/2 + 1⌉ (× ``order_factor``); after the expansion the step is
h = ρ · exp(−2) · exp(−0.7/(p − 1)), with ρ = min((1/‖y^[p−1]‖)^{1/(p−1)}, (1/‖y^[p]‖)^{1/p}) the
radius of convergence estimated from the last two coefficients, ‖·‖ the max norm over the scaled
components (q by 1, ω by |ω|: a relative test per group, as spinorbit's DOP853 default atol), and
the same estimate from a Keplerian perturber's orbit series (position by |r|, velocity by |v|), so a
fast flyby also limits the step. With ``order_factor > 1`` the order is raised and the step
taken from the tolerance directly, h = ρ tol^{1/p} exp(−0.7/(p − 1)) (fewer, longer steps, larger
errors at the same tol; measured no better per unit of accuracy, so the default is 1). There are no
rejected steps: the series at t is valid for any h below ρ, so h is chosen after it is computed.

**Truncated orbit series.** A Keplerian perturber's own series (position, velocity, |r|², |r|⁻⁵)
stops at the first order m after which two consecutive terms, at the largest step allowed
(STEP_GROWTH × the previous step), are below ORBIT_TOLERANCE_FRACTION × tol relative to |r| and |v|:
the higher ones are exactly zero in the products. The Sun seen from an asteroid moves ~300× slower
than the body turns, so m ≈ 6 where the attitude needs p = 13 (tol 1e-10), and the products with
the orbit cost m + 1 instead of k + 1 terms. The *torque* series is not truncated: in the body frame
it turns with the body (at twice the spin rate, being quadratic in the rotation), so its high
coefficients are what dominates ω's series; truncating it lost 1e-5 rad at tol 1e-10 (tried).

Dense output: the Taylor polynomial evaluated (Horner) at the requested times inside each step,
q renormalised. Error control is local (per step) as in every adaptive method: the global attitude
error grows with the number of steps; ``docs/performance.md`` shows it against tol.
"""

import math
import warnings

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, STATE_SIZE
from spinorbit.core.dynamics.validation import validate_sampled_span, validate_state
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C, BODY_NMAX
from spinorbit.core.integrators.quaternion import IntegrationError, integrate_quaternion
from spinorbit.core.dynamics.validation import validate_output_times
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

#: Highest Taylor order (tol ≥ 1e-16 with order_factor ≤ 2 needs ≤ 40).
MAX_ORDER = 48
#: Largest growth of the step from one step to the next: bounds the step for which the orbit series'
#: order m is chosen (see the module docstring).
STEP_GROWTH = 1.5
#: An orbit series stops when two consecutive terms at the largest step are below this × tol relative
#: to |r| and |v|: the torque's relative error is then ~1e-2 tol times a factor of order 1, and it
#: enters ω multiplied by the (small) torque.
ORBIT_TOLERANCE_FRACTION = 1e-2
#: A Kepler perturber is re-seeded from the exact Kepler solution every this many steps and advanced
#: by its own Taylor polynomial in between (each advance is exact to ORBIT_TOLERANCE_FRACTION × tol
#: relative, so 16 of them add < 2e-1 tol relative to the position, a 1e-1 tol relative torque error
#: times the torque's small weight in ω); the Kepler solve was ~9 % of a step.
KEPLER_RESEED_INTERVAL = 16
#: Default cap on the number of steps.
DEFAULT_MAX_STEPS = 100_000_000

STATUS_SUCCESS = 0
STATUS_MAX_STEPS = 1
STATUS_STEP_TOO_SMALL = 2
STATUS_NOT_FINITE = 3
STAT_STEPS, STAT_ORDER_SUM, STAT_ORBIT_ORDER_SUM, STAT_STATUS = 0, 1, 2, 3

# Rows of the series array: the attitude state, the summed torque, then one block per perturber.
_Q0, _W0, _N0 = 0, 4, 7
_HEAD_ROWS = 10
# Perturber block: position, velocity, |r|², |r|^-5, |r|^-3, c = u × r, r_body, pair products.
_X, _V, _R2, _S5, _S3, _C, _B, _P = 0, 3, 6, 7, 8, 9, 12, 15
_BLOCK_ROWS = 18


class TaylorFallbackWarning(UserWarning):
    """The model needs a term the Taylor recurrences do not have (degree ≥ 3 field): DOP853 was used."""


@jit(inline="always")
def _cauchy(s, a, b, k):
    """k-th coefficient of the product of the series in rows a and b: Σ_j s[a, j] s[b, k − j]."""
    acc = 0.0
    for j in range(k + 1):
        acc += s[a, j] * s[b, k - j]
    return acc


@jit(inline="always")
def _power(s, u, a, alpha, k):
    """k-th coefficient (k ≥ 1) of u = a^alpha from u's lower ones: k a₀ u_k = Σ (α(k−j) − j) a_{k−j} u_j."""
    acc = 0.0
    for j in range(k):
        acc += (alpha * (k - j) - j) * s[a, k - j] * s[u, j]
    return acc / (k * s[a, 0])


@jit
def _seed_perturbers(t, model, s, n_pert, t_stop, direction, h_last, orbit_orders, kepler_exact):
    """Order-0 rows of each perturber at time t (all rows of a sampled one); returns the step limit.

    Sampled perturbers write their whole (cubic) series and limit the step to the boundary of their
    Hermite interval in the direction of integration; Kepler and fixed ones impose no limit
    (``t_stop`` returned unchanged). With ``kepler_exact`` False a Kepler perturber is advanced by its
    own Taylor polynomial of the last step (length h_last, orders ≤ orbit_orders[p]) instead of a
    Kepler solve (module docstring: KEPLER_RESEED_INTERVAL).
    """
    for p in range(n_pert):
        row = MODEL_PERTURBERS + 1 + p * PERTURBER_ROW
        kind = int(model[row])
        off = row + 2
        base = _HEAD_ROWS + p * _BLOCK_ROWS
        if kind == KIND_KEPLER and not kepler_exact:
            m = orbit_orders[p]
            for i in range(6):
                acc = s[base + i, m]
                for k in range(m - 1, -1, -1):
                    acc = acc * h_last + s[base + i, k]
                s[base + i, 0] = acc
                for k in range(1, m + 1):
                    s[base + i, k] = 0.0
            continue
        for i in range(6):
            for k in range(s.shape[1]):
                s[base + i, k] = 0.0
        if kind == KIND_KEPLER:
            px, py, vx, vy = kepler_perifocal(t, model[off + K_A], model[off + K_E], model[off + K_M0],
                                               model[off + K_T0], model[off + K_MEAN_MOTION], model[off + K_ROOT])
            for i in range(3):
                s[base + _X + i, 0] = model[off + K_P + i] * px + model[off + K_Q + i] * py
                s[base + _V + i, 0] = model[off + K_P + i] * vx + model[off + K_Q + i] * vy
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
                s[base + _X + i, 0] = p0 + x * (c1 + x * (c2 + x * c3))
                s[base + _X + i, 1] = (c1 + x * (2.0 * c2 + x * 3.0 * c3)) / h
                s[base + _X + i, 2] = (c2 + 3.0 * c3 * x) / (h * h)
                s[base + _X + i, 3] = c3 / (h * h * h)
            end = model[lo + 1] if direction > 0.0 else t_lo
            if direction * (end - t) > 0.0 and direction * (end - t_stop) < 0.0:
                t_stop = end
        else:  # KIND_FIXED
            for i in range(3):
                s[base + _X + i, 0] = model[off + i]
    return t_stop


@jit
def taylor_coefficients_into(t, model, s, n_pert, order, h_bound, orbit_tol, orbit_orders):
    """Fill the series array s (rows × ≥ order+1) with the Taylor coefficients at t.

    On entry s[0:7, 0] holds the state (unit q) and the perturber rows are seeded
    (:func:`_seed_perturbers`). Attitude and torque rows get orders 0..order. A Keplerian
    perturber's orbit series (position, |r|², |r|⁻⁵) stops at the first order m after which two
    consecutive terms, at the largest step ``h_bound``, are below ``orbit_tol`` relative to |r| and |v|:
    the Sun's orbit varies ~300× slower than the attitude, so m ≈ 5 instead of p (module docstring).
    ``orbit_orders[p]`` receives m (``order`` for a sampled perturber, 0 for a fixed one); 0 < orbit_tol.
    """
    a_mom, b_mom, c_mom = model[BODY_A], model[BODY_B], model[BODY_C]
    for p in range(n_pert):
        kind = int(model[MODEL_PERTURBERS + 1 + p * PERTURBER_ROW])
        orbit_orders[p] = 0 if kind == KIND_FIXED else order
    for k in range(order):
        # --- torque N^[k]
        nx = 0.0
        ny = 0.0
        nz = 0.0
        for p in range(n_pert):
            row = MODEL_PERTURBERS + 1 + p * PERTURBER_ROW
            mu = model[row + 1]
            b = _HEAD_ROWS + p * _BLOCK_ROWS
            m = orbit_orders[p]
            if k <= m:
                s[b + _R2, k] = (_cauchy(s, b + _X, b + _X, k) + _cauchy(s, b + _X + 1, b + _X + 1, k)
                                 + _cauchy(s, b + _X + 2, b + _X + 2, k))
                if k == 0:
                    s[b + _S5, 0] = s[b + _R2, 0] ** -2.5
                else:
                    s[b + _S5, k] = _power(s, b + _S5, b + _R2, -2.5, k)
                if int(model[row]) == KIND_KEPLER and k < m:
                    # Two-body motion of the relative position: r'' = −μ_orbit r |r|⁻³.
                    s[b + _S3, k] = _cauchy(s, b + _S5, b + _R2, k)
                    mu_orbit = model[row + 2 + K_MU]
                    inv = 1.0 / (k + 1)
                    for i in range(3):
                        s[b + _X + i, k + 1] = s[b + _V + i, k] * inv
                        s[b + _V + i, k + 1] = -mu_orbit * _cauchy(s, b + _S3, b + _X + i, k) * inv
                    if k >= 1 and _orbit_term(s, b, k, h_bound) < orbit_tol \
                            and _orbit_term(s, b, k + 1, h_bound) < orbit_tol:
                        orbit_orders[p] = k + 1
            lo = max(0, k - m)  # r, |r|⁻⁵ are zero above order m
            # c = u × r, u = (q1, q2, q3)
            cx = 0.0
            cy = 0.0
            cz = 0.0
            for j in range(lo, k + 1):
                rx, ry, rz = s[b + _X, k - j], s[b + _X + 1, k - j], s[b + _X + 2, k - j]
                q1, q2, q3 = s[_Q0 + 1, j], s[_Q0 + 2, j], s[_Q0 + 3, j]
                cx += q2 * rz - q3 * ry
                cy += q3 * rx - q1 * rz
                cz += q1 * ry - q2 * rx
            s[b + _C, k] = cx
            s[b + _C + 1, k] = cy
            s[b + _C + 2, k] = cz
            # r_body = r + 2 (u × c − q0 c)
            bx = 0.0
            by = 0.0
            bz = 0.0
            for j in range(k + 1):
                q0, q1, q2, q3 = s[_Q0, j], s[_Q0 + 1, j], s[_Q0 + 2, j], s[_Q0 + 3, j]
                cx, cy, cz = s[b + _C, k - j], s[b + _C + 1, k - j], s[b + _C + 2, k - j]
                bx += q2 * cz - q3 * cy - q0 * cx
                by += q3 * cx - q1 * cz - q0 * cy
                bz += q1 * cy - q2 * cx - q0 * cz
            xk = s[b + _X, k] if k <= m else 0.0
            yk = s[b + _X + 1, k] if k <= m else 0.0
            zk = s[b + _X + 2, k] if k <= m else 0.0
            s[b + _B, k] = xk + 2.0 * bx
            s[b + _B + 1, k] = yk + 2.0 * by
            s[b + _B + 2, k] = zk + 2.0 * bz
            # Pair products (y z, z x, x y) of r_body, then N = 3μ |r|⁻⁵ ((C − B) yz, (A − C) zx, (B − A) xy)
            px = 0.0
            py = 0.0
            pz = 0.0
            for j in range(k + 1):
                bxj, byj, bzj = s[b + _B, j], s[b + _B + 1, j], s[b + _B + 2, j]
                px += byj * s[b + _B + 2, k - j]
                py += bzj * s[b + _B, k - j]
                pz += bxj * s[b + _B + 1, k - j]
            s[b + _P, k] = px
            s[b + _P + 1, k] = py
            s[b + _P + 2, k] = pz
            sx = 0.0
            sy = 0.0
            sz = 0.0
            for j in range(lo, k + 1):
                w = s[b + _S5, k - j]
                sx += w * s[b + _P, j]
                sy += w * s[b + _P + 1, j]
                sz += w * s[b + _P + 2, j]
            three_mu = 3.0 * mu
            nx += three_mu * (c_mom - b_mom) * sx
            ny += three_mu * (a_mom - c_mom) * sy
            nz += three_mu * (b_mom - a_mom) * sz
        s[_N0, k] = nx
        s[_N0 + 1, k] = ny
        s[_N0 + 2, k] = nz
        # --- Euler: A ω̇x = (B − C) ωy ωz + Nx, cyclic; and q̇ = ½ q ⊗ (0, ω)
        wyz = 0.0
        wzx = 0.0
        wxy = 0.0
        q0w = 0.0
        q1w = 0.0
        q2w = 0.0
        q3w = 0.0
        for j in range(k + 1):
            q0, q1, q2, q3 = s[_Q0, j], s[_Q0 + 1, j], s[_Q0 + 2, j], s[_Q0 + 3, j]
            wxj, wyj, wzj = s[_W0, j], s[_W0 + 1, j], s[_W0 + 2, j]
            wx, wy, wz = s[_W0, k - j], s[_W0 + 1, k - j], s[_W0 + 2, k - j]
            wyz += wyj * wz
            wzx += wzj * wx
            wxy += wxj * wy
            q0w += -q1 * wx - q2 * wy - q3 * wz
            q1w += q0 * wx + q2 * wz - q3 * wy
            q2w += q0 * wy - q1 * wz + q3 * wx
            q3w += q0 * wz + q1 * wy - q2 * wx
        inv = 1.0 / (k + 1)
        s[_W0, k + 1] = ((b_mom - c_mom) * wyz + nx) / a_mom * inv
        s[_W0 + 1, k + 1] = ((c_mom - a_mom) * wzx + ny) / b_mom * inv
        s[_W0 + 2, k + 1] = ((a_mom - b_mom) * wxy + nz) / c_mom * inv
        half = 0.5 * inv
        s[_Q0, k + 1] = half * q0w
        s[_Q0 + 1, k + 1] = half * q1w
        s[_Q0 + 2, k + 1] = half * q2w
        s[_Q0 + 3, k + 1] = half * q3w


@jit(inline="always")
def _orbit_term(s, b, k, h):
    """max(|r^[k]|/|r|, |v^[k]|/|v|) h^k of the perturber block at row b: its k-th term, relative."""
    r = math.sqrt(s[b + _X, 0] ** 2 + s[b + _X + 1, 0] ** 2 + s[b + _X + 2, 0] ** 2)
    v = math.sqrt(s[b + _V, 0] ** 2 + s[b + _V + 1, 0] ** 2 + s[b + _V + 2, 0] ** 2)
    term = 0.0
    for i in range(3):
        term = max(term, abs(s[b + _X + i, k]) / r, abs(s[b + _V + i, k]) / v)
    return term * h ** k


@jit
def _scaled_norm(s, k, w_scale):
    """Max over the scaled components of the order-k coefficients (see the module docstring)."""
    norm = 0.0
    for i in range(4):
        norm = max(norm, abs(s[_Q0 + i, k]))
    for i in range(3):
        norm = max(norm, abs(s[_W0 + i, k]) / w_scale)
    return norm


@jit
def _orbit_radius(s, n_pert, orbit_orders, order):
    """Radius of convergence of the Kepler perturbers' series from their last two orders (inf if none).

    A series truncated below ``order`` is skipped: its terms are already below the orbit tolerance at
    the largest step allowed, so it cannot limit the step.
    """
    rho = np.inf
    for p in range(n_pert):
        m = orbit_orders[p]
        if m < 2 or m < order:
            continue
        b = _HEAD_ROWS + p * _BLOCK_ROWS
        r = math.sqrt(s[b + _X, 0] ** 2 + s[b + _X + 1, 0] ** 2 + s[b + _X + 2, 0] ** 2)
        v = math.sqrt(s[b + _V, 0] ** 2 + s[b + _V + 1, 0] ** 2 + s[b + _V + 2, 0] ** 2)
        if v == 0.0:
            continue
        for k in (m - 1, m):
            nk = 0.0
            for i in range(3):
                nk = max(nk, abs(s[b + _X + i, k]) / r, abs(s[b + _V + i, k]) / v)
            if nk > 0.0:
                rho = min(rho, nk ** (-1.0 / k))
    return rho


@jit
def _horner(s, rows, order, dt, out):
    """out[i] = Σ_k s[i, k] dt^k for i < rows (the Taylor polynomial at t + dt)."""
    for i in range(rows):
        acc = s[i, order]
        for k in range(order - 1, -1, -1):
            acc = acc * dt + s[i, k]
        out[i] = acc


@jit
def _normalize_quaternion(y):
    norm = math.sqrt(y[0] * y[0] + y[1] * y[1] + y[2] * y[2] + y[3] * y[3])
    for i in range(4):
        y[i] /= norm


@jit
def taylor_order(tol, order_factor):
    """Order p = ⌈(−ln tol / 2 + 1) · order_factor⌉ (heyoka's rule at order_factor = 1), 2 ≤ p ≤ MAX_ORDER."""
    p = int(math.ceil((-math.log(tol) / 2.0 + 1.0) * order_factor))  # noqa: RUF046 (numba int)
    return min(max(p, 2), MAX_ORDER)


@jit
def integrate_taylor_kernel(y0, t0, t_out, model, tol, order_factor, max_steps):
    """Adaptive Taylor integration from (t0, y0) with output at the monotone times ``t_out``.

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out (q renormalised).
    stats : ndarray (4,) int64
        [steps, Σ order, Σ orbit-series orders over perturbers, status].
    """
    n = STATE_SIZE
    n_out = t_out.shape[0]
    ys = np.full((n_out, n), np.nan)
    stats = np.zeros(4, dtype=np.int64)
    n_pert = int(model[MODEL_PERTURBERS])
    order = taylor_order(tol, order_factor)
    s = np.zeros((_HEAD_ROWS + n_pert * _BLOCK_ROWS, order + 1))
    y = y0.copy()
    _normalize_quaternion(y)
    t_end = t_out[n_out - 1]
    direction = 1.0 if t_end >= t0 else -1.0
    # heyoka's safety factor on ρ (order_factor = 1), or the tolerance itself for raised orders.
    if order_factor == 1.0:
        step_factor = math.exp(-2.0) * math.exp(-0.7 / (order - 1))
    else:
        step_factor = tol ** (1.0 / order) * math.exp(-0.7 / (order - 1))
    orbit_orders = np.zeros(max(n_pert, 1), dtype=np.int64)
    orbit_tol = ORBIT_TOLERANCE_FRACTION * tol
    w_norm = math.sqrt(y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
    h_prev = 1.0 / (math.e * math.e * max(w_norm, 1e-300))
    h_last = 0.0
    t = t0
    i_out = 0
    while i_out < n_out and t_out[i_out] == t0:
        ys[i_out] = y
        i_out += 1
    steps = 0
    while i_out < n_out:
        if steps >= max_steps:
            stats[STAT_STATUS] = STATUS_MAX_STEPS
            return ys, stats
        for i in range(n):
            s[i, 0] = y[i]
        exact = steps % KEPLER_RESEED_INTERVAL == 0
        t_stop = _seed_perturbers(t, model, s, n_pert, t_end, direction, h_last, orbit_orders, exact)
        w_norm = math.sqrt(y[4] * y[4] + y[5] * y[5] + y[6] * y[6])
        w_scale = max(w_norm, 1e-300)
        h_cap = STEP_GROWTH * h_prev
        taylor_coefficients_into(t, model, s, n_pert, order, h_cap, orbit_tol, orbit_orders)
        n_last = _scaled_norm(s, order, w_scale)
        n_prev = _scaled_norm(s, order - 1, w_scale)
        rho = np.inf
        if n_prev > 0.0:
            rho = n_prev ** (-1.0 / (order - 1))
        if n_last > 0.0:
            rho = min(rho, n_last ** (-1.0 / order))
        if n_pert > 0:
            rho = min(rho, _orbit_radius(s, n_pert, orbit_orders, order))
        h_abs = min(rho * step_factor, h_cap)
        if not math.isfinite(h_abs) or h_abs <= 0.0:
            if math.isinf(rho) and math.isfinite(h_cap):
                h_abs = h_cap  # exactly polynomial solution (e.g. at rest)
            else:
                stats[STAT_STATUS] = STATUS_NOT_FINITE
                return ys, stats
        t_new = t + direction * h_abs
        if direction * (t_new - t_stop) > 0.0:
            t_new = t_stop
        h = t_new - t
        if not (abs(h) > 10.0 * abs(np.nextafter(t, t + direction) - t)):
            stats[STAT_STATUS] = STATUS_STEP_TOO_SMALL
            return ys, stats
        steps += 1
        stats[STAT_STEPS] += 1
        stats[STAT_ORDER_SUM] += order
        for p in range(n_pert):
            stats[STAT_ORBIT_ORDER_SUM] += orbit_orders[p]
        while i_out < n_out and direction * (t_out[i_out] - t_new) <= 0.0:
            _horner(s, n, order, t_out[i_out] - t, ys[i_out])
            _normalize_quaternion(ys[i_out])
            i_out += 1
        _horner(s, n, order, h, y)
        _normalize_quaternion(y)
        for i in range(n):
            if not math.isfinite(y[i]):
                stats[STAT_STATUS] = STATUS_NOT_FINITE
                return ys, stats
        h_last = h
        if t_new != t_stop or abs(h) >= h_prev:
            h_prev = abs(h)
        t = t_new
    stats[STAT_STATUS] = STATUS_SUCCESS
    return ys, stats


@jit
def taylor_series(t, y, model, order):
    """The (7, order+1) Taylor coefficients of the attitude state at (t, y) (q normalised first).

    For tests and diagnostics: row i, column k is y_i^(k)(t)/k!, with untruncated orbit series.
    """
    n_pert = int(model[MODEL_PERTURBERS])
    s = np.zeros((_HEAD_ROWS + n_pert * _BLOCK_ROWS, order + 1))
    for i in range(STATE_SIZE):
        s[i, 0] = y[i]
    norm = math.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2 + y[3] ** 2)
    for i in range(4):
        s[i, 0] /= norm
    _seed_perturbers(t, model, s, n_pert, np.inf, 1.0, 0.0, np.zeros(max(n_pert, 1), dtype=np.int64), True)
    taylor_coefficients_into(t, model, s, n_pert, order, 0.0, 0.0, np.zeros(max(n_pert, 1), dtype=np.int64))
    return s[:STATE_SIZE].copy()


@jit
def integrate_taylor_fixed_kernel(y0, t0, t1, n_steps, model, order):
    """n_steps equal Taylor steps of the given order (full torque series, q renormalised) → y(t1).

    For measuring the order of convergence: the local error is O(h^(order+1)), the global O(h^order).
    """
    n_pert = int(model[MODEL_PERTURBERS])
    s = np.zeros((_HEAD_ROWS + n_pert * _BLOCK_ROWS, order + 1))
    orbit_orders = np.zeros(max(n_pert, 1), dtype=np.int64)
    y = y0.copy()
    _normalize_quaternion(y)
    h = (t1 - t0) / n_steps
    for step in range(n_steps):
        t = t0 + step * h
        for i in range(STATE_SIZE):
            s[i, 0] = y[i]
        _seed_perturbers(t, model, s, n_pert, t1, 1.0 if h > 0.0 else -1.0, h, orbit_orders, True)
        taylor_coefficients_into(t, model, s, n_pert, order, 0.0, 0.0, orbit_orders)
        _horner(s, STATE_SIZE, order, h, y)
        _normalize_quaternion(y)
    return y


# ---------------------------------------------------------------------------------------------
# Python front end: validation only, then one call into the kernel.

_STATUS_MESSAGES = {
    STATUS_MAX_STEPS: "reached max_steps; raise max_steps",
    STATUS_STEP_TOO_SMALL: "the step size underflowed; the solution may be singular (e.g. a perturber "
    "passing through the body)",
    STATUS_NOT_FINITE: "the state or its Taylor series became NaN/inf; check that sampled perturbers cover "
    "the whole time span",
}


def _validate_tolerance(tol):
    if not (isinstance(tol, (int, float, np.floating)) and np.isfinite(tol) and tol > 0):
        raise ValueError(f"tol: expected a tolerance > 0, got {tol!r}; try 1e-10.")
    if tol < 1e-16:
        raise ValueError(f"tol: expected tol ≥ 1e-16 (double precision cannot do better), got {tol!r}.")
    return float(tol)


def _validate_order_factor(order_factor):
    if not (np.isfinite(order_factor) and 1.0 <= order_factor <= 2.0):
        raise ValueError(f"order_factor: expected a number in [1, 2] (1 = heyoka's order), got {order_factor!r}.")
    return float(order_factor)


def _needs_fallback(model):
    return int(model[BODY_NMAX]) > 2


#: Default raise of the order over heyoka's rule. 1.2–1.6 gave 1.9–2.5× fewer steps but 10–300× larger
#: errors at the same tol and the same CPU per unit of accuracy (±10 %) in scenes (a) and (b).
DEFAULT_ORDER_FACTOR = 1.0


def integrate_taylor(y0, t0, t_out, model, tol=1e-10, order_factor=DEFAULT_ORDER_FACTOR,
                     max_steps=DEFAULT_MAX_STEPS, return_stats=False):
    """Integrate the rotational equations of motion with an adaptive Taylor method and renormalised q.

    Parameters
    ----------
    y0 : array_like (7,)
        Initial state (q0, q1, q2, q3, ωx, ωy, ωz): scalar-first quaternion (normalised here) and
        body angular velocity (rad/time unit).
    t0 : float
        Initial time (time unit of the model).
    t_out : array_like (n,)
        Output times, strictly monotone away from t0.
    model : ndarray
        From :func:`spinorbit.core.dynamics.equations.make_model`. A figure with degree-3/4 Stokes terms is
        integrated by :func:`spinorbit.core.integrators.quaternion.integrate_quaternion` instead
        (``rtol = tol``), with a :class:`TaylorFallbackWarning`.
    tol : float
        Local error tolerance per step, relative per component group (q by 1, ω by |ω|);
        1e-16 ≤ tol.
    order_factor : float
        Multiplies heyoka's order ⌈−ln(tol)/2 + 1⌉, in [1, 2] (module docstring).
    max_steps : int
        Cap on the number of steps.
    return_stats : bool
        Also return a dict: ``steps``, ``order``, ``mean_orbit_order`` (orbit-series order per step,
        summed over perturbers).

    Returns
    -------
    ys : ndarray (n, 7)
        States at t_out.
    stats : dict, optional

    Raises
    ------
    ValueError
        Bad state, times, tolerance or order factor, or output times outside the span of a sampled
        perturber.
    IntegrationError
        The kernel stopped early (see the message).
    """
    y0 = validate_state(y0)
    t0 = float(t0)
    t_out = validate_output_times(t0, t_out)
    tol = _validate_tolerance(tol)
    order_factor = _validate_order_factor(order_factor)
    model = np.ascontiguousarray(model, dtype=float)
    validate_sampled_span(model, t0, t_out)
    if _needs_fallback(model):
        warnings.warn(
            f"integrate_taylor: the figure has degree-{int(model[BODY_NMAX])} Stokes terms, for which there "
            "is no Taylor recurrence; integrating with DOP853 (integrate_quaternion, rtol = tol) instead.",
            TaylorFallbackWarning, stacklevel=2)
        return integrate_quaternion(y0, t0, t_out, model, rtol=tol, return_stats=return_stats)
    ys, stats = integrate_taylor_kernel(y0, t0, t_out, model, tol, order_factor, int(max_steps))
    status = int(stats[STAT_STATUS])
    if status != STATUS_SUCCESS:
        raise IntegrationError(f"integration stopped at step {int(stats[STAT_STEPS])}: {_STATUS_MESSAGES[status]}.")
    if return_stats:
        steps = max(int(stats[STAT_STEPS]), 1)
        return ys, {"steps": int(stats[STAT_STEPS]), "order": taylor_order(tol, order_factor),
                    "mean_orbit_order": float(stats[STAT_ORBIT_ORDER_SUM]) / steps}
    return ys


def integrate_taylor_fixed_step(y0, t0, t1, n_steps, model, order):
    """y(t1) after ``n_steps`` equal Taylor steps of ``order`` (order measurements; no error control)."""
    y0 = validate_state(y0)
    if int(n_steps) < 1:
        raise ValueError(f"n_steps: expected a positive number of steps, got {n_steps!r}.")
    if not (1 <= int(order) <= MAX_ORDER):
        raise ValueError(f"order: expected an order in [1, {MAX_ORDER}], got {order!r}.")
    if _needs_fallback(np.asarray(model)):
        raise ValueError("model: the fixed-step Taylor mode has no degree-3/4 field; use integrate_fixed_step.")
    return integrate_taylor_fixed_kernel(y0, float(t0), float(t1), int(n_steps),
                                         np.ascontiguousarray(model, dtype=float), int(order))
