"""The ensemble's batch route against the per-member route: the same rows where the plans agree, honest where not.

Members are Apophis-like encounters on Kepler orbits (``benchmarks/encounter_kepler.py``: the Earth on
a hyperbola passing at 38 000 km, the Sun on an ellipse, both as EphemerisPerturbers), the published
Apophis state at sampled rotation phases and moment ratios. Each batch row is held against the same
member run through its own Scene (``route="member"``).
"""

import concurrent.futures

import numpy as np
import pytest
from astropy import units as u

from benchmarks import encounter_kepler as ek
from spinorbit.core.integrators.batch_quaternion import integrate_quaternion_batch
from spinorbit.core.integrators.dop853 import STATUS_NOT_FINITE
from spinorbit.ensemble import Ensemble, EnsembleError
from spinorbit.ensemble.apophis import apophis_parameters
from spinorbit.ensemble import batch
from spinorbit.scene.bounds import attitude_sensitivities, attitude_sensitivity

GM_EARTH, GM_SUN = 8.887692462968594e-10, 0.0002959122082855911  # DE421, au³/day²
EARTH_STATE = np.array([2.5e-4, 0.3e-4, -0.2e-4, -0.9e-3, 4.0e-3, 0.3e-3])  # 37 000 km, 7.1 km/s (au, au/day)
SUN_STATE = np.array([-0.6, -0.75, 0.1, 0.0135, -0.0105, 0.0008])
FLOAT_COLUMNS = ("energy_ratio", "P_psi", "P_phi", "sidereal_period", "pole_ra", "pole_dec", "pole_lon", "pole_lat",
                 "pole_shift", "P_psi_initial", "P_phi_initial", "sidereal_period_initial", "energy_ratio_initial")


def orbits():
    """The Earth and Sun orbit strings of encounter_kepler, with the perigee of the real encounter's day."""
    perigee = ek.span_days(0.0)[1]
    return tuple(" ".join(repr(float(x)) for x in (mu, *ek.elements_from_state(state, mu), perigee))
                 for state, mu in ((EARTH_STATE, GM_EARTH), (SUN_STATE, GM_SUN)))


def members(n, seed=2029, **extra):
    earth, sun = orbits()
    return [dict(row, earth=earth, sun=sun, span=2.0, **extra) for row in ek.state_rows(apophis_parameters(n, seed))]


def columns(table, name):
    return np.asarray(u.Quantity(table[name]).value if name in FLOAT_COLUMNS + ("error_estimate",) else table[name])


@pytest.fixture(scope="module")
def both():
    rows = members(6)
    batch = Ensemble(ek.kepler_member, rows, chunk_size=3).run(executor="serial")
    member = Ensemble(ek.kepler_member, rows, chunk_size=3, route="member").run(executor="serial")
    return rows, batch, member


def test_the_batch_rows_are_the_per_member_rows(both):
    _, batch, member = both
    assert batch.meta["member_routes"] == {"batch": 6} and member.meta["member_routes"] == {"scene": 6}
    # the encounter turned the spin (otherwise equal rows would say nothing)
    assert np.all(np.abs(columns(batch, "P_phi") - columns(batch, "P_phi_initial")) > 1e-3)
    # the plans agree (both perturbers kept, DOP853 at the Scene's rtol): the integration is the Scene's to
    # the last bit (the batch DOP853 is the scalar one per lane), and so is every column computed from it
    for name in FLOAT_COLUMNS + ("mode", "route", "tolerance_met"):
        assert columns(batch, name).tobytes() == columns(member, name).tobytes(), name
    # the error estimate: the same run and check, the sampling part from the planner's κ
    assert columns(batch, "error_estimate").tobytes() == columns(member, "error_estimate").tobytes()
    assert np.all(batch["tolerance_met"])


def test_the_groups_sensitivity_is_the_planners():
    scenes = [ek.kepler_member(**row) for row in members(4)]
    kappas = attitude_sensitivities([s.state for s in scenes], scenes[0].span_days)
    # a member's κ does not depend on the members computed with it: the planner's own, bit for bit
    assert kappas.tolist() == [attitude_sensitivity(s.state, s.span_days) for s in scenes]
    assert np.all(kappas >= 1.0)


