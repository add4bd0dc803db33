"""Elliptic integrals F(φ|m), Π(φ, n|m) and Fukushima's pn(u, n|m), for every parameter m ≥ 0.

Numba scalar kernels (dimensionless), written in Carlson's symmetric integrals (:mod:`.carlson`).
The hot-loop forms take the constants of :func:`.elliptic_periods.parameter_constants` and of the
characteristic (``characteristic_constants`` for Π, ``pn_constants`` for pn: the ``NK_*`` layout);
φ is reduced by π and u by the half period, so the secular part is exact multiples of the complete
integrals. pn (paper eq. 9) is Π evaluated at the sn, cn, dn of the reduced argument, no
trigonometric call. Domain, NaN cases and formulas: ``docs/elliptic.md`` (DLMF 19.25, 22.5, 22.17).
"""

import math

from spinorbit.core.jit import jit
from spinorbit.core.math.carlson import rc_from_difference, rd, rf, rj
from spinorbit.core.math.elliptic_periods import (
    HALF_PI,
    MK_HEAD,
    MK_K_HI,
    MK_K_LO,
    MK_MC,
    MK_MU,
    MK_MUC,
    MK_SQRT_M,
    MK_SQRT_MUC,
    MK_TAIL,
    parameter_constants,
    reduce_by_period,
    reduce_by_pi,
)
from spinorbit.core.math.jacobi import sncndn_reduced

# Methods for the characteristic n (see characteristic_constants).
METHOD_GENERAL = 0  # Π = F + (n/3) s³ R_J(c², Δ², 1, p), n < 1 and not the cases below (DLMF 19.25.5, 19.25.14)
METHOD_LARGE_NEGATIVE = 1  # n = −f with f ≥ 1: R_C form (DLMF 19.7.8), no cancellation for f → ∞
METHOD_EQUAL_TO_M = 2  # n = m: R_J(c², Δ², 1, Δ²) = R_D(c², 1, Δ²), exact as m → 1 (DLMF 19.20.18)
METHOD_DIVERGENT = 3  # pn(u, m | m) for m > 1: 1/(1 − m sn²) is non-integrable; result NaN

# Indices into the characteristic-constants tuple (characteristic_constants, pn_constants).
NK_METHOD, NK_N, NK_F, NK_G, NK_COMPLETE = range(5)
NK_SIZE = 5


@jit
def _carlson_f(s, c2, delta2):
    """F over the principal range: s R_F(c², Δ², 1) (DLMF 19.25.5)."""
    return s * rf(c2, delta2, 1.0)


@jit
def characteristic_constants(n, m, mc):
    """Constants of the characteristic n for Π(φ, n | m): (method, n, f, g, Π(n|m)).

    method (``METHOD_*``) picks the formula: n == m → R_D form; n = −f with f ≥ 1 → R_C form with
    g = m/f (DLMF 19.7.8; never used at f = 0); otherwise the plain Carlson form. Π(n|m) is the
    complete integral for 0 ≤ m < 1 (used for the reduction φ = jπ + r), NaN for m ≥ 1 where no
    reduction happens (F, Π are only real on |φ| ≤ π/2 there).
    """
    method, f, g = _characteristic_method(n, m)
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
def _characteristic_method(n, m):
    """(METHOD_*, f = −n, g) for the characteristic n (see characteristic_constants)."""
    f = -n
    g = 0.0
    if n == m:
        method = METHOD_EQUAL_TO_M
    elif f >= 1.0:
        method = METHOD_LARGE_NEGATIVE
        g = m / f
    else:
        method = METHOD_GENERAL
    return method, f, g


