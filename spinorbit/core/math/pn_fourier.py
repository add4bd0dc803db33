"""The periodic part of pn(u, n | m) for n ≤ 0, 0 ≤ m < 1 as a sine series in the nome.

For n = −f < 0 the integrand 1/(1 + f sn²u) is even with period 2K, so on the principal range

    pn(u) = (Π(n|m)/K) u + Σ_{k≥1} c_k sin(k θ),   θ = π u / K,

and Jacobi's form of Π (Π(u, a) = u Z(a) + ½ ln[Θ(u − a)/Θ(u + a)], n = m sn²a, DLMF 22.16.31 with
the product of Θ, DLMF 20.5.4 taken logarithmically) gives c_k ∝ q^k sinh(kπγ/K)/(k(1 − q^{2k})),
where q = e^{−πK'/K} is the nome and a = iγ. Written with β = K' − γ (the distance of the nearest
pole of the integrand, sn²(iβ) = −1/f, from the real axis, sc(β | 1 − m) = 1/√f):

    c_k = C (ρ^k − σ^k) / (k (1 − q^{2k})),   ρ = e^{−πβ/K},  σ = q²/ρ ≤ ρ,

and the constant C follows from pn'(0) = 1: (π/K) Σ k c_k = 1 − Π/K, which Jacobi's form gives in
closed form, C = √(f / ((1 + f)(f + m))) (checked with mpmath to 40 digits: then
1 − Π/K = (π/K) C Σ_k (ρ^k − σ^k)/(1 − q^{2k}); no Π, no sum over the terms, no cancellation as
f → 0, where C → 0 with the periodic part). β comes without a
trigonometric call: β = F(φ | 1 − m) with sin²φ = 1/(1 + f), i.e. s R_F(c², Δ², 1) with
c² = f/(1 + f), Δ² = (f + m)/(1 + f).

Why: per evaluation this is one sin/cos and a Clenshaw sum of a few terms instead of Carlson's R_J
(five duplication steps, each with an R_C). The series converges like ρ^k; it is used only where
ρ ≤ ``FOURIER_RHO_MAX`` (at most ``FOURIER_MAX_TERMS`` terms, tail below 1e-17 of the first term).
Near the separatrix (m → 1: K → ∞, ρ → 1) and for a strongly negative n (f ≫ 1: β → 0) the caller
keeps the Carlson path. Checked against mpmath on both sides of the rule in
``tests/test_torque_free.py``.
"""

import math

import numpy as np

from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.carlson import rf

# Tail of the series: N terms with ρ^N below this (the first omitted term over the first kept is
# ρ^N): the omitted terms are below ε/20 of the leading one.
FOURIER_TAIL = 1e-17
# At most this many terms; with the tail above this allows ρ up to FOURIER_RHO_MAX.
FOURIER_MAX_TERMS = 24
FOURIER_RHO_MAX = FOURIER_TAIL ** (1.0 / FOURIER_MAX_TERMS)  # ≈ 0.196
_RECIPROCALS = np.array([1.0 / k for k in range(1, FOURIER_MAX_TERMS + 1)])  # 1/k, no division per set-up


@jit
def pn_fourier_ratio(f, m, k_quarter):
    """ρ = e^{−πβ/K}, the convergence ratio of the series (see the module docstring).

    Parameters
    ----------
    f : float
        −n > 0 (dimensionless).
    m : float
        Parameter, 0 ≤ m < 1.
    k_quarter : float
        K(m), the quarter period.
    """
    prefactor, x, y, z, near = pole_integral(f, m)
    return _pole_ratios(prefactor * rf(x, y, z), near, k_quarter, nome(m, k_quarter))[0]


