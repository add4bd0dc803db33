"""Fukushima's canonical elements of rotational motion (S, Z, H; s, z, h), in every rotation mode.

Paper: T. Fukushima, "Canonical elements of rotational motion" (eqs. 4–12; full derivation in AJ 136,
1728, 2008). ``docs/theory.md`` gives the derivation checks and every correction; the conventions
are in ``docs/conventions.md``.

How the paper's formulas are evaluated here
-------------------------------------------
The forward map (eq. 4) and the backward map (eqs. 7–8) are written in terms of the body angular
momentum components M = (M_x, M_y, M_z) (principal axes A ≤ B ≤ C), because those forms keep full
accuracy where the angle forms lose it (spin near C, where J → 0; spin near A, where m → ∞;
B → C, where f → ∞). With a − b, b − c, a − c from inertia differences and

    (d − c) G² = (a − c) M_x² + (b − c) M_y²,   (a − d) G² = (a − b) M_y² + (a − c) M_z²,
    (b − d) G² = (b − c) M_z² − (a − b) M_x²,

every quantity below is a ratio of positive products, never a difference of rounded numbers:

* Short-axis mode (SAM, b − d > 0), parameter m = (a−b)(d−c) / ((a−d)(b−c)) < 1 and argument u:
  M = G (√((d−c)/(a−c)) cn u, √((d−c)/(b−c)) sn u, √((a−d)/(a−c)) dn u), i.e. am(u|m) =
  atan2(√(b−c) M_y, √(a−c) M_x), the paper's φ of eq. (5) (tan φ = cot l / √(1+f)).
* Long-axis mode (LAM, b − d < 0): the reciprocal parameter μ = 1/m = (a−d)(b−c)/((a−b)(d−c)) < 1
  and argument v = √m u (DLMF 22.17): M = G (√((d−c)/(a−c)) dn v, √((a−d)/(a−b)) sn v,
  √((a−d)/(a−c)) cn v), am(v|μ) = atan2(√(a−b) M_y, √(a−c) M_z). This is eq. (7) with
  sn(u|m) = sn(v|μ)/√m, cn(u|m) = dn(v|μ), dn(u|m) = cn(v|μ), and pn(u, n|m) = pn(v, n/m|μ)/√m.
  Everything stays finite as m → ∞ (spin about A, or B → C).
* The separatrix b = d is the SAM form at m = 1 (closed forms in the elliptic kernels).

With κ(s) = the argument per unit s and n the characteristic actually integrated,

    SAM: u = √((a−d)(b−c)/(a d)) s,  g = z + c s/√(a d) + (a−c) pn(u, −f | m) / √((a−d)(b−c))
    LAM: v = √((a−b)(d−c)/(a d)) s,  g = z + c s/√(a d) + (a−c) pn(v, −(a−d)/(d−c) | μ) / √((a−b)(d−c))

which are eqs. (7)–(8) rewritten (c u/√((a−d)(b−c)) = c s/√(ad)). S = √(d/a) G, Z = G (eqs. 4, 8).

Branches: the sense of rotation
-------------------------------
The paper's maps cover SAM about +C (M_z > 0) and LAM about +A (M_x > 0) (and separatrix arcs with
M_x ≥ 0, M_z ≥ 0). The other senses are mapped onto them by turning the body frame by π about a
principal axis (a constant rotation that keeps the inertia tensor diagonal, hence a canonical change
of Andoyer variables): ``FLIP_B`` (π about B) for −C in SAM and −A in LAM. In the paper-named
functions the flip is carried by the sign of S: (S, s) → (−S, −s) is canonical and leaves the
Hamiltonian ½ a S² unchanged, so S < 0 means "rotating about −C (SAM) or −A (LAM)" and the torque-free
solution s = s0 + a S t holds as it stands. Only the exact separatrix with M_x and M_z of opposite
signs needs ``FLIP_A`` or ``FLIP_C``, which the sign of S cannot carry: the state layer stores the flip
explicitly; the paper-named functions reject those two measure-zero arcs with a clear error.

Permanent rotations (spin exactly about B, the degenerate cases of symmetric bodies, spheres) have
no finite elements (s = ±∞): ``MODE_UNIFORM`` marks them and the state layer propagates them as a
uniform rotation.
"""

import math

import numpy as np

