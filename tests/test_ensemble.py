"""spinorbit.ensemble: the same bits on every executor, resumes that run only what is missing, failures kept.

The executors are real: a ``ProcessPoolExecutor`` and a Dask ``LocalCluster`` of two worker processes
(``dask_client`` in ``tests/conftest.py``, started once for the test run). Workers die for real (``os._exit`` inside a member, in the worker).
"""

import concurrent.futures
import os
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.scene import Scene
from spinorbit.ensemble import Ensemble, EnsembleError, EnsembleInterrupted, Normal, SamplerError, Uniform
from spinorbit.ensemble import member_seed, sample_parameters
from spinorbit.ensemble import state_at_phase
from spinorbit.ensemble.store import ChunkStore
from spinorbit.runs.checkpoint import CheckpointError
from spinorbit.ensemble.process_memo import clear_process_samplings
from spinorbit.scene import EphemerisPerturber, FixedPerturber

BODY = RigidBody([0.61, 0.965, 1.0])
EPOCH = Time("2029-04-08T00:00:00", scale="tdb")
END = EPOCH + 0.2 * u.day
#: An Earth-mass point at 40 000 km: torques strong enough that the planner keeps it (E/E0 moves by ~1e-3).
EARTH_GM = 398600.4418 * u.km**3 / u.s**2
N_MEMBERS, CHUNK = 8, 2


def member(phase, distance_km=40000.0, torque=True, fail=False, die_marker="", main_pid=0, log=""):
    """A small tumbler (Apophis's moments) at a rotation phase, torqued by a fixed Earth-mass point."""
    if log and os.getpid() != main_pid:
        with open(log, "a") as stream:
            stream.write(f"{phase!r}\n")
    if die_marker and os.getpid() != main_pid and not os.path.exists(die_marker):
        open(die_marker, "w").close()
        os._exit(1)  # the worker process dies here, for real
    if fail:
        raise ValueError(f"member asked to fail at phase {phase}")
    state = state_at_phase(RotationState(BODY, [1.0, 0.0, 0.0, 0.0], [0.3, 0.1, 2.0] * u.rad / u.day), phase)
    perturbers = (FixedPerturber("earth", EARTH_GM, [distance_km, 0.0, 0.0] * u.km),) if torque else ()
    return Scene(state, EPOCH, END, perturbers=perturbers)


def phases(n=N_MEMBERS, **extra):
    return [dict(phase=float(p), **extra) for p in np.linspace(0.0, 0.875, n)]


NUMERIC = ("energy_ratio", "P_psi", "P_phi", "sidereal_period", "pole_ra", "pole_dec", "pole_lon", "pole_lat",
           "pole_shift", "error_estimate")


def assert_same_bits(a, b):
    assert a.colnames == b.colnames
    for name in a.colnames:
        left, right = np.asarray(u.Quantity(a[name]).value if name in NUMERIC else a[name]), \
            np.asarray(u.Quantity(b[name]).value if name in NUMERIC else b[name])
        assert left.tobytes() == right.tobytes(), name


@pytest.fixture(scope="module")
def serial():
    ensemble = Ensemble(member, phases(), chunk_size=CHUNK)
    return ensemble.run(executor="serial")


def test_serial_run_has_one_row_per_member_in_order_with_its_outcome(serial):
    assert len(serial) == N_MEMBERS
    assert list(serial["phase"]) == [row["phase"] for row in phases()]
    assert set(serial["route"]) == {"one-way"} and all(serial["tolerance_met"]) and not any(serial["error"])
    # each row is the member's own Scene run, at the end
    alone = member(float(serial["phase"][3])).run()
    assert serial["P_psi"][3] == alone.table["P_psi"][-1]
    assert serial["error_estimate"][3] == alone.error_estimate
    assert serial["P_psi"].unit == u.h and serial["pole_ra"].unit == u.deg
    # the torque moved the spin: E/E0 differs from its initial value (otherwise the test could not fail)
    assert np.all(np.abs(serial["energy_ratio"] - serial["energy_ratio_initial"]) > 1e-6)


