"""The Jacobian ∂(L, G, H, l, g, h)/∂(S, Z, H, s, z, h) of the canonical elements (paper section 4).

Paper: T. Fukushima, "Canonical elements of rotational motion", section 4, eqs. (13)–(14). The printed
(PDF-extracted) eq. (14) has errors; ``docs/theory.md`` ("The Jacobian (paper section 4)") lists every
correction and how each was verified. This module evaluates the Jacobian on the same body-momentum
form of the backward map (eqs. 7–8) that :mod:`spinorbit.core.elements.canonical` uses, in both rotation modes,
and for both senses of rotation (the sign of S).

Structure (derived, not read from the garbled printed list)
-----------------------------------------------------------
G = Z, H = H and h = h, while L, l, g depend on (S, Z, s) only and g moves one-for-one with z.
With rows (L, G, H, l, g, h) and columns (S, Z, H, s, z, h) the 13 non-zero components are

    L: ∂L/∂S, ∂L/∂Z, ∂L/∂s          G: ∂G/∂Z = 1          H: ∂H/∂H = 1
    l: ∂l/∂S, ∂l/∂Z, ∂l/∂s          g: ∂g/∂S, ∂g/∂Z, ∂g/∂s, ∂g/∂z = 1          h: ∂h/∂h = 1

and the other 23 vanish identically (``ZERO_COMPONENTS``):
∂L/∂H, ∂L/∂z, ∂L/∂h; ∂G/∂S, ∂G/∂H, ∂G/∂s, ∂G/∂z, ∂G/∂h; ∂H/∂S, ∂H/∂Z, ∂H/∂s, ∂H/∂z, ∂H/∂h;
∂l/∂H, ∂l/∂z, ∂l/∂h; ∂g/∂H, ∂g/∂h; ∂h/∂S, ∂h/∂Z, ∂h/∂H, ∂h/∂s, ∂h/∂z.

How the non-zero components are formed (eq. 13)
------------------------------------------------
S and Z enter L, l, g only through d = a S²/Z² and (for L) the factor G = Z, so with X ∈ {L, l, g}

    ∂X/∂S = X_d · 2d/S,    ∂X/∂Z = X_d · (−2d/Z) + (∂X/∂G)*,    (∂L/∂G)* = L/G, (∂l/∂G)* = (∂g/∂G)* = 0,

where X_d = ∂X/∂d at fixed s and G. The starred term of ∂L/∂Z is the one missing from the printed
eq. (13). X_d and ∂X/∂s are built per mode from the parameter derivatives below.

Short-axis mode (0 ≤ m < 1), argument u = κ s (eq. 8), κ = √((a−d)(b−c)/(a d)):
    u_d = −a u / (2 d (a−d)),  m_d = f (a−c)/(a−d)²,  jm = ∫₀ᵘ sn²/dn² du′ = (pn(u, m|m) − u)/m.

Long-axis mode (m > 1), argument v = √m u, parameter μ = 1/m:
    v_d = c v / (2 d (d−c)),  μ_d = −(b−c)(a−c)/((a−b)(d−c)²),  jμ = ∫₀^v sn²/dn² dv′(v|μ).

The g-derivative needs no derivative with respect to a characteristic in either mode: at fixed u the
characteristic −f of pn(u, −f|m) is a constant, and the d-derivative of g collapses (the pn and
∫sn²/(1 + f sn²) terms cancel exactly) to

    SAM: g_d = −c s/(2d√(ad)) + C_g [u (d (a−b) sn² − (a−d)(b−c))/d − (a−b) dn² jm] / (2 (a−d)((b−c) + (a−b) sn²))
    LAM: g_d = −c s/(2d√(ad)) + C′_g [v (sn² − (d−c)/d) − cn² T] / (2 ((d−c) + (a−d) sn²))

with C_g = (a−c)/√((a−d)(b−c)), C′_g = (a−c)/√((a−b)(d−c)) and cn² T = cn²(v|μ) ∫₀^v sn²/cn² dv′,
the finite product of a double zero and the simple poles of the meromorphic ∫ sc² (at the LAM turning
points, M_z = 0). In the (u, m) form that product is m^{3/2} dn²(u|m) (pn(u, m|m) − u)/m, whose factors
are separately singular for m > 1; this is the LAM rewrite the paper's (u, m) formulas need.

Sense of rotation
-----------------
S < 0 means the working body frame is turned by π about B (``FLIP_B``): the working elements are
(−S, Z, H, −s, z, h) and the Andoyer variables are (L, l, g) = (−L_w, −l_w, g_w + π). Both maps are
canonical and linear, so J = D · J_w · D with D = diag(−1, 1, 1, −1, 1, 1).
"""