from spinorbit.core.elements.andoyer import node_frame
from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.elliptic_integrals import ellipf_k, pn_constants, pn_k
from spinorbit.core.math.elliptic_periods import parameter_constants
from spinorbit.core.math.jacobi import sncndn_k
from spinorbit.core.math.lanes import choose

# Body-frame flips: the working frame is the body frame turned by π about one principal axis.
FLIP_NONE, FLIP_A, FLIP_B, FLIP_C = 0, 1, 2, 3

MODE_SAM, MODE_LAM, MODE_UNIFORM = 1, -1, 0

# Offsets of the canonical elements (S, Z, H, s, z, h) in a (6,) state array (paper eq. 4 order).
EL_S, EL_Z, EL_H, EL_SMALL_S, EL_SMALL_Z, EL_SMALL_H = range(6)

# Indices into the "motion constants" tuple (one torque-free motion; see motion_constants).
(
    MO_MODE,  # MODE_SAM (separatrix included) / MODE_LAM / MODE_UNIFORM
    MO_G,  # |M|
    MO_D,  # d = 2T/G²
    MO_S,  # S = √(d/a) G ≥ 0 (the flip carries the sense)
    MO_PARAM,  # m (SAM) or μ = 1/m (LAM)
    MO_PARAM_C,  # 1 − m or 1 − μ, from inertia differences
    MO_ARG_PER_S,  # u/s (SAM) or v/s (LAM)
    MO_S_RATE,  # ds/dt = a S = √(a d) G
    MO_G_PER_S,  # c/√(a d): the coefficient of s in g
    MO_PN_COEFF,  # coefficient of pn in g
    MO_PN_N,  # characteristic n of that pn
    MO_X_AMP,  # M_x = X · cn u (SAM) or X · dn v (LAM)
    MO_Y_AMP,  # M_y = Y · sn
    MO_Z_AMP,  # M_z = Z · dn u (SAM) or Z · cn v (LAM)
    MO_SIN_L_W,  # sin l ∝ w_s · (cn u | dn v)
    MO_COS_L_W,  # cos l ∝ w_c · sn
) = range(16)
MO_SIZE = 16


@jit
def inertia_constants(big_a, big_b, big_c):
    """(a, b, c, a − b, b − c, a − c) with the differences from the moments' differences.

    a − b = (B − A)/(AB) keeps full relative accuracy for nearly symmetric bodies, where 1/A − 1/B
    of rounded reciprocals would not.
    """
    a, b, c = 1.0 / big_a, 1.0 / big_b, 1.0 / big_c
    return a, b, c, (big_b - big_a) / (big_a * big_b), (big_c - big_b) / (big_b * big_c), (
        big_c - big_a
    ) / (big_a * big_c)


@jit
def flip_signs(flip):
    """Diagonal of the body-frame flip (a rotation by π about A, B or C; the identity for FLIP_NONE)."""
    if flip == FLIP_A:
        return 1.0, -1.0, -1.0
    if flip == FLIP_B:
        return -1.0, 1.0, -1.0
    if flip == FLIP_C:
        return -1.0, -1.0, 1.0
    return 1.0, 1.0, 1.0


@jit
def energy_differences(mx, my, mz, a_b, b_c, a_c):
    """(G², d − c, a − d, b − d) from body momentum components, without cancellation where avoidable.

    b − d changes sign at the separatrix; its cancellation there is the separatrix's own
    conditioning, not the formula's.
    """
    g2 = mx * mx + my * my + mz * mz
    d_c = (a_c * mx * mx + b_c * my * my) / g2
    a_d = (a_b * my * my + a_c * mz * mz) / g2
    b_d = (b_c * mz * mz - a_b * mx * mx) / g2
    return g2, d_c, a_d, b_d


@jit
def choose_flip(mx, mz, b_d, a_b, b_c):
    """(mode, flip) for a body momentum: which formulas apply and how to turn the frame for them."""
    if b_d > 0.0:
        return MODE_SAM, FLIP_B if mz < 0.0 else FLIP_NONE
    if b_d < 0.0:
        return MODE_LAM, FLIP_B if mx < 0.0 else FLIP_NONE
    # b − d == 0: the separatrix of a triaxial body, or a permanent rotation.
    if a_b <= 0.0 or b_c <= 0.0 or (mx == 0.0 and mz == 0.0):
        return MODE_UNIFORM, FLIP_NONE
    if mx < 0.0 and mz < 0.0:
        return MODE_SAM, FLIP_B
    if mz < 0.0:
        return MODE_SAM, FLIP_A
    if mx < 0.0:
        return MODE_SAM, FLIP_C
    return MODE_SAM, FLIP_NONE


