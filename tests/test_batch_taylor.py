"""The batch Taylor integrator (spinorbit.core.integrators.batch_taylor) against the scalar one.

The batch kernel calls the scalar kernel's functions (seeding, recurrences, norms, step rule, Horner)
in the scalar kernel's order per lane, so each member's end state, steps and orbit-series orders must
equal ``integrate_taylor(..., t_out=[t_end])``'s **bit for bit**, whatever its lane and lane-mates; no
tolerance is needed, and any change of the arithmetic or of the step sequence would fail these tests.
"""

import numpy as np
import pytest
from _batch_members import SOURCES, break_mass, members, spans

from spinorbit.core import integrate_taylor, integrate_taylor_batch, make_model
from spinorbit.core.errors import NonFiniteError, WorkLimitError
from spinorbit.core.integrators.batch_quaternion import raise_for_batch_status
from spinorbit.core.integrators.dop853 import STATUS_MAX_STEPS, STATUS_NOT_FINITE, STATUS_SUCCESS, IntegrationError
from spinorbit.core.model.perturbers import sampled_source


def _scalar(y0, t0, t_end, model, tol):
    ys, stats = integrate_taylor(y0, t0, [t_end], model, tol=tol, return_stats=True)
    return ys[-1], stats


@pytest.mark.parametrize("lanes", [1, 3, 4])
def test_each_member_is_the_scalar_integrators_bits(lanes):
    """Own moments, states, spans (forward and backward), start times and tolerances (so orders) per member."""
    y0s, models, rng = members(7)
    t0s, t_ends = spans(rng, 7)
    tols = 10.0 ** -rng.uniform(6.0, 13.0, 7)
    ys, stats = integrate_taylor_batch(y0s, t0s, t_ends, models, tols, lanes=lanes)
    assert len(set(stats["order"].tolist())) > 2  # lanes of different orders side by side
    for m in range(7):
        end, scalar_stats = _scalar(y0s[m], t0s[m], t_ends[m], models[m], tols[m])
        assert ys[m].tobytes() == end.tobytes(), m
        assert stats["status"][m] == STATUS_SUCCESS
        assert (int(stats["steps"][m]), int(stats["order"][m])) == (scalar_stats["steps"], scalar_stats["order"])
        assert float(stats["mean_orbit_order"][m]) == scalar_stats["mean_orbit_order"]
    assert np.array_equal(stats["accepted"], stats["steps"]) and not stats["rejected"].any()
    assert stats["steps"].max() > 2 * 16  # past the Kepler re-seed interval: both seeding branches ran


def test_a_members_result_does_not_depend_on_its_lane_mates():
    y0s, models, _ = members(6, seed=3)
    ys, _ = integrate_taylor_batch(y0s, 0.0, 4.0, models, 1e-10, lanes=4)
    order = [5, 2, 0, 4, 1, 3]
    shuffled, _ = integrate_taylor_batch(y0s[order], 0.0, 4.0, [models[i] for i in order], 1e-10, lanes=2)
    assert shuffled.tobytes() == ys[order].tobytes()


def test_finished_lanes_are_masked_and_refilled():
    """Spans from 0.5 to 8 in 3 lanes: short members finish while long ones still step, their lanes take the
    next members, and a lane left idle at the end of the queue changes no other member's bits."""
    y0s, models, _ = members(8, seed=5)
    t_ends = np.array([0.5, 8.0, 1.0, 6.0, 0.7, 3.0, 8.0, 0.5])
    ys, stats = integrate_taylor_batch(y0s, 0.0, t_ends, models, 1e-9, lanes=3)
    assert stats["steps"].max() > 5 * stats["steps"].min()
    for m in range(8):
        assert ys[m].tobytes() == _scalar(y0s[m], 0.0, t_ends[m], models[m], 1e-9)[0].tobytes(), m
    alone, _ = integrate_taylor_batch(y0s[1:2], 0.0, t_ends[1:2], models[1:2], 1e-9, lanes=8)  # 7 idle lanes
    assert alone.tobytes() == ys[1:2].tobytes()


def test_sampled_and_fixed_perturbers_and_one_model_for_all():
    """A sampled perturber (steps clipped at its sample times) and a fixed one, one model for every member."""
    times = np.linspace(-1.0, 5.0, 13)
    positions = np.column_stack([3.0 * np.cos(0.3 * times), 3.0 * np.sin(0.3 * times), 0.2 + 0.0 * times])
    velocities = np.column_stack([-0.9 * np.sin(0.3 * times), 0.9 * np.cos(0.3 * times), 0.0 * times])
    model = make_model((0.6, 0.85, 1.0), [sampled_source(2e-2, times, positions, velocities)])
    y0s, _, _ = members(3, seed=6)
    ys, stats = integrate_taylor_batch(y0s, 0.0, 4.0, model, 1e-10, lanes=2)
    for m in range(3):
        end, scalar_stats = _scalar(y0s[m], 0.0, 4.0, model, 1e-10)
        assert ys[m].tobytes() == end.tobytes() and int(stats["steps"][m]) == scalar_stats["steps"]


