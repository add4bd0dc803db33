"""The wobble amplitude of a state and its rotation class (PA / SAM / LAM), against independent constructions.

Two references that use none of spinorbit's kernels:

- **the motion itself**: Euler's equations dM/dt = M × I⁻¹M integrated with SciPy's DOP853 over more than a
  polhode period, the nutation angle of the circulation axis (cos θ = |M_z|/G in SAM, |M_x|/G in LAM)
  measured on the solution, its largest value located by event detection where dθ/dt = 0;
- **the Jacobi solution** (Landau & Lifshitz, *Mechanics* §37) in mpmath at 40 digits: M_z ∝ dn in SAM,
  M_x ∝ dn in LAM, so cos²θ_max = C(G² − 2TA)/((C − A) G²) · (1 − k²) in SAM with
  k² = (B − A)(2TC − G²)/((C − B)(G² − 2TA)), and A(2TC − G²)/((C − A) G²) · (1 − k²) in LAM with
  k² = (C − B)(G² − 2TA)/((B − A)(2TC − G²)).
"""

import math

import mpmath
import numpy as np
import pytest
from astropy import units as u
from scipy.integrate import solve_ivp

from spinorbit import RigidBody, RotationState
from spinorbit.quantities import QuantityInputError
from spinorbit.spin_forms import PA_MAX_WOBBLE, SpinFormError, rotation_classes

MOMENTS = (1.0, 1.2, 1.5)  # the asteroid
#: The integration's own error: DOP853 at rtol = atol = 1e-13 on |M| = 1 keeps G and T to ~1e-13, and an
#: angle read off the solution is good to about that over sin θ (the event's location error is second order
#: at an extremum). Measured: ≤ 3.9e-12 rad on the cases below (the largest 1e-8 from the separatrix, where cos θ_max → 0).
ODE_ATOL = 2e-11
#: mpmath at 40 digits against the double formula: a few ulps of θ (relative), as the cosine side is formed
#: without cancelling 1 − sin²; near the separatrix the inputs' own rounding (ε relative in M) moves the true
#: cos θ_max by ε Mz²/(cos θ_max G²), which the absolute bar covers (measured 7.6e-14 rad at cos θ_max = 2.2e-4).
MP_RTOL = 1e-14
MP_ATOL_NEAR_SEPARATRIX = 1e-10


def _state(moments, momentum):
    body = RigidBody(list(moments))
    return RotationState(body, [1.0, 0.0, 0.0, 0.0], (np.asarray(momentum, dtype=float) / np.asarray(moments)) * u.rad / u.day)


def _momentum_at_energy_ratio(moments, ratio, y_share=0.3):
    """Unit body momentum of E/E0 = ratio with a share of the energy excess on the intermediate axis."""
    big_a, big_b, big_c = moments
    # E/E0 = C Σ M_i²/I_i with ΣM_i² = 1: solve for M_x² given M_y²
    my2 = y_share * (ratio - 1.0) / (big_c / big_b - 1.0) if ratio < big_c / big_b else y_share
    mx2 = (ratio - 1.0 - my2 * (big_c / big_b - 1.0)) / (big_c / big_a - 1.0)
    return np.array([math.sqrt(mx2), math.sqrt(my2), math.sqrt(1.0 - mx2 - my2)])


def _measured_amplitude(moments, momentum, mode, span):
    """Largest nutation angle of the circulation axis over ``span`` of Euler's equations (SciPy)."""
    inverse = 1.0 / np.asarray(moments)
    axis = 2 if mode == "SAM" else 0

    def euler(_, m):
        return np.cross(m, inverse * m)

    def turning(_, m):  # d|M_axis|²/dt = 0: an extremum of θ
        return m[axis] * euler(0, m)[axis]

    solution = solve_ivp(euler, (0.0, span), momentum, method="DOP853", rtol=1e-13, atol=1e-13, events=turning,
                         dense_output=True)
    assert solution.status == 0 and len(solution.t_events[0]) >= 4
    extremes = solution.y_events[0]
    angles = np.arctan2(np.hypot(*np.delete(extremes, axis, axis=1).T), np.abs(extremes[:, axis]))
    samples = solution.sol(np.linspace(0.0, span, 20001))
    sampled = np.arctan2(np.hypot(*np.delete(samples, axis, axis=0)), np.abs(samples[axis]))
    return float(angles.max()), float(sampled.max())