@jit
def motion_constants(mode, big_g, d_c, a_d, b_d, a, b, c, a_b, b_c, a_c):
    """Constants of one torque-free motion (tuple indexed by the ``MO_*`` names).

    Parameters are G and the energy differences of :func:`energy_differences` (for the flipped
    frame, which has the same differences) and the inertia constants.
    """
    mo = np.empty(MO_SIZE)
    motion_constants_into(mo, mode, big_g, d_c, a_d, b_d, a, b, c, a_b, b_c, a_c)
    return mo


@jit(inline=INLINE)
def motion_constants_into(mo, mode, big_g, d_c, a_d, b_d, a, b, c, a_b, b_c, a_c):
    """:func:`motion_constants` into a caller's (MO_SIZE,) array (loops over many states reuse one
    buffer: the allocation cost ≈ 20 ns of the torque-free set-up)."""
    mo[:] = 0.0
    mo[MO_MODE] = mode
    mo[MO_G] = big_g
    if mode == MODE_UNIFORM:
        return mo
    d, big_s, s_rate, g_per_s, x_amp, sqrt_ad = motion_shared_terms(big_g, d_c, a_d, a, c, a_c)
    mo[MO_D], mo[MO_S], mo[MO_S_RATE], mo[MO_G_PER_S], mo[MO_X_AMP] = d, big_s, s_rate, g_per_s, x_amp
    if mode == MODE_SAM:
        terms = motion_sam_terms(big_g, d_c, a_d, b_d, a_b, b_c, a_c, sqrt_ad)
    else:
        terms = motion_lam_terms(big_g, d_c, a_d, b_d, a_b, b_c, a_c, sqrt_ad)
    (mo[MO_PARAM], mo[MO_PARAM_C], mo[MO_ARG_PER_S], mo[MO_PN_COEFF], mo[MO_PN_N], mo[MO_Y_AMP], mo[MO_Z_AMP],
     mo[MO_SIN_L_W], mo[MO_COS_L_W]) = terms
    return mo


# The pieces of motion_constants_into, plain arithmetic: the torque-free set-up of eight states at
# once (spinorbit.core.free_motion.flow_blocks) runs them in lanes, each lane keeping its mode's terms.


@jit(inline=INLINE)
def motion_shared_terms(big_g, d_c, a_d, a, c, a_c):
    """(d, S, ds/dt, the coefficient of s in g, the M_x amplitude, √(a d)) of a SAM or LAM motion."""
    d = choose(d_c < a_d, c + d_c, a - a_d)  # from the smaller difference: fewer rounding errors
    sqrt_ad = math.sqrt(a * d)
    return d, math.sqrt(d / a) * big_g, sqrt_ad * big_g, c / sqrt_ad, big_g * math.sqrt(d_c / a_c), sqrt_ad


@jit(inline=INLINE)
def motion_sam_terms(big_g, d_c, a_d, b_d, a_b, b_c, a_c, sqrt_ad):
    """SAM: (m, 1 − m, u/s, the pn coefficient, n, the M_y and M_z amplitudes, w_s, w_c)."""
    root = math.sqrt(a_d * b_c)
    return (a_b * d_c / (a_d * b_c), a_c * b_d / (a_d * b_c), root / sqrt_ad, a_c / root, -a_b / b_c,
            big_g * math.sqrt(d_c / b_c), big_g * math.sqrt(a_d / a_c), math.sqrt(b_c), math.sqrt(a_c))


@jit(inline=INLINE)
def motion_lam_terms(big_g, d_c, a_d, b_d, a_b, b_c, a_c, sqrt_ad):
    """LAM: (μ, 1 − μ, v/s, the pn coefficient, n, the M_y and M_z amplitudes, w_s, w_c)."""
    root = math.sqrt(a_b * d_c)
    return (a_d * b_c / (a_b * d_c), a_c * (-b_d) / (a_b * d_c), root / sqrt_ad, a_c / root, -a_d / d_c,
            big_g * math.sqrt(a_d / a_b), big_g * math.sqrt(a_d / a_c), math.sqrt(a_b * d_c), math.sqrt(a_c * a_d))