import math

import numpy as np

from spinorbit.core.elements.canonical import (
    EL_S,
    EL_SMALL_S,
    EL_Z,
    MO_ARG_PER_S,
    MO_D,
    MO_G,
    MO_G_PER_S,
    MO_MODE,
    MO_PARAM,
    MO_PARAM_C,
    MO_PN_COEFF,
    MO_Z_AMP,
    MODE_LAM,
    MODE_SAM,
    elliptic_constants,
    motion_from_elements,
)
from spinorbit.core.jit import jit
from spinorbit.core.math.carlson import rd, rf, rj
from spinorbit.core.math.ddouble import parity
from spinorbit.core.math.elliptic_periods import (
    MK_HEAD,
    MK_K_HI,
    MK_K_LO,
    MK_MU,
    MK_MUC,
    MK_SQRT_MUC,
    MK_TAIL,
    reduce_by_period,
)

# The reduced-argument kernel is used directly so that sn, cn, dn and the associate integrals below
# come from one reduction u = 2jK + r (|r| ≤ K), not from two that could disagree by one half period
# at the boundary.
from spinorbit.core.math.jacobi import sncndn_reduced

# Row / column indices of the Jacobian.
ROW_L, ROW_G, ROW_H, ROW_SMALL_L, ROW_SMALL_G, ROW_SMALL_H = range(6)
COL_S, COL_Z, COL_H, COL_SMALL_S, COL_SMALL_Z, COL_SMALL_H = range(6)  # the EL_* order of the elements

ANDOYER_NAMES = ("L", "G", "H", "l", "g", "h")
ELEMENT_NAMES = ("S", "Z", "H", "s", "z", "h")

# The 23 components that vanish identically (row, column), derived in the module docstring.
ZERO_COMPONENTS = (
    (ROW_L, COL_H), (ROW_L, COL_SMALL_Z), (ROW_L, COL_SMALL_H),
    (ROW_G, COL_S), (ROW_G, COL_H), (ROW_G, COL_SMALL_S), (ROW_G, COL_SMALL_Z), (ROW_G, COL_SMALL_H),
    (ROW_H, COL_S), (ROW_H, COL_Z), (ROW_H, COL_SMALL_S), (ROW_H, COL_SMALL_Z), (ROW_H, COL_SMALL_H),
    (ROW_SMALL_L, COL_H), (ROW_SMALL_L, COL_SMALL_Z), (ROW_SMALL_L, COL_SMALL_H),
    (ROW_SMALL_G, COL_H), (ROW_SMALL_G, COL_SMALL_H),
    (ROW_SMALL_H, COL_S), (ROW_SMALL_H, COL_Z), (ROW_SMALL_H, COL_H), (ROW_SMALL_H, COL_SMALL_S),
    (ROW_SMALL_H, COL_SMALL_Z),
)


# --------------------------------------------------------------------------------------------------
# Building blocks: associate integrals and parameter derivatives at fixed argument (parameter < 1)
# --------------------------------------------------------------------------------------------------