def test_a_members_model_lanes_are_make_models_array_of_its_moments():
    from spinorbit.core import make_model

    scenes = [ek.kepler_member(**row) for row in members(3)]
    samples = scenes[0].sample_perturbers("user", ["earth", "sun"], scenes[0].sample_tolerance)
    moments = [s.state.body.principal_moments for s in scenes]
    models = batch._models(moments, samples.sources())
    for m, member in enumerate(moments):
        alone = make_model(member, samples.sources())
        assert models[m].tobytes() == alone.tobytes() and models[3 + m].tobytes() == alone.tobytes()
    with pytest.raises(ValueError, match="A ≤ B ≤ C"):
        batch._models([(1.0, 0.5, 2.0)], samples.sources())


def test_the_error_estimates_plain_conversion_is_astropys():
    # the batch route converts with astropy's scale factors as plain floats: the Quantity's values, bit for bit
    values = np.random.default_rng(11).random(2000) * 10.0 ** np.random.default_rng(12).integers(-15, 1, 2000)
    for x in values:
        in_arcsec = (float(x) * u.rad).to(u.arcsec)
        assert batch.ARCSEC_PER_RAD * float(x) == in_arcsec.to_value(u.arcsec)
        assert batch.RAD_PER_ARCSEC * (batch.ARCSEC_PER_RAD * float(x)) == in_arcsec.to_value(u.rad)


def test_a_process_pool_gives_the_serial_bits_of_the_batch_route(both):
    rows, batch, _ = both
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        pooled = Ensemble(ek.kepler_member, rows, chunk_size=3).run(executor=pool)
    assert pooled.meta["member_routes"] == {"batch": 6}
    for name in batch.colnames:
        assert columns(pooled, name).tobytes() == columns(batch, name).tobytes(), name


#: A nearly spherical body: (C − A)/A = 1e-5, so the Sun's torque on it stays below half the tolerance.
ROUND = dict(i1_i3=0.99999, i2_i3=0.999995)


def test_a_member_whose_own_plan_drops_more_runs_the_groups_plan_within_its_estimate():
    apophis, rounded = members(2)
    rounded.update(ROUND)
    own = ek.kepler_member(**rounded).plan()
    assert own.dropped == ("sun",)  # its own Scene would leave the Sun out; the Apophis leader keeps it
    table = Ensemble(ek.kepler_member, [apophis, rounded], chunk_size=2).run(executor="serial")
    alone = Ensemble(ek.kepler_member, [rounded], route="member").run(executor="serial")
    assert table.meta["member_routes"] == {"batch": 2}
    # the group kept the Sun (no dropped part) and accepted its first rtol, where the Scene, which pays the
    # drop, retried 100× tighter; both estimates hold: the two runs' poles differ by no more than both together
    from spinorbit.pole import angle_between_deg, directions_from_ra_dec_deg

    poles = [directions_from_ra_dec_deg(t["pole_ra"][k].to_value(u.deg), t["pole_dec"][k].to_value(u.deg))
             for t, k in ((table, 1), (alone, 0))]
    gap = angle_between_deg(*poles)[0] * 3600.0
    assert gap <= table["error_estimate"][1].to_value(u.arcsec) + alone["error_estimate"][0].to_value(u.arcsec)
    assert table["tolerance_met"][1] and alone["tolerance_met"][0]
    assert table["error_estimate"][1] != alone["error_estimate"][0]  # a different plan, not the Scene's row


def test_members_that_cannot_share_the_plan_run_through_their_own_scene():
    apophis, rounded, later = members(3)
    rounded.update(ROUND)
    # the rounded leader drops the Sun; the Apophis member cannot afford that drop: its own Scene runs it
    table = Ensemble(ek.kepler_member, [rounded, apophis], chunk_size=2).run(executor="serial")
    assert table.meta["member_routes"] == {"batch": 1, "scene": 1}
    alone = Ensemble(ek.kepler_member, [apophis], route="member").run(executor="serial")
    for name in FLOAT_COLUMNS + ("error_estimate",):
        assert columns(table, name)[1] == columns(alone, name)[0], name
    # several output times: the batch integrators give end states only, so the member is its Scene's
    times = ek.end_time(2.0) - [1.0, 0.0] * u.day
    several = Ensemble(lambda **row: _with_times(row, times), [later], route="auto", chunk_size=1)
    assert several.run(executor="serial").meta["member_routes"] == {"scene": 1}


def _with_times(row, times):
    scene = ek.kepler_member(**row)
    from spinorbit.scene import Scene

    return Scene(scene.state, scene.epoch, times, perturbers=tuple(scene.moving), tolerance=1 * u.arcsec)


