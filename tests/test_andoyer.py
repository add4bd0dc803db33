"""Andoyer variables: the conventions of docs/conventions.md, and round trips through the attitude."""

import math

import numpy as np
from hypothesis import given
from hypothesis import strategies as st

from spinorbit.core.elements import andoyer
from spinorbit.core.math import rotations as rot

ROUNDING = 1e-14  # a few ulp of quantities of order 1
EPS = np.finfo(float).eps


def transverse_momentum_bound(momentum):
    """Error bound for the momentum rebuilt from (L, G) near J = 0 (momentum along body C).

    The transverse part √(G² − L²) comes from G − L, which carries an absolute rounding error ~ε G;
    through the square root that is ~ε G²/|M⊥|, capped at ~√(2ε) G when |M⊥| ≲ √ε G. This is the
    Andoyer J = 0 singularity showing through, not a defect of the code.
    """
    big_g = np.linalg.norm(momentum)
    transverse = math.hypot(momentum[0], momentum[1])
    return 8 * ROUNDING * big_g + min(4 * EPS * big_g**2 / max(transverse, 1e-300), 2 * math.sqrt(EPS) * big_g)

unit_quaternions = st.lists(st.floats(-1, 1), min_size=4, max_size=4).filter(
    lambda v: np.linalg.norm(v) > 0.1
).map(lambda v: np.array(v) / np.linalg.norm(v))
momenta = st.lists(st.floats(-3, 3), min_size=3, max_size=3).filter(
    lambda v: np.linalg.norm(v) > 0.05
).map(np.array)


def singular_set_bound(sin_angle):
    """Error from a sine rebuilt as √((G − X)(G + X))/G near the Andoyer singular sets (I or J → 0)."""
    return min(4 * EPS / max(sin_angle, 1e-300), 2 * math.sqrt(EPS))


def attitude_bound(attitude, momentum):
    """Attitude round-trip bound: rounding, plus the J = 0 and I = 0 conditioning (sin J, sin I)."""
    big_g = np.linalg.norm(momentum)
    inertial = attitude.T @ momentum
    sin_j = math.hypot(momentum[0], momentum[1]) / big_g
    sin_i = math.hypot(inertial[0], inertial[1]) / big_g
    return 8 * ROUNDING + singular_set_bound(sin_j) + singular_set_bound(sin_i)


@given(unit_quaternions, momenta)
def test_attitude_andoyer_round_trip(q, momentum):
    attitude = rot.quat_to_attitude(q)
    big_l, big_g, big_h, l, g, h = andoyer.andoyer_from_attitude(attitude, momentum)
    back, momentum_back = andoyer.attitude_from_andoyer(big_l, big_g, big_h, l, g, h)
    assert np.abs(back - attitude).max() < attitude_bound(attitude, momentum)
    assert np.abs(momentum_back - momentum).max() < transverse_momentum_bound(momentum)


@given(unit_quaternions, momenta)
def test_andoyer_meaning(q, momentum):
    attitude = rot.quat_to_attitude(q)
    big_l, big_g, big_h, l, g, h = andoyer.andoyer_from_attitude(attitude, momentum)
    inertial = attitude.T @ momentum
    assert math.isclose(big_g, np.linalg.norm(momentum), rel_tol=ROUNDING)
    assert math.isclose(big_h, inertial[2], rel_tol=ROUNDING, abs_tol=ROUNDING * big_g)
    assert math.isclose(big_l, momentum[2], rel_tol=ROUNDING, abs_tol=ROUNDING * big_g)
    sin_i = math.sqrt(max(1 - (big_h / big_g) ** 2, 0))
    expected = big_g * np.array([sin_i * math.sin(h), -sin_i * math.cos(h), big_h / big_g])
    assert np.abs(expected - inertial).max() < 1e-7 * big_g  # sin I from 1 − cos²I loses half the digits


def test_singular_sets_round_trip_without_nan():
    # J = 0 (momentum along body C) and I = 0 (momentum along inertial z), and both at once.
    for q, momentum in [
        (np.array([math.cos(0.4), 0.3, -0.2, 0.1]), np.array([0.0, 0.0, 2.0])),
        (np.array([1.0, 0.0, 0.0, 0.0]), np.array([0.0, 0.0, -1.5])),
        (np.array([math.cos(0.3), 0.0, 0.0, math.sin(0.3)]), np.array([0.0, 0.0, 1.0])),
    ]:
        q = q / np.linalg.norm(q)
        attitude = rot.quat_to_attitude(q)
        variables = andoyer.andoyer_from_attitude(attitude, momentum)
        assert all(math.isfinite(v) for v in variables)
        back, momentum_back = andoyer.attitude_from_andoyer(*variables)
        assert np.abs(back - attitude).max() < attitude_bound(attitude, momentum)
        assert np.abs(momentum_back - momentum).max() < transverse_momentum_bound(momentum)


def test_energy_formula_eq10():
    a, b, c = 1.0, 0.5, 0.4
    momentum = np.array([0.3, -0.7, 0.5])
    big_l, big_g, _, l, _, _ = andoyer.andoyer_from_attitude(np.eye(3), momentum)
    direct = 0.5 * (a * momentum[0] ** 2 + b * momentum[1] ** 2 + c * momentum[2] ** 2)
    assert math.isclose(andoyer.kinetic_energy_andoyer(big_l, big_g, l, a, b, c), direct, rel_tol=ROUNDING)
