"""The exact state transition matrix of the free flow, and its sensitivities to the moment ratios.

State and parameters (``docs/conventions.md``, "State transition matrices")
---------------------------------------------------------------------------
The local state is x = (δθ, ω): δθ the body-frame rotation vector of q = q_ref ⊗ exp(δθ/2) (q scalar
first, body → inertial), ω the body angular velocity on the principal axes A ≤ B ≤ C. The
parameters are the moment ratios p = (A/C, B/C) at fixed C (the free motion of ω and q depends on
the ratios only). Φ(t) = ∂x(t)/∂x(0) is 6 × 6, Ψ(t) = ∂x(t)/∂p is 6 × 2.

How Φ is formed (the elements make the flow linear)
---------------------------------------------------
In the canonical elements E = (S, Z, H, s, z, h) the free flow is E(t) = E(0) + (0, 0, 0, a S t, 0, 0)
(paper eq. 12), so its STM is F(t) = 1 + a t e_s e_Sᵀ. With K(t) = ∂x/∂E at E(t) (the backward map's
Jacobian), Φ(t) = K(t) F(t) K(0)⁻¹. K is written in a basis of element directions whose columns are
known exactly; only one needs the paper's section-4 Jacobian (:mod:`spinorbit.core.elements.jacobian`):

* e_S, the energy direction at fixed (Z, H, s, z, h): (∂L, ∂l, ∂g)/∂S from the Jacobian, then
  δM = ∂M/∂L δL + ∂M/∂l δl and δθ = e_z δl + (cos l, −sin l, 0) δJ + (M/G) δg with δJ = −δL/(G sin J)
  (attitude R3(l) R1(J) R3(g) R1(I) R3(h), inertial → body);
* the scale (S, Z, H, 0, 0, 0): every momentum scaled at fixed (d, s, z, h), so δθ = 0, δM = M; the
  flow adds a S t to s;
* e_s, the phase: ∂x/∂s = ẋ/(a S) = (ω, M × ω)/(a S) in (δθ, M);
* three rigid rotations of the inertial frame (any basis of the directions H, z, h span): δθ = R e_k,
  δM = 0, unchanged by the flow.

Then F(t) in that basis is the identity plus a t (e_S → s) and a S t (scale → s). The momentum
components are turned into ω by T = diag(1, 1, 1, A, B, C): Φ_ω = T⁻¹ Φ_M T.

Parameter sensitivities (variation of constants over the exact Φ)
-----------------------------------------------------------------
Ψ(t) = ∫₀ᵗ Φ(t, τ) g(τ) dτ, g = (0, ∂ω̇/∂p), and Φ(t, τ) = K(t) F(t − τ) K(τ)⁻¹, so

    Ψ(t) = K(t) [W₀(t) + N W₁(t)],   W₀ = ∫₀ᵗ w dτ,   W₁ = ∫₀ᵗ (t − τ) w dτ,   w = K(τ)⁻¹ g(τ),

N the nilpotent part of F per unit time. w is smooth and quasi-periodic, so Gauss–Legendre panels
no longer than 1/4 of the shortest period of the motion (16 nodes each) give it to rounding: with 2
panels per period Ψ agrees with 16 panels per period to 1.5e-14 relative (Toutatis over 30 d and two
states of the body (1, 2, 3) over 69 time units, measured), and ``tests/test_stm.py`` checks it against
40-digit finite differences.

Not covered: permanent rotations and the exact separatrix (no finite elements), J = 0 exactly (spin
exactly along C: l and g are separately undefined), and bodies with two equal moments (their free
motion takes the regular precession, not the elliptic flow): :class:`SingularElementsError`.
"""

import math

import numpy as np

from spinorbit.core.elements.canonical import (
    EL_S,
    EL_SMALL_S,
    STATUS_OK,
    canonical_from_andoyer_scalar,
    inertia_constants,
    motion_from_momentum,
)
from spinorbit.core.elements.jacobian import COL_S, ROW_L, ROW_SMALL_G, ROW_SMALL_L, andoyer_jacobian
from spinorbit.core.errors import SingularElementsError
from spinorbit.core.free_motion.flow import torque_free_states
from spinorbit.core.free_motion.summary import periods
from spinorbit.core.jit import jit
from spinorbit.core.math.rotations import quat_to_attitude

