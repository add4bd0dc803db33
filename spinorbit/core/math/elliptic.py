"""Exact elliptic-function kernels for the canonical elements of rotational motion.

Numba scalar kernels (``nopython``, callable from other compiled code). All are dimensionless; m is
the *parameter* (not the modulus k = √m) and every kernel that depends on m also takes the exact
complementary parameter ``mc = 1 − m``, formed by the caller from inertia differences
(``docs/conventions.md``). The sign of ``mc`` selects the regime: ``mc > 0`` short-axis mode
(0 ≤ m < 1), ``mc == 0`` the separatrix m = 1 (closed forms), ``mc < 0`` long-axis mode (m > 1,
through the reciprocal parameter μ = 1/m with μ_c = −mc/m). Formulas and the reasons for each
choice: ``/work/shared/notes/elliptic-numerics.md`` ("note §6.x") and ``docs/elliptic.md``.

Hot-loop API: precompute per-parameter constants once, then call the ``*_k`` kernels
------------------------------------------------------------------------------------
``mk = parameter_constants(m, mc)``
    Tuple of 10 floats (layout: the ``MK_*`` indices below): m, mc, the reduced parameter μ and
    μ_c actually used by the sn/cn/dn algorithm (μ = m for m ≤ 1, 1/m for m > 1), √μ_c, √m
    (1 for m ≤ 1), the quarter period K(μ) as a double-double (hi, lo), and the u-space half
    period 2K(μ)/√m split into a 24-bit head and a tail so that ``j*head`` is exact.
``nk = characteristic_constants(n, m, mc)``
    For Π(φ, n | m): (method, n, f, g, Π(n|m)) with f = −n, g = m/f and the complete integral.
``pk = pn_constants(n, m, mc)``
    For pn(u, n | m): the same layout, for the characteristic actually integrated (n/m with the
    reciprocal parameter 1/m when m > 1, note §6.2). ``method == METHOD_DIVERGENT`` (n = m > 1)
    makes ``pn_k`` return NaN.

``sncndn_k(u, mk) -> (sn, cn, dn)``, ``am_k(u, mk)``, ``ellipf_k(phi, mk)``,
``ellippi_k(phi, mk, nk)``, ``pn_k(u, mk, pk)``
    The same values as the convenience kernels below, with no per-m work.

Convenience kernels (compute the constants on every call; fine outside hot loops):
``rf(x, y, z)``, ``rd(x, y, z)``, ``rj(x, y, z, p)`` (p > 0), ``rc(x, y)`` (y > 0),
``ellipk(m, mc)``, ``sncndn(u, m, mc)``, ``am(u, m, mc)``, ``ellipf(phi, m, mc)``,
``ellippi(n, phi, m, mc)``, ``pn(u, n, m, mc)``.

Domain and NaN cases (documented in the kernels): m ≥ 0; for m > 1, F and Π are real only for
|φ| ≤ arcsin(1/√m) (NaN elsewhere); at m = 1, F and Π diverge at |φ| ≥ π/2 (±inf);
pn(u, m | m) for m > 1 is non-integrable at the turning points (NaN); ``ellipk`` for m > 1 returns
the real quarter period K(1/m)/√m (the real part of the complex K(m)).
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.math.ddouble import (
    dd_add as _dd_add,
    dd_div as _dd_div,
    dd_mul as _dd_mul,
    dd_sqrt as _dd_sqrt,
    split as _split,
    two_prod as _two_prod,
    two_sum as _two_sum,
)

# --------------------------------------------------------------------------------------------------
# Constants
# --------------------------------------------------------------------------------------------------

EPSILON = 2.0**-52
# Carlson (1995) stopping constants: iterate until 4^-n Q < |A_n| with Q = C·max|A0 − arg|.
# Carlson's bound on the truncated series gives C = (3ε)^(-1/6) for R_F and (ε/4)^(-1/6) for
# R_D, R_J (note pitfall 14: a wrong constant here fails silently).
RF_STOP = (3.0 * EPSILON) ** (-1.0 / 6.0)  # ≈ 338
RDJ_STOP = (0.25 * EPSILON) ** (-1.0 / 6.0)  # ≈ 513, for R_D and R_J

# π as a double-double, and split for Cody–Waite reduction of φ: PI_HEAD has 24 significant bits so
# j*PI_HEAD is exact for |j| < 2^29; PI_MID = PI_HI − PI_HEAD is exact; PI_LO is the remainder.
PI_HI = math.pi
PI_LO = 1.2246467991473532e-16
HALF_PI = 0.5 * math.pi

# Veltkamp split factor (the 26-bit one lives in ``ddouble``): 2^29 + 1 leaves a 24-bit head, so
# head*j stays exact for |j| < 2^29 (|u| / period up to 5e8).
SPLIT_24 = 536870913.0

# Maclaurin series of sn, cn, dn are used below this |u|; each is truncated where the first omitted
# term (sn: u^11, cn and dn: u^12, coefficients ≤ 0.009 for 0 ≤ m ≤ 1) is below ε/2 of the value.
SERIES_LIMIT = 0.035

# Methods for the characteristic n (see characteristic_constants).
METHOD_GENERAL = 0  # Π = F + (n/3) s³ R_J(c², Δ², 1, p), n < 1 and not the cases below (note §6.3)
METHOD_LARGE_NEGATIVE = 1  # n = −f with f ≥ 1: R_C form (note §6.4), no cancellation for f → ∞
METHOD_EQUAL_TO_M = 2  # n = m: R_J(c², Δ², 1, Δ²) = R_D(c², 1, Δ²), exact as m → 1 (note §6.5)
METHOD_DIVERGENT = 3  # pn(u, m | m) for m > 1: 1/(1 − m sn²) is non-integrable; result NaN

# Indices into the parameter-constants tuple returned by parameter_constants().
MK_M, MK_MC, MK_MU, MK_MUC, MK_SQRT_MUC, MK_SQRT_M, MK_K_HI, MK_K_LO, MK_HEAD, MK_TAIL = range(10)
# Indices into the characteristic-constants tuple.
NK_METHOD, NK_N, NK_F, NK_G, NK_COMPLETE = range(5)


def _split_pi():
    t = SPLIT_24 * PI_HI
    head = t - (t - PI_HI)
    return head, PI_HI - head


PI_HEAD, PI_MID = _split_pi()

# --------------------------------------------------------------------------------------------------
# Error-free transformations and double-double arithmetic: one copy, in ``ddouble`` (shared with the
# long-span torque-free flow); the private names are kept so the kernels below read unchanged.
# --------------------------------------------------------------------------------------------------

# --------------------------------------------------------------------------------------------------
# Carlson symmetric integrals (Carlson 1995, arXiv:math/9409227; DLMF 19.36.1–2)
# --------------------------------------------------------------------------------------------------


@jit
def rf(x, y, z):
    """Carlson's R_F(x, y, z) = ½∫₀^∞ dt / √((t+x)(t+y)(t+z)) (DLMF 19.16.1).

    x, y, z ≥ 0, at most one zero. Duplication (DLMF 19.26.18) until the Taylor series of degree 5
    (DLMF 19.36.1) is accurate to ε; series variables from the current iterates.
    """
    a0 = (x + y + z) / 3.0
    q = RF_STOP * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    a = a0
    while q >= abs(a):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sx * sz + sy * sz
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        a = (x + y + z) / 3.0
        q *= 0.25
    dx = (a - x) / a
    dy = (a - y) / a
    dz = -(dx + dy)
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    return (1.0 - e2 / 10.0 + e3 / 14.0 + e2 * e2 / 24.0 - 3.0 * e2 * e3 / 44.0) / math.sqrt(a)


@jit
def _rc_from_difference(x, y, y_minus_x):
    """R_C(x, y) for x ≥ 0, y > 0, with d = y − x supplied by the caller (DLMF 19.2.17–19).

    Exact when d is known without cancellation (note §6.4: y − x = s²(1 + m + f + g)).
    y > x: atan2(√d, √x)/√d. y < x: atanh(√(−d/x))/√(−d) while −d/x ≤ ½, else the logarithm
    ln((√x + √(−d))/√y)/√(−d), because atanh near 1 would amplify the rounding of its argument.
    """
    d = y_minus_x
    if d > 0.0:
        sd = math.sqrt(d)
        return math.atan2(sd, math.sqrt(x)) / sd
    if d < 0.0:
        sd = math.sqrt(-d)
        if -d <= 0.5 * x:
            return math.atanh(sd / math.sqrt(x)) / sd
        return math.log((math.sqrt(x) + sd) / math.sqrt(y)) / sd
    return 1.0 / math.sqrt(x)


@jit
def rc(x, y):
    """Carlson's R_C(x, y) = ½∫₀^∞ dt / ((t+y)√(t+x)) for x ≥ 0, y > 0 (DLMF 19.2.17–19).

    Closed forms with atan/atanh/log; y − x is exact when x and y are close (Sterbenz), so there
    is no cancellation in the argument.
    """
    return _rc_from_difference(x, y, y - x)


@jit
def rd(x, y, z):
    """Carlson's R_D(x, y, z) = R_J(x, y, z, z) (DLMF 19.16.5); x, y ≥ 0 (one may be 0), z > 0.

    Duplication with the series of Carlson (1995) eq. (2.29); the sum of the duplication terms is
    3 Σ 4^-k / (√z_k (z_k + λ_k)).
    """
    a0 = (x + y + 3.0 * z) / 5.0
    q = RDJ_STOP * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))
    a = a0
    power4 = 1.0
    total = 0.0
    while q >= abs(a):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sx * sz + sy * sz
        total += power4 / (sz * (z + lam))
        power4 *= 0.25
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        a = (x + y + 3.0 * z) / 5.0
        q *= 0.25
    dx = (a - x) / a
    dy = (a - y) / a
    dz = -(dx + dy) / 3.0
    xy = dx * dy
    zz = dz * dz
    e2 = xy - 6.0 * zz
    e3 = (3.0 * xy - 8.0 * zz) * dz
    e4 = 3.0 * (xy - zz) * zz
    e5 = xy * zz * dz
    series = (
        1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0
    )
    return 3.0 * total + power4 * series / (a * math.sqrt(a))


@jit
def rj(x, y, z, p):
    """Carlson's R_J(x, y, z, p) = 3/2 ∫₀^∞ dt / ((t+p)√((t+x)(t+y)(t+z))) for p > 0 (DLMF 19.16.2).

    x, y, z ≥ 0, at most one zero. Duplication (DLMF 19.26.20) with the duplication terms
    3 Σ 4^-k R_C(α_k, β_k), α_k = (p_k(√x_k+√y_k+√z_k) + √(x_k y_k z_k))², β_k = p_k(p_k+λ_k)²
    (Carlson 1995): α and β are sums of positive terms, so R_C stays well conditioned even for
    p ≪ x, y, z, where the equivalent R_C(1, 1 + δ/d²) form sits next to its log singularity.
    """
    a0 = (x + y + z + 2.0 * p) / 5.0
    q = RDJ_STOP * max(abs(a0 - x), abs(a0 - y), abs(a0 - z), abs(a0 - p))
    a = a0
    power4 = 1.0
    total = 0.0
    while q >= abs(a):
        sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
        lam = sx * sy + sx * sz + sy * sz
        alpha = p * (sx + sy + sz) + sx * sy * sz
        alpha *= alpha
        beta = p * (p + lam) * (p + lam)
        total += power4 * rc(alpha, beta)
        power4 *= 0.25
        x = 0.25 * (x + lam)
        y = 0.25 * (y + lam)
        z = 0.25 * (z + lam)
        p = 0.25 * (p + lam)
        a = (x + y + z + 2.0 * p) / 5.0
        q *= 0.25
    dx = (a - x) / a
    dy = (a - y) / a
    dz = (a - z) / a
    dp = -0.5 * (dx + dy + dz)
    pp = dp * dp
    e2 = dx * dy + dx * dz + dy * dz - 3.0 * pp
    xyz = dx * dy * dz
    e3 = xyz + 2.0 * e2 * dp + 4.0 * pp * dp
    e4 = (2.0 * xyz + e2 * dp + 3.0 * pp * dp) * dp
    e5 = xyz * pp
    series = (
        1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0
    )
    return 3.0 * total + power4 * series / (a * math.sqrt(a))


# --------------------------------------------------------------------------------------------------
# Per-parameter constants: K in double-double from the AGM (DLMF 19.8.5), split half period
# --------------------------------------------------------------------------------------------------


@jit
def _quarter_period_dd(mc_hi, mc_lo):
    """K as a double-double from K = π / (2 AGM(1, √mc)) (DLMF 19.8.5), 0 < mc ≤ 1.

    Every AGM step runs in double-double, so K is good to ~1e-30 relative; stopping once
    |a − b| < 1e-17 a leaves an AGM error below (a − b)²/a ≈ 1e-34.
    """
    ah, al = 1.0, 0.0
    bh, bl = _dd_sqrt(mc_hi, mc_lo)
    for _ in range(64):
        if abs(ah - bh) <= 1e-17 * ah:
            break
        sh, sl = _dd_add(ah, al, bh, bl)
        ph, pl = _dd_mul(ah, al, bh, bl)
        ah, al = 0.5 * sh, 0.5 * sl
        bh, bl = _dd_sqrt(ph, pl)
    # final mean: (a + b)/2
    sh, sl = _dd_add(ah, al, bh, bl)
    return _dd_div(PI_HI, PI_LO, sh, sl)  # π / (2 · (a+b)/2)


@jit
def parameter_constants(m, mc):
    """Constants of the parameter m needed by the ``*_k`` kernels (tuple of 10 floats).

    Layout (indices ``MK_*``): (m, mc, μ, μ_c, √μ_c, √m, K_hi, K_lo, head, tail).
    For m < 1: μ = m, μ_c = mc, K = K(m), and head + tail = 2K (the half period of sn, cn in u).
    For m > 1: μ = 1/m, μ_c = −mc/m (from the supplied mc, never 1 − 1/m; note §6.2), K = K(μ)
    (quarter period of the functions of v = √m u), head + tail = 2K(μ)/√m (half period in u).
    For m = 1 (mc == 0): K = head = ∞ and the kernels use closed forms (note §6.7).
    NaN m or mc gives all-NaN constants, so every kernel then returns NaN.
    head has 24 significant bits so ``j*head`` is exact for |j| < 2^29 (note §6.1).
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
            muc_hi, muc_lo = _two_sum(1.0, -m)
    elif mc < 0.0:
        mu = 1.0 / m
        # μ_c = −mc/m as a double-double: the exact remainder of the division comes from two_prod.
        muc_hi = -mc / m
        p, e = _two_prod(muc_hi, m)
        muc_lo = ((-mc - p) - e) / m
        sqrt_m = math.sqrt(m)
    else:
        inf = math.inf
        return (m, mc, m, mc, 0.0, 1.0, inf, 0.0, inf, 0.0)
    k_hi, k_lo = _quarter_period_dd(muc_hi, muc_lo)
    # half period in u: 2K(μ)/√m, in double-double (√m exact to a double-double too)
    if mc < 0.0:
        sm_hi, sm_lo = _dd_sqrt(m, 0.0)
        h_hi, h_lo = _dd_div(2.0 * k_hi, 2.0 * k_lo, sm_hi, sm_lo)
    else:
        h_hi, h_lo = 2.0 * k_hi, 2.0 * k_lo
    head, rest = _split(h_hi, SPLIT_24)
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


