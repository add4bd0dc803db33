"""Periods of the elliptic functions and the reduction of arguments by them.

The per-parameter constants every hot-loop kernel of :mod:`.jacobi` and :mod:`.elliptic_integrals`
takes (``mk = parameter_constants(m, mc)``: the reduced parameter, the quarter period K in
double-double from the AGM, the half period split for exact multiples), the complete integral
K(m), and the two reductions built on them: of u by the half period 2K and of φ by π (Cody–Waite).
Dimensionless numba scalar kernels; m is the parameter and mc = 1 − m is supplied exactly by the
caller (``docs/conventions.md``). Why double-double and why the split: ``docs/elliptic.md`` (docs/elliptic.md, Reduction).
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.math.ddouble import (
    dd_add,
    dd_div,
    dd_mul,
    dd_sqrt,
    split,
    two_prod,
    two_sum,
)

# π as a double-double, and split for Cody–Waite reduction of φ: PI_HEAD has 24 significant bits so
# j*PI_HEAD is exact for |j| < 2^29; PI_MID = PI_HI − PI_HEAD is exact; PI_LO is the remainder.
PI_HI = math.pi
PI_LO = 1.2246467991473532e-16
HALF_PI = 0.5 * math.pi

# Veltkamp split factor (the 26-bit one lives in ``ddouble``): 2^29 + 1 leaves a 24-bit head, so
# head*j stays exact for |j| < 2^29 (|u| / period up to 5e8).
SPLIT_24 = 536870913.0

# Indices into the parameter-constants tuple returned by parameter_constants().
MK_M, MK_MC, MK_MU, MK_MUC, MK_SQRT_MUC, MK_SQRT_M, MK_K_HI, MK_K_LO, MK_HEAD, MK_TAIL = range(10)
MK_SIZE = 10


def _split_pi():
    t = SPLIT_24 * PI_HI
    head = t - (t - PI_HI)
    return head, PI_HI - head


PI_HEAD, PI_MID = _split_pi()


@jit
def quarter_period_dd(mc_hi, mc_lo):
    """K as a double-double from K = π / (2 AGM(1, √mc)) (DLMF 19.8.5), 0 < mc ≤ 1.

    Every AGM step runs in double-double, so K is good to ~1e-30 relative; stopping once
    |a − b| < 1e-17 a leaves an AGM error below (a − b)²/a ≈ 1e-34.
    """
    ah, al = 1.0, 0.0
    bh, bl = dd_sqrt(mc_hi, mc_lo)
    for _ in range(64):
        if abs(ah - bh) <= 1e-17 * ah:
            break
        sh, sl = dd_add(ah, al, bh, bl)
        ph, pl = dd_mul(ah, al, bh, bl)
        ah, al = 0.5 * sh, 0.5 * sl
        bh, bl = dd_sqrt(ph, pl)
    # final mean: (a + b)/2
    sh, sl = dd_add(ah, al, bh, bl)
    return dd_div(PI_HI, PI_LO, sh, sl)  # π / (2 · (a+b)/2)


@jit
def parameter_constants(m, mc):
    """Constants of the parameter m needed by the ``*_k`` kernels (tuple of 10 floats).

    Layout (indices ``MK_*``): (m, mc, μ, μ_c, √μ_c, √m, K_hi, K_lo, head, tail).
    For m < 1: μ = m, μ_c = mc, K = K(m), and head + tail = 2K (the half period of sn, cn in u).
    For m > 1: μ = 1/m, μ_c = −mc/m (from the supplied mc, never 1 − 1/m; DLMF 22.17.2–4), K = K(μ)
    (quarter period of the functions of v = √m u), head + tail = 2K(μ)/√m (half period in u).
    For m = 1 (mc == 0): K = head = ∞ and the kernels use closed forms (DLMF 22.5.8).
    NaN m or mc gives all-NaN constants, so every kernel then returns NaN.
    head has 24 significant bits so ``j*head`` is exact for |j| < 2^29 (docs/elliptic.md, Reduction).
    """
    if m != m or mc != mc:
        nan = math.nan
        return (nan, nan, nan, nan, nan, nan, nan, nan, nan, nan)
    if mc > 0.0:
        mu, muc_hi, muc_lo, sqrt_m = m, mc, 0.0, 1.0
        if m < 0.5:
            # Here the double m is the datum and 1 − m may not be a double: carry it exactly, or
            # its rounding (≤ 5.6e-17) would shift K and hence the phase at |u| = 1e6 by ~1e-11.
            # For m ≥ 0.5 the supplied mc is the datum (m = 1 − mc may be the rounded one).
            muc_hi, muc_lo = two_sum(1.0, -m)
    elif mc < 0.0:
        mu = 1.0 / m
        # μ_c = −mc/m as a double-double: the exact remainder of the division comes from two_prod.
        muc_hi = -mc / m
        p, e = two_prod(muc_hi, m)
        muc_lo = ((-mc - p) - e) / m
        sqrt_m = math.sqrt(m)
    else:
        inf = math.inf
        return (m, mc, m, mc, 0.0, 1.0, inf, 0.0, inf, 0.0)
    k_hi, k_lo = quarter_period_dd(muc_hi, muc_lo)
    return _constants_with_quarter_period(m, mc, mu, muc_hi, sqrt_m, k_hi, k_lo)


@jit
def parameter_constants_with_k(m, mc, k_hi, k_lo):
    """:func:`parameter_constants` for 0 ≤ m < 1 with K(m) already known as a double-double.

    For callers that hold K from their own (compensated) AGM (the flow set-up forms K from the
    exact inputs, :func:`spinorbit.core.math.complete_agm.complete_k_pi_dd`), so the AGM
    is not run twice per state.
    """
    return _constants_with_quarter_period(m, mc, m, mc, 1.0, k_hi, k_lo)


@jit
def _constants_with_quarter_period(m, mc, mu, muc_hi, sqrt_m, k_hi, k_lo):
    """The MK_* tuple from the reduced parameter and K(μ) (the common tail of the two above)."""
    # half period in u: 2K(μ)/√m, in double-double (√m exact to a double-double too)
    if mc < 0.0:
        sm_hi, sm_lo = dd_sqrt(m, 0.0)
        h_hi, h_lo = dd_div(2.0 * k_hi, 2.0 * k_lo, sm_hi, sm_lo)
    else:
        h_hi, h_lo = 2.0 * k_hi, 2.0 * k_lo
    head, rest = split(h_hi, SPLIT_24)
    tail = rest + h_lo
    return (m, mc, mu, muc_hi, math.sqrt(muc_hi), sqrt_m, k_hi, k_lo, head, tail)


@jit
def ellipk(m, mc):
    """Complete elliptic integral of the first kind K(m) (DLMF 19.2.8), from the double-double AGM.

    m = 1 (mc == 0) gives inf. For m > 1 returns the real part of the complex K(m), which is
    K(1/m)/√m (DLMF 19.7.3), the quarter period of sn(u|m) in u.
    """
    if mc == 0.0:
        return math.inf
    mk = parameter_constants(m, mc)
    return (mk[MK_K_HI] + mk[MK_K_LO]) / mk[MK_SQRT_M]


@jit
def reduce_by_period(u, head, tail):
    """j = rint(u / P), r = u − j P with P = head + tail; j*head exact, u − j*head exact (Sterbenz).

    Parameters
    ----------
    u : float
        Argument of the elliptic functions (dimensionless).
    head, tail : float
        The half period P = 2K(μ)/√m split as ``mk[MK_HEAD]``, ``mk[MK_TAIL]`` (24-bit head).

    Returns
    -------
    j, r : float
        The whole number of half periods and the remainder, |r| ≤ P/2 up to rounding.
    """
    j = np.rint(u / (head + tail))
    return j, (u - j * head) - j * tail


@jit
def reduce_by_pi(phi):
    """j = rint(φ/π), r = φ − jπ with π in three parts (Cody–Waite; docs/elliptic.md, Reduction).

    Parameters
    ----------
    phi : float
        Amplitude φ of F or Π (rad).

    Returns
    -------
    j, r : float
        Whole turns of π and the remainder r ∈ [−π/2, π/2] (rad), exact for |j| < 2^29.
    """
    j = np.rint(phi / PI_HI)
    return j, ((phi - j * PI_HEAD) - j * PI_MID) - j * PI_LO
