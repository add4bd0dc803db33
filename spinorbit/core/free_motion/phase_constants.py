"""The secular constants of one torque-free motion in double-double, for one state or eight at once.

From the exact double inputs (moments A ≤ B ≤ C, working-frame body momentum M) the set-up of the
flow (:mod:`.flow_constants`) needs the argument rate ν, the rate c G of g, κ, f = −n and p_c in
double-double (why: :mod:`.flow`). :func:`phase_constants_dd` forms them for one state;
:func:`phase_constants_lanes` for eight states of one body in one ``<8 x double>`` register
(:mod:`spinorbit.core.math.lanes`), each lane taking its own mode's formulas with the same
operations, so every lane is :func:`phase_constants_dd`'s result bit for bit.
"""

from spinorbit.core.elements.canonical import MODE_SAM, inertia_constants
from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.ddouble import (
    dd_add,
    dd_difference_ratio,
    dd_div,
    dd_mul,
    dd_sqrt,
    dd_sqrt_lanes,
    two_prod,
)
from spinorbit.core.math.lanes import select_tuple


@jit
def moment_constants(big_a, big_b, big_c):
    """The per-body part of the set-up: (:func:`.canonical.inertia_constants`, double-double
    (a − b, b − c, a − c, c) as an 8-tuple), formed once for states that share their moments."""
    abh, abl = dd_difference_ratio(big_a, big_b)
    bch, bcl = dd_difference_ratio(big_b, big_c)
    ach, acl = dd_difference_ratio(big_a, big_c)
    ch, cl = dd_div(1.0, 0.0, big_c, 0.0)
    return inertia_constants(big_a, big_b, big_c), (abh, abl, bch, bcl, ach, acl, ch, cl)


@jit(inline=INLINE)
def _dd_lin(ah, al, xh, xl, bh, bl, yh, yl):
    """a·x + b·y for double-doubles."""
    uh, ul = dd_mul(ah, al, xh, xl)
    vh, vl = dd_mul(bh, bl, yh, yl)
    return dd_add(uh, ul, vh, vl)


@jit
def phase_constants_dd(mode, mx, my, mz, inertia_dd):
    """Secular constants of a SAM/LAM motion as double-doubles from the exact double inputs.

    Parameters
    ----------
    mode : int
        MODE_SAM or MODE_LAM (from :func:`.canonical.motion_from_momentum`).
    mx, my, mz : float
        Body angular momentum (any flip: only squares enter).
    inertia_dd : tuple
        The double-double (a − b, b − c, a − c, c) of :func:`moment_constants`.

    Returns
    -------
    tuple of 11 floats
        (ν_hi, ν_lo, cG_hi, cG_lo, κ_hi, κ_lo, f_hi, f_lo, p_c,hi, p_c,lo, p): the argument rate ν
        (argument per time unit), the secular rate c G of g (rad per time unit), the pn coefficient
        κ (rad), f = −n and p_c = 1 − p as double-doubles (the inputs of :func:`complete_k_pi_dd`;
        p_c ≤ 0 at the separatrix), and the parameter p rounded once from its double-double value
        (for the double kernels: near the separatrix p_c from doubles would lose ε/p_c). The AGM is
        the caller's, so that work which does not need K can be issued before it.

    Notes
    -----
    With P_a = (a−b) M_y² + (a−c) M_z² = (a−d) G², Q = (a−c) M_x² + (b−c) M_y² = (d−c) G² and
    R = (b−c) M_z² − (a−b) M_x² = (b−d) G² (``canonical`` module docstring, eqs. 5, 7, 8):
    SAM ν² = P_a (b−c), p = (a−b) Q / (P_a (b−c)), p_c = (a−c) R / (P_a (b−c)), n = −(a−b)/(b−c);
    LAM ν² = Q (a−b), p = P_a (b−c) / ((a−b) Q), p_c = −(a−c) R / ((a−b) Q), n = −P_a / Q;
    κ = (a−c) G / ν in both modes.
    """
    quadratics = _momentum_quadratics(mx, my, mz, inertia_dd)
    g2h, g2l = quadratics[6], quadratics[7]
    gh, gl = dd_sqrt(g2h, g2l)
    terms = _sam_terms(quadratics, inertia_dd) if mode == MODE_SAM else _lam_terms(quadratics, inertia_dd)
    nuh, nul = dd_sqrt(terms[0], terms[1])
    return _phase_from_terms(terms, nuh, nul, gh, gl, inertia_dd)


