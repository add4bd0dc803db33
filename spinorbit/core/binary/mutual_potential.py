"""The mutual potential of two rigid bodies, its gradient and both torques, from one expansion.

Force function (minus the mutual potential energy, the sign of :mod:`spinorbit.core.model.gravity_field`)

    U = G ∫_A ∫_B dm_A dm_B / |R + ρ_B − ρ_A|

with R the position of B's centre of mass relative to A's, and ρ_A, ρ_B points of each body from its
centre of mass, all on A's body axes. Taylor-expanding 1/|R + s| in s = ρ_B − ρ_A and splitting
s^α/α! by the multinomial theorem gives Hou, Scheeres & Xin (2017, CeMDA 127, 369, eqs. 14–20) in
multi-index form:

    U_N = G Σ_{|β|+|γ| ≤ N} (−1)^|γ| / (β! γ!) · ∂^{β+γ}(1/R) · T_B^β · T_A^γ

where T_A^γ are A's inertia integrals on its own axes and T_B^β are B's rotated onto A's axes
(:func:`spinorbit.core.binary.inertia_integrals.rotate_integrals`). The series converges for R
larger than the sum of the two bodies' circumscribing radii (the contact distance refused by the
front ends). Order N = 2 is point mass + each body's MacCullagh term; order 4 adds the degree-4
shape of each body and the coupling of the two inertia tensors.

Everything else is a derivative of this one U:

- **force on B**, ∂U/∂R_i = G Σ (−1)^|γ|/(β!γ!) ∂^{β+γ+e_i}(1/R) T_B^β T_A^γ (A's axes), and −∂U/∂R on A;
- **torques**: an infinitesimal rotation δθ of body X moves its points by δθ × ρ, which changes its
  integrals by δT^β = Σ_i β_i ε_{iab} δθ_a T^{β−e_i+e_b}; with W_β = ∂U/∂T^β,
  N_a = ∂U/∂θ_a = Σ_β W_β Σ_{i,b} ε_{iab} β_i T^{β−e_i+e_b} (the gravity field's convention δU = N·δθ).

Each order's term is a full contraction of tensors, so U_N is invariant under a common rotation of
R and both bodies: N_A + N_B + R × ∂U/∂R = 0 at every order, which is what conserves the total
angular momentum of the truncated problem exactly.

The derivatives D_α = ∂^α(1/R) come from the recurrence (obtained from ∇²(1/R) = 0 and Euler's
theorem on homogeneous functions)

    |α| R² D_α = −(2|α| − 1) Σ_i α_i x_i D_{α−e_i} − (|α| − 1) Σ_i α_i (α_i − 1) D_{α−2e_i}.
"""

import numpy as np

from spinorbit.core.binary.monomials import (
    DEGREE_START,
    DOWN,
    DOWN2,
    EXPONENTS,
    PAIR_BETA,
    PAIR_COEFFICIENT,
    PAIR_END,
    PAIR_GAMMA,
    PAIR_SUM,
    PAIRS,
    ROTATED,
    UP,
)
from spinorbit.core.jit import jit

AXIS_X, AXIS_Y, AXIS_Z = 0, 1, 2


@jit(inline="always")  # RHS hot path: no call boundary for the arrays to cross
def inverse_distance_derivatives(x, y, z, max_degree, out):
    """out[α] = ∂^α (1/R) at (x, y, z) for every |α| ≤ max_degree (recurrence of the module docstring)."""
    r2 = x * x + y * y + z * z
    out[0] = 1.0 / np.sqrt(r2)
    position = (x, y, z)
    for n in range(1, max_degree + 1):
        for index in range(DEGREE_START[n], DEGREE_START[n + 1]):
            acc = 0.0
            for axis in range(3):
                a_i = EXPONENTS[index, axis]
                if a_i > 0:
                    acc -= (2 * n - 1) * a_i * position[axis] * out[DOWN[index, axis]]
                    if a_i > 1:
                        acc -= (n - 1) * a_i * (a_i - 1) * out[DOWN2[index, axis]]
            out[index] = acc / (n * r2)


@jit(inline="always")  # RHS hot path: no call boundary for the arrays to cross
def mutual_field(x, y, z, g, integrals_a, integrals_b, order, derivatives, weights_a, weights_b):
    """U, ∂U/∂R and the weights W = ∂U/∂T of both bodies at B's position (x, y, z) on A's axes.

    Parameters
    ----------
    x, y, z : float
        R, B's centre of mass relative to A's, on A's axes (length).
    g : float
        Gravitational constant (length³ mass⁻¹ time⁻²).
    integrals_a, integrals_b : ndarray
        T_A on A's axes and T_B rotated onto A's axes (:mod:`.inertia_integrals`).
    order : int
        Expansion order N, 0 ≤ N ≤ MAX_ORDER.
    derivatives, weights_a, weights_b : ndarray
        Scratch for D_α (degree ≤ N + 1) and outputs W_A, W_B (degree ≤ N), overwritten.

    Returns
    -------
    (U, dU/dx, dU/dy, dU/dz) : floats
        Force function (mass·length²/time²) and its gradient: the force on B (A feels the opposite).
    """
    inverse_distance_derivatives(x, y, z, order + 1, derivatives)
    for k in range(DEGREE_START[order + 1]):
        weights_a[k] = 0.0
        weights_b[k] = 0.0
    u = 0.0
    gx = 0.0
    gy = 0.0
    gz = 0.0
    for p in range(PAIR_END[order]):
        beta = PAIRS[p, PAIR_BETA]
        gamma = PAIRS[p, PAIR_GAMMA]
        total = PAIRS[p, PAIR_SUM]
        c = g * PAIR_COEFFICIENT[p]
        ta = integrals_a[gamma]
        tb = integrals_b[beta]
        d = derivatives[total]
        product = c * ta * tb
        u += product * d
        gx += product * derivatives[UP[total, AXIS_X]]
        gy += product * derivatives[UP[total, AXIS_Y]]
        gz += product * derivatives[UP[total, AXIS_Z]]
        weights_b[beta] += c * d * ta
        weights_a[gamma] += c * d * tb
    return u, gx, gy, gz


@jit(inline="always")  # RHS hot path: no call boundary for the arrays to cross
def torque_from_weights(weights, integrals, order):
    """N = ∂U/∂θ of the body with integrals T and weights W = ∂U/∂T (axes of T), degrees 2..order."""
    nx = 0.0
    ny = 0.0
    nz = 0.0
    for index in range(DEGREE_START[2], DEGREE_START[order + 1]):
        w = weights[index]
        if w == 0.0:
            continue
        bx, by, bz = EXPONENTS[index, AXIS_X], EXPONENTS[index, AXIS_Y], EXPONENTS[index, AXIS_Z]
        # ε_{iab} with a = x: +1 for (i, b) = (z, y), −1 for (y, z); cyclic for N_y, N_z.
        if by > 0:
            nx -= w * by * integrals[ROTATED[index, AXIS_Y, AXIS_Z]]
            nz += w * by * integrals[ROTATED[index, AXIS_Y, AXIS_X]]
        if bz > 0:
            nx += w * bz * integrals[ROTATED[index, AXIS_Z, AXIS_Y]]
            ny -= w * bz * integrals[ROTATED[index, AXIS_Z, AXIS_X]]
        if bx > 0:
            ny += w * bx * integrals[ROTATED[index, AXIS_X, AXIS_Z]]
            nz -= w * bx * integrals[ROTATED[index, AXIS_X, AXIS_Y]]
    return nx, ny, nz
