"""The torque-free motion of given periods: the inverse of :func:`.summary.periods`.

Tumblers are published by their periods P_ψ, P_φ (Pravec et al. 2005, Icarus 173, 108) and their moment
ratios. At fixed moments the ratio P_ψ/P_φ depends on the shape of the motion alone (d = 2T/G²), and
both periods scale as 1/G, so the shape is found from the ratio and G from P_ψ.

The shape is written as μ ∈ (0, 1), how far the motion is from the circulation axis towards the
separatrix (principal moments A ≤ B ≤ C, a = 1/A, b = 1/B, c = 1/C):

- SAM (circulation about C): μ = (d − c)/(b − c), the squared momentum fraction on B where the polhode
  crosses the B–C plane, M = G (0, √μ, √(1 − μ));
- LAM (circulation about A): μ = (a − d)/(a − b), M = G (√(1 − μ), √μ, 0) where it crosses the A–B plane.

μ keeps full relative accuracy for a small wobble (d − c is never formed as a difference of d and c).
All functions take and return plain floats: moments in any unit, the periods in any time unit, and G
in moment unit × rad per that time unit.
"""

import math

from spinorbit.core.free_motion.summary import MODE_SEPARATRIX, motion_summary
from spinorbit.core.elements.canonical import MODE_LAM, MODE_SAM, MODE_UNIFORM

#: μ is searched in logit space between these bounds: e^±36 is μ ≈ 2e-16 from either end, closer
#: than which the momentum direction itself is rounded to a principal axis or to the separatrix.
LOGIT_BOUND = 36.0
#: Bisection steps: the logit interval of width 72 halves to below one ulp of its values in < 60.
MAX_BISECTIONS = 200
#: Largest relative mismatch of the solved P_ψ/P_φ: resolvable shapes meet it to ~1e-14 (tests/test_spin_forms.py);
#: a ratio missed by more belongs to a motion within rounding of the separatrix (μ within ~1e-15 of 1,
#: where P_ψ grows only as log 1/(1 − μ)), which float64 cannot place.
RATIO_RTOL = 1e-10


def unit_momentum(mu, mode, big_a, big_b, big_c):
    """Principal-axis momentum (M_A, M_B, M_C) of |M| = 1 and shape ``mu`` (module docstring)."""
    if mode == MODE_SAM:
        return 0.0, math.sqrt(mu), math.sqrt(1.0 - mu)
    return math.sqrt(1.0 - mu), math.sqrt(mu), 0.0


def unit_periods(mu, mode, big_a, big_b, big_c):
    """(P_ψ, P_φ) of shape ``mu`` at G = 1, in 1 / (the rate unit of G = 1)."""
    m_a, m_b, m_c = unit_momentum(mu, mode, big_a, big_b, big_c)
    code, _, p_psi, p_phi, _ = motion_summary(m_a, m_b, m_c, big_a, big_b, big_c)
    if code in (MODE_UNIFORM, MODE_SEPARATRIX) or code != mode:
        return math.nan, math.nan
    return p_psi, p_phi


def period_ratio_range(mode, big_a, big_b, big_c):
    """(lowest, highest) P_ψ/P_φ that a motion of this mode can have (the ends of the μ search)."""
    return tuple(_ratio(_mu(t), mode, big_a, big_b, big_c) for t in (-LOGIT_BOUND, LOGIT_BOUND))


def _mu(t):
    """μ of logit t: μ/(1 − μ) = e^t, from the side that keeps its relative accuracy."""
    if t < 0.0:
        e = math.exp(t)
        return e / (1.0 + e)
    return 1.0 / (1.0 + math.exp(-t))


def _ratio(mu, mode, big_a, big_b, big_c):
    p_psi, p_phi = unit_periods(mu, mode, big_a, big_b, big_c)
    return p_psi / p_phi


def motion_of_periods(p_psi, p_phi, mode, big_a, big_b, big_c):
    """(μ, G) of the motion of this mode with periods (P_ψ, P_φ), Pravec et al. (2005) convention.

    Parameters
    ----------
    p_psi, p_phi : float
        Rotation and precession periods (one time unit, > 0, finite).
    mode : int
        ``MODE_SAM`` or ``MODE_LAM`` of :mod:`spinorbit.core.elements.canonical`.
    big_a, big_b, big_c : float
        Principal moments A < B < C.

    Returns
    -------
    mu : float
        The shape (module docstring).
    big_g : float
        |angular momentum| in moment unit × rad per time unit of the periods.

    Raises
    ------
    ValueError
        The ratio P_ψ/P_φ is outside :func:`period_ratio_range` (no motion of this mode has it) or
        within rounding of the separatrix (:data:`RATIO_RTOL`), or the body is axisymmetric (its P_ψ
        is not a polhode period of a triaxial motion).
    """
    if not (big_a < big_b < big_c):
        raise ValueError(f"a tumbling state of given periods needs a triaxial body A < B < C; got moments "
                         f"({big_a!r}, {big_b!r}, {big_c!r}).")
    target = p_psi / p_phi
    low, high = period_ratio_range(mode, big_a, big_b, big_c)
    if not low < target < high:
        name = "SAM" if mode == MODE_SAM else "LAM"
        raise ValueError(f"P_psi/P_phi = {target:.10g} is outside the range ({low:.10g}, {high:.6g}) that a {name} of "
                         f"moments A:B:C = {big_a:g}:{big_b:g}:{big_c:g} can have.")
    t_low, t_high = -LOGIT_BOUND, LOGIT_BOUND
    for _ in range(MAX_BISECTIONS):  # the ratio grows with μ in both modes (tests/test_spin_forms.py)
        t_mid = 0.5 * (t_low + t_high)
        if t_mid in (t_low, t_high):
            break
        if _ratio(_mu(t_mid), mode, big_a, big_b, big_c) < target:
            t_low = t_mid
        else:
            t_high = t_mid
    candidates = (_mu(t_low), _mu(t_high))
    mu = min(candidates, key=lambda m: abs(_ratio(m, mode, big_a, big_b, big_c) - target))
    achieved = _ratio(mu, mode, big_a, big_b, big_c)
    if not abs(achieved / target - 1.0) <= RATIO_RTOL:
        raise ValueError(f"P_psi/P_phi = {target:.10g} belongs to a motion within rounding of the separatrix (the nearest "
                         f"resolvable one has {achieved:.10g}): float64 cannot place it.")
    unit_p_psi, _ = unit_periods(mu, mode, big_a, big_b, big_c)
    return mu, unit_p_psi / p_psi


def nutation_sine_squared(mu, psi, i1, i2, i3, i_mid):
    """sin²θ of the motion of shape ``mu`` where its Euler angle ψ is ``psi`` (Landau–Lifshitz z-x-z).

    The body axes (x, y, z) carry moments (I1, I2, I3), z the circulation axis (the largest moment in
    SAM, the smallest in LAM), and the body momentum is G (sin θ sin ψ, sin θ cos ψ, cos θ); ``i_mid``
    is the intermediate moment B. From 2T = G² d:
    sin²θ = μ |1/B − 1/I3| / (sin²ψ |1/I1 − 1/I3| + cos²ψ |1/I2 − 1/I3|), each |1/I − 1/I3| formed as
    |I3 − I| / (I I3) (the common 1/I3 cancels). The polhode reaches every ψ, so this is ≤ μ < 1.
    """
    s, c = math.sin(psi), math.cos(psi)
    return mu * (abs(i3 - i_mid) / i_mid) / (s * s * abs(i3 - i1) / i1 + c * c * abs(i3 - i2) / i2)