@jit
def associate_integrals(x, mk, f, want_jn=True, want_cn2_t=True):
    """sn, cn, dn of (x | q) and three associate integrals, from one period reduction (0 ≤ q < 1).

    Parameters
    ----------
    x : float
        Argument (u in SAM, v in LAM).
    mk : tuple
        ``parameter_constants(q, q_c)`` with 0 ≤ q < 1 (q_c > 0).
    f : float
        f ≥ 0 of the characteristic n = −f in ``jn``.

    Returns
    -------
    sn, cn, dn : float
    jm : float
        ∫₀ˣ sn²/dn² dx′ = (pn(x, q|q) − x)/q = J(am x, q|q), Fukushima's associate integral of the
        third kind at n = q: (s³/3) R_D(c², 1, d²) on the reduced argument plus 2j·R_D(0, 1, q_c)/3.
        O(x) as q → 0, where the difference form (pn − x)/q would cancel completely.
    jn : float
        ∫₀ˣ sn²/(1 + f sn²) dx′ = (x − pn(x, −f|q))/f: (s³/3) R_J(c², d², 1, 1 + f s²) + 2j R_J(0,
        q_c, 1, 1 + f)/3. No cancellation for any f ≥ 0 (f = 0 gives ∫ sn²).
    cn2_t : float
        cn²(x) ∫₀ˣ sn²/cn² dx′ (sc², meromorphic with simple poles at the zeros of cn; the product is
        analytic). On |r| < K: c² (s³/3) R_D(d², 1, c²); each half period adds −2E(q)/q_c to the
        integral (∫ sc² = (sn dn/cn − E(x))/q_c, DLMF 22.16.25 style, with sn dn/cn 2K-periodic).

    want_jn, want_cn2_t : bool
        False skips that integral (returned as 0.0): its Carlson R_J / R_D is a good part of the cost,
        and the Jacobian itself needs only jm (SAM) or jm and cn² T (LAM).

    Notes
    -----
    Carlson forms: DLMF 19.25.14 family, ∫₀^φ sin²θ dθ/((1 − n sin²θ)Δ) = (s³/3) R_J(c², Δ², 1, 1 − n s²),
    with sin φ, cos φ, Δ = sn, cn, dn at the reduced argument (φ = am r, |φ| ≤ π/2).
    """
    j, r = reduce_by_period(x, mk[MK_HEAD], mk[MK_TAIL])
    q, qc = mk[MK_MU], mk[MK_MUC]
    s, c, d = sncndn_reduced(r, q, qc, mk[MK_SQRT_MUC], mk[MK_K_HI], mk[MK_K_LO])
    sign = 1.0 - 2.0 * parity(j)
    s2, c2, d2 = s * s, c * c, d * d
    s3 = s * s2 / 3.0
    jm = s3 * rd(c2, 1.0, d2)
    jn = s3 * rj(c2, d2, 1.0, 1.0 + f * s2) if want_jn else 0.0
    # c² R_D(d², 1, c²) → 0 like |c| at the turning point; R_D itself is infinite there.
    cn2_t = c2 * s3 * rd(d2, 1.0, c2) if (want_cn2_t and c2 > 0.0) else 0.0
    if j != 0.0:
        jm += 2.0 * j * rd(0.0, 1.0, qc) / 3.0
        if want_jn:
            jn += 2.0 * j * rj(0.0, qc, 1.0, 1.0 + f) / 3.0
        if want_cn2_t:
            complete_e = rf(0.0, qc, 1.0) - q * rd(0.0, qc, 1.0) / 3.0
            cn2_t -= 2.0 * j * c2 * complete_e / qc
    return sign * s, sign * c, d, jm, jn, cn2_t


@jit
def jacobi_parameter_derivatives(sn, cn, dn, jm, q):
    """∂(sn, cn, dn, am)/∂q at fixed argument, for 0 ≤ q < 1.

    ∂am/∂q = −dn·jm/2 with jm = (pn(x, q|q) − x)/q (from x = F(am x | q) and DLMF 19.4.3; the rotation
    note's dn (x − pn(x, q|q))/(2q)), then ∂sn = cn ∂am, ∂cn = −sn ∂am, and from dn² = 1 − q sn²,
    ∂dn = −sn²/(2 dn) + q sn cn jm/2.

    Returns
    -------
    dsn, dcn, ddn, dam : float
    """
    dam = -0.5 * dn * jm
    return cn * dam, -sn * dam, -0.5 * sn * sn / dn + 0.5 * q * sn * cn * jm, dam


