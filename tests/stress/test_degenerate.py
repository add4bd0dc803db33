"""Consistent refusals for degenerate states (issue 14, class 4), and the free flow at absurd times (class 6).

hypothesis builds states with spins from 0 through 1e±320 to 1e308 and bodies from subnormal to
huge moments, and asks every property and function: each answer is finite (inf only where a
period is infinite: separatrix, permanent rotation) or the documented exception, never NaN. NaN and
inf injected anywhere (times, spans, steps, moments, mass, radius, G·M, states) give
:class:`spinorbit.NonFiniteError` from every entry point. The free flow is checked against mpmath
(40+ digits) up to the phase where it is refused.
"""

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from hypothesis import given, settings
from hypothesis import strategies as st

from spinorbit import InvalidBodyError, InvalidStateError, NonFiniteError, RigidBody, RotationState
from spinorbit import SingularElementsError
from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.integrators.elements import integrate_elements, integrate_elements_fixed_step
from spinorbit.core.integrators.handover import integrate_with_handover
from spinorbit.core.integrators.quaternion import integrate_fixed_step, integrate_quaternion
from spinorbit.core.integrators.splitting import integrate_splitting
from spinorbit.core.integrators.taylor import integrate_taylor, integrate_taylor_fixed_step
from spinorbit.core.math.rotations import rotation_angle_between_many
from spinorbit.core.model.perturbers import fixed_source, kepler_source
from spinorbit.core.free_motion.flow import torque_free_states
from spinorbit.runs.resumable import integrate_resumable
from spinorbit.scene.inputs import FixedPerturber
from spinorbit.state import MAX_FLOW_PHASE

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
from _mp_reference import exact_states  # noqa: E402

EXAMPLES = 80
MOMENTS = (1.0, 2.0, 2.5)
STATE = np.array([1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 0.3])
BAD = [math.nan, math.inf, -math.inf]

#: Every property or function of a state, with the exceptions it may raise (the refusals).
PROPERTIES = {
    "mode": lambda s: s.mode,
    "sense": lambda s: s.sense,
    "periods": lambda s: [p.value for p in s.periods],
    "energy_ratio": lambda s: s.energy_ratio,
    "angular_momentum_direction": lambda s: s.angular_momentum_direction,
    "andoyer_variables": lambda s: [value.value for value in s.andoyer_variables()],
    "canonical_elements": lambda s: [getattr(s.canonical_elements(), k) for k in "SZHszh"],
    "propagate_torque_free": lambda s: np.concatenate([a.ravel() if not hasattr(a, "value") else a.value.ravel()
                                                       for a in s.propagate_torque_free([0.0, 1.0, 1e3] * u.day)]),
    "core_state": lambda s: s.core_state(),
    "angular_momentum": lambda s: s.angular_momentum.value,
}
REFUSALS = (InvalidStateError, SingularElementsError)


def assert_finite_or_refused(state, name):
    try:
        value = PROPERTIES[name](state)
    except REFUSALS:
        return "refused"
    if isinstance(value, str):
        return value
    values = np.asarray(value, dtype=float).ravel()
    assert not np.any(np.isnan(values)), (name, state, values)
    if name != "periods":  # an infinite period is a period (separatrix, permanent rotation)
        assert np.all(np.isfinite(values)), (name, state, values)
    return "finite"


decade = st.integers(-320, 308)
direction = st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))


@settings(max_examples=EXAMPLES)
@given(st.sampled_from([(1.0, 2.0, 2.5), (1.0, 1.0, 2.0), (1.0, 2.0, 2.0), (1.0, 1.0, 1.0), (0.61, 0.965, 1.0)]),
       st.integers(-200, 200), decade, direction, st.sampled_from(sorted(PROPERTIES)))
def test_every_property_of_any_magnitude_is_finite_or_refused(moments, moment_decade, spin_decade, axis, name):
    scale = 10.0 ** moment_decade
    try:
        body = RigidBody(np.array(moments) * scale)
    except InvalidBodyError:
        return
    omega = np.array(axis) * 10.0 ** spin_decade
    try:
        state = RotationState(body, [1.0, 0.0, 0.0, 0.0], omega * u.rad / u.day)
    except InvalidStateError as error:  # I ω overflows: refused when the state is made
        assert "overflows" in str(error)
        return
    outcome = assert_finite_or_refused(state, name)
    if not np.any(omega) and name not in ("core_state", "angular_momentum", "propagate_torque_free"):
        assert outcome == "refused", name  # zero spin: no mode, periods, E/E0, direction or elements


