"""Carlson's symmetric elliptic integrals R_F, R_D, R_J and R_C, by duplication.

Numba scalar kernels (dimensionless) that every incomplete and complete integral of
:mod:`.elliptic_integrals` is written in (Carlson 1995, arXiv:math/9409227; DLMF 19.16, 19.36).
Each iterates the duplication theorem until Carlson's truncation bound puts the remaining Taylor
series below ε, then sums that series. Choices and pitfalls: ``docs/elliptic.md``.
"""

import math

from spinorbit.core.jit import jit
from spinorbit.core.math.lanes import any_lane, select

EPSILON = 2.0**-52
# Carlson (1995) stopping constants: iterate until 4^-n Q < |A_n| with Q = C·max|A0 − arg|, i.e.
# until the iterates' largest relative deviation from their mean is below 1/C (Carlson 1995's stopping rule; a
# wrong constant here fails silently). R_F sums its series to degree 7 (DLMF 19.36.1), whose
# truncation error is ∝ deviation⁸: C = (3ε)^(-1/8) stops one duplication (three square roots)
# earlier than the degree-5 series' (3ε)^(-1/6) ≈ 338, with a smaller worst truncation error
# (0.05 ε against 0.07 ε, mpmath over deviations at the bound; the whole R_F there within 2 ε:
# tests/test_special_integrals.py). R_D, R_J: degree 5, C = (ε/4)^(-1/6).
RF_STOP = (3.0 * EPSILON) ** (-1.0 / 8.0)  # ≈ 79
RDJ_STOP = (0.25 * EPSILON) ** (-1.0 / 6.0)  # ≈ 513, for R_D and R_J


@jit
def _duplicate(x, y, z):
    """One step of the duplication theorem (DLMF 19.26.18): (√x, √y, √z, λ, x′, y′, z′), w′ = (w + λ)/4."""
    sx, sy, sz = math.sqrt(x), math.sqrt(y), math.sqrt(z)
    lam = sx * sy + sx * sz + sy * sz
    return sx, sy, sz, lam, 0.25 * (x + lam), 0.25 * (y + lam), 0.25 * (z + lam)


@jit
def _rf_mean(x, y, z):
    """(x + y + z)/3, as a product with the rounded 1/3: one rounding more than the quotient, no
    division (R_F's loop forms it at every step; a divider is shared with the square roots)."""
    return (x + y + z) * (1.0 / 3.0)


@jit
def _rf_start(x, y, z):
    """(A₀, Q) of R_F's duplication: the mean and Carlson's stopping bound Q = C·max|A₀ − arg|."""
    a0 = _rf_mean(x, y, z)
    return a0, RF_STOP * max(abs(a0 - x), abs(a0 - y), abs(a0 - z))


@jit
def _rf_series(x, y, z, a):
    """R_F from the last iterates and their mean a: the Taylor series of degree 7 (DLMF 19.36.1).

    Divisions by constants as products with their reciprocals: the terms are below 1e-3, so the
    extra rounding is far below ε of the sum. The terms are summed smallest first.
    """
    inv = 1.0 / a
    dx = (a - x) * inv
    dy = (a - y) * inv
    dz = -(dx + dy)
    e2 = dx * dy - dz * dz
    e3 = dx * dy * dz
    e22 = e2 * e2
    high = (e22 * e3 * (1.0 / 16.0) + e3 * e3 * (3.0 / 104.0) - e22 * e2 * (5.0 / 208.0)
            - e2 * e3 * (3.0 / 44.0) + e22 * (1.0 / 24.0))
    return (1.0 + ((e3 * (1.0 / 14.0) - e2 * (1.0 / 10.0)) + high)) / math.sqrt(a)


@jit
def rf(x, y, z):
    """Carlson's R_F(x, y, z) = ½∫₀^∞ dt / √((t+x)(t+y)(t+z)) (DLMF 19.16.1).

    x, y, z ≥ 0, at most one zero. Duplication (DLMF 19.26.18) until the Taylor series of degree 7
    (DLMF 19.36.1) is accurate to ε; series variables from the current iterates.
    """
    a, q = _rf_start(x, y, z)
    while q >= abs(a):
        _, _, _, _, x, y, z = _duplicate(x, y, z)
        a = _rf_mean(x, y, z)
        q *= 0.25
    return _rf_series(x, y, z, a)


