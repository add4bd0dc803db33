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
  torque at the attitude's orders is the rotation and the pair products only, without the three
  products with a |r|⁻⁵ series of the formulation N = 3μ|r|⁻⁵ (…) (4–9 % less CPU per coefficient
  call in scenes (a)–(c); same physics, only the rounding differs: |r|⁻⁵ is split in two factors).

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
from spinorbit.core.jit import FUSED_MULTIPLY_ADD, jit
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

# Rows of the series array: the attitude state, the summed torque, then one block per perturber.
_Q0, _W0, _N0 = 0, 4, 7
_HEAD_ROWS = 10
# Perturber block: position, velocity, |r|², |r|^-5/2, |r|^-3, ρ = |r|^-5/2 r, c = u × ρ, ρ_body.
_X, _V, _R2, _S52, _S3, _RHO, _C, _B = 0, 3, 6, 7, 8, 9, 12, 15
_BLOCK_ROWS = 18

@jit
def series_array(n_pert, order):
    """Zeroed series array for n_pert perturbers up to ``order``: rows 0..6 are the state (q, ω)."""
    return np.zeros((_HEAD_ROWS + n_pert * _BLOCK_ROWS, order + 1))


@jit(inline="always")
def _cauchy(s, a, b, k):
    """k-th coefficient of the product of the series in rows a and b: Σ_j s[a, j] s[b, k − j]."""
    acc = 0.0
    for j in range(k + 1):
        acc += s[a, j] * s[b, k - j]
    return acc


@jit(inline="always")
def _cauchy_vector(s, a, b, a_stride, k):
    """k-th coefficients of the three products of rows (a + i·a_stride) and (b + i), i = 0, 1, 2, in one loop.

    a_stride 0: a scalar series times a 3-vector; 1: the componentwise products of two 3-vectors. The
    same sums as three :func:`_cauchy` calls (same order, same bits), with three independent chains of
    fused multiply-adds per iteration instead of one (a single Cauchy sum is bound by their latency).
    """
    x = 0.0
    y = 0.0
    z = 0.0
    for j in range(k + 1):
        x += s[a, j] * s[b, k - j]
        y += s[a + a_stride, j] * s[b + 1, k - j]
        z += s[a + 2 * a_stride, j] * s[b + 2, k - j]
    return x, y, z


@jit(inline="always")
def _set_vector(s, row, k, x, y, z):
    """The order-k coefficients of the 3-vector series in rows row, row + 1, row + 2."""
    s[row, k] = x
    s[row + 1, k] = y
    s[row + 2, k] = z


@jit(inline="always")
def _cauchy_cross(s, a, b, k, lo):
    """k-th coefficient of the cross product of the 3-row series at rows a and b: Σ_{j=lo}^{k} a^[j] × b^[k−j].

    ``lo`` > 0 skips the terms where b^[k−j] is known to be zero (a truncated orbit series).
    """
    x = 0.0
    y = 0.0
    z = 0.0
    for j in range(lo, k + 1):
        ax, ay, az = s[a, j], s[a + 1, j], s[a + 2, j]
        bx, by, bz = s[b, k - j], s[b + 1, k - j], s[b + 2, k - j]
        x += ay * bz - az * by
        y += az * bx - ax * bz
        z += ax * by - ay * bx
    return x, y, z


@jit(inline="always")
def _power(s, u, a, alpha, k):
    """k-th coefficient (k ≥ 1) of u = a^alpha from u's lower ones: k a₀ u_k = Σ (α(k−j) − j) a_{k−j} u_j."""
    acc = 0.0
    for j in range(k):
        acc += (alpha * (k - j) - j) * s[a, k - j] * s[u, j]
    return acc / (k * s[a, 0])


@jit
def seed_perturbers(t, model, s, n_pert, t_stop, direction, h_last, orbit_orders, kepler_exact):
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