def _jacobi_amplitude(moments, momentum, mode):
    """θ_max from the Jacobi solution's amplitude and modulus, mpmath at 40 digits."""
    with mpmath.workdps(40):
        big_a, big_b, big_c = (mpmath.mpf(x) for x in moments)
        mx, my, mz = (mpmath.mpf(float(x)) for x in momentum)
        g2 = mx * mx + my * my + mz * mz
        t2 = mx * mx / big_a + my * my / big_b + mz * mz / big_c
        if mode == "SAM":
            k2 = (big_b - big_a) * (t2 * big_c - g2) / ((big_c - big_b) * (g2 - t2 * big_a))
            cos2 = big_c * (g2 - t2 * big_a) / ((big_c - big_a) * g2) * (1 - k2)
        else:
            k2 = (big_c - big_b) * (g2 - t2 * big_a) / ((big_b - big_a) * (t2 * big_c - g2))
            cos2 = big_a * (t2 * big_c - g2) / ((big_c - big_a) * g2) * (1 - k2)
        return float(mpmath.acos(mpmath.sqrt(cos2)))


CASES = {
    "SAM, small wobble": (MOMENTS, _momentum_at_energy_ratio(MOMENTS, 1.0 + 1e-4), "SAM"),
    "SAM, Apophis-like": ((0.61, 0.965, 1.0), _momentum_at_energy_ratio((0.61, 0.965, 1.0), 1.024), "SAM"),
    "SAM, 1e-8 from the separatrix": (MOMENTS, _momentum_at_energy_ratio(MOMENTS, 1.25 * (1 - 1e-8)), "SAM"),
    "LAM, Toutatis-like": ((1.0, 3.0836, 3.235), np.array([0.93, 0.3, math.sqrt(1 - 0.93 ** 2 - 0.09)]), "LAM"),
    "LAM, 1e-8 from the separatrix": (MOMENTS, _momentum_at_energy_ratio(MOMENTS, 1.25 * (1 + 1e-8)), "LAM"),
}


@pytest.mark.parametrize("name", CASES)
def test_wobble_amplitude_is_the_largest_nutation_angle_of_the_motion(name):
    moments, momentum, mode = CASES[name]
    state = _state(moments, momentum)
    assert state.mode == mode
    amplitude = state.wobble_amplitude.to_value(u.rad)
    # 2.5 polhode periods (θ has two maxima per period): the state's P_ψ only sets how long to integrate
    span = 2.5 * state.periods[0].to_value(u.day)
    at_extremes, sampled = _measured_amplitude(moments, momentum, mode, span)
    assert abs(amplitude - at_extremes) < ODE_ATOL, (amplitude, at_extremes)
    assert sampled <= amplitude + ODE_ATOL  # no angle on the path exceeds it
    jacobi = _jacobi_amplitude(moments, momentum, mode)
    bar = MP_ATOL_NEAR_SEPARATRIX if "separatrix" in name else MP_RTOL * jacobi
    assert abs(amplitude - jacobi) <= bar, (amplitude, jacobi)


@pytest.mark.parametrize("tilt", [1e-9, 1e-5, 0.01, 0.3])
def test_small_wobbles_keep_their_relative_accuracy(tilt):
    """θ_max ∝ the tilt for small wobbles: the formula never forms 1 − cos² (mpmath at 40 digits)."""
    momentum = np.array([math.sin(tilt) * 0.6, math.sin(tilt) * 0.8, math.cos(tilt)])
    amplitude = _state(MOMENTS, momentum).wobble_amplitude.to_value(u.rad)
    jacobi = _jacobi_amplitude(MOMENTS, momentum, "SAM")
    assert abs(amplitude / jacobi - 1) < MP_RTOL


