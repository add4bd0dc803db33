"""P_ψ, P_φ and the sidereal period in every mode, against an independent mpmath reference.

The reference integrates the Andoyer rates over one polhode period by quadrature (mpmath, 30 digits):
in SAM with the C axis as reference (l circulates), in LAM with the A axis as reference, so the LAM
values do not rest on the kernels' "one turn less" relation between the two. With
f(l) = a sin²l + b cos²l (C reference) the energy gives L² = G² (f − d)/(f − c), and
l̇ = L (c − f), ġ = G f; with the A reference f'(l') = b sin²l' + c cos²l', L'² = G² (d − f')/(a − f'),
l̇' = L' (a − f'), ġ' = G f'. Then P_ψ = ∮ dl/|l̇|, ⟨ġ⟩ = ∮ ġ dl/|l̇| / P_ψ, and (docs/conventions.md,
"Periods") SAM: P_φ = 2π/⟨ġ⟩, P_sid = 2π/(⟨ġ⟩ − 2π/P_ψ); LAM: P_φ = 2π/⟨ġ'⟩, P_sid = 2π/(⟨ġ'⟩ + 2π/P_ψ).
"""

import math

import mpmath
import numpy as np
import pytest
from astropy import units as u

from spinorbit import RigidBody, RotationState

mpmath.mp.dps = 30

#: Moments A < B < C of the bodies used (ratios): generic, Apophis-like (Pravec et al. 2014), Toutatis-like.
BODIES = [(1.0, 2.0, 3.0), (0.61, 0.965, 1.0), (1.0, 3.0836, 3.235)]
#: 8 h, the short-axis rotator of issue 15, in rad/day.
SPIN = 2 * math.pi / (8 / 24)
#: The kernels work in double precision: K(m), Π(n|m) and the rates to a few ulps each, and 1 − m is
#: formed from inertia differences; 1e-12 relative leaves room for that and nothing else.
RTOL = 1e-12


def reference_periods(moments, omega):
    """(P_ψ, P_φ, P_sid) in days by mpmath quadrature of the Andoyer rates (module docstring)."""
    big_a, big_b, big_c = (mpmath.mpf(m) for m in moments)
    a, b, c = 1 / big_a, 1 / big_b, 1 / big_c
    m = [mpmath.mpf(x) for x in omega]
    momentum = [big_a * m[0], big_b * m[1], big_c * m[2]]
    g2 = sum(x * x for x in momentum)
    big_g = mpmath.sqrt(g2)
    d = (a * momentum[0] ** 2 + b * momentum[1] ** 2 + c * momentum[2] ** 2) / g2
    sam = d < b
    if sam:
        def f(l):
            return a * mpmath.sin(l) ** 2 + b * mpmath.cos(l) ** 2

        def rate(l):  # |l̇|
            return mpmath.sqrt(g2 * (f(l) - d) / (f(l) - c)) * (f(l) - c)
    else:
        def f(l):
            return b * mpmath.sin(l) ** 2 + c * mpmath.cos(l) ** 2

        def rate(l):
            return mpmath.sqrt(g2 * (d - f(l)) / (a - f(l))) * (a - f(l))
    nodes = [k * mpmath.pi / 2 for k in range(5)]
    p_psi = mpmath.quad(lambda l: 1 / rate(l), nodes)
    mean_g = mpmath.quad(lambda l: big_g * f(l) / rate(l), nodes) / p_psi
    two_pi = 2 * mpmath.pi
    p_sid = two_pi / (mean_g - two_pi / p_psi) if sam else two_pi / (mean_g + two_pi / p_psi)
    return float(p_psi), float(two_pi / mean_g), float(p_sid)


def state(moments, omega):
    return RotationState(RigidBody(list(moments)), [1.0, 0.0, 0.0, 0.0], np.asarray(omega, dtype=float) * u.rad / u.day)


def computed(s):
    p_psi, p_phi = s.periods
    return p_psi.to_value(u.day), p_phi.to_value(u.day), s.sidereal_period.to_value(u.day)


@pytest.mark.parametrize("moments", BODIES)
@pytest.mark.parametrize("axis", [0, 1, 2])
def test_permanent_rotation_about_each_axis(moments, axis):
    omega = np.zeros(3)
    omega[axis] = -SPIN if axis == 1 else SPIN
    s = state(moments, omega)
    p_psi, p_phi, p_sid = computed(s)
    assert s.mode == "permanent rotation"
    assert p_psi == math.inf
    # 2π/|ω| of an exactly given |ω|: one division, so within an ulp or two
    assert p_phi == pytest.approx(8 / 24, rel=4e-16) and p_sid == pytest.approx(8 / 24, rel=4e-16)


