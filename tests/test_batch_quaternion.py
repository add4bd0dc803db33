"""The batch DOP853 (spinorbit.core.integrators.batch_quaternion) against the scalar integrator.

The batch kernel runs the scalar kernel's arithmetic in the scalar kernel's order per lane (the same
stage sums, error norm, step-size control and renormalisation), so each member's end state and step
counts must equal ``integrate_quaternion(..., t_out=[t_end])``'s **bit for bit**, whatever its lanes and
lane-mates; no tolerance is needed, and any reordering of the arithmetic would fail these tests.
"""

import numpy as np
import pytest
from _batch_members import break_mass, members, spans

from spinorbit.core import integrate_quaternion, make_model
from spinorbit.core.integrators.batch_quaternion import integrate_quaternion_batch, raise_for_batch_status
from spinorbit.core.integrators.dop853 import STATUS_NOT_FINITE, STATUS_SUCCESS, IntegrationError


def _scalar(y0, t0, t_end, model, rtol):
    ys, stats = integrate_quaternion(y0, t0, [t_end], model, rtol=rtol, return_stats=True)
    return ys[-1], stats


@pytest.mark.parametrize("lanes", [1, 3, 4])
def test_each_member_is_the_scalar_integrators_bits(lanes):
    """Own moments, spans (forward and backward), start times and rtols per member."""
    y0s, models, rng = members(7)
    t0s, t_ends = spans(rng, 7)
    rtols = 10.0 ** -rng.uniform(6.0, 12.0, 7)
    ys, stats = integrate_quaternion_batch(y0s, t0s, t_ends, models, rtols, lanes=lanes)
    for m in range(7):
        end, scalar_stats = _scalar(y0s[m], t0s[m], t_ends[m], models[m], rtols[m])
        assert ys[m].tobytes() == end.tobytes(), m
        assert stats["status"][m] == STATUS_SUCCESS
        assert {key: int(stats[key][m]) for key in scalar_stats} == scalar_stats, m
    assert stats["rejected"].sum() > 0  # the rejection branch ran in some lane


def test_a_members_result_does_not_depend_on_its_lane_mates():
    y0s, models, _ = members(6, seed=3)
    ys, _ = integrate_quaternion_batch(y0s, 0.0, 4.0, models, 1e-10, lanes=4)
    order = [5, 2, 0, 4, 1, 3]
    shuffled, _ = integrate_quaternion_batch(y0s[order], 0.0, 4.0, [models[i] for i in order], 1e-10, lanes=2)
    assert shuffled.tobytes() == ys[order].tobytes()


def test_one_model_for_all_members_and_per_component_atol():
    y0s, models, _ = members(3, seed=4)
    atol = np.array([1e-9] * 4 + [1e-8] * 3)
    ys, _ = integrate_quaternion_batch(y0s, 0.0, 3.0, models[0], 1e-9, atol=atol, lanes=2)
    for m in range(3):
        end = integrate_quaternion(y0s[m], 0.0, [3.0], models[0], rtol=1e-9, atol=atol)[-1]
        assert ys[m].tobytes() == end.tobytes()


def test_a_failing_member_is_reported_and_leaves_the_others_alone():
    """A NaN in one member's perturber mass makes its torque NaN: the member stops NOT_FINITE, its row
    is NaN, its lane is refilled, and every other member keeps the scalar integrator's bits."""
    y0s, models, _ = members(5, seed=2)
    broken = break_mass(models, 1)
    with pytest.raises(IntegrationError, match="NaN/inf"):  # the scalar integrator stops on it too
        integrate_quaternion(y0s[1], 0.0, [3.0], broken, rtol=1e-10)
    ys, stats = integrate_quaternion_batch(y0s, 0.0, 3.0, models, 1e-10, lanes=2)
    assert stats["status"][1] == STATUS_NOT_FINITE and np.all(np.isnan(ys[1]))
    for m in (0, 2, 3, 4):
        assert stats["status"][m] == STATUS_SUCCESS
        assert ys[m].tobytes() == _scalar(y0s[m], 0.0, 3.0, models[m], 1e-10)[0].tobytes()
    with pytest.raises(IntegrationError, match=r"1 member\(s\) stopped, first member 1 .*NaN/inf"):
        raise_for_batch_status(stats)
    raise_for_batch_status({key: np.delete(value, 1) for key, value in stats.items()})  # the others: no error


@pytest.mark.parametrize("kwargs, match", [
    (dict(y0s=np.zeros((3, 6))), r"y0s: expected an \(N, 7\) array"),
    (dict(y0s=np.zeros((0, 7))), r"y0s: expected an \(N, 7\) array"),
    (dict(lanes=0), "lanes: expected a whole number of lanes from 1 to 64, got 0"),
    (dict(lanes=65), "lanes: expected a whole number of lanes from 1 to 64, got 65"),
    (dict(lanes=2.0), "lanes: expected a whole number"),
    (dict(lanes=True), "lanes: expected a whole number"),
    (dict(t_end=[1.0, 2.0]), r"t_end: expected one end time or 3 of them \(one per member\), got shape \(2,\)"),
    (dict(t_end=0.0), "t_end: expected an end time other than t0 for every member; member 0"),
    (dict(t0=np.nan), "t0/t_end: expected finite times"),
    (dict(rtol=1e-17), "rtol: expected rtol ≥ 1e-15"),
    (dict(rtol=[1e-9, 0.0, 1e-9]), "rtol: expected a relative tolerance > 0, got 0.0 for member 1"),
    (dict(atol=np.ones((2, 7))), r"atol: expected a scalar, 7 values or an \(N, 7\) array with N = 3"),
    (dict(atol=-1.0), "atol: expected absolute tolerances ≥ 0"),
])
def test_bad_input_is_refused_with_a_specific_message(kwargs, match):
    y0s, models, _ = members(3)
    arguments = dict(y0s=y0s, t0=0.0, t_end=2.0, models=models, rtol=1e-10)
    arguments.update(kwargs)
    with pytest.raises(ValueError, match=match):
        integrate_quaternion_batch(**arguments)


def test_bad_states_and_models_are_refused():
    y0s, models, _ = members(3)
    bad = y0s.copy()
    bad[2, 5] = np.inf
    with pytest.raises(ValueError, match=r"y0s: expected finite states \(q, ω\)"):
        integrate_quaternion_batch(bad, 0.0, 2.0, models)
    with pytest.raises(ValueError, match=r"models: expected one model per member \(3\) or one for all, got 2"):
        integrate_quaternion_batch(y0s, 0.0, 2.0, models[:2])
    bad = y0s.copy()
    bad[1, :4] = 0.0
    with pytest.raises(ValueError, match="y0s: expected a non-zero quaternion .* member 1"):
        integrate_quaternion_batch(bad, 0.0, 2.0, models)
    with pytest.raises(ValueError, match="max_steps = 10; raise max_steps"):
        integrate_quaternion_batch(y0s, 0.0, 200.0, models, max_steps=10)
    with pytest.raises(ValueError, match="models: expected model arrays of one length"):
        integrate_quaternion_batch(y0s, 0.0, 2.0, [models[0], models[1], make_model((0.5, 0.8, 1.0))])
