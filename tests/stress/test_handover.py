"""Elements ↔ quaternion hand-over near the singular sets of the elements (issue 7).

Scene: a triaxial body (A, B, C) = (0.6, 0.9, 1.0) in short-axis rotation, |M| = 3, with a point
mass μ = 3 on an eccentric (e = 0.3) inclined orbit of a = 2 around it: a strong torque that drives
1 − m from 0.23 across the separatrix and back several times in 60 time units (~30 turns). The same
torque on a state far from the separatrix (1 − m ≈ 0.64 in SAM, 0.60 in LAM) never comes near it.

Yardstick: quaternion DOP853 at rtol 1e-15 (its difference from rtol 1e-14 here: 4.0e-11 rad).
The hand-over runs at rtol 1e-12 and must be at least as accurate as the non-singular integrator
at the same rtol, measured in the same test (it was 6.5e-10 rad against 7.4e-9 rad): switching must
cost less than the tolerance buys, whatever the conditioning of the passage.
"""

import math

import numpy as np
import pytest

from spinorbit.core.dynamics import make_model
from spinorbit.core.integrate_elements import (
    MIN_SEPARATRIX_DISTANCE,
    ElementsSingularityError,
    integrate_elements,
)
from spinorbit.core.integrate_handover import (
    ELEMENTS,
    QUATERNION,
    RESUME_MARGIN,
    integrate_with_handover,
    singularity_distances_of_state,
)
from spinorbit.core.integrate_quaternion import integrate_quaternion
from spinorbit.core.perturbers import kepler_source
from spinorbit.core.rotations import rotation_angle_between_many

MOMENTS = np.array([0.6, 0.9, 1.0])
T_OUT = np.linspace(0.0, 60.0, 61)[1:]
RTOL = 1e-12
#: The kernel checks the distance at the end of each accepted step, so the state where it stops is
#: below the threshold by at most one step's change of 1 − m (measured 0.91–0.94 × the threshold).
STOP_OVERSHOOT = 1.0


def model():
    return make_model(MOMENTS, [kepler_source(3.0, 2.0, 0.3, 0.4, 0.2, 0.1, 0.0)])


def state_with_gap(gap):
    """(q, ω) with d = 2T/G² = (1 − gap)·b: gap > 0 SAM, gap < 0 LAM (b = 1/B), |M| = 3."""
    a, b, c = 1.0 / MOMENTS
    d = (1.0 - gap) * b
    momentum = np.array([math.sqrt((d - c) / (a - d)), 0.0, 1.0]) if d > c else None
    if gap < 0:
        momentum = np.array([1.0, 0.0, math.sqrt((a - d) / (d - c))])
    momentum *= 3.0 / np.linalg.norm(momentum)
    q = np.array([math.cos(0.3), 0.6 * math.sin(0.3), 0.0, 0.8 * math.sin(0.3)])
    return np.r_[q, momentum / MOMENTS]


def angle(ys, ref):
    return float(rotation_angle_between_many(np.ascontiguousarray(ys[:, :4]), np.ascontiguousarray(ref[:, :4])).max())


def reference(y0, times=T_OUT):
    return integrate_quaternion(y0, 0.0, times, model(), rtol=1e-15)


def test_separatrix_passages_are_handed_over_and_agree_with_dop853():
    y0 = state_with_gap(0.02)  # 1 − m = 0.23
    ys, switches = integrate_with_handover(y0, 0.0, T_OUT, model(), rtol=RTOL)
    ref = reference(y0)
    plain = integrate_quaternion(y0, 0.0, T_OUT, model(), rtol=RTOL)
    assert len(switches) >= 2
    assert [s.to for s in switches] == [QUATERNION, ELEMENTS] * (len(switches) // 2) + [QUATERNION] * (len(switches) % 2)
    for switch in switches:
        sep = singularity_distances_of_state(reference(y0, [switch.t])[0], MOMENTS)[0]
        if switch.to == QUATERNION:
            assert switch.reason == "separatrix" and sep < STOP_OVERSHOOT * MIN_SEPARATRIX_DISTANCE
        else:
            assert switch.reason == "safely away" and sep >= RESUME_MARGIN * MIN_SEPARATRIX_DISTANCE
    error, plain_error = angle(ys, ref), angle(plain, ref)
    assert error <= plain_error
    omega_scale = np.abs(ref[:, 4:]).max()
    assert np.abs(ys[:, 4:] - ref[:, 4:]).max() <= np.abs(plain[:, 4:] - ref[:, 4:]).max() + 1e-15 * omega_scale
    # the passage really is one: plain elements stop at the separatrix
    with pytest.raises(ElementsSingularityError) as info:
        integrate_elements(y0, 0.0, T_OUT, model(), rtol=RTOL)
    assert info.value.kind == "separatrix" and info.value.t_stop == switches[0].t
    at_stop = reference(y0, [switches[0].t])
    assert angle(info.value.y_stop[None], at_stop) <= plain_error  # the state handed over is the true one
    np.testing.assert_allclose(info.value.y_stop[4:], at_stop[0, 4:], rtol=0, atol=plain_error * omega_scale)


@pytest.mark.parametrize("gap", [0.06, -0.1], ids=["SAM", "LAM"])
def test_same_torque_without_passage_never_switches(gap):
    y0 = state_with_gap(gap)
    ys, switches = integrate_with_handover(y0, 0.0, T_OUT, model(), rtol=RTOL)
    assert switches == []
    # no switch: exactly the element integrator's run
    np.testing.assert_array_equal(ys, integrate_elements(y0, 0.0, T_OUT, model(), rtol=RTOL))
    ref = reference(y0)
    plain = integrate_quaternion(y0, 0.0, T_OUT, model(), rtol=RTOL)
    assert angle(ys, ref) <= max(angle(plain, ref), 1e-10)


def test_start_next_to_spin_about_c_begins_with_the_quaternion_integrator():
    y0 = np.r_[1.0, 0.0, 0.0, 0.0, 3e-6, 0.0, 3.0]  # sin J = 6e-7
    times = T_OUT[:10]
    ys, switches = integrate_with_handover(y0, 0.0, times, model(), rtol=RTOL)
    assert switches[0].t == 0.0 and switches[0].to == QUATERNION and switches[0].reason == "spin about C"
    ref = reference(y0, times)
    assert angle(ys, ref) <= max(angle(integrate_quaternion(y0, 0.0, times, model(), rtol=RTOL), ref), 1e-10)


@pytest.mark.parametrize("kwargs, pattern", [
    ({"resume_margin": 0.5}, "resume_margin.*0.5"),
    ({"check_interval": -1.0}, "check_interval.*-1.0"),
    ({"check_interval": math.nan}, "check_interval.*nan"),
])
def test_bad_driver_parameters_say_what_was_expected(kwargs, pattern):
    with pytest.raises(ValueError, match=pattern):
        integrate_with_handover(state_with_gap(0.02), 0.0, T_OUT, model(), **kwargs)