@jit
def characteristic_constants_with_complete(n, m, complete):
    """:func:`characteristic_constants` for 0 ≤ m < 1 with Π(n|m) already known.

    For callers that hold Π from their own (compensated) AGM (the flow set-up,
    :func:`spinorbit.core.math.complete_agm.complete_k_pi_dd`), so the complete integral is
    not formed a second time in Carlson's form.
    """
    method, f, g = _characteristic_method(n, m)
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
        # y − x = s²(1 + m + f + g) exactly, because f·g = m (DLMF 19.7.8)
        y_minus_x = s2 * (1.0 + m_term + f + g)
        rc_term = rc_from_difference(x, x + y_minus_x, y_minus_x)
        result = s * rc_term
        if g != 0.0:
            # (g s²)(s/3), not g (s³/3): s³ underflows for m > 1e200, where s ≤ 1/√m and g s² ≤ m s² ≤ 1
            result += (g * s2) * (s / 3.0) * rj(c2, delta2, 1.0, one_g)
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

    m < 1: φ = jπ + r, F = 2jK + s R_F(c², c² + mc s², 1) (DLMF 19.2.10, 19.25.5). m = 1: atanh(sin φ)
    via the same Carlson form for |φ| < π/2, ±inf beyond. m > 1: Carlson form unchanged where
    m sin²φ ≤ 1 and |φ| ≤ π/2 (DLMF 22.17.2–4), NaN elsewhere.
    """
    mc = mk[MK_MC]
    if mc > 0.0:
        j, r = reduce_by_pi(phi)
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
        j, r = reduce_by_pi(phi)
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

    m ≤ 1: those of Π(·, n | m). m > 1: those of Π(·, n/m | 1/m) (DLMF 22.17.2–4:
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
    """pn(u, n | 1) in closed form (integrate 1/(1 − n tanh²u); DLMF 22.5.8 with atanh(tanh u) = u)."""
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

    m < 1 (docs/elliptic.md, Formulas): u = 2jK + r, pn = 2jΠ(n|m) + Π(am r, n|m), where Π(am r) comes from
    s, c, d = sn, cn, dn(r) with Δ² = d² and F(am r) = r (no trigonometric call).
    m > 1: the same at (√m r, n/m | 1/m), divided by √m (DLMF 22.17.2–4). m = 1: closed forms.
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


# The double AGM below stops once a − g ≤ this fraction of a (the next gap, ≈ (a − g)²/(8a), is then
# below 1e-31 of a) and the last Π term is below ε/2 of the sum.
AGM_GAP_DOUBLE = 1e-15
AGM_TERM_DOUBLE = 1.1e-16
# f = −n up to 1e30 needs ≈ 50 halvings of p_k before the quadratic phase; 200 is never reached.
AGM_MAX_STEPS_DOUBLE = 200


@jit
def complete_k_pi(f, mc):
    """K(m) and Π(n | m) for n = −f ≤ 0, 0 < mc = 1 − m ≤ 1, in double precision from one AGM.

    The algorithm of :func:`spinorbit.core.math.complete_agm.complete_k_pi_dd` (DLMF 19.8.5,
    19.8.6–8, written as sums of positive terms so nothing cancels for f → ∞), in doubles: for callers
    that need the two complete integrals as doubles (the periods of :mod:`spinorbit.core.free_motion.summary`),
    at a fraction of the double-double's cost and of Carlson's R_F and R_J. Relative error a few ε
    (``tests/test_torque_free.py`` checks it against mpmath).

    Parameters
    ----------
    f : float
        −n ≥ 0 (dimensionless).
    mc : float
        Complementary parameter 1 − m, 0 < mc ≤ 1.

    Returns
    -------
    k, pi : float
        K(m) and Π(n | m).
    """
    a = 1.0
    g = math.sqrt(mc)
    one_f = 1.0 + f
    p = math.sqrt(one_f)
    prod = 1.0  # Π_{i<k} ε_i = 1 − D_k
    d = 0.0  # D_k
    t = 0.0  # partial sum of T = Σ 2^-k D_k
    weight = 1.0
    for _ in range(AGM_MAX_STEPS_DOUBLE):
        ag = a * g
        p2 = p * p
        den = p2 + ag
        d += (2.0 * ag / den) * prod
        prod *= (p2 - ag) / den
        weight *= 0.5
        t += weight * d
        p = den / (2.0 * p)
        a, g = 0.5 * (a + g), math.sqrt(ag)
        if prod * weight <= AGM_TERM_DOUBLE * t and a - g <= AGM_GAP_DOUBLE * a:
            break
    t += weight
    k = math.pi / (a + g)
    return k, 0.5 * k * (2.0 + f * t) / one_f
