"""K(p) and Π(n | p) in double-double from one compensated AGM, for one input or eight at once.

The complete integrals of the torque-free flow's set-up (:mod:`spinorbit.core.free_motion.flow_constants`)
belong to the exact double inputs, so they are formed in double-double. The set-up of one state is
bound by this AGM's divisions and square roots; :func:`complete_k_pi_lanes` runs the same step
(:func:`_agm_step`) on eight states in one ``<8 x double>`` register (:mod:`.lanes`), each lane
stopping where the scalar loop stops, so every lane gives :func:`complete_k_pi_dd`'s result bit for bit.
"""

import math

from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.ddouble import fma, quick_two_sum, two_sum
from spinorbit.core.math.elliptic_periods import PI_HI, PI_LO
from spinorbit.core.math.lanes import all_lanes, any_lane, constant_like, select_tuple

# The compensated AGM for K and Π stops when the bound on what the rest of the Π series can still
# change is below this fraction of Π (the double-double unit roundoff is 2^-106 ≈ 1.2e-32) ...
AGM_TOLERANCE = 1e-33
# ... and the AGM gap (a − g)/a is below this: K = π/(a + g) then differs from π/(2 M) by
# (a − g)²/(16 a²) < 1e-33 relative. The compensated gap is only known to ≈ ε² (first-order
# corrections), so the stop cannot ask for AGM_TOLERANCE there.
AGM_GAP = 1e-16
# f = −n up to 1e30 needs ≈ 50 halvings of p_k before the quadratic phase; 200 is never reached.
AGM_MAX_STEPS = 200


@jit
def complete_k_pi_dd(f_hi, f_lo, mc_hi, mc_lo):
    """K(p) and Π(n | p) for n = −f ≤ 0, 0 ≤ p < 1, as double-doubles (DLMF 19.8.5, 19.8.6–8).

    Parameters
    ----------
    f_hi, f_lo : float
        f = −n ≥ 0 as a double-double (dimensionless; up to 1e30 checked).
    mc_hi, mc_lo : float
        Complementary parameter p_c = 1 − p > 0 as a double-double.

    Returns
    -------
    k_hi, k_lo, pi_hi, pi_lo : float
        K(p) = π / (2 M(1, √p_c)) and Π(n | p) = ∫₀^{π/2} dθ / ((1 − n sin²θ) √(1 − p sin²θ)).

    Notes
    -----
    DLMF 19.8.6 reads Π = K/2 · (2 + n/(1 − n) Σ_{k≥0} Q_k), with p_0² = 1 − n, Q_0 = 1,
    ε_k = (p_k² − a_k g_k)/(p_k² + a_k g_k), Q_{k+1} = Q_k ε_k / 2, p_{k+1} = (p_k² + a_k g_k)/(2 p_k).
    For n → −∞ the bracket cancels catastrophically (Σ Q → 2, Π → 0). Written with
    T = 1 − Σ_{k≥1} Q_k = Σ_{k≥1} 2^{-k} D_k, D_k = 1 − Π_{i<k} ε_i, the result is
    Π = K/2 · (2 + f T)/(1 + f), and D_{k+1} = D_k + δ_k (1 − D_k) with δ_k = 1 − ε_k = 2 a_k g_k /
    (p_k² + a_k g_k) sums positive terms only (ε_k ≥ 0 for n ≤ 0). Once ε_k = 0 all later D are 1,
    so the tail of T is the last weight 2^{-k}.

    Arithmetic: compensated, not double-double. Each quantity is a double x plus a double x' that
    carries its error to first order: the double AGM runs unchanged on the x's, and x' collects the
    exact rounding error of every operation (``two_prod`` by FMA, ``two_sum``, the residual of
    every quotient and root) plus the propagated x' of the operands, never renormalised. The
    neglected terms are products of two errors, ≈ ε² ≈ 5e-32 relative per step. The quotients'
    and roots' corrections multiply by a reciprocal instead of dividing again, and the x chain
    never waits for the x' chain, so one step costs about four roundings' worth of division and
    root instead of the double-double's eight (``benchmarks/bench_elliptic.py`` times both AGMs).
    Checked against mpmath (50 digits) for p_c from 1e-16 to 1 and f from 0 to 1e30
    (``tests/test_torque_free.py``, AGM_TOLERANCE there).

    The step is :func:`_agm_step`, which :func:`complete_k_pi_lanes` runs on eight inputs at once.
    """
    state, one_h, one_l = _agm_start(f_hi, f_lo, mc_hi, mc_lo)
    for _ in range(AGM_MAX_STEPS):
        state, done = _agm_step(state, f_hi)
        if done:
            break
    return _agm_result(state, f_hi, f_lo, one_h, one_l)


@jit
def complete_k_pi_lanes(f_hi, f_lo, mc_hi, mc_lo):
    """:func:`complete_k_pi_dd` of eight inputs (``Lanes``) at once, each lane's result bit for bit.

    A lane that has met its stop keeps its state (``select_tuple``) while the others step on; the
    loop ends when no lane is left.
    """
    state, one_h, one_l = _agm_start(f_hi, f_lo, mc_hi, mc_lo)
    active = all_lanes()
    for _ in range(AGM_MAX_STEPS):
        new, done = _agm_step(state, f_hi)
        state = select_tuple(active, new, state)
        active = active & ~done
        if not any_lane(active):
            break
    return _agm_result(state, f_hi, f_lo, one_h, one_l)