def test_issue_15_short_axis_rotator_reports_its_8_h():
    # the case of the issue: a principal-axis rotator about its short axis (C), 8 h, Apophis-like body
    s = state(BODIES[1], [0.0, 0.0, SPIN])
    assert s.periods[1].to_value(u.h) == pytest.approx(8.0, rel=1e-15)
    assert s.periods[0] == math.inf * u.day and s.sidereal_period.to_value(u.h) == pytest.approx(8.0, rel=1e-15)


@pytest.mark.validation
@pytest.mark.parametrize("moments", BODIES)
@pytest.mark.parametrize("omega_over_spin", [(0.3, 0.2, 1.0), (0.05, 0.0, 1.0), (1.0, 0.4, 0.2), (1.0, 0.0, 0.05),
                                             (1e-4, 3e-5, 1.0), (1.0, 1e-4, 2e-5)])
def test_tumbling_periods_against_mpmath(moments, omega_over_spin):
    omega = SPIN * np.asarray(omega_over_spin)
    expected = reference_periods(moments, omega)
    assert computed(state(moments, omega)) == pytest.approx(expected, rel=RTOL)


@pytest.mark.validation
@pytest.mark.parametrize("moments", BODIES)
@pytest.mark.parametrize("axis", ["C", "A"])
def test_periods_approach_the_axis_continuously(moments, axis):
    """Off the axis by ε: P_sid → 2π/|ω| (continuous), P_ψ, P_φ → the small-wobble limits (not ∞, 2π/|ω|)."""
    big_a, big_b, big_c = moments
    a, b, c = 1 / big_a, 1 / big_b, 1 / big_c
    errors = []
    for eps in (1e-2, 1e-3, 1e-4, 1e-5):
        omega = SPIN * (np.array([eps, 0.5 * eps, 1.0]) if axis == "C" else np.array([1.0, 0.5 * eps, eps]))
        s = state(moments, omega)
        p_psi, p_phi, p_sid = computed(s)
        assert (p_psi, p_phi, p_sid) == pytest.approx(reference_periods(moments, omega), rel=RTOL)
        big_g = float(np.linalg.norm(np.array(moments) * omega))
        if axis == "C":  # linearised Euler equations about C: ν₀ = G √((a−c)(b−c)), ⟨ġ⟩ → |ω| + ν₀
            nu0, spin = big_g * math.sqrt((a - c) * (b - c)), big_g * c
            limits = (2 * math.pi / nu0, 2 * math.pi / (spin + nu0), 2 * math.pi / spin)
        else:  # about A: ν₀ = G √((a−b)(a−c)), ⟨ġ'⟩ → |ω| − ν₀
            nu0, spin = big_g * math.sqrt((a - b) * (a - c)), big_g * a
            limits = (2 * math.pi / nu0, 2 * math.pi / (spin - nu0), 2 * math.pi / spin)
        errors.append(np.abs(np.array([p_psi, p_phi, p_sid]) / np.array(limits) - 1))
    errors = np.array(errors)
    # the departures from the limits are O(ε²): each decade closer shrinks them ~100× (the first
    # terms of the expansion; 30..300 allows for the next ones at ε = 1e-2 and rounding at 1e-5)
    ratios = errors[:-1] / np.maximum(errors[1:], 1e-16)
    assert np.all(errors[-1] < 1e-9), errors
    assert np.all((ratios[:2] > 30) & (ratios[:2] < 300)), ratios
    on_axis = state(moments, [0, 0, SPIN] if axis == "C" else [SPIN, 0, 0])
    assert on_axis.sidereal_period.to_value(u.day) == pytest.approx(computed(s)[2], rel=1e-9)


def test_sidereal_period_is_continuous_across_the_separatrix():
    moments = BODIES[0]
    big_b = moments[1]
    values = []
    for side in (+1, -1):  # d just below (SAM) and just above (LAM) b
        eps = 1e-9
        omega = SPIN * np.array([eps * (side < 0) + 1e-12, 1.0, eps * (side > 0) + 1e-12])
        s = state(moments, omega)
        assert s.mode == ("SAM" if side > 0 else "LAM")
        values.append(s.sidereal_period.to_value(u.day))
    # both sides tend to 2π B/G like 1/log(1/ε) (the polhode period grows like log): at ε = 1e-9 within 5 %
    limit = 2 * math.pi * big_b / (big_b * SPIN)
    assert values == pytest.approx([limit, limit], rel=0.05)
