"""Jacobian elliptic functions sn, cn, dn and the amplitude am, for every parameter m ≥ 0.

Numba scalar kernels (dimensionless). The hot-loop forms ``sncndn_k(u, mk)`` and ``am_k(u, mk)``
take the constants of :func:`.elliptic_periods.parameter_constants`; u is first reduced by the
double-double half period, so the phase does not drift with |u|. On the reduced range the values
come from a Maclaurin series and the duplication formulas, written so that nothing cancels
(m > 1 through the reciprocal parameter, m = 1 in closed form). Choices: ``docs/elliptic.md``.
"""

import math

from spinorbit.core.jit import jit
from spinorbit.core.math.ddouble import parity
from spinorbit.core.math.elliptic_periods import (
    MK_HEAD,
    MK_K_HI,
    MK_K_LO,
    MK_M,
    MK_MC,
    MK_MU,
    MK_MUC,
    MK_SQRT_M,
    MK_SQRT_MUC,
    MK_TAIL,
    PI_HI,
    PI_LO,
    parameter_constants,
    reduce_by_period,
)

# Maclaurin series of sn, cn, dn are used below this |u|; each is truncated where the first omitted
# term (sn: u^11, cn and dn: u^12, coefficients ≤ 0.009 for 0 ≤ m ≤ 1) is below ε/2 of the value.
SERIES_LIMIT = 0.035


@jit
def _sncndn_series(u, m):
    """Maclaurin series (DLMF 22.10.4–6, extended to u^11) for |u| ≤ SERIES_LIMIT, 0 ≤ m ≤ 1.

    Returns sn and the complements 1 − cn, 1 − dn, which keep full relative accuracy for small u.
    The coefficients are multiplied by the reciprocals of their denominators, not divided (twelve
    divisions per call, ≈ 15 ns of divider time): the extra rounding is ε relative in a term below
    u² ≈ 1e-3 of the value.
    """
    u2 = u * u
    sn = u * (
        1.0
        + u2 * (-(1.0 + m) * (1.0 / 6.0)
        + u2 * ((1.0 + m * (14.0 + m)) * (1.0 / 120.0)
        + u2 * (-(1.0 + m * (135.0 + m * (135.0 + m))) * (1.0 / 5040.0)
        + u2 * (1.0 + m * (1228.0 + m * (5478.0 + m * (1228.0 + m)))) * (1.0 / 362880.0))))
    )
    one_minus_cn = u2 * (
        0.5
        - u2 * ((1.0 + 4.0 * m) * (1.0 / 24.0)
        - u2 * ((1.0 + m * (44.0 + 16.0 * m)) * (1.0 / 720.0)
        - u2 * ((1.0 + m * (408.0 + m * (912.0 + 64.0 * m))) * (1.0 / 40320.0)
        - u2 * (1.0 + m * (3688.0 + m * (30768.0 + m * (15808.0 + 256.0 * m)))) * (1.0 / 3628800.0))))
    )
    one_minus_dn = m * u2 * (
        0.5
        - u2 * ((4.0 + m) * (1.0 / 24.0)
        - u2 * ((16.0 + m * (44.0 + m)) * (1.0 / 720.0)
        - u2 * ((64.0 + m * (912.0 + m * (408.0 + m))) * (1.0 / 40320.0)
        - u2 * (256.0 + m * (15808.0 + m * (30768.0 + m * (3688.0 + m)))) * (1.0 / 3628800.0))))
    )
    return sn, one_minus_cn, one_minus_dn


# While the doubled 1 − cn stays below this, the doubling steps carry the complements 1 − cn and
# 1 − dn (their relative errors grow only additively); from then on they carry cn and dn
# themselves, whose relative accuracy matters near K/2 when m → 1 (1/dn² in pn(u, m|m)).
COMPLEMENT_LIMIT = 0.5


@jit
def _sncndn_duplication(u, m, mc):
    """sn, cn, dn for 0 ≤ u ≤ K/2, 0 ≤ m < 1: halve u into the series range, then double back.

    Duplication formulas (DLMF 22.8.1–3 at v = u), written so that nothing cancels on [0, K/2]:
    1 − m s⁴ = c² + s²d²,  1 − cn(2u) = 2 s²d²/(1 − m s⁴),  1 − dn(2u) = 2 m s²c²/(1 − m s⁴),
    cn(2u) = (c⁴ − mc s⁴)/(1 − m s⁴),  dn(2u) = (mc + m c⁴)/(1 − m s⁴).
    (Conditional duplication in the spirit of Fukushima 2009: complements first, then cn, dn.)
    """
    halvings = 0
    while u > SERIES_LIMIT:
        u *= 0.5
        halvings += 1
    s, x, y = _sncndn_series(u, m)
    c = 1.0 - x
    d = 1.0 - y
    step = 0
    while step < halvings:
        s2 = s * s
        inverse = 1.0 / (c * c + s2 * d * d)
        x_next = 2.0 * s2 * d * d * inverse
        if x_next >= COMPLEMENT_LIMIT:
            break  # cn(2u) ≤ 1/2: this and later steps must produce cn, dn directly
        s, x, y = 2.0 * s * c * d * inverse, x_next, 2.0 * m * s2 * c * c * inverse
        c = 1.0 - x
        d = 1.0 - y
        step += 1
    while step < halvings:
        s2 = s * s
        c2 = c * c
        inverse = 1.0 / (c2 + s2 * d * d)
        s, c, d = (
            2.0 * s * c * d * inverse,
            (c2 * c2 - mc * s2 * s2) * inverse,
            (mc + m * c2 * c2) * inverse,
        )
        step += 1
    return s, c, d