@jit
def motion_from_momentum(mx, my, mz, ic):
    """(motion constants, flip) of the torque-free motion through body momentum (M_x, M_y, M_z)."""
    mo = np.empty(MO_SIZE)
    flip = motion_from_momentum_into(mo, mx, my, mz, ic)
    return mo, flip


@jit(inline=INLINE)
def motion_from_momentum_into(mo, mx, my, mz, ic):
    """:func:`motion_from_momentum` into a caller's (MO_SIZE,) array; returns the flip."""
    a, b, c, a_b, b_c, a_c = ic
    g2, d_c, a_d, b_d = energy_differences(mx, my, mz, a_b, b_c, a_c)
    mode, flip = choose_flip(mx, mz, b_d, a_b, b_c)
    motion_constants_into(mo, mode, math.sqrt(g2), d_c, a_d, b_d, a, b, c, a_b, b_c, a_c)
    return flip


@jit
def motion_from_elements(big_s, big_z, ic):
    """Motion constants from S (≥ 0, the flip already removed) and Z = G.

    d = a S²/Z², and its differences are formed from S and Z directly (a − d = a (Z − S)(Z + S)/Z²
    is exact to rounding where d → a), the smaller gap first and the others from it.
    """
    a, b, c, a_b, b_c, a_c = ic
    z2 = big_z * big_z
    a_d = max(a * (big_z - big_s) * (big_z + big_s) / z2, 0.0)
    d = a * big_s * big_s / z2
    d_c = max(d - c, 0.0)
    # Symmetric bodies: the smaller gap is kept as formed above and the other two are taken from it,
    # so that m and 1 − m (μ, 1 − μ) belong to one d; formed independently they belong to d's an ulp
    # apart and the motion leaves sn² + cn² = 1. Triaxial bodies keep b − d = b − fl(d), the
    # difference 1 − m rests on near the separatrix. Why, with the cases: docs/theory.md, item 7.
    if a_b == 0.0 or b_c == 0.0:
        if a_d < d_c:
            d_c = max(a_c - a_d, 0.0)
            b_d = a_d - a_b
        else:
            a_d = max(a_c - d_c, 0.0)
            b_d = b_c - d_c
    else:
        b_d = b - d
    if b_d > 0.0:
        mode = MODE_SAM
    elif b_d < 0.0:
        mode = MODE_LAM
    else:
        mode = MODE_SAM if (a_b > 0.0 and b_c > 0.0) else MODE_UNIFORM
    if mode == MODE_SAM and (a_b <= 0.0 or b_c <= 0.0) and a_d <= 0.0:
        mode = MODE_UNIFORM
    if mode == MODE_LAM and b_c <= 0.0 and d_c <= 0.0:  # B = C, spin in the B–C plane (d = c)
        mode = MODE_UNIFORM
    return motion_constants(mode, big_z, d_c, a_d, b_d, a, b, c, a_b, b_c, a_c)


# (S, Z) resolve the gap of an axisymmetric body's motion to its permanent rotation only to about
# this many units of roundoff (relative to a or d): one ulp each of S and Z moves d = a S²/Z² by
# ≈ 2ε d and (Z − S)(Z + S) by ≈ 2ε Z², and the backward map adds ≈ 2ε of its own.
GAP_RESOLUTION_ULPS = 4.0


@jit
def symmetric_gap_resolved(big_s, big_z, ic):
    """False if (S, Z) of an axisymmetric body cannot tell its motion from the permanent rotation.

    For B = C the rate of the elliptic argument is ∝ √(d − c) (LAM, eq. 8), for A = B ∝ √(a − d)
    (SAM): the backward map needs that gap from S and Z, where it is a difference of nearly equal
    numbers known to ≈ ``GAP_RESOLUTION_ULPS`` ε (relative to d, resp. a). Below that the gap, and
    with it every angle of the state, is not determined by the elements in double precision: they
    are singular there (s ~ 1/√gap is finite but carries no phase), like the permanent rotation
    itself. Above it the round trip degrades like ε d / gap, which is the elements' own
    conditioning (``tests/stress/test_phase_space_floor.py`` measures it against the floor of the
    map; ``tests/stress/test_fuzz.py`` the refusals). Triaxial
    bodies: always True (their gaps to C and A enter only the amplitudes).
    """
    a, b, c, a_b, b_c, a_c = ic
    z2 = big_z * big_z
    d = a * big_s * big_s / z2
    eps = np.finfo(np.float64).eps
    if b_c <= 0.0 < a_b:
        return d - c > GAP_RESOLUTION_ULPS * eps * d
    if a_b <= 0.0 < b_c:
        return a * (big_z - big_s) * (big_z + big_s) / z2 > GAP_RESOLUTION_ULPS * eps * a
    return True