@pytest.mark.parametrize("name", sorted(PROPERTIES))
def test_zero_spin_gets_the_same_refusal_from_every_property_that_describes_the_rotation(name):
    state = RotationState(RigidBody(MOMENTS), [1.0, 0.0, 0.0, 0.0], [0.0, 0.0, 0.0] * u.rad / u.day)
    if name in ("core_state", "angular_momentum", "propagate_torque_free"):
        values = np.asarray(PROPERTIES[name](state), dtype=float)
        assert np.all(np.isfinite(values))  # a body at rest stays at rest: exact
        return
    with pytest.raises(InvalidStateError, match="zero spin"):
        PROPERTIES[name](state)


# ------------------------------------------------------------------------------- NaN and inf anywhere
def model():
    return make_model(MOMENTS)


def with_bad(vector, index, bad):
    vector = np.array(vector, dtype=float)
    vector[index] = bad
    return vector


ENTRY_POINTS = {
    "RigidBody moments": lambda b, i: RigidBody(with_bad(MOMENTS, i % 3, b)),
    "RigidBody mass": lambda b, i: RigidBody(MOMENTS, mass=b * u.kg),
    "RigidBody radius": lambda b, i: RigidBody(MOMENTS, radius=b * u.km),
    "RotationState quaternion": lambda b, i: RotationState(RigidBody(MOMENTS), with_bad([1, 0, 0, 0], i % 4, b), [1, 0, 0] * u.rad / u.day),
    "RotationState spin": lambda b, i: RotationState(RigidBody(MOMENTS), [1, 0, 0, 0], with_bad([1, 0, 0], i % 3, b) * u.rad / u.day),
    "from_euler313": lambda b, i: RotationState.from_euler313(RigidBody(MOMENTS), *with_bad([0.1, 0.2, 0.3], i % 3, b) * u.rad,
                                                              [1, 0, 0] * u.rad / u.day),
    "from_matrix": lambda b, i: RotationState.from_matrix(RigidBody(MOMENTS), with_bad(np.eye(3), (i % 3, i % 2), b),
                                                          [1, 0, 0] * u.rad / u.day),
    "propagate_torque_free dt": lambda b, i: RotationState(RigidBody(MOMENTS), [1, 0, 0, 0], [1, 2, 3] * u.rad / u.day)
    .propagate_torque_free(with_bad([0.0, 1.0, 2.0], i % 3, b) * u.day),
    "integrate_quaternion y0": lambda b, i: integrate_quaternion(with_bad(STATE, i % 7, b), 0.0, [1.0], model()),
    "integrate_quaternion t0": lambda b, i: integrate_quaternion(STATE, b, [1.0], model()),
    "integrate_quaternion t_out": lambda b, i: integrate_quaternion(STATE, 0.0, with_bad([1.0, 2.0], i % 2, b), model()),
    "integrate_elements t_out": lambda b, i: integrate_elements(STATE, 0.0, with_bad([1.0, 2.0], i % 2, b), model()),
    "integrate_taylor y0": lambda b, i: integrate_taylor(with_bad(STATE, i % 7, b), 0.0, [1.0], model()),
    "integrate_with_handover t_out": lambda b, i: integrate_with_handover(STATE, 0.0, [b], model()),
    "integrate_splitting step": lambda b, i: integrate_splitting(STATE, 0.0, [1.0], model(), b),
    "integrate_splitting y0": lambda b, i: integrate_splitting(with_bad(STATE, i % 7, b), 0.0, [1.0], model(), 0.1),
    "integrate_fixed_step t1": lambda b, i: integrate_fixed_step(STATE, 0.0, b, 10, model()),
    "integrate_elements_fixed_step t0": lambda b, i: integrate_elements_fixed_step(STATE, b, 1.0, 10, model()),
    "integrate_taylor_fixed_step t1": lambda b, i: integrate_taylor_fixed_step(STATE, 0.0, b, 10, model(), 6),
    "integrate_resumable t_out": lambda b, i: integrate_resumable("dop853", STATE, 0.0, [b], model(), chunk=1.0),
    "make_model moments": lambda b, i: make_model(with_bad(MOMENTS, i % 3, b)),
    "make_model mass": lambda b, i: make_model(MOMENTS, mass=b),
    "perturber gm (kepler)": lambda b, i: kepler_source(b, 4.0, 0.3, 0.4, 0.1, 0.2, 0.0),
    "perturber gm (fixed)": lambda b, i: fixed_source(b, [1.0, 0.0, 0.0]),
    "perturber elements": lambda b, i: kepler_source(1.0, *with_bad([4.0, 0.3, 0.4, 0.1, 0.2, 0.0], i % 6, b)),
    "perturber position": lambda b, i: fixed_source(1.0, with_bad([1.0, 0.0, 0.0], i % 3, b)),
    "Scene perturber gm": lambda b, i: FixedPerturber("p", b * u.m**3 / u.s**2, [1.0, 0.0, 0.0] * u.au),
    "Scene perturber position": lambda b, i: FixedPerturber("p", 1.0 * u.m**3 / u.s**2,
                                                            with_bad([1.0, 0.0, 0.0], i % 3, b) * u.au),
}