#: Offsets of the local state (δθ, ω) and of the parameters (A/C, B/C).
X_THETA, X_OMEGA = 0, 3
LOCAL_SIZE = 6
P_A_OVER_C, P_B_OVER_C = 0, 1
PARAMETER_SIZE = 2
#: Columns of K: energy direction, scale, phase, and the three inertial rotations.
K_ENERGY, K_SCALE, K_PHASE, K_ROTATION = 0, 1, 2, 3
#: Gauss–Legendre nodes per panel and panels per shortest period of the parameter quadrature.
QUADRATURE_NODES = 16
PANELS_PER_PERIOD = 4
#: A perpendicular momentum below this fraction of G is treated as J = 0 (l and g undefined).
SMALLEST_SIN_J = 1e-9


@jit
def element_basis(q, momentum, big_s, s, moments, ic):
    """K = ∂(δθ, M)/∂(element directions) at one state, 6 × 6 (columns ``K_*``, module docstring).

    ``big_s`` and ``s`` are the canonical S (signed) and the unreduced s of the state; ``momentum`` its
    body momentum on the principal axes.
    """
    big_a, big_b, big_c = moments
    mx, my, mz = momentum[0], momentum[1], momentum[2]
    wx, wy, wz = mx / big_a, my / big_b, mz / big_c
    big_g = math.sqrt(mx * mx + my * my + mz * mz)
    perp = math.hypot(mx, my)
    elements = np.zeros(6)
    elements[EL_S] = big_s
    elements[1] = big_g
    elements[EL_SMALL_S] = s
    jac = andoyer_jacobian(elements, ic)
    d_l, d_sl, d_g = jac[ROW_L, COL_S], jac[ROW_SMALL_L, COL_S], jac[ROW_SMALL_G, COL_S]
    k = np.zeros((6, 6))
    # energy direction: M = (P sin l, P cos l, L) with P = √(G² − L²), sin l = M_x/P, cos l = M_y/P
    d_j = -d_l / perp
    k[0, K_ENERGY] = (my / perp) * d_j + mx / big_g * d_g
    k[1, K_ENERGY] = -(mx / perp) * d_j + my / big_g * d_g
    k[2, K_ENERGY] = d_sl + mz / big_g * d_g
    k[3, K_ENERGY] = -mz * mx / (perp * perp) * d_l + my * d_sl
    k[4, K_ENERGY] = -mz * my / (perp * perp) * d_l - mx * d_sl
    k[5, K_ENERGY] = d_l
    # scale: δM = M
    k[3, K_SCALE], k[4, K_SCALE], k[5, K_SCALE] = mx, my, mz
    # phase: ẋ/(a S), ẋ = (ω, M × ω)
    rate = big_s / big_a
    k[0, K_PHASE], k[1, K_PHASE], k[2, K_PHASE] = wx / rate, wy / rate, wz / rate
    k[3, K_PHASE] = (my * wz - mz * wy) / rate
    k[4, K_PHASE] = (mz * wx - mx * wz) / rate
    k[5, K_PHASE] = (mx * wy - my * wx) / rate
    # inertial rotations: δθ = R e_k (R inertial → body)
    attitude = quat_to_attitude(q)
    for j in range(3):
        for i in range(3):
            k[i, K_ROTATION + j] = attitude[i, j]
    return k


@jit
def flow_matrix(big_s, big_a, t):
    """F(t) of the linear element flow in the ``K_*`` basis: 1 + a t (e_S → s) + a S t (scale → s)."""
    f = np.eye(6)
    f[K_PHASE, K_ENERGY] = t / big_a
    f[K_PHASE, K_SCALE] = big_s * t / big_a
    return f


@jit
def omega_basis(k, moments):
    """K in (δθ, δω) rows: the momentum rows divided by the moments (δω = I⁻¹ δM at fixed moments)."""
    out = k.copy()
    for i in range(3):
        for j in range(6):
            out[X_OMEGA + i, j] = k[X_OMEGA + i, j] / moments[i]
    return out


@jit
def parameter_forcing(omega, moments):
    """g = ∂(δθ̇, ω̇)/∂(A/C, B/C) at fixed C and ω, 6 × 2, from Euler's torque-free equations.

    A ω̇x = (B − C) ωy ωz, B ω̇y = (C − A) ωz ωx, C ω̇z = (A − B) ωx ωy; A = p₁ C, B = p₂ C.
    """
    big_a, big_b, big_c = moments
    wx, wy, wz = omega[0], omega[1], omega[2]
    g = np.zeros((6, 2))
    # ∂/∂A, times C
    g[3, 0] = -(big_b - big_c) * wy * wz / (big_a * big_a) * big_c
    g[4, 0] = -wz * wx / big_b * big_c
    g[5, 0] = wx * wy
    # ∂/∂B, times C
    g[3, 1] = wy * wz / big_a * big_c
    g[4, 1] = -(big_c - big_a) * wz * wx / (big_b * big_b) * big_c
    g[5, 1] = -wx * wy
    return g