@jit
def pn_parameter_derivative(sn, dn, jm, jn, f, weight_f):
    """∂pn(x, −f | q)/∂q at fixed x and f ≥ 0, for 0 ≤ q < 1.

    From pn = Π(am x, −f | q), ∂Π/∂q at fixed φ = [Π(φ, q|q) − Π(φ, −f|q)]/(2(q + f)) and ∂am/∂q:

        ∂pn/∂q = f/(2(q + f)) · [jn − dn² jm/(1 + f sn²)],

    where ``weight_f`` = f/(q + f) is passed by the caller, because it is known exactly from inertia
    differences ((a−d)/(a−c) in SAM) and stays defined at q = f = 0 (A = B). The bracket has no
    cancellation beyond O(x⁵) at small x.
    """
    return 0.5 * weight_f * (jn - dn * dn * jm / (1.0 + f * sn * sn))


# --------------------------------------------------------------------------------------------------
# The Jacobian
# --------------------------------------------------------------------------------------------------


@jit
def _working_derivatives(big_s, big_z, s, ic):
    """(L, X_d, X_s) for X = L, l, g in the working frame (S > 0), or NaNs where undefined.

    Returns a (3, 3) array: rows L, l, g; columns (value-free) d-derivative at fixed (s, G),
    s-derivative, and (∂X/∂G)* at fixed (d, s).
    """
    mo = motion_from_elements(big_s, big_z, ic)
    mk, _ = elliptic_constants(mo)
    return _working_derivatives_motion(big_s, big_z, s, ic, mo, mk)