@jit
def elliptic_constants(mo):
    """Precomputed elliptic constants (parameter, characteristic) for a motion."""
    mk = parameter_constants(mo[MO_PARAM], mo[MO_PARAM_C])
    pk = pn_constants(mo[MO_PN_N], mo[MO_PARAM], mo[MO_PARAM_C])
    return mk, pk


@jit
def amplitude_from_momentum(mx, my, mz, mo, ic):
    """am of the elliptic argument at body momentum M (working frame).

    SAM: φ = am(u|m) = atan2(√(b−c) M_y, √(a−c) M_x) (the φ of eq. 5); LAM: am(v|μ) =
    atan2(√(a−b) M_y, √(a−c) M_z). Taken from M itself, not from l, so the phase stays well
    conditioned at the LAM turning points (M_z = 0) and at J = 0 (where it is 0 by the atan2(0, 0)
    rule, consistent with l = π/2 below).
    """
    _a, _b, _c, a_b, b_c, a_c = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    if mo[MO_MODE] == MODE_SAM:
        return math.atan2(math.sqrt(b_c) * my, math.sqrt(a_c) * mx)
    return math.atan2(math.sqrt(a_b) * my, math.sqrt(a_c) * mz)


@jit
def body_from_argument(arg, mo, mk):
    """Body momentum (M_x, M_y, M_z) and (sin l, cos l) at elliptic argument u (SAM) or v (LAM).

    (sin l, cos l) ∝ (√(b−c) cn u, √(a−c) sn u) in SAM — eq. (7)'s l = π/2 − am − atan(…) without the
    atan or the am — and ∝ (√((a−b)(d−c)) dn v, √((a−c)(a−d)) sn v) in LAM. Both stay defined at J = 0,
    where M_x = M_y = 0 but l still moves (only l + g is physical there).
    """
    sn, cn, dn = sncndn_k(arg, mk)
    return body_from_sncndn(sn, cn, dn, mo)


@jit
def body_from_sncndn(sn, cn, dn, mo):
    """:func:`body_from_argument` from sn, cn, dn already at hand (callers that reduce the phase themselves)."""
    if mo[MO_MODE] == MODE_SAM:
        first, third = cn, dn
    else:
        first, third = dn, cn
    mx = mo[MO_X_AMP] * first
    my = mo[MO_Y_AMP] * sn
    mz = mo[MO_Z_AMP] * third
    ws = mo[MO_SIN_L_W] * first
    wc = mo[MO_COS_L_W] * sn
    # not hypot (≈ 15 ns per evaluation): amplitudes below 1e150 cannot overflow the squares
    inv = 1.0 / math.sqrt(ws * ws + wc * wc)
    return mx, my, mz, ws * inv, wc * inv


@jit
def node_to_body(sin_l, cos_l, sin_j, cos_j):
    """W = R3(l) R1(J): from the frame of the angular momentum's node to the body frame.

    Its third column is M/G = (sin J sin l, sin J cos l, cos J).
    """
    w = np.empty((3, 3))
    w[0, 0], w[0, 1], w[0, 2] = cos_l, sin_l * cos_j, sin_l * sin_j
    w[1, 0], w[1, 1], w[1, 2] = -sin_l, cos_l * cos_j, cos_l * sin_j
    w[2, 0], w[2, 1], w[2, 2] = 0.0, -sin_j, cos_j
    return w


@jit
def multiply3(a, b):
    """a · b for 3×3 arrays, written out: numba sends ``@`` on small matrices to BLAS, whose call
    overhead (~150 ns) is larger than the 27 multiplications (measured in the element integrator's RHS)."""
    out = np.empty((3, 3))
    for i in range(3):
        a0, a1, a2 = a[i, 0], a[i, 1], a[i, 2]
        for j in range(3):
            out[i, j] = a0 * b[0, j] + a1 * b[1, j] + a2 * b[2, j]
    return out