def _initial_elements(momentum, ic):
    """(S, s) of a body momentum (principal axes), or SingularElementsError where they do not exist."""
    mx, my, mz = (float(v) for v in momentum)
    big_g = math.sqrt(mx * mx + my * my + mz * mz)
    perp = math.hypot(mx, my)
    if big_g == 0.0 or perp < SMALLEST_SIN_J * big_g:
        raise SingularElementsError(
            f"the free-flow STM needs the angular momentum off the C axis (sin J ≥ {SMALLEST_SIN_J:g}); got body "
            f"momentum {[mx, my, mz]}. At J = 0 the Andoyer angles l and g are separately undefined: use the "
            "DOP853 variational equations (spinorbit.core.integrators.variational) for this state."
        )
    big_s, _, _, s, _, _, status = canonical_from_andoyer_scalar(mz, big_g, 0.0, math.atan2(mx, my), 0.0, 0.0, ic)
    if status != STATUS_OK:
        raise SingularElementsError(
            f"the state with body momentum {[mx, my, mz]} has no finite canonical elements (a permanent rotation or "
            "the exact separatrix), so the free flow has no element STM there; use the DOP853 variational "
            "equations (spinorbit.core.integrators.variational) instead."
        )
    return big_s, s


def _check_moments(moments):
    big_a, big_b, big_c = (float(v) for v in moments)
    if not (0.0 < big_a < big_b < big_c):
        raise SingularElementsError(
            f"the free-flow STM needs a triaxial body 0 < A < B < C; got moments {[big_a, big_b, big_c]}. Bodies "
            "with two equal moments take the regular precession; use the DOP853 variational equations "
            "(spinorbit.core.integrators.variational) for them."
        )
    return np.array([big_a, big_b, big_c])


def shortest_period(momentum, inertia, ic):
    """min(P_ψ, P_φ, 2π/|ω|) of the free motion through a body momentum (the quadrature's time scale)."""
    mo, _ = motion_from_momentum(momentum[0], momentum[1], momentum[2], ic)
    p_psi, p_phi = periods(mo, momentum[0], momentum[1], momentum[2], *inertia)
    return min(p_psi, p_phi, 2.0 * math.pi / float(np.linalg.norm(momentum / inertia)))


def _quadrature_grid(breakpoints, shortest_period):
    """Gauss–Legendre nodes, weights and panel ends on consecutive breakpoints (0 first, monotone).

    Each interval is cut into panels of at most shortest_period/PANELS_PER_PERIOD. Returns (nodes,
    weights, index of the interval of each node).
    """
    x, w = np.polynomial.legendre.leggauss(QUADRATURE_NODES)
    nodes, weights, interval = [], [], []
    longest = shortest_period / PANELS_PER_PERIOD
    for k in range(breakpoints.size - 1):
        lo, hi = breakpoints[k], breakpoints[k + 1]
        panels = max(1, int(math.ceil(abs(hi - lo) / longest)))
        edges = np.linspace(lo, hi, panels + 1)
        half = 0.5 * np.diff(edges)
        nodes.append(((0.5 * (edges[:-1] + edges[1:]))[:, None] + half[:, None] * x[None, :]).ravel())
        weights.append((half[:, None] * w[None, :]).ravel())
        interval.append(np.full(panels * QUADRATURE_NODES, k))
    if not nodes:
        return np.empty(0), np.empty(0), np.empty(0, dtype=np.int64)
    return np.concatenate(nodes), np.concatenate(weights), np.concatenate(interval)


@jit
def node_forcing(qs, ms, taus, big_s, s0, inertia, ic, out):
    """w(τ) = K(τ)⁻¹ g(τ) (6 × 2) at each quadrature node, into ``out`` (n, 6, 2)."""
    rate = big_s / inertia[0]
    for k in range(taus.shape[0]):
        basis = omega_basis(element_basis(qs[k], ms[k], big_s, s0 + rate * taus[k], inertia, ic), inertia)
        omega = np.empty(3)
        for i in range(3):
            omega[i] = ms[k, i] / inertia[i]
        out[k] = np.linalg.solve(basis, parameter_forcing(omega, inertia))