@jit(inline="always")
def _orbit_series_into(s, b, kind, order, mu_orbit, h_bound, orbit_tol_sq):
    """A perturber's orbit rows (r, |r|², |r|⁻⁵ᐟ², ρ = |r|⁻⁵ᐟ² r) to its truncation order m, which it returns.

    Independent of the attitude, so computed before it. A Kepler perturber's two-body motion
    r'' = −μ_orbit r |r|⁻³ fills r and v up to m (module docstring, *Truncated orbit series*); a
    sampled one's r rows are given (cubic), m = order; a fixed one has m = 0. ρ carries the torque's
    |r|⁻⁵ as the square of its |r|⁻⁵ᐟ², so that the torque needs no product with a |r|⁻⁵ series at
    the attitude's orders (module docstring, *Torque*).
    """
    m = 0 if kind == KIND_FIXED else order
    r2 = s[b + _X, 0] * s[b + _X, 0] + s[b + _X + 1, 0] * s[b + _X + 1, 0] + s[b + _X + 2, 0] * s[b + _X + 2, 0]
    inv_r2 = 1.0 / r2
    inv_v2 = 1.0 / (s[b + _V, 0] ** 2 + s[b + _V + 1, 0] ** 2 + s[b + _V + 2, 0] ** 2)
    h_pow_sq = 1.0  # h_bound^(2k), by one product per order (no power function in the loop)
    for k in range(order):
        if k > m:
            break
        h_pow_sq_next = h_pow_sq * h_bound * h_bound
        x2, y2, z2 = _cauchy_vector(s, b + _X, b + _X, 1, k)
        s[b + _R2, k] = x2 + y2 + z2
        if k == 0:
            s[b + _S52, 0] = 1.0 / (r2 * math.sqrt(math.sqrt(r2)))  # |r|⁻⁵ᐟ² without a power function
        else:
            s[b + _S52, k] = _power(s, b + _S52, b + _R2, -1.25, k)
        rx, ry, rz = _cauchy_vector(s, b + _S52, b + _X, 0, k)
        _set_vector(s, b + _RHO, k, rx, ry, rz)
        if kind == KIND_KEPLER and k < m:
            if k == 0:
                s[b + _S3, 0] = 1.0 / (r2 * math.sqrt(r2))
            else:
                s[b + _S3, k] = _power(s, b + _S3, b + _R2, -1.5, k)
            inv = 1.0 / (k + 1)
            ax, ay, az = _cauchy_vector(s, b + _S3, b + _X, 0, k)
            for i in range(3):
                s[b + _X + i, k + 1] = s[b + _V + i, k] * inv
            _set_vector(s, b + _V, k + 1, -mu_orbit * ax * inv, -mu_orbit * ay * inv, -mu_orbit * az * inv)
            if k >= 1 and _orbit_term_sq(s, b, k, inv_r2, inv_v2) * h_pow_sq < orbit_tol_sq \
                    and _orbit_term_sq(s, b, k + 1, inv_r2, inv_v2) * h_pow_sq_next < orbit_tol_sq:
                m = k + 1
        h_pow_sq = h_pow_sq_next
    return m