@jit
def _working_derivatives_motion(big_s, big_z, s, ic, mo, mk):
    """:func:`_working_derivatives` with the motion and parameter constants of (S, Z) supplied."""
    a, b, c, a_b, b_c, a_c = ic
    out = np.full((3, 3), np.nan)
    mode = mo[MO_MODE]
    if (mode != MODE_SAM and mode != MODE_LAM) or mo[MO_PARAM_C] <= 0.0:
        # permanent rotation, or the exact separatrix (m = 1): not covered (docs/theory.md)
        return out
    d = mo[MO_D]
    big_g = mo[MO_G]
    z2 = big_z * big_z
    a_d = a * (big_z - big_s) * (big_z + big_s) / z2
    d_c = d - c
    sqrt_ad = math.sqrt(a * d)
    q = mo[MO_PARAM]
    kappa = mo[MO_ARG_PER_S]
    x = kappa * s
    amp_z = mo[MO_Z_AMP]  # G √((a−d)/(a−c))
    g_s_direct = mo[MO_G_PER_S]  # c/√(ad)
    g_d_direct = -c * s / (2.0 * d * sqrt_ad)
    if mode == MODE_SAM:
        f = a_b / b_c
        sn, cn, dn, jm, _, _ = associate_integrals(x, mk, f, False, False)
        _, _, ddn, dam = jacobi_parameter_derivatives(sn, cn, dn, jm, q)
        x_d = -a * x / (2.0 * d * a_d)
        q_d = f * a_c / (a_d * a_d)
        big_l = amp_z * dn
        out[0, 0] = -big_l / (2.0 * a_d) + amp_z * (-q * sn * cn * x_d + ddn * q_d)
        out[0, 1] = -amp_z * q * sn * cn * kappa
        # l = atan2(√(b−c) cn, √(a−c) sn): dl = −√((a−c)(b−c)) d(am) / ((b−c) cn² + (a−c) sn²)
        weight = math.sqrt(a_c * b_c) / (b_c * cn * cn + a_c * sn * sn)
        out[1, 0] = -weight * (dn * x_d + dam * q_d)
        out[1, 1] = -weight * dn * kappa
        coeff = mo[MO_PN_COEFF]  # (a−c)/√((a−d)(b−c))
        denom = b_c + a_b * sn * sn
        out[2, 0] = g_d_direct + coeff * (
            x * (d * a_b * sn * sn - a_d * b_c) / d - a_b * dn * dn * jm
        ) / (2.0 * a_d * denom)
        out[2, 1] = g_s_direct + coeff * kappa * b_c / denom
    else:
        f = a_d / d_c  # −n′ of pn(v, n′|μ); only cn² T is used below
        sn, cn, dn, jm, _, cn2_t = associate_integrals(x, mk, f, False, True)
        _, dcn, _, _ = jacobi_parameter_derivatives(sn, cn, dn, jm, q)
        x_d = c * x / (2.0 * d * d_c)
        q_d = -b_c * a_c / (a_b * d_c * d_c)
        big_l = amp_z * cn
        out[0, 0] = -big_l / (2.0 * a_d) + amp_z * (-sn * dn * x_d + dcn * q_d)
        out[0, 1] = -amp_z * sn * dn * kappa
        # l = atan2(w_s, w_c), w_s = √((a−b)(d−c)) dn, w_c = √((a−c)(a−d)) sn; the weights depend on d.
        # w_c dw_s − w_s dw_c simplifies with μ sn² + dn² = 1 and sn ∂dn − dn ∂sn = cn jμ/2 − sn³/(2dn).
        root_s = math.sqrt(a_b * d_c)
        root_c = math.sqrt(a_c * a_d)
        den = a_b * d_c * dn * dn + a_c * a_d * sn * sn
        out[1, 0] = root_s * root_c * (
            sn * dn * a_c / (2.0 * d_c * a_d) - x_d * cn + q_d * (0.5 * cn * jm - 0.5 * sn ** 3 / dn)
        ) / den
        out[1, 1] = -root_s * root_c * cn * kappa / den
        coeff = mo[MO_PN_COEFF]  # (a−c)/√((a−b)(d−c))
        denom = d_c + a_d * sn * sn
        out[2, 0] = g_d_direct + coeff * (x * (sn * sn - d_c / d) - cn2_t) / (2.0 * denom)
        out[2, 1] = g_s_direct + coeff * kappa * d_c / denom
    out[0, 2] = big_l / big_g
    out[1, 2] = 0.0
    out[2, 2] = 0.0
    return out


@jit
def andoyer_jacobian(elements, ic):
    """Jacobian ∂(L, G, H, l, g, h)/∂(S, Z, H, s, z, h) of the backward map (paper eqs. 7–8, 13–14).

    Parameters
    ----------
    elements : (6,) ndarray
        Canonical elements (S, Z, H, s, z, h). S < 0 means the sense −C (SAM) or −A (LAM): the
        working frame is turned by π about B (see :mod:`spinorbit.core.elements.canonical`).
    ic : tuple
        :func:`spinorbit.core.elements.canonical.inertia_constants`.

    Returns
    -------
    jacobian : (6, 6) ndarray
        J[i, j] = ∂(L, G, H, l, g, h)_i / ∂(S, Z, H, s, z, h)_j (rows / columns in that order; angle
        rows per radian, momenta in the unit of Z). NaN where the elements have no finite Jacobian:
        the exact separatrix m = 1 and permanent rotations.

    Notes
    -----
    Eq. (13) with the corrected partials of eq. (14) (``docs/theory.md``): every d-derivative is taken
    at fixed s and G, ∂d/∂S = 2d/S, ∂d/∂Z = −2d/Z, plus the explicit (∂L/∂Z)* = L/Z. The SAM parts are
    evaluated in (u, m), the LAM parts in (v, μ) = (√m u, 1/m) (module docstring). The 23 zero
    components are exactly zero.
    """
    big_s, big_z = elements[EL_S], elements[EL_Z]
    mo = motion_from_elements(abs(big_s), big_z, ic)
    mk, _ = elliptic_constants(mo)
    return andoyer_jacobian_motion(elements, ic, mo, mk)