def free_flow_stm(quaternion, omega, moments, times, parameters=True):
    """Exact torque-free states, their STM in (δθ, ω), and the sensitivities to (A/C, B/C).

    Parameters
    ----------
    quaternion : (4,) array_like
        Attitude at t = 0, scalar first, principal axes → inertial (``docs/conventions.md``).
    omega : (3,) array_like
        Body angular velocity at t = 0 on the principal axes (rad per time unit).
    moments : (3,) array_like
        Principal moments 0 < A < B < C.
    times : (T,) array_like
        Times since the epoch of the state (the time unit of ω).
    parameters : bool
        Also return Ψ = ∂x(t)/∂(A/C, B/C) (costs a quadrature, module docstring).

    Returns
    -------
    q : (T, 4) ndarray
        Attitude quaternions (the reference attitudes of δθ).
    w : (T, 3) ndarray
        Body angular velocities.
    phi : (T, 6, 6) ndarray
        ∂(δθ(t), ω(t))/∂(δθ(0), ω(0)).
    psi : (T, 6, 2) ndarray or None
        ∂(δθ(t), ω(t))/∂(A/C, B/C) at fixed C, δθ(0) and ω(0).

    Raises
    ------
    SingularElementsError
        Bodies with two equal moments, permanent rotations, the separatrix, J = 0 (module docstring).
    """
    inertia = _check_moments(moments)
    q0 = np.asarray(quaternion, dtype=float)
    w0 = np.asarray(omega, dtype=float)
    t = np.ascontiguousarray(times, dtype=float).reshape(-1)
    if q0.shape != (4,) or w0.shape != (3,):
        raise ValueError(f"quaternion and omega: expected shapes (4,) and (3,), got {q0.shape} and {w0.shape}.")
    if not (np.all(np.isfinite(q0)) and np.all(np.isfinite(w0)) and np.all(np.isfinite(t))):
        raise ValueError("quaternion, omega and times must be finite; remove NaN/inf inputs.")
    q0 = q0 / np.linalg.norm(q0)
    ic = inertia_constants(*inertia)
    m0 = inertia * w0
    big_s, s0 = _initial_elements(m0, ic)
    qs, ms = torque_free_states(q0, m0, *inertia, t, closed_forms=False)
    rate = big_s / inertia[0]  # ds/dt = a S
    k0 = omega_basis(element_basis(q0, m0, big_s, s0, inertia, ic), inertia)
    k0_inv = np.linalg.inv(k0)
    phi = np.empty((t.size, 6, 6))
    kt = np.empty((t.size, 6, 6))
    for i, ti in enumerate(t):
        kt[i] = omega_basis(element_basis(qs[i], ms[i], big_s, s0 + rate * ti, inertia, ic), inertia)
        phi[i] = kt[i] @ flow_matrix(big_s, inertia[0], ti) @ k0_inv
    psi = _parameter_sensitivities(q0, m0, inertia, ic, big_s, s0, t, kt) if parameters else None
    return qs, ms / inertia, phi, psi


def _parameter_sensitivities(q0, m0, inertia, ic, big_s, s0, t, kt):
    """Ψ(t_k) = K(t_k) [W₀ + N W₁], W₁ = t W₀ − ∫ τ w dτ, one cumulative quadrature per time direction."""
    shortest = shortest_period(m0, inertia, ic)
    nilpotent = flow_matrix(big_s, inertia[0], 1.0) - np.eye(6)
    psi = np.zeros((t.size, 6, 2))
    for sign in (1.0, -1.0):
        chosen = np.flatnonzero(sign * t > 0.0)
        if chosen.size == 0:
            continue
        ends = np.unique(sign * t[chosen])
        nodes, weights, interval = _quadrature_grid(np.concatenate([[0.0], ends]) * sign, shortest)
        qn, mn = torque_free_states(q0, m0, *inertia, nodes, closed_forms=False)
        w = np.empty((nodes.size, 6, 2))
        node_forcing(qn, mn, nodes, big_s, s0, inertia, ic, w)
        # integrals over each interval, then running sums up to each breakpoint
        zeroth = np.zeros((ends.size, 6, 2))
        first = np.zeros((ends.size, 6, 2))
        np.add.at(zeroth, interval, weights[:, None, None] * w)
        np.add.at(first, interval, (weights * nodes)[:, None, None] * w)
        zeroth, first = np.cumsum(zeroth, axis=0), np.cumsum(first, axis=0)
        for i in chosen:
            k = int(np.searchsorted(ends, sign * t[i]))
            w0_sum, w1_sum = zeroth[k], t[i] * zeroth[k] - first[k]
            psi[i] = kt[i] @ (w0_sum + nilpotent @ w1_sum)
    return psi