@jit
def pole_integral(f, m):
    """The distance of the pole as prefactor · R_F(x, y, z): (prefactor, x, y, z, near).

    f ≥ m (near False): β = s R_F(c², Δ², 1) (module docstring). f < m (near True): the pole is near
    the nome's (β → K' as f → 0), so γ = K' − β = F(arctan √(f/m) | 1 − m) = √f R_F(m, m(1 + f), f + m)
    instead. No K is needed, so callers can start this R_F before their AGM, or pair it with
    another one (:func:`.carlson.rf_pair`). Outside the series' domain (f ≤ 0, m ∉ [0, 1), NaN) the
    arguments (1, 1, 1) with prefactor 0: R_F(0, 0, 1) at f = m = 0 would never meet its stop.
    """
    if not (f > 0.0) or not (0.0 <= m < 1.0):
        return 0.0, 1.0, 1.0, 1.0, False
    if f >= m:
        s2 = 1.0 / (1.0 + f)
        return math.sqrt(s2), f * s2, (f + m) * s2, 1.0, False
    return math.sqrt(f), m, m * (1.0 + f), f + m, True


@jit
def _pole_ratios(distance, near, k_quarter, q):
    """(ρ, w, 1 − w) with w = σ/ρ = q²/ρ² ≤ 1, so that ρ^k − σ^k = ρ^k (1 − w^k) without cancellation.

    ``distance`` and ``near`` as :func:`pole_integral` gives them. β (not near): ρ = e^{−πβ/K} and
    w = (q/ρ)² ≤ 0.07, so 1 − w is exact enough. γ (near): ρ = q e^{x}, 1 − w = −expm1(−2x),
    x = πγ/K, and nothing cancels as f → 0 (the periodic part keeps its relative accuracy).
    """
    if not near:
        rho = math.exp(-math.pi * distance / k_quarter)
        ratio = q / rho
        w = ratio * ratio
        return rho, w, 1.0 - w
    x = math.pi * distance / k_quarter
    one_minus_w = -math.expm1(-2.0 * x)
    return q * math.exp(x), 1.0 - one_minus_w, one_minus_w


# Nome from the modulus (DLMF 20.9.4 inverted, q = Σ a_j λ^{4j+1}, OEIS A005797), where it converges fast:
# 11 terms leave < 1e-19 relative for λ ≤ NOME_LAMBDA_MAX (checked against mpmath.qfrom in
# tests/test_torque_free.py); the series path replaces an R_F and an exp (≈ 80 ns of the set-up).
_NOME_SERIES = (1.0, 2.0, 15.0, 150.0, 1707.0, 20910.0, 268616.0, 3567400.0, 48555069.0, 673458874.0,
                9481557398.0)
NOME_LAMBDA_MAX = 0.2


@jit
def nome(m, k_quarter):
    """The nome q = e^{−πK'/K} of the parameter 0 ≤ m < 1 (dimensionless), K = ``k_quarter``.

    λ = (1 − √k')/(2(1 + √k')) with k' = √(1 − m), written as m / (2 (1 + k') (1 + √k')²) so that
    it keeps its relative accuracy as m → 0; then q = λ (1 + 2λ⁴ + 15λ⁸ + …) for λ ≤
    NOME_LAMBDA_MAX, else e^{−πK'/K} with K' = R_F(0, m, 1).
    """
    if not m > 0.0:
        return 0.0
    kp = math.sqrt(1.0 - m)
    skp = 1.0 + math.sqrt(kp)
    lam = m / (2.0 * (1.0 + kp) * (skp * skp))
    if lam <= NOME_LAMBDA_MAX:
        l4 = (lam * lam) * (lam * lam)
        acc = _NOME_SERIES[10]
        for j in range(9, -1, -1):
            acc = acc * l4 + _NOME_SERIES[j]
        return lam * acc
    return math.exp(-math.pi * rf(0.0, m, 1.0) / k_quarter)  # K' = K(1 − m) = R_F(0, m, 1)


@jit
def pn_fourier_coefficients(f, m, k_quarter, scale, out):
    """Write scale · c_k, k = 1..N, into out[0:N] and return N (0 if the series is not used).

    Parameters
    ----------
    f : float
        −n > 0 (dimensionless).
    m : float
        Parameter, 0 ≤ m < 1.
    k_quarter : float
        K(m).
    scale : float
        Factor applied to every coefficient (κ of the flow, rad per unit of pn).
    out : ndarray
        At least FOURIER_MAX_TERMS slots.

    Returns
    -------
    int
        N, the number of terms written; 0 when ρ > FOURIER_RHO_MAX (use the Carlson form).
    """
    prefactor, x, y, z, near = pole_integral(f, m)  # outside the domain: prefactor 0, and `_at` returns 0
    return pn_fourier_coefficients_at(f, m, k_quarter, scale, prefactor * rf(x, y, z), near, out)