@jit
def attitude_from_parts(mx, my, mz, sin_l, cos_l, g, cos_i, sin_i, h):
    """R = R3(l) R1(J) R3(g) R1(I) R3(h), with J from the momentum's direction (sin J = |M⊥|/|M|, cos J = M_z/|M|).

    J is normalised by the computed |M|, not by the element G = Z: the elliptic amplitudes meet
    |M| = G only to rounding of the energy differences (≈ ε d/(a − c), large for nearly symmetric
    bodies), and dividing by G would make R1(J), hence R, non-orthonormal by that much. Each factor
    is then a rotation to rounding, so R is one whatever the conditioning of the elements.
    """
    norm = math.sqrt(mx * mx + my * my + mz * mz)
    w = node_to_body(sin_l, cos_l, math.hypot(mx, my) / norm, mz / norm)
    cg, sg = math.cos(g), math.sin(g)
    r3g = np.zeros((3, 3))
    r3g[0, 0], r3g[0, 1], r3g[1, 0], r3g[1, 1], r3g[2, 2] = cg, sg, -sg, cg, 1.0
    return multiply3(multiply3(w, r3g), node_frame(cos_i, sin_i, h))


@jit
def node_angles(attitude, momentum, sin_l, cos_l):
    """(H, cos I, sin I, h, g) of an attitude given the body momentum and a chosen (sin l, cos l).

    g is solved from R = R3(l) R1(J) R3(g) · R1(I) R3(h) with the *given* l, so that the split of
    l + g at J = 0 follows the elements' convention instead of an arbitrary one.
    """
    return node_angles_of(attitude, momentum[0], momentum[1], momentum[2], sin_l, cos_l)


@jit
def node_angles_of(attitude, mx, my, mz, sin_l, cos_l):
    """:func:`node_angles` with the body momentum as three floats.

    Rᵀ M and the first row of R3(g) = Wᵀ R Nᵀ are written out entry by entry, with no temporary
    array: W = R3(l) R1(J) (:func:`node_to_body`) enters only through its first column
    (cos l, −sin l, 0) and N = R1(I) R3(h) (:func:`.andoyer.node_frame`) through its first two rows.
    The 3 × 3 products by ``@`` (BLAS calls) and then the six temporaries cost the per-state set-up
    of the free flow most of its time (0.9 µs of 2.3, then ≈ 0.2 µs of 1.6).
    """
    big_g = math.sqrt(mx ** 2 + my ** 2 + mz ** 2)
    i0 = attitude[0, 0] * mx + attitude[1, 0] * my + attitude[2, 0] * mz
    i1 = attitude[0, 1] * mx + attitude[1, 1] * my + attitude[2, 1] * mz
    big_h = attitude[0, 2] * mx + attitude[1, 2] * my + attitude[2, 2] * mz
    sin_i = math.hypot(i0, i1) / big_g
    cos_i = big_h / big_g
    h = math.atan2(i0, -i1)
    ch, sh = math.cos(h), math.sin(h)
    # first row of Wᵀ R (the zero of W's first column kept as a term, as in the matrix product)
    row0 = cos_l * attitude[0, 0] + -sin_l * attitude[1, 0] + 0.0 * attitude[2, 0]
    row1 = cos_l * attitude[0, 1] + -sin_l * attitude[1, 1] + 0.0 * attitude[2, 1]
    row2 = cos_l * attitude[0, 2] + -sin_l * attitude[1, 2] + 0.0 * attitude[2, 2]
    r3g_00 = row0 * ch + row1 * sh + row2 * 0.0
    r3g_01 = row0 * (-cos_i * sh) + row1 * (cos_i * ch) + row2 * sin_i
    return big_h, cos_i, sin_i, h, math.atan2(r3g_01, r3g_00)


@jit
def flip_attitude(attitude, flip):
    """Attitude of the flipped body frame: diag(flip) · R (the flip is its own inverse)."""
    fx, fy, fz = flip_signs(flip)
    out = attitude.copy()
    out[0, :] *= fx
    out[1, :] *= fy
    out[2, :] *= fz
    return out


@jit
def reduce_angle(x):
    """x reduced to (−π, π]."""
    return math.atan2(math.sin(x), math.cos(x))