@jit
def rf_pair(x1, y1, z1, x2, y2, z2):
    """(R_F(x1, y1, z1), R_F(x2, y2, z2)), each bit for bit as :func:`rf` gives it.

    The two duplications run in one loop, each stepping only until its own stop, so their chains of
    square roots (the latency of R_F) overlap instead of following one another.
    """
    a1, q1 = _rf_start(x1, y1, z1)
    a2, q2 = _rf_start(x2, y2, z2)
    while q1 >= abs(a1) or q2 >= abs(a2):
        if q1 >= abs(a1):
            _, _, _, _, x1, y1, z1 = _duplicate(x1, y1, z1)
            a1 = _rf_mean(x1, y1, z1)
            q1 *= 0.25
        if q2 >= abs(a2):
            _, _, _, _, x2, y2, z2 = _duplicate(x2, y2, z2)
            a2 = _rf_mean(x2, y2, z2)
            q2 *= 0.25
    return _rf_series(x1, y1, z1, a1), _rf_series(x2, y2, z2, a2)


@jit
def rf_pair_lanes(x1, y1, z1, x2, y2, z2):
    """:func:`rf_pair` of eight argument pairs (``Lanes``, :mod:`.lanes`), each lane bit for bit :func:`rf`.

    Every lane duplicates until its own stop and then keeps its iterates (``select``) while the
    others go on.
    """
    a1, q1 = _rf_start(x1, y1, z1)
    a2, q2 = _rf_start(x2, y2, z2)
    go1, go2 = q1 >= abs(a1), q2 >= abs(a2)
    while any_lane(go1 | go2):
        _, _, _, _, nx1, ny1, nz1 = _duplicate(x1, y1, z1)
        x1, y1, z1 = select(go1, nx1, x1), select(go1, ny1, y1), select(go1, nz1, z1)
        a1, q1 = select(go1, _rf_mean(x1, y1, z1), a1), select(go1, q1 * 0.25, q1)
        _, _, _, _, nx2, ny2, nz2 = _duplicate(x2, y2, z2)
        x2, y2, z2 = select(go2, nx2, x2), select(go2, ny2, y2), select(go2, nz2, z2)
        a2, q2 = select(go2, _rf_mean(x2, y2, z2), a2), select(go2, q2 * 0.25, q2)
        go1, go2 = q1 >= abs(a1), q2 >= abs(a2)
    return _rf_series(x1, y1, z1, a1), _rf_series(x2, y2, z2, a2)


@jit
def rc_from_difference(x, y, y_minus_x):
    """R_C(x, y) for x ≥ 0, y > 0, with d = y − x supplied by the caller (DLMF 19.2.17–19).

    Exact when d is known without cancellation (DLMF 19.7.8: y − x = s²(1 + m + f + g)).
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
    return rc_from_difference(x, y, y - x)


@jit
def _rdj_series(e2, e3, e4, e5):
    """The degree-5 series shared by R_D and R_J (Carlson 1995 eq. (2.29) and DLMF 19.36.2)."""
    return (
        1.0 - 3.0 * e2 / 14.0 + e3 / 6.0 + 9.0 * e2 * e2 / 88.0 - 3.0 * e4 / 22.0
        - 9.0 * e2 * e3 / 52.0 + 3.0 * e5 / 26.0
    )


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
        _, _, sz, lam, x_next, y_next, z_next = _duplicate(x, y, z)
        total += power4 / (sz * (z + lam))
        power4 *= 0.25
        x, y, z = x_next, y_next, z_next
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
    return 3.0 * total + power4 * _rdj_series(e2, e3, e4, e5) / (a * math.sqrt(a))


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
        sx, sy, sz, lam, x, y, z = _duplicate(x, y, z)
        alpha = p * (sx + sy + sz) + sx * sy * sz
        alpha *= alpha
        beta = p * (p + lam) * (p + lam)
        total += power4 * rc(alpha, beta)
        power4 *= 0.25
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
    return 3.0 * total + power4 * _rdj_series(e2, e3, e4, e5) / (a * math.sqrt(a))