@jit(inline=INLINE)
def pn_fourier_coefficients_at(f, m, k_quarter, scale, distance, near, out):
    """:func:`pn_fourier_coefficients` from the pole's distance (``distance``, ``near``: :func:`pole_integral`).

    For the flow's set-up, which forms that R_F together with another one before its AGM.
    """
    if not (f > 0.0) or not (0.0 <= m < 1.0):
        return 0
    q = nome(m, k_quarter)
    rho, w, one_minus_w = _pole_ratios(distance, near, k_quarter, q)
    if not (0.0 < rho <= FOURIER_RHO_MAX):  # ρ underflows only for m < 1e-200 (K'/K > 237); NaN too
        return 0
    q2 = q * q
    norm = scale * math.sqrt(f / ((1.0 + f) * (f + m)))  # scale · C (module docstring)
    # N: the first with ρ^N ≤ FOURIER_TAIL, found by the loop that forms ρ^k anyway (no log, no
    # division; ρ ≤ FOURIER_RHO_MAX keeps N ≤ FOURIER_MAX_TERMS). ρ^k − σ^k = ρ^k (1 − w^k) with
    # 1 − w^{k+1} = (1 − w^k) + w^k (1 − w): positive terms only
    rho_k, q2_k = norm, 1.0  # C ρ^k: the scale rides along, no second pass
    t, w_k = one_minus_w, 1.0
    stop = FOURIER_TAIL * abs(norm)
    k = 0
    while q2_k > FOURIER_TAIL and k < FOURIER_MAX_TERMS:  # the few terms with 1/(1 − q^{2k}) ≠ 1
        rho_k *= rho
        q2_k *= q2
        out[k] = rho_k * t / ((1.0 - q2_k) * (k + 1.0))
        w_k *= w
        t += w_k * one_minus_w
        k += 1
        if abs(rho_k) <= stop:
            return k
    # 1/(1 − q^{2k}) is 1 to the last bit once q^{2k} < ε/10: no division in the rest
    for j in range(k, FOURIER_MAX_TERMS):
        rho_k *= rho
        out[j] = rho_k * t * _RECIPROCALS[j]
        w_k *= w
        t += w_k * one_minus_w
        if abs(rho_k) <= stop:
            return j + 1
    return FOURIER_MAX_TERMS


@jit(inline=INLINE)
def sine_series(theta, coefficients, offset, terms):
    """Σ_{k=1}^{terms} a_k sin(kθ), a_k = coefficients[offset + k − 1], by Clenshaw's recurrence.

    The odd and the even terms are summed as two independent recurrences in steps of 2θ
    (φ_{j+1} = 2 cos 2θ φ_j − φ_{j−1}), so the two dependent chains run side by side, each written
    as (a − b_{j+2}) + α b_{j+1} to keep one product and one sum on its critical path:
    odd part = (b_0 + b_1) sin θ (sin 3θ − α sin θ = sin θ), even part = b_0 sin 2θ. Both are sin θ times a polynomial in
    cos θ, so the sum keeps its relative accuracy near θ = 0 and θ = π.
    """
    s = math.sin(theta)
    c = math.cos(theta)
    alpha = 2.0 * ((c - s) * (c + s))  # 2 cos 2θ without the cancellation of 1 − 2 sin²θ
    odd1, odd2, even1, even2 = 0.0, 0.0, 0.0, 0.0
    top = terms - 1  # index of the last term (k = terms)
    if top % 2 == 1:  # the last term is even (k = terms even): start the even chain with it
        even1 = coefficients[offset + top]
        top -= 1
    # now coefficients[offset + top] is odd (k = top + 1 odd); pair (odd k, even k − 1)
    for index in range(top, 0, -2):
        odd1, odd2 = (coefficients[offset + index] - odd2) + alpha * odd1, odd1
        even1, even2 = (coefficients[offset + index - 1] - even2) + alpha * even1, even1
    odd1, odd2 = (coefficients[offset] - odd2) + alpha * odd1, odd1
    return (odd1 + odd2) * s + even1 * (2.0 * s * c)
