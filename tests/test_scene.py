"""Scenes and their planner (``spinorbit.scene``, ``spinorbit.planner``).

Every skip is checked both ways — taken when it should be, not taken when it should not — and every
skipped run is compared with the full run of the same scene (``Scene.plan(skip=False)``: all
perturbers, the orbits as given, nothing left out), actually run. Numbers in comments were measured
on the shared 2-core machine when the tests were written.
"""


import numpy as np
import pytest
from _offline import no_network  # noqa: F401
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.asteroids import (
    APOPHIS_2029,
    apophis_encounter_simulation,
    apophis_rotation_state,
)
from spinorbit.coupling.rebound_adapter import MissingBodyError, simulation_from_de421
from spinorbit.ephemeris import UnknownBodyError, de421_constants, moon_orientation
from spinorbit.planner import ARCSEC_PER_RAD, Plan, attitude_sensitivity
from spinorbit.scene import FixedPerturber, Orbit, PlanError, Scene, SceneError, _angles  # noqa: F401

EPOCH = Time("2020-01-01", scale="tdb")


def sam_state():
    """Apophis-like short-axis mode (moment ratios of Pravec et al. 2014), a 9-hour spin."""
    return RotationState.from_euler313(RigidBody([0.61, 0.965, 1.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg,
                                       [5, 3, 40] * u.deg / u.hour)


def worst_difference(a, b):
    """Largest attitude angle (rad) between two results' tables."""
    return float(np.max(_angles(a.table["quaternion"], b.table["quaternion"])))


# ------------------------------------------------------------------------------------------------
# Skip 1: the exact torque-free solution.


def test_no_perturbers_is_the_exact_free_motion():
    state = sam_state()
    times = EPOCH + [1.0, 2.0, 10.0] * u.day
    scene = Scene(state, EPOCH, times)
    plan = scene.plan()
    assert plan.route == "torque-free" and plan.integrator == "exact"
    result = scene.run(plan)
    q, _ = state.propagate_torque_free([1.0, 2.0, 10.0])
    assert np.max(_angles(result.table["quaternion"], q)) < 1e-14
    assert result.error_estimate.value == 0.0


def _closed_form_decision(plan):
    return next(d for d in plan.decisions if d.topic == "closed form")


@pytest.mark.parametrize("moments", [(1.0, 1.0, 2.0), (0.5, 1.0, 1.0)], ids=["oblate A = B", "prolate B = C"])
def test_axisymmetric_body_takes_the_regular_precession_within_tolerance_of_the_elliptic_run(moments, monkeypatch):
    # Skip: the closed form. Taken for an exactly symmetric body; the reference plan runs the elliptic
    # flow; the two runs agree far inside the tolerance (both exact: ~1e-15 rad, test_regular_precession).
    state = RotationState.from_euler313(RigidBody(moments), 10 * u.deg, 40 * u.deg, 70 * u.deg,
                                        [5, 3, 40] * u.deg / u.hour)
    scene = Scene(state, EPOCH, EPOCH + np.linspace(1.0, 3000.0, 50) * u.day, tolerance=1e-12 * u.rad)
    plan, reference = scene.plan(), scene.plan(skip=False)
    assert _closed_form_decision(plan).choice.startswith("regular precession in closed form"), str(plan)
    assert "closed form not taken" in _closed_form_decision(reference).choice, str(reference)
    kernels = []  # what each run asked the free flow for: the plan's words must be what runs
    propagate = RotationState.propagate_torque_free
    monkeypatch.setattr(RotationState, "propagate_torque_free",
                        lambda self, dt, closed_forms=True: kernels.append(closed_forms) or propagate(self, dt, closed_forms))
    skipped, full = scene.run(plan), scene.run(reference)
    assert kernels == [True, False]
    assert worst_difference(skipped, full) <= min(scene.tolerance_rad, 1e-14)


def test_nearly_symmetric_or_principal_axis_states_keep_the_exact_elliptic_flow():
    # One ulp from symmetric, 1e-6 rad of wobble: no approximate form is claimed or run.
    body = RigidBody([1.0, np.nextafter(1.0, 2.0), 2.0])
    state = RotationState.from_angular_momentum(body, [1.0, 0.0, 0.0, 0.0], [1e-6, 0.0, 1.0])
    decision = _closed_form_decision(Scene(state, EPOCH, EPOCH + 1 * u.day).plan())
    assert decision.choice.startswith("elliptic free flow") and "no approximate form" in decision.choice
    assert "no tested bound" in decision.reason and "wobble" in decision.reason
    permanent = RotationState(RigidBody([0.61, 0.965, 1.0]), [1.0, 0.0, 0.0, 0.0], [0.0, 2.0, 0.0])
    assert _closed_form_decision(Scene(permanent, EPOCH, EPOCH + 1 * u.day).plan()).choice.startswith("uniform")


def test_torque_free_route_taken_when_the_torques_are_below_tolerance_and_stays_within_it():
    # Body on a 2.5 au circle, Sun and Jupiter, 0.2 d: all torques bounded by 0.05 arcsec (measured).
    scene = Scene(sam_state(), EPOCH, EPOCH + np.linspace(0.05, 0.2, 4) * u.day, perturbers=("sun", "jupiter"),
                  orbit=Orbit.circular(2.5 * u.au), tolerance=1 * u.arcsec)
    plan = scene.plan()
    assert plan.route == "torque-free", str(plan)
    assert "exact torque-free" in str(plan) and "arcsec" in str(plan)
    skipped = scene.run(plan)
    full = scene.run(scene.plan(skip=False))
    measured = worst_difference(skipped, full)
    assert measured <= scene.tolerance_rad
    # The estimate that justified the skip really bounds what was skipped.
    assert measured <= plan.dropped_bound_rad + full.error_estimate.to_value(u.rad)


def test_torque_free_route_not_taken_when_a_torque_exceeds_tolerance():
    # 60 d: the Sun's torque moves the attitude by ~4 arcsec (over 20 d only 0.7 arcsec, which the
    # conservative bound would also refuse to skip).
    scene = Scene(sam_state(), EPOCH, EPOCH + np.linspace(2.0, 60.0, 4) * u.day, perturbers=("sun", "jupiter"),
                  orbit=Orbit.circular(2.5 * u.au), tolerance=1 * u.arcsec)
    plan = scene.plan()
    assert plan.route == "one-way" and "sun" in plan.kept
    # The skipped torques really matter here: the free motion is off by more than the tolerance.
    free = Scene(sam_state(), EPOCH, scene.times).run()
    full = scene.run(scene.plan(skip=False))
    assert worst_difference(free, full) > scene.tolerance_rad


# ------------------------------------------------------------------------------------------------
# Skip 2: dropping perturbers.


def test_dropped_perturbers_stay_within_tolerance_of_the_full_run():
    scene = Scene(sam_state(), EPOCH, EPOCH + np.linspace(2.0, 20.0, 5) * u.day,
                  perturbers=("sun", "jupiter", "venus", "mars", "saturn"), orbit=Orbit.circular(2.5 * u.au),
                  tolerance=1 * u.arcsec)
    plan = scene.plan()
    assert set(plan.dropped) == {"jupiter", "venus", "mars", "saturn"} and plan.kept == ("sun",)
    skipped, full = scene.run(plan), scene.run(scene.plan(skip=False))
    measured = worst_difference(skipped, full)
    assert measured <= scene.tolerance_rad
    assert measured <= skipped.error_estimate.to_value(u.rad) + full.error_estimate.to_value(u.rad)
    assert skipped.error_estimate.to_value(u.rad) <= scene.tolerance_rad


def test_perturber_kept_when_its_bound_exceeds_the_tolerance_share():
    # Same scene, tolerance 1e-4 arcsec: Jupiter's bound (≈ 2e-3 arcsec) no longer fits.
    scene = Scene(sam_state(), EPOCH, EPOCH + np.linspace(2.0, 20.0, 5) * u.day, perturbers=("sun", "jupiter"),
                  orbit=Orbit.circular(2.5 * u.au), tolerance=1e-4 * u.arcsec)
    plan = scene.plan()
    assert "jupiter" in plan.kept, str(plan)


@pytest.mark.parametrize("which", ["SAM", "LAM", "near separatrix"])
def test_dropped_torque_bound_holds_against_full_runs(which):
    # A fixed point mass of known strength; its measured effect (full run with vs without it) must stay
    # below the planner's bound. Measured ratios bound/effect: 20-2400 (the bound takes the worst
    # attitude at every instant; the real torque averages out as the body turns).
    states = {
        "SAM": sam_state(),
        "LAM": RotationState.from_euler313(RigidBody([3.0836, 3.235, 1.0]), 145.498 * u.deg, 65.865 * u.deg,
                                           241.524 * u.deg, [14.51, 33.529, -98.709] * u.deg / u.day),
        "near separatrix": RotationState(RigidBody([1.0, 2.0, 3.0]), [1, 0, 0, 0], [1e-3, 1.0, 1e-3]),
    }
    state = states[which]
    mass = FixedPerturber("p", 1e-7 * u.au**3 / u.day**2, [0.3, 0.5, 0.8] * u.au)
    times = EPOCH + np.linspace(5.0, 50.0, 10) * u.day
    scene = Scene(state, EPOCH, times, perturbers=(mass,), tolerance=1e-9 * u.rad)
    plan = scene.plan(skip=False)
    with_mass = scene.run(plan)
    free = Scene(state, EPOCH, times).run()
    measured = worst_difference(with_mass, free)
    bound = plan.estimates["p"].bound_rad
    assert measured <= bound
    assert measured > 100 * with_mass.error_estimate.to_value(u.rad)  # the effect is resolved, not noise


def test_sensitivity_is_measured_large_near_the_separatrix():
    near = RotationState(RigidBody([1.0, 2.0, 3.0]), [1, 0, 0, 0], [1e-3, 1.0, 1e-3])
    assert attitude_sensitivity(near, 50.0) > 10  # measured 88.8
    assert attitude_sensitivity(sam_state(), 50.0) < 1.5  # measured 1.0


# ------------------------------------------------------------------------------------------------
# Skip 3: known orbits from the ephemeris instead of an N-body run.


def moon_scene(orbit, span_days=1.0):
    constants = de421_constants()
    q, omega = moon_orientation(EPOCH)
    state = RotationState(RigidBody(list(constants.moon_moments_over_mr2)), q, omega)
    return Scene(state, EPOCH, EPOCH + np.linspace(0.25, span_days, 4) * u.day, perturbers=("earth", "sun"),
                 orbit=orbit, tolerance=1 * u.arcsec)


def test_known_orbit_uses_de421_instead_of_the_rebound_run():
    sim = simulation_from_de421(EPOCH)
    scene = moon_scene(Orbit.rebound(sim, "Moon"))
    plan = scene.plan()
    assert plan.orbit_source == "de421" and "instead of the REBOUND" in str(plan)
    assert "back-reaction NOT estimated" in str(plan)  # the Moon has mass: no false claim of negligible
    full_plan = scene.plan(skip=False)
    assert full_plan.orbit_source == "rebound"
    measured = worst_difference(scene.run(plan), scene.run(full_plan))
    assert measured <= scene.tolerance_rad  # measured ~1e-7 arcsec: REBOUND reproduces DE421 to metres


def test_unknown_orbit_keeps_the_rebound_run():
    sim = apophis_encounter_simulation("published")
    start = APOPHIS_2029.time_tdb - 0.5 * u.day
    scene = Scene(apophis_rotation_state(), start, start + [0.5, 1.0] * u.day, perturbers=("sun", "earth", "moon"),
                  orbit=Orbit.rebound(sim, "Apophis"), tolerance=1 * u.arcsec)
    plan = scene.plan()
    assert plan.orbit_source == "rebound" and "not a DE421 body" in str(plan)
    assert "massless in the orbit model" in str(plan)
    assert "earth" in plan.kept and "moon" in plan.kept  # the flyby's torques are radians


def test_flyby_with_planets_dropped_stays_within_tolerance_of_the_full_nbody_run():
    # The REBOUND route reuses the planning survey's samples for the kept perturbers; the full run
    # samples everything itself. Measured difference 2.7e-3 arcsec (benchmarks/bench_scene_skips.py).
    sim = apophis_encounter_simulation("published")
    start = APOPHIS_2029.time_tdb - 0.5 * u.day
    scene = Scene(apophis_rotation_state(), start, start + np.linspace(0.1, 1.0, 10) * u.day,
                  perturbers=("sun", "earth", "moon", "venus", "jupiter"), orbit=Orbit.rebound(sim, "Apophis"),
                  tolerance=1 * u.arcsec)
    plan = scene.plan()
    assert set(plan.dropped) == {"venus", "jupiter"} and plan.samples is not None
    skipped, full = scene.run(plan), scene.run(scene.plan(skip=False))
    assert worst_difference(skipped, full) <= scene.tolerance_rad
    assert skipped.error_estimate.to_value(u.rad) <= scene.tolerance_rad


# ------------------------------------------------------------------------------------------------
# Skip 4: only the end.


def test_end_only_gives_one_row_equal_to_the_dense_run():
    times = EPOCH + np.linspace(2.0, 20.0, 5) * u.day
    orbit = Orbit.circular(2.5 * u.au)
    dense = Scene(sam_state(), EPOCH, times, perturbers=("sun",), orbit=orbit, tolerance=1 * u.arcsec)
    end = Scene(sam_state(), EPOCH, times[-1], perturbers=("sun",), orbit=orbit, tolerance=1 * u.arcsec)
    assert end.plan().end_only and not dense.plan().end_only
    assert "end only: one output time" in str(end.plan())
    a, b = end.run(), dense.run()
    assert len(a.table) == 1
    assert _angles(a.table["quaternion"][-1:], b.table["quaternion"][-1:])[0] <= end.tolerance_rad


# ------------------------------------------------------------------------------------------------
# Integrator choice and the singular sets.


def test_elements_asked_away_from_singular_sets_are_used_and_agree():
    times = EPOCH + np.linspace(2.0, 20.0, 3) * u.day
    kwargs = {"perturbers": ("sun",), "orbit": Orbit.circular(2.5 * u.au), "tolerance": 1 * u.arcsec}
    elements = Scene(sam_state(), EPOCH, times, integrator="elements", **kwargs)
    plan = elements.plan()
    assert plan.integrator == "elements"
    measured = worst_difference(elements.run(plan), Scene(sam_state(), EPOCH, times, **kwargs).run())
    assert measured <= elements.tolerance_rad


def test_elements_asked_near_the_separatrix_fall_back_to_quaternions():
    near = RotationState(RigidBody([1.0, 2.0, 3.0]), [1, 0, 0, 0], [1e-3, 1.0, 1e-3])
    scene = Scene(near, EPOCH, EPOCH + 5 * u.day, perturbers=("sun",), orbit=Orbit.circular(2.5 * u.au),
                  tolerance=1e-3 * u.arcsec, integrator="elements")
    plan = scene.plan()
    assert plan.integrator == "quaternion" and "singular sets" in str(plan)


def test_error_estimate_covers_the_difference_to_a_tight_reference():
    times = EPOCH + np.linspace(2.0, 20.0, 5) * u.day
    kwargs = {"perturbers": ("sun", "jupiter"), "orbit": Orbit.circular(2.5 * u.au)}
    loose = Scene(sam_state(), EPOCH, times, tolerance=10 * u.arcsec, **kwargs).run()
    tight = Scene(sam_state(), EPOCH, times, tolerance=1e-5 * u.arcsec, **kwargs)
    reference = tight.run(tight.plan(skip=False))
    measured = worst_difference(loose, reference)
    assert measured <= loose.error_estimate.to_value(u.rad) + reference.error_estimate.to_value(u.rad)
    assert loose.error_estimate <= 10 * u.arcsec


def test_a_tolerance_out_of_reach_is_reported_not_hidden():
    # 200 d at 1e-12 rad: even at rtol 1e-13 the integration estimate is ~1e-9 rad (measured 9.8e-10).
    result = Scene(sam_state(), EPOCH, EPOCH + 200 * u.day, perturbers=("sun",), orbit=Orbit.circular(2.5 * u.au),
                   tolerance=1e-12 * u.rad).run()
    assert result.stats["rtol"] == 1e-13
    assert not result.tolerance_met and result.table.meta["tolerance_met"] is False
    assert result.error_estimate.to_value(u.rad) > 1e-12


def test_plan_reads_like_explain():
    scene = Scene(sam_state(), EPOCH, EPOCH + np.linspace(2.0, 20.0, 5) * u.day, perturbers=("sun", "jupiter"),
                  orbit=Orbit.circular(2.5 * u.au), tolerance=1 * u.arcsec)
    text = str(scene.plan())
    for words in ("perturber jupiter", "dropped", "because", "at most", "arcsec", "integrator", "coupling",
                  "one-way", "docs/performance.md"):
        assert words in text, words
    assert ARCSEC_PER_RAD * scene.plan().dropped_bound_rad < 0.5


# ------------------------------------------------------------------------------------------------
# Bad input.


@pytest.mark.parametrize("change, message", [
    ({"state": "not a state"}, "RotationState"),
    ({"epoch": "2020-01-01"}, "scalar astropy Time"),
    ({"times": [1.0, 2.0]}, "astropy Time"),
    ({"times": EPOCH - 1 * u.day}, "after the epoch"),
    ({"times": EPOCH + [2.0, 1.0] * u.day}, "strictly increasing"),
    ({"tolerance": 1e-6}, "angle Quantity"),
    ({"tolerance": 1 * u.m}, "angle Quantity"),
    ({"tolerance": 1 * u.rad}, "between 1e-12 rad and 0.1 rad"),
    ({"quantities": ("attitude", "spin")}, "quantities"),
    ({"integrator": "rk4"}, "integrator"),
    ({"orbit": None}, "need the body's orbit"),
    ({"orbit": "de421"}, "Orbit.de421"),
    ({"perturbers": (3,)}, "body names"),
    ({"perturbers": ("sun", "sun")}, "twice"),
    ({"sample_tolerance": 1.0}, "sample_tolerance"),
])
def test_bad_inputs_raise_scene_error_in_words(change, message):
    kwargs = {"state": sam_state(), "epoch": EPOCH, "times": EPOCH + 1 * u.day, "perturbers": ("sun",),
                  "orbit": Orbit.circular(2.5 * u.au), "tolerance": 1 * u.arcsec}
    kwargs.update(change)
    with pytest.raises(SceneError, match=message):
        Scene(**kwargs)


def test_bad_names_raise_the_ephemeris_and_rebound_errors():
    with pytest.raises(UnknownBodyError):
        Scene(sam_state(), EPOCH, EPOCH + 1 * u.day, perturbers=("vulcan",), orbit=Orbit.circular(2.5 * u.au))
    with pytest.raises(UnknownBodyError):
        Orbit.de421("vulcan")
    with pytest.raises(MissingBodyError):
        Orbit.rebound(simulation_from_de421(EPOCH), "Apophis")
    with pytest.raises(SceneError, match="no particle named 'vulcan'"):
        Scene(sam_state(), EPOCH, EPOCH + 1 * u.day, perturbers=("vulcan",),
              orbit=Orbit.rebound(simulation_from_de421(EPOCH), "Moon"))
    with pytest.raises(SceneError, match="callable"):
        Orbit.ephemeris("not callable")
    with pytest.raises(SceneError, match="itself"):
        Scene(sam_state(), EPOCH, EPOCH + 1 * u.day, perturbers=("moon",), orbit=Orbit.de421("moon"))


@pytest.mark.parametrize("gm, position, message", [
    (1e-7, [1, 0, 0] * u.au, "gm expects"),
    (1e-7 * u.au**3 / u.day**2, [1, 0, 0], "position expects"),
    (1e-7 * u.au**3 / u.day**2, [0, 0, 0] * u.au, "non-zero"),
    (1e-7 * u.au**3 / u.day**2, [1, 0] * u.au, "shape"),
])
def test_fixed_perturber_bad_input(gm, position, message):
    with pytest.raises(SceneError, match=message):
        FixedPerturber("p", gm, position)


def test_run_refuses_something_that_is_not_a_plan():
    scene = Scene(sam_state(), EPOCH, EPOCH + 1 * u.day)
    with pytest.raises(SceneError, match="Plan"):
        scene.run(plan="fast")
    assert isinstance(scene.plan(), Plan)
