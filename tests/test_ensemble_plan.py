"""Members sharing a sampling reuse what depends on it alone, with the bits of a fresh per-member plan and run.

The planner's a priori grid of a shared sampling (``SharedSamples.grid_of``) is computed once per
samples object, in a chunk and across the chunks of a process; the one-way route's check run is
integrated without a table. Each member of a chunk is held to the same bits as the member planned and
run alone (its own sampling, its own grid), every column and every metadata entry.
"""

import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.scene import Scene
from spinorbit.coupling.one_way import propagate_one_way
from spinorbit.ensemble import state_at_phase
from spinorbit.ensemble.ensemble import run_chunk
from spinorbit.ensemble.process_memo import clear_process_samplings
from spinorbit.scene import EphemerisPerturber, sampling
from spinorbit.scene.routes import attitude_angles
from spinorbit.scene.tolerances import check_tolerance
from spinorbit.state_table import quaternion_array
from spinorbit.time import time_from_tdb_days

BODY = RigidBody([0.61, 0.965, 1.0])
EPOCH = Time("2029-04-08T00:00:00", scale="tdb")
END = EPOCH + 0.2 * u.day
EARTH_GM = 398600.4418 * u.km**3 / u.s**2


def _earth_states(days):
    """An Earth-mass point circling the body at 40 000 km in 1 day (relative ICRF states, au and au/day)."""
    radius, rate = (40000.0 * u.km).to_value(u.au), 2.0 * np.pi
    angle = rate * (np.asarray(days, dtype=float) - 10690.0)
    positions = radius * np.stack([np.cos(angle), np.sin(angle), 0.0 * angle], axis=1)
    velocities = radius * rate * np.stack([-np.sin(angle), np.cos(angle), 0.0 * angle], axis=1)
    return positions, velocities


EARTH = EphemerisPerturber("earth", EARTH_GM, _earth_states, relative=True)


def member(phase):
    state = state_at_phase(RotationState(BODY, [1.0, 0.0, 0.0, 0.0], [0.3, 0.1, 2.0] * u.rad / u.day), phase)
    return Scene(state, EPOCH, END, perturbers=(EARTH,))


PHASES = [0.0, 0.3, 0.55, 0.8]


def _bits(table):
    columns = [(name, (table[name].isot if name == "time" else np.asarray(getattr(table[name], "value", table[name])))
                .tobytes()) for name in table.colnames]
    return columns, {key: repr(value) for key, value in table.meta.items()}


def test_members_reusing_the_shared_plan_pieces_give_the_bits_of_fresh_per_member_plans(monkeypatch):
    grids = []
    real = sampling.grid_of_samples
    monkeypatch.setattr(sampling, "grid_of_samples", lambda *args: grids.append(1) or real(*args))
    clear_process_samplings()
    rows, failures, tables = run_chunk(member, [(i, {"phase": p}) for i, p in enumerate(PHASES[:2])], keep_tables=True)
    assert len(grids) == 1  # one grid for the chunk's shared sampling, not one per member
    more, more_failures, more_tables = run_chunk(member, [(i, {"phase": p}) for i, p in enumerate(PHASES[2:], 2)],
                                                 keep_tables=True)
    assert len(grids) == 1  # the next chunk of this process reuses it with the sampling
    assert not failures and not more_failures
    rows.update(more)
    tables.update(more_tables)
    for i, phase in enumerate(PHASES):
        alone = member(phase).run()  # its own sampling and its own grid, nothing shared
        assert alone.plan.route == "one-way" and "knots" in str(alone.plan)
        assert _bits(tables[i]) == _bits(alone.table), i
        assert rows[i]["error_estimate"] == alone.error_estimate.to_value(u.arcsec)
    assert len(grids) == 1 + len(PHASES)


def test_plans_sharing_a_sampling_say_what_fresh_plans_say():
    shared = sampling.SharedSamples()
    for phase in PHASES:
        scene = member(phase)
        with scene.sharing_samples(shared):
            planned = scene.plan()
        assert str(planned) == str(member(phase).plan())  # the knot counts of the integrator choice included


def test_the_check_without_a_table_is_the_error_of_the_two_tabled_runs():
    scene = member(0.3)
    result = scene.run()
    plan, rtol = result.plan, result.stats["rtol"]
    samples = scene.sample_perturbers("user", ["earth"], scene.sample_tolerance)
    epoch, times = time_from_tdb_days(scene.epoch_day), time_from_tdb_days(scene.output_days)
    run = propagate_one_way(scene.state, epoch, times, samples, rtol=rtol, integrator=plan.integrator)
    check = propagate_one_way(scene.state, epoch, times, samples, rtol=check_tolerance(plan.integrator, rtol),
                              periods=False, integrator=plan.integrator)
    angle = float(np.max(attitude_angles(quaternion_array(run), quaternion_array(check))))
    assert result.error_parts["integration"].to_value(u.arcsec) == (angle * u.rad).to_value(u.arcsec)
    assert _bits(run)[0] == [(n, b) for n, b in _bits(result.table)[0] if n in run.colnames]