@jit
def phase_constants_lanes(sam, mx, my, mz, inertia_dd):
    """:func:`phase_constants_dd` of eight states of one body (``Lanes``; ``sam``: the lanes in SAM)."""
    quadratics = _momentum_quadratics(mx, my, mz, inertia_dd)
    gh, gl = dd_sqrt_lanes(quadratics[6], quadratics[7])
    terms = select_tuple(sam, _sam_terms(quadratics, inertia_dd), _lam_terms(quadratics, inertia_dd))
    nuh, nul = dd_sqrt_lanes(terms[0], terms[1])
    return _phase_from_terms(terms, nuh, nul, gh, gl, inertia_dd)


@jit(inline=INLINE)
def _momentum_quadratics(mx, my, mz, inertia_dd):
    """(P_a, Q, R, G²) as double-doubles (the docstring of :func:`phase_constants_dd`), an 8-tuple."""
    abh, abl, bch, bcl, ach, acl, _ch, _cl = inertia_dd
    x2h, x2l = two_prod(mx, mx)
    y2h, y2l = two_prod(my, my)
    z2h, z2l = two_prod(mz, mz)
    pah, pal = _dd_lin(abh, abl, y2h, y2l, ach, acl, z2h, z2l)
    qh, ql = _dd_lin(ach, acl, x2h, x2l, bch, bcl, y2h, y2l)
    rh, rl = _dd_lin(bch, bcl, z2h, z2l, -abh, -abl, x2h, x2l)
    g2h, g2l = dd_add(x2h, x2l, y2h, y2l)
    g2h, g2l = dd_add(g2h, g2l, z2h, z2l)
    return pah, pal, qh, ql, rh, rl, g2h, g2l


@jit(inline=INLINE)
def _sam_terms(quadratics, inertia_dd):
    """SAM: (ν², ±(a−c) R, f, the numerator of p) as double-doubles, ν² also the denominator of p, p_c."""
    pah, pal, qh, ql, rh, rl, _g2h, _g2l = quadratics
    abh, abl, bch, bcl, ach, acl, _ch, _cl = inertia_dd
    denh, denl = dd_mul(pah, pal, bch, bcl)
    ah_, al_ = dd_mul(ach, acl, rh, rl)
    fh, fl = dd_div(abh, abl, bch, bcl)
    numh, numl = dd_mul(abh, abl, qh, ql)
    return denh, denl, ah_, al_, fh, fl, numh, numl


@jit(inline=INLINE)
def _lam_terms(quadratics, inertia_dd):
    """LAM: the same four as :func:`_sam_terms`."""
    pah, pal, qh, ql, rh, rl, _g2h, _g2l = quadratics
    abh, abl, bch, bcl, ach, acl, _ch, _cl = inertia_dd
    denh, denl = dd_mul(abh, abl, qh, ql)
    ah_, al_ = dd_mul(-ach, -acl, rh, rl)
    fh, fl = dd_div(pah, pal, qh, ql)
    numh, numl = dd_mul(pah, pal, bch, bcl)
    return denh, denl, ah_, al_, fh, fl, numh, numl


@jit(inline=INLINE)
def _phase_from_terms(terms, nuh, nul, gh, gl, inertia_dd):
    """The 11-tuple of :func:`phase_constants_dd` from a mode's terms, ν = √ν² and G."""
    denh, denl, ah_, al_, fh, fl, numh, numl = terms
    _abh, _abl, _bch, _bcl, ach, acl, ch, cl = inertia_dd
    pch, pcl = dd_div(ah_, al_, denh, denl)
    param = dd_div(numh, numl, denh, denl)[0]
    cgh, cgl = dd_mul(ch, cl, gh, gl)
    # κ = (a−c) G / ν
    kah, kal = dd_mul(ach, acl, gh, gl)
    kah, kal = dd_div(kah, kal, nuh, nul)
    return nuh, nul, cgh, cgl, kah, kal, fh, fl, pch, pcl, param