@jit(fastmath=FUSED_MULTIPLY_ADD)
def taylor_coefficients_into(t, model, s, n_pert, order, h_bound, orbit_tol, orbit_orders):
    """Fill the series array s (rows × ≥ order+1) with the Taylor coefficients at t.

    On entry s[0:7, 0] holds the state (unit q) and the perturber rows are seeded
    (:func:`seed_perturbers`). Attitude and torque rows get orders 0..order. A Keplerian
    perturber's orbit series (position, |r|², |r|⁻⁵ᐟ², ρ) stops at the first order m after which two
    consecutive terms, at the largest step ``h_bound``, are below ``orbit_tol`` relative to |r| and |v|:
    the Sun's orbit varies ~300× slower than the attitude, so m ≈ 5 instead of p (module docstring).
    ``orbit_orders[p]`` receives m (``order`` for a sampled perturber, 0 for a fixed one); 0 < orbit_tol.

    The orbit series do not depend on the attitude, so they are computed first, each to its own m
    (:func:`_orbit_series_into`); then order by order the torque and the attitude. Fused multiply-adds
    (``jit.FUSED_MULTIPLY_ADD``): the step is Cauchy products.
    """
    a_mom, b_mom, c_mom = model[BODY_A], model[BODY_B], model[BODY_C]
    orbit_tol_sq = orbit_tol * orbit_tol
    for p in range(n_pert):
        row = MODEL_PERTURBERS + 1 + p * PERTURBER_ROW
        kind = int(model[row])
        orbit_orders[p] = _orbit_series_into(s, _HEAD_ROWS + p * _BLOCK_ROWS, kind, order, model[row + 2 + K_MU],
                                             h_bound, orbit_tol_sq)
    for k in range(order):
        # --- torque N^[k]
        nx = 0.0
        ny = 0.0
        nz = 0.0
        for p in range(n_pert):
            mu = model[MODEL_PERTURBERS + 1 + p * PERTURBER_ROW + 1]
            b = _HEAD_ROWS + p * _BLOCK_ROWS
            m = orbit_orders[p]
            lo = max(0, k - m)  # ρ is zero above order m
            # c = u × ρ, u = (q1, q2, q3)
            cx, cy, cz = _cauchy_cross(s, _Q0 + 1, b + _RHO, k, lo)
            _set_vector(s, b + _C, k, cx, cy, cz)
            # ρ_body = ρ + 2 (u × c − q0 c)
            bx = 0.0
            by = 0.0
            bz = 0.0
            for j in range(k + 1):
                q0, q1, q2, q3 = s[_Q0, j], s[_Q0 + 1, j], s[_Q0 + 2, j], s[_Q0 + 3, j]
                cx, cy, cz = s[b + _C, k - j], s[b + _C + 1, k - j], s[b + _C + 2, k - j]
                bx += q2 * cz - q3 * cy - q0 * cx
                by += q3 * cx - q1 * cz - q0 * cy
                bz += q1 * cy - q2 * cx - q0 * cz
            xk = s[b + _RHO, k] if k <= m else 0.0
            yk = s[b + _RHO + 1, k] if k <= m else 0.0
            zk = s[b + _RHO + 2, k] if k <= m else 0.0
            _set_vector(s, b + _B, k, xk + 2.0 * bx, yk + 2.0 * by, zk + 2.0 * bz)
            # Pair products (y z, z x, x y) of ρ_body = |r|⁻⁵ (y z, z x, x y) of r_body, then
            # N = 3μ ((C − B) yz, (A − C) zx, (B − A) xy)
            # Two partial sums (j < k/2 and the rest, paired as j, k − j): each sum's chain of dependent
            # fused multiply-adds is half as long (the loop was bound by their latency, 3 per iteration).
            sx, sy, sz = 0.0, 0.0, 0.0
            tx, ty, tz = 0.0, 0.0, 0.0
            half = (k + 1) // 2
            for j in range(half):
                i = k - j
                sx += s[b + _B + 1, j] * s[b + _B + 2, i]
                sy += s[b + _B + 2, j] * s[b + _B, i]
                sz += s[b + _B, j] * s[b + _B + 1, i]
                tx += s[b + _B + 1, i] * s[b + _B + 2, j]
                ty += s[b + _B + 2, i] * s[b + _B, j]
                tz += s[b + _B, i] * s[b + _B + 1, j]
            if 2 * half < k + 1:
                sx += s[b + _B + 1, half] * s[b + _B + 2, half]
                sy += s[b + _B + 2, half] * s[b + _B, half]
                sz += s[b + _B, half] * s[b + _B + 1, half]
            sx += tx
            sy += ty
            sz += tz
            three_mu = 3.0 * mu
            nx += three_mu * (c_mom - b_mom) * sx
            ny += three_mu * (a_mom - c_mom) * sy
            nz += three_mu * (b_mom - a_mom) * sz
        _set_vector(s, _N0, k, nx, ny, nz)
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
def _orbit_term_sq(s, b, k, inv_r2, inv_v2):
    """max(|r^[k]|²/|r|², |v^[k]|²/|v|²) of the perturber block at row b: its k-th coefficient, relative, squared.

    ``inv_r2``, ``inv_v2``: 1/|r|², 1/|v|² of the block's order-0 rows, computed once per step.

    Squared, so that the truncation test (times h^2k against orbit_tol²) needs no square root and
    no power function (the square roots and h**k were ~15 % of a Taylor step in scenes (a)–(c)).
    """
    term = 0.0
    for i in range(3):
        term = max(term, s[b + _X + i, k] ** 2 * inv_r2, s[b + _V + i, k] ** 2 * inv_v2)
    return term


@jit
def scaled_norm(s, k, w_scale):
    """Max over the scaled components of the order-k coefficients (see the module docstring)."""
    norm = 0.0
    for i in range(4):
        norm = max(norm, abs(s[_Q0 + i, k]))
    for i in range(3):
        norm = max(norm, abs(s[_W0 + i, k]) / w_scale)
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


@jit(fastmath=FUSED_MULTIPLY_ADD)
def horner(s, rows, order, dt, out):
    """out[i] = Σ_k s[i, k] dt^k for i < rows (the Taylor polynomial at t + dt); ``out`` is not a view of s.

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
        s[i, 0] = y[i]
    norm = math.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2 + y[3] ** 2)
    for i in range(4):
        s[i, 0] /= norm
    seed_perturbers(t, model, s, n_pert, np.inf, 1.0, 0.0, np.zeros(max(n_pert, 1), dtype=np.int64), True)
    taylor_coefficients_into(t, model, s, n_pert, order, 0.0, 0.0, np.zeros(max(n_pert, 1), dtype=np.int64))
    return s[:STATE_SIZE].copy()


#: Public names of the series array's layout, for modules that read the rows this one fills (the Taylor
#: variational equations need each perturber's body-frame ρ = |r|⁻⁵ᐟ² r_body).
SERIES_HEAD_ROWS = _HEAD_ROWS
PERTURBER_BLOCK_ROWS = _BLOCK_ROWS
SCALED_BODY_POSITION_OFFSET = _B