def test_a_failing_member_is_reported_and_leaves_the_others_alone():
    """A NaN perturber mass makes one member's torque NaN: it stops NOT_FINITE with a NaN row, its lane is
    refilled, and every other member keeps the scalar integrator's bits; a step cap stops another one."""
    y0s, models, _ = members(5, seed=2)
    broken = break_mass(models, 1)
    with pytest.raises(IntegrationError, match="NaN/inf"):  # the scalar integrator stops on it too
        integrate_taylor(y0s[1], 0.0, [3.0], broken, tol=1e-10)
    ys, stats = integrate_taylor_batch(y0s, 0.0, 3.0, models, 1e-10, lanes=2)
    assert stats["status"][1] == STATUS_NOT_FINITE and np.all(np.isnan(ys[1]))
    for m in (0, 2, 3, 4):
        assert stats["status"][m] == STATUS_SUCCESS
        assert ys[m].tobytes() == _scalar(y0s[m], 0.0, 3.0, models[m], 1e-10)[0].tobytes()
    with pytest.raises(IntegrationError, match=r"1 member\(s\) stopped, first member 1 .*NaN/inf"):
        raise_for_batch_status(stats)
    capped_ys, capped = integrate_taylor_batch(y0s[[0, 2]], 0.0, [3.0, 0.3], models[0], 1e-10, max_steps=8, lanes=2)
    assert capped["status"].tolist() == [STATUS_MAX_STEPS, STATUS_SUCCESS] and np.all(np.isnan(capped_ys[0]))


@pytest.mark.parametrize("kwargs, error, match", [
    (dict(y0s=np.zeros((3, 6))), ValueError, r"y0s: expected an \(N, 7\) array"),
    (dict(y0s=np.zeros((0, 7))), ValueError, r"y0s: expected an \(N, 7\) array"),
    (dict(lanes=0), ValueError, "lanes: expected a whole number of lanes from 1 to 64, got 0"),
    (dict(lanes=2.0), ValueError, "lanes: expected a whole number"),
    (dict(t_end=[1.0, 2.0]), ValueError, r"t_end: expected one end time or 3 of them \(one per member\)"),
    (dict(t_end=0.0), ValueError, "t_end: expected an end time other than t0 for every member; member 0"),
    (dict(t0=np.nan), ValueError, "t0/t_end: expected finite times"),
    (dict(tol=1e-17), ValueError, r"tol: expected tol ≥ 1e-16 .* \(member 0\)"),
    (dict(tol=[1e-9, 0.0, 1e-9]), ValueError, r"tol: expected a tolerance > 0, got 0.0.* \(member 1\)"),
    (dict(tol=[1e-9, 1e-9]), ValueError, r"tol: expected one tolerance or 3 of them"),
    (dict(order_factor=3.0), ValueError, r"order_factor: expected a number in \[1, 2\]"),
    (dict(t_end=200.0, max_steps=10), WorkLimitError, "max_steps = 10; raise max_steps"),
])
def test_bad_input_is_refused_with_a_specific_message(kwargs, error, match):
    y0s, models, _ = members(3)
    arguments = dict(y0s=y0s, t0=0.0, t_end=2.0, models=models, tol=1e-10)
    arguments.update(kwargs)
    with pytest.raises(error, match=match):
        integrate_taylor_batch(**arguments)


def test_bad_states_and_models_are_refused():
    y0s, models, _ = members(3)
    bad = y0s.copy()
    bad[2, 5] = np.inf
    with pytest.raises(NonFiniteError, match=r"y0s: expected finite states \(q, ω\)"):
        integrate_taylor_batch(bad, 0.0, 2.0, models)
    bad = y0s.copy()
    bad[1, :4] = 0.0
    with pytest.raises(ValueError, match="y0s: expected a non-zero quaternion .* member 1"):
        integrate_taylor_batch(bad, 0.0, 2.0, models)
    with pytest.raises(ValueError, match=r"models: expected one model per member \(3\) or one for all, got 2"):
        integrate_taylor_batch(y0s, 0.0, 2.0, models[:2])
    with pytest.raises(ValueError, match="models: expected model arrays of one length"):
        integrate_taylor_batch(y0s, 0.0, 2.0, [models[0], models[1], make_model((0.5, 0.8, 1.0))])
    stokes_c = np.zeros((4, 4))
    stokes_c[3, 0] = 1e-3
    octupole = make_model((0.5, 0.8, 1.0), SOURCES, mass=1.0, stokes_c=stokes_c, stokes_s=np.zeros((4, 4)))
    with pytest.raises(ValueError, match="models: member 0 has degree-3 Stokes terms, .* integrate_quaternion_batch"):
        integrate_taylor_batch(y0s, 0.0, 2.0, octupole)