# --------------------------------------------------------------------------------------------------
# Jacobian elliptic functions
# --------------------------------------------------------------------------------------------------


@jit
def _sncndn_series(u, m):
    """Maclaurin series (DLMF 22.10.4–6, extended to u^11) for |u| ≤ SERIES_LIMIT, 0 ≤ m ≤ 1.

    Returns sn and the complements 1 − cn, 1 − dn, which keep full relative accuracy for small u.
    """
    u2 = u * u
    sn = u * (
        1.0
        + u2 * (-(1.0 + m) / 6.0
        + u2 * ((1.0 + m * (14.0 + m)) / 120.0
        + u2 * (-(1.0 + m * (135.0 + m * (135.0 + m))) / 5040.0
        + u2 * (1.0 + m * (1228.0 + m * (5478.0 + m * (1228.0 + m)))) / 362880.0)))
    )
    one_minus_cn = u2 * (
        0.5
        - u2 * ((1.0 + 4.0 * m) / 24.0
        - u2 * ((1.0 + m * (44.0 + 16.0 * m)) / 720.0
        - u2 * ((1.0 + m * (408.0 + m * (912.0 + 64.0 * m))) / 40320.0
        - u2 * (1.0 + m * (3688.0 + m * (30768.0 + m * (15808.0 + 256.0 * m)))) / 3628800.0)))
    )
    one_minus_dn = m * u2 * (
        0.5
        - u2 * ((4.0 + m) / 24.0
        - u2 * ((16.0 + m * (44.0 + m)) / 720.0
        - u2 * ((64.0 + m * (912.0 + m * (408.0 + m))) / 40320.0
        - u2 * (256.0 + m * (15808.0 + m * (30768.0 + m * (3688.0 + m)))) / 3628800.0)))
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
def reduce_by_period(u, head, tail):
    """j = rint(u / P), r = u − j P with P = head + tail; j*head exact, u − j*head exact (Sterbenz)."""
    j = np.rint(u / (head + tail))
    return j, (u - j * head) - j * tail


@jit
def sncndn_k(u, mk):
    """sn(u|m), cn(u|m), dn(u|m) with precomputed ``mk = parameter_constants(m, mc)``.

    m < 1: u = 2jK + r, |r| ≤ K, sn = (−1)^j sn r, cn = (−1)^j cn r, dn = dn r (DLMF 22.4.3).
    m > 1: reciprocal parameter (DLMF 22.17.2–4, note §6.2), v = √m·r with the reduction done in u.
    m = 1: sn = tanh u, cn = dn = sech u (DLMF 22.5.8, note §6.7).
    """
    mc = mk[MK_MC]
    if mc == 0.0:
        sech = 1.0 / math.cosh(u)
        return math.tanh(u), sech, sech
    j, r = reduce_by_period(u, mk[MK_HEAD], mk[MK_TAIL])
    sign = 1.0 - 2.0 * (abs(j) % 2.0)
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
    (note §6.1, pitfall 9). m > 1: bounded, am = atan2(sn, cn) with cn > 0 (note §6.2).
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
    return am_k(u, parameter_constants(m, mc))


# --------------------------------------------------------------------------------------------------
# Incomplete integrals F and Π
# --------------------------------------------------------------------------------------------------


@jit
def _reduce_angle(phi):
    """j = rint(φ/π), r = φ − jπ with π in three parts (Cody–Waite; note §6.1)."""
    j = np.rint(phi / PI_HI)
    return j, ((phi - j * PI_HEAD) - j * PI_MID) - j * PI_LO


@jit
def _carlson_f(s, c2, delta2):
    """F over the principal range: s R_F(c², Δ², 1) (DLMF 19.25.5)."""
    return s * rf(c2, delta2, 1.0)


@jit
def characteristic_constants(n, m, mc):
    """Constants of the characteristic n for Π(φ, n | m): (method, n, f, g, Π(n|m)).

    method (``METHOD_*``) picks the formula: n == m → R_D form; n = −f with f ≥ 1 → R_C form with
    g = m/f (note §6.4; never used at f = 0); otherwise the plain Carlson form. Π(n|m) is the
    complete integral for 0 ≤ m < 1 (used for the reduction φ = jπ + r), NaN for m ≥ 1 where no
    reduction happens (F, Π are only real on |φ| ≤ π/2 there).
    """
    f = -n
    g = 0.0
    if n == m:
        method = METHOD_EQUAL_TO_M
    elif f >= 1.0:
        method = METHOD_LARGE_NEGATIVE
        g = m / f
    else:
        method = METHOD_GENERAL
    complete = math.nan
    if mc > 0.0:
        k = rf(0.0, mc, 1.0)
        if method == METHOD_EQUAL_TO_M:
            complete = k + (m / 3.0) * rd(0.0, 1.0, mc)
        elif method == METHOD_LARGE_NEGATIVE:
            complete = (g / 3.0) * rj(0.0, mc, 1.0, 1.0 + g) + HALF_PI / math.sqrt(
                (1.0 + f) * (1.0 + g)
            )
        elif n == 0.0:
            complete = k
        else:
            complete = k + (n / 3.0) * rj(0.0, mc, 1.0, 1.0 - n)
    return (float(method), n, f, g, complete)


@jit
def pi_principal(s, c2, delta2, f_part, nk):
    """Π over a principal range from s, c², Δ² (Δ² = 1 − m s² = c² + mc s²).

    ``f_part`` is the F value already known to the caller (s R_F(c², Δ², 1) for φ, or r for pn,
    since F(am r) = r), or NaN to have it computed here; the R_C method does not need it.
    """
    method = nk[NK_METHOD]
    n = nk[NK_N]
    s2 = s * s
    if method == METHOD_LARGE_NEGATIVE:
        f = nk[NK_F]
        g = nk[NK_G]
        m_term = g * f  # ≈ m
        one_g = 1.0 + g * s2
        x = c2 * delta2
        # y − x = s²(1 + m + f + g) exactly, because f·g = m (note §6.4)
        y_minus_x = s2 * (1.0 + m_term + f + g)
        rc_term = _rc_from_difference(x, x + y_minus_x, y_minus_x)
        result = s * rc_term
        if g != 0.0:
            result += g * (s * s2 / 3.0) * rj(c2, delta2, 1.0, one_g)
        return result
    if f_part != f_part:
        f_part = _carlson_f(s, c2, delta2)
    if n == 0.0:
        return f_part
    if method == METHOD_EQUAL_TO_M:
        return f_part + (n / 3.0) * s * s2 * rd(c2, 1.0, delta2)
    if n > 0.0:
        p = c2 + (1.0 - n) * s2
    else:
        p = 1.0 - n * s2
    return f_part + (n / 3.0) * s * s2 * rj(c2, delta2, 1.0, p)


@jit
def ellipf_k(phi, mk):
    """Incomplete integral of the first kind F(φ|m) = ∫₀^φ dθ/√(1 − m sin²θ) (DLMF 19.2.4).

    m < 1: φ = jπ + r, F = 2jK + s R_F(c², c² + mc s², 1) (note §6.1, §6.3). m = 1: atanh(sin φ)
    via the same Carlson form for |φ| < π/2, ±inf beyond. m > 1: Carlson form unchanged where
    m sin²φ ≤ 1 and |φ| ≤ π/2 (note §6.2), NaN elsewhere.
    """
    mc = mk[MK_MC]
    if mc > 0.0:
        j, r = _reduce_angle(phi)
        s = math.sin(r)
        c = math.cos(r)
        f_r = _carlson_f(s, c * c, c * c + mc * s * s)
        return 2.0 * j * mk[MK_K_HI] + (2.0 * j * mk[MK_K_LO] + f_r)
    if abs(phi) > HALF_PI:
        return math.copysign(math.inf, phi) if mc == 0.0 else math.nan
    s = math.sin(phi)
    c = math.cos(phi)
    delta2 = c * c + mc * s * s
    if delta2 < 0.0:
        return math.nan
    return _carlson_f(s, c * c, delta2)


@jit
def ellippi_k(phi, mk, nk):
    """Π(φ, n | m) = ∫₀^φ dθ / ((1 − n sin²θ)√(1 − m sin²θ)) with precomputed constants.

    ``nk = characteristic_constants(n, m, mc)``. m < 1: φ = jπ + r, Π = 2jΠ(n|m) + Π(r) for
    n < 1. m = 1: |φ| < π/2 only (±inf beyond). m > 1: defined where m sin²φ ≤ 1, |φ| ≤ π/2
    (NaN elsewhere). n ≥ 1 other than n = m ≤ 1: only |φ| < π/2 with 1 − n sin²φ > 0 is returned.
    """
    mc = mk[MK_MC]
    n = nk[NK_N]
    if mc > 0.0 and n < 1.0:
        j, r = _reduce_angle(phi)
        s = math.sin(r)
        c = math.cos(r)
        c2 = c * c
        pi_r = pi_principal(s, c2, c2 + mc * s * s, math.nan, nk)
        return 2.0 * j * nk[NK_COMPLETE] + pi_r
    if abs(phi) > HALF_PI:
        return math.copysign(math.inf, phi) if mc == 0.0 else math.nan
    s = math.sin(phi)
    c = math.cos(phi)
    c2 = c * c
    delta2 = c2 + mc * s * s
    if delta2 < 0.0 or (n > 1.0 and n * s * s >= 1.0):
        return math.nan
    return pi_principal(s, c2, delta2, math.nan, nk)


@jit
def ellipf(phi, m, mc):
    """F(φ | m) (computes the constants; use ellipf_k in loops)."""
    return ellipf_k(phi, parameter_constants(m, mc))


@jit
def ellippi(n, phi, m, mc):
    """Π(φ, n | m) (computes the constants; use ellippi_k in loops)."""
    return ellippi_k(phi, parameter_constants(m, mc), characteristic_constants(n, m, mc))


# --------------------------------------------------------------------------------------------------
# pn(u, n | m) = ∫₀ᵘ du′ / (1 − n sn²(u′|m))  (paper eq. 9, secular for every m)
# --------------------------------------------------------------------------------------------------


@jit
def pn_constants(n, m, mc):
    """Characteristic constants for pn, in the layout of characteristic_constants.

    m ≤ 1: those of Π(·, n | m). m > 1: those of Π(·, n/m | 1/m) (note §6.2:
    pn(u, n|m) = pn(√m u, n/m | 1/m)/√m); n = m > 1 gives METHOD_DIVERGENT (NaN results).
    """
    if mc >= 0.0:
        return characteristic_constants(n, m, mc)
    if n == m:
        return (float(METHOD_DIVERGENT), 1.0, -1.0, 0.0, math.nan)
    mu = 1.0 / m
    muc = -mc / m
    return characteristic_constants(n / m, mu, muc)


@jit
def _pn_separatrix(u, n):
    """pn(u, n | 1) in closed form (integrate 1/(1 − n tanh²u); note §6.7 with atanh(tanh u) = u)."""
    if n == 1.0:
        return 0.5 * u + 0.25 * math.sinh(2.0 * u)  # ∫ cosh²
    if n <= 0.0:
        f = -n
        rf_ = math.sqrt(f)
        return (u + rf_ * math.atan(rf_ * math.tanh(u))) / (1.0 + f)
    rn = math.sqrt(n)
    return (u - rn * math.atanh(rn * math.tanh(u))) / (1.0 - n)


@jit
def pn_k(u, mk, pk):
    """pn(u, n | m) with ``mk = parameter_constants(m, mc)``, ``pk = pn_constants(n, m, mc)``.

    m < 1 (note §6.6): u = 2jK + r, pn = 2jΠ(n|m) + Π(am r, n|m), where Π(am r) comes from
    s, c, d = sn, cn, dn(r) with Δ² = d² and F(am r) = r (no trigonometric call).
    m > 1: the same at (√m r, n/m | 1/m), divided by √m (note §6.2). m = 1: closed forms.
    """
    mc = mk[MK_MC]
    method = pk[NK_METHOD]
    if method == METHOD_DIVERGENT:
        return math.nan
    if mc == 0.0:
        return _pn_separatrix(u, pk[NK_N])
    j, r = reduce_by_period(u, mk[MK_HEAD], mk[MK_TAIL])
    sqrt_m = mk[MK_SQRT_M]
    v = sqrt_m * r if mc < 0.0 else r
    s, c, d = sncndn_reduced(v, mk[MK_MU], mk[MK_MUC], mk[MK_SQRT_MUC], mk[MK_K_HI], mk[MK_K_LO])
    pi_r = pi_principal(s, c * c, d * d, v, pk)
    result = 2.0 * j * pk[NK_COMPLETE] + pi_r if j != 0.0 else pi_r
    if mc < 0.0:
        result /= sqrt_m
    return result


@jit
def pn(u, n, m, mc):
    """pn(u, n | m) (computes the constants; use pn_k in loops)."""
    return pn_k(u, parameter_constants(m, mc), pn_constants(n, m, mc))