@jit
def sncndn_reduced(r, m, mc, sqrt_mc, k_hi, k_lo):
    """sn, cn, dn for |r| ≤ K (plus rounding), 0 ≤ m < 1.

    For |r| > K/2 uses t = K − |r| and sn = cd(t), cn = √mc sn(t)/dn(t), dn = √mc/dn(t)
    (DLMF 22.4.3 table, u → K − t), so cn and dn near their minima keep full relative accuracy.
    K − |r| is exact: K_hi − |r| by Sterbenz, then + K_lo.
    """
    a = abs(r)
    if a <= 0.5 * k_hi:
        s, c, d = _sncndn_duplication(a, m, mc)
    else:
        t = (k_hi - a) + k_lo
        st, ct, dt = _sncndn_duplication(abs(t), m, mc)
        if t < 0.0:
            st = -st
        # sn = cd(t) = 1 − mc sn²t / (dn t (dn t + cn t)): the small correction carries the error,
        # not the ratio of two small numbers (cn t, dn t → mc^¼ at t = K/2 as m → 1).
        s = 1.0 - mc * st * st / (dt * (dt + ct))
        c = sqrt_mc * st / dt
        d = sqrt_mc / dt
    if r < 0.0:
        s = -s
    return s, c, d


@jit
def sncndn_k(u, mk):
    """sn(u|m), cn(u|m), dn(u|m) with precomputed ``mk = parameter_constants(m, mc)``.

    m < 1: u = 2jK + r, |r| ≤ K, sn = (−1)^j sn r, cn = (−1)^j cn r, dn = dn r (DLMF 22.4.3).
    m > 1: reciprocal parameter (DLMF 22.17.2–4, DLMF 22.17.2–4), v = √m·r with the reduction done in u.
    m = 1: sn = tanh u, cn = dn = sech u (DLMF 22.5.8, DLMF 22.5.8).
    """
    mc = mk[MK_MC]
    if mc == 0.0:
        sech = 1.0 / math.cosh(u)
        return math.tanh(u), sech, sech
    j, r = reduce_by_period(u, mk[MK_HEAD], mk[MK_TAIL])
    sign = 1.0 - 2.0 * parity(j)
    if mc > 0.0:
        s, c, d = sncndn_reduced(r, mk[MK_M], mc, mk[MK_SQRT_MUC], mk[MK_K_HI], mk[MK_K_LO])
        return sign * s, sign * c, d
    sqrt_m = mk[MK_SQRT_M]
    s, c, d = sncndn_reduced(
        sqrt_m * r, mk[MK_MU], mk[MK_MUC], mk[MK_SQRT_MUC], mk[MK_K_HI], mk[MK_K_LO]
    )
    return sign * s / sqrt_m, d, sign * c


@jit
def am_k(u, mk):
    """Jacobi amplitude am(u|m) with precomputed constants (DLMF 22.16.1).

    m < 1: am = jπ + atan2(sn r, cn r), |r| ≤ K, so it is continuous and never jumps by 2π
    (docs/elliptic.md, Reduction). m > 1: bounded, am = atan2(sn, cn) with cn > 0 (DLMF 22.17.2–4).
    m = 1: the Gudermannian gd(u) = 2 atan(tanh(u/2)) (DLMF 4.23.41), finite for every u.
    """
    mc = mk[MK_MC]
    if mc == 0.0:
        return 2.0 * math.atan(math.tanh(0.5 * u))
    if mc < 0.0:
        s, c, d = sncndn_k(u, mk)
        return math.atan2(s, c)
    j, r = reduce_by_period(u, mk[MK_HEAD], mk[MK_TAIL])
    s, c, d = sncndn_reduced(r, mk[MK_M], mc, mk[MK_SQRT_MUC], mk[MK_K_HI], mk[MK_K_LO])
    return j * PI_HI + (j * PI_LO + math.atan2(s, c))


@jit
def sncndn(u, m, mc):
    """sn, cn, dn of (u | m) for any m ≥ 0 (computes the constants; use sncndn_k in loops)."""
    return sncndn_k(u, parameter_constants(m, mc))


@jit
def am(u, m, mc):
    """am(u | m) for any m ≥ 0 (computes the constants; use am_k in loops)."""