def stopping_batch(y0s, t0, t_end, models, rtol, **options):
    """integrate_quaternion_batch, with every member spinning faster than 30 rad/day stopped (NaN end state, as
    the kernel leaves a member it stops): a pluggable batch integrator that fails chosen members."""
    ys, stats = integrate_quaternion_batch(y0s, t0, t_end, models, rtol, **options)
    stopped = np.linalg.norm(np.asarray(y0s)[:, 4:], axis=1) > 30.0
    ys[stopped] = np.nan
    stats["status"][stopped] = STATUS_NOT_FINITE
    return ys, stats


def test_a_member_stopped_in_the_batch_is_recorded_and_the_others_keep_their_bits(both):
    rows, batch, _ = both
    failing = [dict(row) for row in rows]
    for name in ("omega_x", "omega_y", "omega_z"):  # member 4 ten times faster: > 30 rad/day (the others ~5)
        failing[4][name] *= 10.0
    ensemble = Ensemble(ek.kepler_member, failing, chunk_size=3, batch_integrators={"quaternion": stopping_batch})
    table = ensemble.run(executor="serial")
    [failure] = ensemble.failures
    assert failure["index"] == 4 and failure["type"] == "IntegrationError" and "NaN/inf" in failure["message"]
    assert table["P_psi"].mask[4] and table["error"][4].startswith("IntegrationError")
    for k in (0, 1, 2, 3, 5):  # its group-mates (3, 5) and the other chunk: the bits of the run without it
        for name in FLOAT_COLUMNS + ("error_estimate",):
            assert columns(table, name)[k] == columns(batch, name)[k], (k, name)


def test_bad_route_and_integrators_are_refused():
    with pytest.raises(EnsembleError, match="route expects one of"):
        Ensemble(ek.kepler_member, members(1), route="batch")
    with pytest.raises(EnsembleError, match="batch_integrators expects a dict"):
        Ensemble(ek.kepler_member, members(1), batch_integrators=[integrate_quaternion_batch])
    # the route is part of what fixes the bits: a checkpoint of one route is not another's
    assert Ensemble(ek.kepler_member, members(1)).fingerprint != Ensemble(ek.kepler_member, members(1),
                                                                          route="member").fingerprint


def test_member_zero_leads_every_chunk_so_the_rows_do_not_depend_on_the_chunk_size(both):
    rows, batch, _ = both
    from spinorbit.ensemble.process_memo import _PROCESS_LEADERS, clear_process_samplings

    clear_process_samplings()
    for size in (1, 6):  # every member its own chunk, and one chunk of all: the fixture's chunks of 3 bit for bit
        table = Ensemble(ek.kepler_member, rows, chunk_size=size).run(executor="serial")
        assert table.meta["member_routes"] == {"batch": 6}
        for name in batch.colnames:
            assert columns(table, name).tobytes() == columns(batch, name).tobytes(), (size, name)
    assert len(_PROCESS_LEADERS) == 1  # one leader plan in this process for both runs and all their chunks


def test_members_that_cannot_afford_member_zeros_drops_are_led_by_the_first_of_them():
    rounded, *apophis = members(4)
    rounded.update(ROUND)
    # member 0 drops the Sun, which the Apophis members cannot afford: the two of chunk 1 form their own group
    # (led by the first of them, whose plan keeps the Sun) and still run by the batch route; the one beside
    # member 0 in chunk 0 is alone, so its own Scene runs it
    table = Ensemble(ek.kepler_member, [rounded, *apophis], chunk_size=2).run(executor="serial")
    assert table.meta["member_routes"] == {"batch": 3, "scene": 1}
    alone = Ensemble(ek.kepler_member, apophis, route="member").run(executor="serial")
    for name in FLOAT_COLUMNS + ("error_estimate",):  # their own plans agree with their leaders': their Scene rows
        assert columns(table, name)[1:].tobytes() == columns(alone, name).tobytes(), name


def test_a_member_zero_that_cannot_be_built_leaves_the_others_their_own_leaders(both):
    rows, batch, _ = both
    broken = [dict(rows[0], omega_x=float("nan")), *rows[1:]]
    ensemble = Ensemble(ek.kepler_member, broken, chunk_size=3)
    table = ensemble.run(executor="serial")
    [failure] = ensemble.failures
    assert failure["index"] == 0 and table["error"][0]
    assert table.meta["member_routes"] == {"batch": 5}
    for name in FLOAT_COLUMNS + ("error_estimate",):  # led by their chunks' first members: the same plans here
        assert columns(table, name)[1:].tobytes() == columns(batch, name)[1:].tobytes(), name