@pytest.mark.parametrize("moments, axis", [((1.0, 1.0, 2.0), 2), ((1.0, 2.0, 2.0), 0)])
def test_axisymmetric_bodies_nod_by_a_constant_angle(moments, axis):
    """Regular precession: the symmetry axis keeps its angle to L, so the amplitude is the angle now."""
    momentum = np.array([0.3, 0.4, 0.5])
    others = np.delete(momentum, axis)
    expected = math.atan2(math.hypot(*others), abs(momentum[axis]))
    assert _state(moments, momentum).wobble_amplitude.to_value(u.rad) == pytest.approx(expected, rel=4e-16)


def test_rotation_class_default_threshold_and_override():
    tilt = math.radians(0.5)  # θ_max = 0.5° · √(B(C − A)/(A(C − B))) ≈ 0.707° along x only: under 1°
    state = _state(MOMENTS, [math.sin(tilt), 0.0, math.cos(tilt)])
    assert state.wobble_amplitude.to_value(u.deg) == pytest.approx(0.5 * math.sqrt(1.2 * 0.5 / 0.3), rel=1e-4)
    assert state.rotation_class() == "PA" and PA_MAX_WOBBLE == 1 * u.deg
    assert state.rotation_class(threshold=0.5 * u.deg) == "SAM"
    assert state.rotation_class(threshold=30 * u.arcmin) == "SAM"
    assert state.rotation_class(threshold=1 * u.rad) == "PA"
    lam = _state(MOMENTS, [math.cos(tilt), math.sin(tilt), 0.0])  # about A: a long-axis rotator without wobble
    assert lam.mode == "LAM" and lam.rotation_class() == "PA" and lam.rotation_class(0.1 * u.deg) == "LAM"
    assert _state(MOMENTS, [0, 0, 1]).rotation_class(0 * u.deg) == "PA"  # permanent rotation: amplitude 0


def test_separatrix_is_ninety_degrees_and_never_pa():
    # moments (3, 4, 6), momentum (1, 0, 1): 2TB = G² exactly (B/A − 1 = 1 − B/C = 1/3), the separatrix itself
    state = _state((3.0, 4.0, 6.0), [1.0, 0.0, 1.0])
    assert state.mode == "separatrix" and state.wobble_amplitude.to_value(u.deg) == 90.0
    assert state.rotation_class(threshold=89.9 * u.deg) == "separatrix"
    near = _state(*CASES["SAM, 1e-8 from the separatrix"][:2])  # 0.013° short of 90°
    assert near.rotation_class(threshold=89.9 * u.deg) == "SAM"


@pytest.mark.parametrize("threshold, error", [(90 * u.deg, SpinFormError), (-1 * u.deg, SpinFormError),
                                              (1.0, QuantityInputError), (1 * u.s, QuantityInputError)])
def test_threshold_outside_its_range_or_without_unit_is_refused(threshold, error):
    state = _state(MOMENTS, [0.1, 0.1, 1.0])
    with pytest.raises(error, match="threshold"):
        state.rotation_class(threshold=threshold)


def test_rotation_classes_of_many_rows():
    classes = rotation_classes(np.array([0.0, 0.5, 3.0, 3.0, 90.0]),
                               np.array(["permanent rotation", "SAM", "SAM", "LAM", "separatrix"]))
    assert classes.tolist() == ["PA", "PA", "SAM", "LAM", "separatrix"]
    with pytest.raises(SpinFormError, match="do not belong"):
        rotation_classes(np.array([5.0]), np.array(["permanent rotation"]))


def test_pole_refuses_a_state_whose_axis_is_near_the_momentum_only_now():
    """At θ's smallest value the C axis is 0.9° from L, but the motion nods to 1.27°: it tumbles, as its class says."""
    tilt = math.radians(0.9)
    state = _state(MOMENTS, [math.sin(tilt), 0.0, math.cos(tilt)])
    assert state.rotation_class() == "SAM" and state.wobble_amplitude.to_value(u.deg) > 1.2
    with pytest.raises(SpinFormError, match="wobble amplitude is 1.27"):
        state.pole()
    assert state.pole(max_wobble=1.3 * u.deg).wobble.to_value(u.deg) == pytest.approx(0.9, rel=1e-12)