@jit
def andoyer_jacobian_motion(elements, ic, mo, mk):
    """:func:`andoyer_jacobian` with the motion constants of (|S|, Z) and their parameter constants
    (``motion_from_elements``, ``elliptic_constants``) supplied by a caller that has them already."""
    big_s, big_z, s = elements[EL_S], elements[EL_Z], elements[EL_SMALL_S]
    sense = 1.0
    if big_s < 0.0:
        sense = -1.0
    part = _working_derivatives_motion(sense * big_s, big_z, sense * s, ic, mo, mk)
    jac = np.zeros((6, 6))
    big_s_w = sense * big_s
    a, _b, _c, _a_b, _b_c, _a_c = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    d = a * big_s_w * big_s_w / (big_z * big_z)
    d_big_s = 2.0 * a * big_s_w / (big_z * big_z)  # = 2d/S, finite for S → 0
    d_big_z = -2.0 * d / big_z
    for row, out_row in ((0, ROW_L), (1, ROW_SMALL_L), (2, ROW_SMALL_G)):
        jac[out_row, COL_S] = part[row, 0] * d_big_s
        jac[out_row, COL_Z] = part[row, 0] * d_big_z + part[row, 2]
        jac[out_row, COL_SMALL_S] = part[row, 1]
    jac[ROW_G, COL_Z] = 1.0
    jac[ROW_H, COL_H] = 1.0
    jac[ROW_SMALL_G, COL_SMALL_Z] = 1.0
    jac[ROW_SMALL_H, COL_SMALL_H] = 1.0
    if sense < 0.0:
        # J = D J_w D with D = diag(−1, 1, 1, −1, 1, 1): flip rows L, l and columns S, s.
        for k in range(6):
            jac[ROW_L, k] = -jac[ROW_L, k]
            jac[ROW_SMALL_L, k] = -jac[ROW_SMALL_L, k]
        for k in range(6):
            jac[k, COL_S] = -jac[k, COL_S]
            jac[k, COL_SMALL_S] = -jac[k, COL_SMALL_S]
    return jac


@jit
def canonical_gradient(du_dandoyer, jacobian):
    """∂U/∂(S, Z, H, s, z, h) = Jᵀ · ∂U/∂(L, G, H, l, g, h) (paper section 4, chain rule).

    Parameters
    ----------
    du_dandoyer : (6,) ndarray
        ∂U/∂(L, G, H, l, g, h).
    jacobian : (6, 6) ndarray
        :func:`andoyer_jacobian` of the same elements.

    Returns
    -------
    (6,) ndarray
        ∂U/∂(S, Z, H, s, z, h), the right-hand sides of eq. (11).
    """
    out = np.zeros(6)
    for j in range(6):
        total = 0.0
        for i in range(6):
            total += jacobian[i, j] * du_dandoyer[i]
        out[j] = total
    return out


def andoyer_jacobian_many(elements, big_a, big_b, big_c):
    """Vectorized :func:`andoyer_jacobian` over stacked elements.

    Parameters
    ----------
    elements : (..., 6) array_like
        Canonical elements (S, Z, H, s, z, h).
    big_a, big_b, big_c : float
        Principal moments A ≤ B ≤ C (same unit as the momenta over a rate).

    Returns
    -------
    (..., 6, 6) ndarray
    """
    from spinorbit.core.elements.canonical import inertia_constants

    elements = np.asarray(elements, dtype=float)
    if elements.shape[-1:] != (6,):
        raise ValueError(f"elements: expected shape (..., 6), got {elements.shape}")
    ic = inertia_constants(float(big_a), float(big_b), float(big_c))
    flat = elements.reshape(-1, 6)
    out = np.empty((flat.shape[0], 6, 6))
    for k in range(flat.shape[0]):
        out[k] = andoyer_jacobian(np.ascontiguousarray(flat[k]), ic)
    return out.reshape(elements.shape[:-1] + (6, 6))
