"""A state belongs to its epoch: a Scene runs from it forwards and backwards (spinorbit.scene.epochs).

References: the exact free motion at negative times; a direct backward DOP853 run
(``propagate_one_way`` integrates towards earlier times natively) on the same samples, against which
the mirrored-time leg is checked; and the same time asked for inside spans of different lengths
and directions.
"""

from __future__ import annotations

import numpy as np
import pytest
from _offline import no_network  # noqa: F401
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.coupling.one_way import propagate_one_way
from spinorbit.coupling.sampling import sample_from_ephemeris
from spinorbit.scene import Orbit, Scene
from spinorbit.scene.epochs import LegPlans
from spinorbit.scene.routes import attitude_angles
from spinorbit.state_table import omega_array, quaternion_array

EPOCH = Time("2020-01-01", scale="tdb")
#: A Sun 0.05 au away on a 4-day circle: a torque that changes the spin visibly within days.
ORBIT = Orbit.circular(0.05 * u.au)
TOLERANCE = 5e-2 * u.arcsec


def state():
    return RotationState.from_euler313(RigidBody([0.61, 0.965, 1.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg,
                                       [5, 3, 40] * u.deg / u.hour)


def row_at(result, when):
    k = int(np.argmin(np.abs((result.table["time"] - when).to_value(u.day))))
    assert abs((result.table["time"][k] - when).to_value(u.s)) < 1e-3
    return result.table[k]


def test_backward_torque_free_is_the_exact_free_motion_at_negative_times():
    times = EPOCH - [10.0, 2.0, 1.0] * u.day
    result = Scene(state(), EPOCH, times).run()
    quaternions, omegas = state().propagate_torque_free([-10.0, -2.0, -1.0] * u.day)
    assert np.max(attitude_angles(quaternion_array(result.table), quaternions)) < 1e-13
    assert np.allclose(omega_array(result.table), omegas.to_value(u.rad / u.day),
                       rtol=0, atol=1e-12)
    assert np.all(np.diff((result.table["time"] - EPOCH).to_value(u.day)) > 0)


def test_backward_leg_matches_a_direct_backward_integration():
    """The mirrored-time leg against DOP853 integrating towards earlier times on the same DE421-free
    samples of the circle: equal to 2e-9 rad (each run's own error, rtol 1e-12, is ≈ 1e-10 rad; the
    torque turns the attitude by ≈ 0.3 rad from the free motion over the 6 days)."""
    times = EPOCH - np.array([6.0, 3.0, 0.5]) * u.day
    result = Scene(state(), EPOCH, times, perturbers=("sun",), orbit=ORBIT, tolerance=TOLERANCE).run()
    samples = sample_from_ephemeris(ORBIT.function, EPOCH - 7 * u.day, EPOCH, perturbers=("sun",), tolerance=1e-11)
    direct = propagate_one_way(state(), EPOCH, times[::-1], samples, rtol=1e-12)
    assert np.max(attitude_angles(quaternion_array(result.table), quaternion_array(direct)[::-1])) < 2e-9
    free, _ = state().propagate_torque_free([-6.0] * u.day)
    assert attitude_angles(quaternion_array(result.table)[:1], free)[0] > 1e-3  # the torque matters here


def test_the_state_at_a_time_does_not_depend_on_the_span_asked_for():
    """The same two times (3 d before and 2 d after the epoch) inside four spans: backward only, around
    the epoch, forward only, end only. They agree to twice the tolerance (5e-2″; each run's estimate is below
    it), where placing the state at each span's start would differ by the spin's whole evolution."""
    before, after = EPOCH - 3 * u.day, EPOCH + 2 * u.day
    spans = {
        "backward": EPOCH - np.linspace(5.0, 0.5, 10) * u.day,
        "around": EPOCH + np.linspace(-8.0, 4.0, 13) * u.day,
        "forward": EPOCH + np.linspace(0.5, 2.0, 4) * u.day,
        "end before": before,
        "end after": after,
    }
    results = {label: Scene(state(), EPOCH, times, perturbers=("sun",), orbit=ORBIT, tolerance=TOLERANCE).run()
               for label, times in spans.items()}
    for result in results.values():
        assert result.tolerance_met
    limit = 2 * TOLERANCE.to_value(u.rad)
    for group, when in ((("backward", "around", "end before"), before), (("around", "forward", "end after"), after)):
        rows = [row_at(results[label], when) for label in group]
        for other in rows[1:]:
            assert attitude_angles(quaternion_array(rows[0]), quaternion_array(other))[0] < limit
            assert np.allclose(omega_array(rows[0]), omega_array(other), rtol=1e-8)
    assert isinstance(results["around"].plan, LegPlans)
    assert "backward leg" in str(results["around"].plan) and "forward leg" in str(results["around"].plan)


def test_a_time_at_the_epoch_is_the_state_itself():
    times = EPOCH + [-1.0, 0.0, 1.0] * u.day
    result = Scene(state(), EPOCH, times, perturbers=("sun",), orbit=ORBIT, tolerance=TOLERANCE).run()
    assert attitude_angles(quaternion_array(result.table)[1:2], state().quaternion)[0] == 0.0
    assert result.table["P_psi"].shape == (3,)
    worse = max((result.stats[leg] for leg in ("backward", "forward")), key=lambda s: s.get("rtol", 0))
    assert worse  # both legs ran
    assert sum(result.error_parts.values()).to_value(u.arcsec) == pytest.approx(
        result.error_estimate.to_value(u.arcsec), rel=1e-12)
    only = Scene(state(), EPOCH, EPOCH, perturbers=("sun",), orbit=ORBIT, tolerance=TOLERANCE).run()
    assert len(only.table) == 1 and only.error_estimate.to_value(u.arcsec) == 0.0
    assert attitude_angles(quaternion_array(only.table), state().quaternion)[0] == 0.0


@pytest.fixture(scope="module")
def apophis_orbit():
    from spinorbit.data.asteroids import apophis_encounter_simulation

    return Orbit.rebound(apophis_encounter_simulation("published"), "Apophis")


def test_apophis_after_the_encounter_does_not_depend_on_the_span(apophis_orbit):
    """The issue's case: spans of 4, 6 and 14 d around the 2029 perigee (the last with a backward leg
    from the state's epoch, 5 d before perigee, through a REBOUND orbit read backwards) and the end
    alone all give the same state 2 d after perigee, to twice the tolerance (1″), where placing the
    published state at each span's start gave SAM 156 h, LAM 268 h, SAM 243 h."""
    from spinorbit.data.asteroids import APOPHIS_2029, APOPHIS_STATE_EPOCH, apophis_rotation_state

    perigee = APOPHIS_2029.time_tdb
    when = perigee + 2 * u.day
    spans = {"4 d": perigee + np.linspace(-2.0, 2.0, 9) * u.day, "6 d": perigee + np.linspace(-3.0, 2.0, 11) * u.day,
             "14 d": perigee + np.linspace(-12.0, 2.0, 15) * u.day, "end": when}
    rows = []
    for times in spans.values():
        result = Scene(apophis_rotation_state(), APOPHIS_STATE_EPOCH, times, perturbers=("sun", "earth", "moon"),
                       orbit=apophis_orbit, tolerance=0.5 * u.arcsec).run()
        assert result.tolerance_met
        rows.append(row_at(result, when))
    for other in rows[1:]:
        assert attitude_angles(quaternion_array(rows[0]), quaternion_array(other))[0] < 2 * (0.5 * u.arcsec).to_value(u.rad)
        assert other["P_psi"].to_value(u.h) == pytest.approx(rows[0]["P_psi"].to_value(u.h), abs=1e-4)
    assert rows[0]["mode"] == "SAM" and abs(rows[0]["P_psi"].to_value(u.h) - 263.0) > 10  # the encounter acted


def test_several_bodies_around_the_epoch_equal_their_single_scenes():
    """Two bodies with times on both sides of the epoch: each body's rows are those of its own scene."""
    other = RotationState.from_euler313(RigidBody([0.5, 0.8, 1.0], name="b"), 1 * u.deg, 2 * u.deg, 3 * u.deg,
                                        [1, 2, 30] * u.deg / u.hour)
    first = RotationState(RigidBody([0.61, 0.965, 1.0], name="a"), state().quaternion, state().angular_velocity)
    times = EPOCH + np.linspace(-3.0, 3.0, 7) * u.day
    both = Scene([first, other], EPOCH, times, perturbers=("sun",), orbit=ORBIT, tolerance=TOLERANCE).run()
    for name, single_state in (("a", first), ("b", other)):
        single = Scene(single_state, EPOCH, times, perturbers=("sun",), orbit=ORBIT, tolerance=TOLERANCE).run()
        assert np.max(attitude_angles(quaternion_array(both[name].table), quaternion_array(single.table))) < 1e-12