@jit(inline=INLINE)
def _agm_start(f_hi, f_lo, mc_hi, mc_lo):
    """The AGM's first state (a, a', g, g', p, p', Π ε, its ', D, D', T, T', weight), and 1 + f."""
    one = constant_like(mc_hi, 1.0)
    zero = constant_like(mc_hi, 0.0)
    g = math.sqrt(mc_hi)
    gl = (fma(-g, g, mc_hi) + mc_lo) * (0.5 / g)
    one_h, one_l = two_sum(one, f_hi)
    one_l = one_l + f_lo
    p = math.sqrt(one_h)
    pl = (fma(-p, p, one_h) + one_l) * (0.5 / p)
    # Π_{i<k} ε_i = 1 − D_k is kept as a product (no cancellation); D_k; the partial sum of T
    return (one, zero, g, gl, p, pl, one, zero, zero, zero, zero, zero, one), one_h, one_l


@jit(inline=INLINE)
def _agm_step(state, f_hi):
    """One step of the compensated AGM: (the next state, whether it meets the stop)."""
    a, al, g, gl, p, pl, prod, prodl, d, dl, t, tl, weight = state
    ag = a * g
    agl = fma(a, g, -ag) + (a * gl + al * g)
    p2 = p * p
    p2l = fma(p, p, -p2) + 2.0 * p * pl
    den, e1 = two_sum(p2, ag)
    denl = e1 + (p2l + agl)
    num, e2 = two_sum(p2, -ag)
    numl = e2 + (p2l - agl)
    inv = 1.0 / den
    eps_k = num * inv
    eps_l = (fma(-eps_k, den, num) + (numl - eps_k * denl)) * inv
    ag2 = 2.0 * ag
    dlt = ag2 * inv
    dlt_l = (fma(-dlt, den, ag2) + (2.0 * agl - dlt * denl)) * inv
    x = dlt * prod
    xl = fma(dlt, prod, -x) + (dlt * prodl + dlt_l * prod)
    d, e3 = two_sum(d, x)
    dl = dl + (e3 + xl)
    new_prod = prod * eps_k
    prodl = fma(prod, eps_k, -new_prod) + (prod * eps_l + prodl * eps_k)
    prod = new_prod
    weight = weight * 0.5
    t, e4 = two_sum(t, weight * d)
    tl = tl + (e4 + weight * dl)
    half_p = 0.5 / p
    new_p = den * half_p
    pl = (fma(-new_p, 2.0 * p, den) + (denl - new_p * 2.0 * pl)) * half_p
    p = new_p
    s, e5 = two_sum(a, g)
    a, al = 0.5 * s, 0.5 * (e5 + (al + gl))
    g = math.sqrt(ag)
    gl = (fma(-g, g, ag) + agl) * (0.5 / g)
    # The rest of T is taken as the last weight (all later D = 1), off by at most weight·(1 − D) =
    # weight·prod; in Π = K (2 + f T) / (2 (1 + f)) that is f·weight·prod of 2 + f T (t ≤ T). The
    # gap with its correction: the double chain alone may stay an ulp apart forever.
    done = ((f_hi * (abs(prod) * weight) <= AGM_TOLERANCE * (2.0 + f_hi * abs(t)))
            & (abs((a - g) + (al - gl)) <= AGM_GAP * a))
    return (a, al, g, gl, p, pl, prod, prodl, d, dl, t, tl, weight), done


@jit(inline=INLINE)
def _agm_result(state, f_hi, f_lo, one_h, one_l):
    """(K_hi, K_lo, Π_hi, Π_lo) from the AGM's last state: K = π / (a + g), Π = K (2 + f T) / (2 (1 + f))."""
    a, al, g, gl, _p, _pl, _prod, _prodl, _d, _dl, t, tl, weight = state
    t, e6 = two_sum(t, weight)  # the rest of T: all later D are 1
    tl = tl + e6
    s, e7 = two_sum(a, g)
    sl = e7 + (al + gl)
    # with the same first-order corrections as the steps
    k = PI_HI / s
    kl = (fma(-k, s, PI_HI) + (PI_LO - k * sl)) / s
    ft = f_hi * t
    ftl = fma(f_hi, t, -ft) + (f_hi * tl + f_lo * t)
    top, e8 = two_sum(2.0, ft)
    topl = e8 + ftl
    ratio = top / one_h
    ratio_l = (fma(-ratio, one_h, top) + (topl - ratio * one_l)) / one_h
    pi_k = 0.5 * k * ratio
    pi_l = fma(0.5 * k, ratio, -pi_k) + 0.5 * (k * ratio_l + kl * ratio)
    kh, kl = quick_two_sum(k, kl)
    pih, pil = quick_two_sum(pi_k, pi_l)
    return kh, kl, pih, pil