@jit
def elements_from_state(attitude, momentum, ic):
    """Canonical elements of a rotation state (forward map, eq. 4, in the working frame).

    Parameters
    ----------
    attitude : (3, 3) ndarray
        Inertial → body attitude matrix, principal axes A ≤ B ≤ C.
    momentum : (3,) ndarray
        Body angular momentum.
    ic : tuple
        :func:`inertia_constants`.

    Returns
    -------
    elements : (6,) ndarray
        (S, Z, H, s, z, h) of the working frame, S ≥ 0, angles z, h in (−π, π].
    flip : int
        FLIP_* code of the working frame.
    mode : int
        MODE_SAM, MODE_LAM or MODE_UNIFORM (then the elements are not defined and are NaN).
    """
    mo, flip = motion_from_momentum(momentum[0], momentum[1], momentum[2], ic)
    out = np.full(6, np.nan)
    mode = int(mo[MO_MODE])
    if mode == MODE_UNIFORM:
        return out, flip, mode
    fx, fy, fz = flip_signs(flip)
    mx, my, mz = fx * momentum[0], fy * momentum[1], fz * momentum[2]
    working = flip_attitude(attitude, flip)
    mk, pk = elliptic_constants(mo)
    arg = ellipf_k(amplitude_from_momentum(mx, my, mz, mo, ic), mk)
    s = arg / mo[MO_ARG_PER_S]
    _, _, _, sin_l, cos_l = body_from_argument(arg, mo, mk)
    flipped = np.array([mx, my, mz])
    big_h, _, _, h, g = node_angles(working, flipped, sin_l, cos_l)
    z = g - mo[MO_G_PER_S] * s - mo[MO_PN_COEFF] * pn_k(arg, mk, pk)
    out[EL_S], out[EL_Z], out[EL_H] = mo[MO_S], mo[MO_G], big_h
    out[EL_SMALL_S], out[EL_SMALL_Z], out[EL_SMALL_H] = s, reduce_angle(z), h
    return out, flip, mode


@jit
def state_from_elements(elements, flip, ic):
    """Attitude matrix and body momentum of canonical elements (backward map, eqs. 7–8).

    ``elements`` = (S, Z, H, s, z, h) of the working frame with S ≥ 0; ``flip`` turns the result back
    into the body frame. Returns (attitude (3, 3), momentum (3,)).
    """
    mo = motion_from_elements(elements[EL_S], elements[EL_Z], ic)
    mk, pk = elliptic_constants(mo)
    return state_from_elements_motion(elements, flip, mo, mk, pk)


@jit
def body_part_of_elements(s, mo, mk, pk):
    """The part of the backward map that depends on s alone: (M_x, M_y, M_z, sin l, cos l, g − z).

    One sn/cn/dn and one pn; callers that vary only z, H or h at fixed (S, Z, s) (the torus grid of
    :mod:`spinorbit.core.averaging.short_period`) compute it once (:func:`state_from_body_part`).
    """
    arg = s * mo[MO_ARG_PER_S]
    mx, my, mz, sin_l, cos_l = body_from_argument(arg, mo, mk)
    return mx, my, mz, sin_l, cos_l, mo[MO_G_PER_S] * s + mo[MO_PN_COEFF] * pn_k(arg, mk, pk)


@jit
def state_from_body_part(elements, flip, body):
    """The rest of the backward map: (attitude, body momentum) from ``body`` =
    :func:`body_part_of_elements` of elements[s] and the elements' Z, H, z, h."""
    big_z, big_h = elements[EL_Z], elements[EL_H]
    z, h = elements[EL_SMALL_Z], elements[EL_SMALL_H]
    mx, my, mz, sin_l, cos_l, g_minus_z = body
    sin_i = math.sqrt(max((big_z - big_h) * (big_z + big_h), 0.0)) / big_z
    working = attitude_from_parts(mx, my, mz, sin_l, cos_l, z + g_minus_z, big_h / big_z, sin_i, h)
    fx, fy, fz = flip_signs(flip)
    return flip_attitude(working, flip), np.array([fx * mx, fy * my, fz * mz])


@jit
def state_from_elements_motion(elements, flip, mo, mk, pk):
    """:func:`state_from_elements` with the motion and elliptic constants of (S, Z) supplied.

    For callers that need them anyway (the element integrator's RHS also builds the Jacobian from
    them): computing them costs about as much as the rest of the backward map.
    """
    return state_from_body_part(elements, flip, body_part_of_elements(elements[EL_SMALL_S], mo, mk, pk))


# Status codes of the paper-named kernels (the Python wrappers turn them into exceptions).
STATUS_OK, STATUS_PERMANENT_ROTATION, STATUS_SEPARATRIX_ARC = 0, 1, 2