def test_process_pool_and_dask_give_the_serial_bits(serial, dask_client):
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        pooled = Ensemble(member, phases(), chunk_size=CHUNK).run(executor=pool)
    assert_same_bits(serial, pooled)
    by_dask = Ensemble(member, phases(), chunk_size=CHUNK)
    assert_same_bits(serial, by_dask.run(executor=dask_client))
    assert by_dask.last_run["members_in_process"] == 0 and "Dask" in by_dask.last_run["executor"]
    one_worker = Ensemble(member, phases(), chunk_size=CHUNK).run(executor=1)
    assert_same_bits(serial, one_worker)


def test_resume_after_a_dask_worker_dies_runs_only_the_missing_members(serial, dask_client, tmp_path):
    marker, log = tmp_path / "died", tmp_path / "log"
    rows = phases(main_pid=os.getpid(), log=str(log))
    rows[-1]["die_marker"] = str(marker)  # the last member kills its worker the first time it is built there
    params = [dict(r, die_marker=r.get("die_marker", "")) for r in rows]
    checkpoint = tmp_path / "chunks"
    ensemble = Ensemble(member, params, chunk_size=CHUNK)
    with pytest.raises(EnsembleInterrupted, match="run again|Call run"):
        ensemble.run(executor=dask_client, checkpoint=checkpoint)
    assert marker.exists()
    stored = sorted(p.name for p in checkpoint.iterdir() if p.name.startswith("chunk-"))  # not the manifest, lock
    assert 0 < len(stored) < N_MEMBERS // CHUNK
    done_chunks = {int(name[6:12]) for name in stored}
    missing = [i for i in range(N_MEMBERS) if i // CHUNK not in done_chunks]
    log.write_text("")
    fresh = Ensemble(member, params, chunk_size=CHUNK)  # a new process would start from the files alone
    table = fresh.run(executor=dask_client, checkpoint=checkpoint)
    assert fresh.last_run["members_restored"] == N_MEMBERS - len(missing)
    ran = [float(line) for line in log.read_text().split()]
    assert sorted(ran) == sorted(params[i]["phase"] for i in missing)  # only the missing members were built
    for name in NUMERIC + ("mode", "route"):
        assert np.asarray(u.Quantity(table[name]).value if name in NUMERIC else table[name]).tobytes() == \
            np.asarray(u.Quantity(serial[name]).value if name in NUMERIC else serial[name]).tobytes(), name


def test_resume_after_a_process_pool_worker_dies(serial, tmp_path):
    marker = tmp_path / "died"
    params = phases(main_pid=os.getpid(), die_marker="")
    params[5]["die_marker"] = str(marker)
    checkpoint = tmp_path / "chunks"
    with pytest.raises(EnsembleInterrupted, match="BrokenProcessPool"):
        Ensemble(member, params, chunk_size=CHUNK).run(executor=2, checkpoint=checkpoint)
    resumed = Ensemble(member, params, chunk_size=CHUNK)
    table = resumed.run(executor="serial", checkpoint=checkpoint)
    assert resumed.last_run["members_run"] + resumed.last_run["members_restored"] == N_MEMBERS
    assert resumed.last_run["members_run"] < N_MEMBERS or resumed.last_run["members_restored"] == 0
    for name in NUMERIC:
        assert u.Quantity(table[name]).value.tobytes() == u.Quantity(serial[name]).value.tobytes(), name


def test_a_failing_member_is_recorded_masked_and_rerun_alone(serial, tmp_path):
    params = phases(fail=False)
    params[3]["fail"] = True
    ensemble = Ensemble(member, params, chunk_size=CHUNK)
    table = ensemble.run(executor="serial", checkpoint=tmp_path)
    [failure] = ensemble.failures
    assert failure["index"] == 3 and failure["type"] == "ValueError" and "asked to fail" in failure["message"]
    assert failure["parameters"]["phase"] == repr(params[3]["phase"])
    assert table["error"][3].startswith("ValueError: member asked to fail") and table["error"][2] == ""
    assert table["P_psi"].mask[3] and not table["P_psi"].mask[2]
    assert table.meta["failures"] == [failure]
    # a second process reads the failure back from the checkpoint, and reruns the member once it is fixed
    ensemble.parameters["fail"][3] = False
    again = Ensemble(member, ensemble.parameters, chunk_size=CHUNK)
    with pytest.raises(CheckpointError, match="another ensemble"):
        again.run(executor="serial", checkpoint=tmp_path)  # the parameters changed: its fingerprint differs
    restored = Ensemble(member, params, chunk_size=CHUNK)
    assert restored.run(checkpoint=tmp_path, executor="serial") is not None and restored.last_run["members_run"] == 0
    assert restored.failures == [failure]
    restored.make_scene = lambda **p: member(**{**p, "fail": False})  # the member's cause fixed (a code change)
    fixed = restored.rerun([3])
    assert not any(fixed["error"]) and not np.ma.is_masked(fixed["P_psi"][3])
    assert fixed["P_psi"][3] == serial["P_psi"][3]  # alone it gives the bits it gives in its chunk


def test_torque_free_members_stay_in_process_and_match_their_scenes():
    ensemble = Ensemble(member, phases(torque=False), chunk_size=CHUNK)
    table = ensemble.run(executor=2)
    assert ensemble.last_run["members_in_process"] == N_MEMBERS and set(table["route"]) == {"torque-free"}
    for i in (0, 5):
        alone = member(float(table["phase"][i]), torque=False).run().table
        assert table["mode"][i] == alone["mode"][-1]
        # constants of the motion: the Scene takes them from the state's properties, the ensemble from the
        # vectorised kernel; the end pole of the Scene differs by the propagated momentum's rounding
        for name in ("energy_ratio", "P_psi", "P_phi", "sidereal_period"):
            assert u.Quantity(table[name][i]).value == pytest.approx(u.Quantity(alone[name][-1]).value, rel=1e-13)
        for name in ("pole_ra", "pole_dec"):
            assert u.Quantity(table[name][i]).to_value(u.deg) == pytest.approx(alone[name][-1].to_value(u.deg),
                                                                              abs=1e-10)


def test_outcomes_at_named_times():
    times = EPOCH + [0.1, 0.2] * u.day
    ensemble = Ensemble(lambda **p: _timed(**p), phases(2), at=times)
    table = ensemble.run(executor="serial")
    alone = _timed(0.0).run().table
    assert table["P_psi_t0"][0] == alone["P_psi"][1] and table["P_psi_t1"][0] == alone["P_psi"][2]
    # a time the member does not output is that member's failure, with the reason
    missed = Ensemble(lambda **p: _timed(**p), phases(1), at=EPOCH + 0.15 * u.day)
    missed.run(executor="serial")
    [failure] = missed.failures
    assert failure["type"] == "EnsembleError" and "not among the member's output times" in failure["message"]


def _timed(phase):
    state = state_at_phase(RotationState(BODY, [1.0, 0.0, 0.0, 0.0], [0.3, 0.1, 2.0] * u.rad / u.day), phase)
    return Scene(state, EPOCH, EPOCH + [0.0, 0.1, 0.2] * u.day,
                 perturbers=(FixedPerturber("earth", EARTH_GM, [40000.0, 0.0, 0.0] * u.km),))


def test_sampled_parameters_come_from_one_seed_per_member():
    small = sample_parameters(3, seed=42, phase=Uniform(0.0, 1.0), ratio=Uniform(0.61 * u.one, 0.64 * u.one))
    large = sample_parameters(10, seed=42, phase=Uniform(0.0, 1.0), ratio=Uniform(0.61 * u.one, 0.64 * u.one))
    assert list(large["phase"][:3]) == list(small["phase"])  # member i does not depend on n
    row = large[7]
    rng = np.random.default_rng(member_seed(row["seed_entropy"], row["seed_spawn_key"]))
    assert rng.uniform(0.0, 1.0) == row["phase"]  # rebuilt from the two recorded columns alone
    assert np.all((large["ratio"] >= 0.61) & (large["ratio"] < 0.64))
    other = sample_parameters(3, seed=43, phase=Uniform(0.0, 1.0))
    assert list(other["phase"]) != list(small["phase"])
    fresh = sample_parameters(2, phase=Uniform(0, 1))  # no seed: fresh entropy, recorded to rebuild the draws
    assert fresh["phase"][1] == np.random.default_rng(member_seed(fresh.meta["seed_entropy"], 1)).uniform(0, 1)
    spins = sample_parameters(500, seed=1, spin=Normal(2.0 * u.rad / u.day, 0.1 * u.rad / u.day))
    assert spins["spin"].unit == u.rad / u.day
    assert abs(np.mean(spins["spin"].value) - 2.0) < 4 * 0.1 / np.sqrt(500)  # 4 sigma of the mean of 500 draws
    with pytest.raises(SamplerError, match="sigma > 0"):
        sample_parameters(1, spin=Normal(1.0, 0.0))
    with pytest.raises(SamplerError, match="low < high"):
        sample_parameters(1, phase=Uniform(1.0, 0.5))


def test_progress_reports_members_done_in_order_up_to_all():
    seen = []
    Ensemble(member, phases(), chunk_size=3).run(executor="serial", progress=lambda done, total: seen.append((done, total)))
    assert seen == [(0, 8), (3, 8), (6, 8), (8, 8)]


def test_state_at_phase_moves_along_the_free_motion_only():
    from spinorbit.data.asteroids import apophis_rotation_state

    start = apophis_rotation_state(0.0)
    moved = state_at_phase(start, 0.3, 0.25)
    assert moved.mode == start.mode and moved.energy_ratio == pytest.approx(start.energy_ratio, rel=1e-13)
    assert np.allclose(moved.angular_momentum_direction, start.angular_momentum_direction, atol=1e-13)
    assert not np.allclose(moved.quaternion, start.quaternion, atol=1e-3)
    # along P_psi alone it is the data module's own phase; the two take P_psi by different routes
    # (the summary's double AGM, ≤ 7 ulp from the double-double one), so they agree to rounding
    assert np.allclose(state_at_phase(start, 0.3).quaternion, apophis_rotation_state(0.3).quaternion, rtol=0, atol=1e-14)


def test_bad_inputs_say_what_was_expected():
    with pytest.raises(EnsembleError, match="QTable or a non-empty list of dicts"):
        Ensemble(member, 3)
    with pytest.raises(EnsembleError, match="chunk_size expects a positive"):
        Ensemble(member, phases(), chunk_size=0)
    with pytest.raises(EnsembleError, match="same keys"):
        Ensemble(member, [dict(phase=0.0), dict(other=1.0)])
    from spinorbit.ensemble import ExecutorError

    with pytest.raises(ExecutorError, match="concurrent.futures.Executor"):
        Ensemble(member, phases(1)).run(executor="threads?")
    with pytest.raises(EnsembleError, match="rerun expects member indices"):
        Ensemble(member, phases(1)).rerun([5])


def test_a_corrupted_chunk_file_is_refused(tmp_path):
    ensemble = Ensemble(member, phases(2, torque=False), chunk_size=1)
    ensemble.run(executor="serial", checkpoint=tmp_path)
    path = Path(ChunkStore(tmp_path, ensemble.fingerprint).path(1))
    data = bytearray(path.read_bytes())
    data[40] ^= 1  # one bit of the header
    path.write_bytes(bytes(data))
    with pytest.raises(CheckpointError, match="corrupted"):
        Ensemble(member, phases(2, torque=False), chunk_size=1).run(executor="serial", checkpoint=tmp_path)


def test_apophis_command_runs_an_ensemble_and_writes_one_row_per_member(tmp_path, capsys):
    from astropy.table import QTable

    from spinorbit import cli

    output, plot = tmp_path / "members.ecsv", tmp_path / "members.png"
    status = cli.main(["apophis", "--members", "2", "--workers", "1", "--seed", "7", "--span", "1", "d",
                       "--output", str(output), "--plot", str(plot)])
    printed = capsys.readouterr().out
    assert status == 0, printed
    assert "pole shift" in printed and "failures           0" in printed and "modes after" in printed
    table = QTable.read(output)
    assert len(table) == 2 and list(table["seed_spawn_key"]) == [0, 1] and plot.stat().st_size > 10_000
    assert np.all(table["P_psi_initial"].to_value(u.h) == pytest.approx(263.0, rel=1e-9))
    assert cli.main(["apophis", "--workers", "2"]) == 2  # an ensemble option without --members
    assert "add --members" in capsys.readouterr().err


@pytest.mark.slow
def test_the_embedded_dask_cluster_gives_the_serial_bits(serial):
    # executor="dask": a LocalCluster of worker processes started and closed by the run itself
    embedded = Ensemble(member, phases(), chunk_size=CHUNK)
    assert_same_bits(serial, embedded.run(executor="dask"))
    assert "embedded Dask LocalCluster" in embedded.last_run["executor"]


def _earth_states(days):
    """An Earth-mass point circling the body at 40 000 km in 1 day (relative ICRF states, au and au/day)."""
    SAMPLED_DAYS.append(np.size(days))
    radius, rate = (40000.0 * u.km).to_value(u.au), 2.0 * np.pi
    angle = rate * (np.asarray(days, dtype=float) - 10690.0)
    positions = radius * np.stack([np.cos(angle), np.sin(angle), 0.0 * angle], axis=1)
    velocities = radius * rate * np.stack([-np.sin(angle), np.cos(angle), 0.0 * angle], axis=1)
    return positions, velocities


SAMPLED_DAYS = []
MOVING_EARTH = EphemerisPerturber("earth", EARTH_GM, _earth_states, relative=True)


def moving_member(phase):
    state = state_at_phase(RotationState(BODY, [1.0, 0.0, 0.0, 0.0], [0.3, 0.1, 2.0] * u.rad / u.day), phase)
    return Scene(state, EPOCH, END, perturbers=(MOVING_EARTH,))


def test_a_process_samples_a_shared_orbit_once_across_chunks_with_the_bits_of_a_fresh_sampling():
    clear_process_samplings()
    SAMPLED_DAYS.clear()
    calls_after_chunk = []
    ensemble = Ensemble(moving_member, [dict(phase=p) for p in np.linspace(0.0, 0.875, 8)], chunk_size=2)
    table = ensemble.run(executor="serial", progress=lambda done, total: calls_after_chunk.append(len(SAMPLED_DAYS)))
    assert set(table["route"]) == {"one-way"} and not any(table["error"])
    # the first chunk samples the orbit; the three others reuse it (before: each chunk sampled again)
    assert calls_after_chunk[1] > 0 and calls_after_chunk[1:] == [calls_after_chunk[1]] * 4
    for i in (0, 5):  # each member alone samples afresh: the same bits
        alone = moving_member(float(table["phase"][i])).run()
        assert table["P_psi"][i] == alone.table["P_psi"][-1] and table["pole_ra"][i] == alone.table["pole_ra"][-1]
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        pooled = Ensemble(moving_member, [dict(phase=p) for p in np.linspace(0.0, 0.875, 8)], chunk_size=2)
        assert_same_bits(table, pooled.run(executor=pool))