@settings(max_examples=EXAMPLES)
@given(st.sampled_from(sorted(ENTRY_POINTS)), st.sampled_from(BAD), st.integers(0, 11))
def test_nan_or_inf_anywhere_is_a_non_finite_error(entry, bad, index):
    with pytest.raises(NonFiniteError, match="nan|inf|finite"):
        ENTRY_POINTS[entry](bad, index)


@pytest.mark.parametrize("entry", sorted(ENTRY_POINTS))
def test_every_entry_point_refuses_nan_with_non_finite_error(entry):
    for bad in BAD:
        with pytest.raises(NonFiniteError):
            ENTRY_POINTS[entry](bad, 0)


@pytest.mark.parametrize("value", [0.0, -1.0, -1e-300])
def test_zero_or_negative_mass_or_radius_is_an_invalid_body(value):
    for keyword, unit in (("mass", u.kg), ("radius", u.km)):
        with pytest.raises(InvalidBodyError, match=f"{keyword} must be positive"):
            RigidBody(MOMENTS, **{keyword: value * unit})


# ------------------------------------------------------------------------------- the free flow at absurd times
Q0 = np.array([0.9, 0.1, -0.3, 0.2]) / np.linalg.norm([0.9, 0.1, -0.3, 0.2])
MOMENTUM = np.array([0.3, 0.5, 1.2])
FLOW_MOMENTS = (1.0, 1.6, 2.1)
#: ≤ 4e-16 rad measured up to a phase G t/A of 6.6e15 rad; 1e-15 leaves rounding room.
FLOW_TOLERANCE = 1e-15


@pytest.mark.parametrize("phase", [1e3, 1e7, 1e11, 1e13, 0.99 * MAX_FLOW_PHASE])
def test_free_flow_is_exact_for_the_double_time_up_to_its_documented_phase(phase):
    rate = np.linalg.norm(MOMENTUM) / FLOW_MOMENTS[0]  # G/A, the fastest angle of the motion
    t = np.array([phase / rate])
    q_mp, _ = exact_states(Q0, MOMENTUM, FLOW_MOMENTS, t, dps=40 + int(math.log10(phase)))
    q, m = torque_free_states(Q0, MOMENTUM, *FLOW_MOMENTS, t)
    assert rotation_angle_between_many(np.ascontiguousarray(q_mp), q)[0] <= FLOW_TOLERANCE
    state = RotationState(RigidBody(FLOW_MOMENTS), Q0, (MOMENTUM / np.array(FLOW_MOMENTS)) * u.rad / u.day)
    quaternions, omega = state.propagate_torque_free(t * u.day)
    assert np.all(np.isfinite(quaternions)) and np.all(np.isfinite(omega.value))


@settings(max_examples=EXAMPLES)
@given(st.floats(1.001, 1e200), st.integers(-6, 6))
def test_free_flow_beyond_its_phase_is_refused(factor, spin_decade):
    omega = np.array([0.1, 0.2, 0.3]) * 10.0 ** spin_decade
    state = RotationState(RigidBody(MOMENTS), [1.0, 0.0, 0.0, 0.0], omega * u.rad / u.day)
    rate = np.linalg.norm(np.array(MOMENTS) * omega) / MOMENTS[0]
    with pytest.raises(InvalidStateError, match="beyond the free flow's domain"):
        state.propagate_torque_free([0.0, -factor * MAX_FLOW_PHASE / rate] * u.day)