@jit
def canonical_from_andoyer_scalar(big_l, big_g, big_h, l, g, h, ic):
    """Paper eq. (4) for one state, all senses: (S, Z, H, s, z, h, status); S < 0 for −C / −A.

    The working-frame phase comes from (sin l, cos l) themselves in SAM — φ = atan2(√(b−c) cos l,
    √(a−c) sin l), eq. (5)'s tan φ = cot l/√(1+f) — so the caller's split of l + g is kept at J = 0.
    """
    nan = np.nan
    transverse = math.sqrt(max((big_g - big_l) * (big_g + big_l), 0.0))
    sl, cl = math.sin(l), math.cos(l)
    mx, my, mz = transverse * sl, transverse * cl, big_l
    mo, flip = motion_from_momentum(mx, my, mz, ic)
    if mo[MO_MODE] == MODE_UNIFORM or not symmetric_gap_resolved(mo[MO_S], big_g, ic):
        return nan, nan, nan, nan, nan, nan, STATUS_PERMANENT_ROTATION
    if flip == FLIP_A or flip == FLIP_C:
        return nan, nan, nan, nan, nan, nan, STATUS_SEPARATRIX_ARC
    if flip == FLIP_B:  # (L, l, g) → (−L, −l, g + π): the body frame turned by π about B
        mx, mz, sl, l, g = -mx, -mz, -sl, -l, g + math.pi
    mk, pk = elliptic_constants(mo)
    _a, _b, _c, a_b, b_c, a_c = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    if mo[MO_MODE] == MODE_SAM:
        amplitude = math.atan2(math.sqrt(b_c) * cl, math.sqrt(a_c) * sl)
    else:
        amplitude = math.atan2(math.sqrt(a_b) * my, math.sqrt(a_c) * mz)
    arg = ellipf_k(amplitude, mk)
    s = arg / mo[MO_ARG_PER_S]
    z = reduce_angle(g - mo[MO_G_PER_S] * s - mo[MO_PN_COEFF] * pn_k(arg, mk, pk))
    big_s = mo[MO_S]
    if flip == FLIP_B:
        big_s, s = -big_s, -s
    return big_s, big_g, big_h, s, z, h, STATUS_OK


@jit
def andoyer_from_canonical_scalar(big_s, big_z, big_h, s, z, h, ic):
    """Paper eqs. (7)–(8) for one state, all senses: (L, G, H, l, g, h, status), angles in (−π, π]."""
    flipped = big_s < 0.0
    if flipped:
        big_s, s = -big_s, -s
    mo = motion_from_elements(big_s, big_z, ic)
    if mo[MO_MODE] == MODE_UNIFORM or not symmetric_gap_resolved(big_s, big_z, ic):
        return np.nan, np.nan, np.nan, np.nan, np.nan, np.nan, STATUS_PERMANENT_ROTATION
    mk, pk = elliptic_constants(mo)
    arg = s * mo[MO_ARG_PER_S]
    _, _, mz, sin_l, cos_l = body_from_argument(arg, mo, mk)
    g = z + mo[MO_G_PER_S] * s + mo[MO_PN_COEFF] * pn_k(arg, mk, pk)
    l = math.atan2(sin_l, cos_l)
    if flipped:
        mz, l, g = -mz, -l, g + math.pi
    return mz, big_z, big_h, reduce_angle(l), reduce_angle(g), h, STATUS_OK


@jit
def canonical_from_andoyer_many(big_l, big_g, big_h, l, g, h, big_a, big_b, big_c, out, status):
    """Loop of :func:`canonical_from_andoyer_scalar` over flat arrays; out is (6, N)."""
    for i in range(big_l.shape[0]):
        ic = inertia_constants(big_a[i], big_b[i], big_c[i])
        r = canonical_from_andoyer_scalar(big_l[i], big_g[i], big_h[i], l[i], g[i], h[i], ic)
        out[0, i], out[1, i], out[2, i], out[3, i], out[4, i], out[5, i], status[i] = r


@jit
def andoyer_from_canonical_many(big_s, big_z, big_h, s, z, h, big_a, big_b, big_c, out, status):
    """Loop of :func:`andoyer_from_canonical_scalar` over flat arrays; out is (6, N)."""
    for i in range(big_s.shape[0]):
        ic = inertia_constants(big_a[i], big_b[i], big_c[i])
        r = andoyer_from_canonical_scalar(big_s[i], big_z[i], big_h[i], s[i], z[i], h[i], ic)
        out[0, i], out[1, i], out[2, i], out[3, i], out[4, i], out[5, i], status[i] = r
