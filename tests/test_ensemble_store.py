"""A checkpoint directory belongs to one ensemble: locked while it runs, its seed kept for a resume (issue 36).

The members are torque-free (one vectorised call, milliseconds), so that these tests are about the
directory alone; the lock is a real ``flock``, held by a real second process in one test.
"""

import subprocess
import sys
import time

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.ensemble import Ensemble, Uniform
from spinorbit.ensemble.store import LOCK_NAME, MANIFEST_NAME, ChunkStore, stored_seed
from spinorbit.runs.checkpoint import CheckpointError
from spinorbit.scene import Scene

EPOCH = Time("2029-04-08T00:00:00", scale="tdb")


def free_member(spin=2.0, wobble=0.1):
    state = RotationState(RigidBody([0.61, 0.965, 1.0]), [1.0, 0.0, 0.0, 0.0], [0.3, wobble, spin] * u.rad / u.day)
    return Scene(state, EPOCH, EPOCH + 1.0 * u.day)


def rows(n=4, spin=2.0):
    return [dict(spin=spin + 0.1 * k) for k in range(n)]


def test_another_ensemble_is_refused_at_once_naming_what_differs(tmp_path):
    table = Ensemble(free_member, rows(), chunk_size=2).run(executor="serial", checkpoint=tmp_path)
    assert (tmp_path / MANIFEST_NAME).exists() and not any(table["error"])
    with pytest.raises(CheckpointError, match=r"differ in the values of parameter column spin\b"):
        Ensemble(free_member, rows(spin=3.0), chunk_size=2).run(executor="serial", checkpoint=tmp_path)
    with pytest.raises(CheckpointError, match=r"chunk size \(2 there, 4 here\)"):
        Ensemble(free_member, rows(), chunk_size=4).run(executor="serial", checkpoint=tmp_path)
    with pytest.raises(CheckpointError, match=r"parameter columns \(\['spin'\] there, \['spin', 'wobble'\] here\)"):
        Ensemble(free_member, [dict(r, wobble=0.1) for r in rows()], chunk_size=2).run(executor="serial",
                                                                                        checkpoint=tmp_path)
    again = Ensemble(free_member, rows(), chunk_size=2)  # the ensemble the directory holds resumes
    again.run(executor="serial", checkpoint=tmp_path)
    assert again.last_run["members_restored"] == 4 and again.last_run["members_run"] == 0


def test_a_directory_in_use_is_refused_in_this_process_and_from_another(tmp_path):
    ensemble = Ensemble(free_member, rows(), chunk_size=2)
    with ChunkStore(tmp_path, ensemble.fingerprint, ensemble.identity):  # a run under way holds the lock
        with pytest.raises(CheckpointError, match="in use by another running ensemble"):
            Ensemble(free_member, rows(), chunk_size=2).run(executor="serial", checkpoint=tmp_path)
    # another process holds it (flock on the same file, as a running ensemble does)
    holder = subprocess.Popen([sys.executable, "-c", "import fcntl, sys, time\n"
                               f"f = open({str(tmp_path / LOCK_NAME)!r}, 'a+'); fcntl.flock(f, fcntl.LOCK_EX)\n"
                               "print('locked', flush=True); time.sleep(60)"], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        with pytest.raises(CheckpointError, match=r"in use by another running ensemble \(process"):
            Ensemble(free_member, rows(), chunk_size=2).run(executor="serial", checkpoint=tmp_path)
    finally:
        holder.kill()
        holder.wait()
        holder.stdout.close()
    time.sleep(0.05)
    table = Ensemble(free_member, rows(), chunk_size=2).run(executor="serial", checkpoint=tmp_path)  # freed with it
    assert len(table) == 4 and not any(table["error"])


def test_a_sampled_ensemble_stores_its_seed_for_a_resume(tmp_path):
    first = Ensemble.sampled(free_member, 6, seed=None, chunk_size=3, spin=Uniform(1.0, 3.0))
    table = first.run(executor="serial", checkpoint=tmp_path)
    assert not any(table["error"])
    seed = stored_seed(tmp_path)
    assert seed is not None and str(seed) == table.meta["seed_entropy"]
    resumed = Ensemble.sampled(free_member, 6, seed=seed, chunk_size=3, spin=Uniform(1.0, 3.0))
    again = resumed.run(executor="serial", checkpoint=tmp_path)
    assert resumed.last_run["members_restored"] == 6
    assert np.asarray(again["spin"]).tobytes() == np.asarray(table["spin"]).tobytes()
    other = Ensemble.sampled(free_member, 6, seed=seed + 1, chunk_size=3, spin=Uniform(1.0, 3.0))
    with pytest.raises(CheckpointError, match=f"the members' seeds \\(seed entropy {seed} there, {seed + 1} here\\)"):
        other.run(executor="serial", checkpoint=tmp_path)
    assert stored_seed(tmp_path / "missing") is None


def test_the_apophis_command_prints_its_seed_and_resumes_without_it(tmp_path, capsys):
    from spinorbit import cli

    directory = str(tmp_path / "chunks")
    command = ["apophis", "--members", "2", "--workers", "1", "--span", "1", "d", "--checkpoint-dir", directory]
    assert cli.main(command) == 0
    first = capsys.readouterr().out
    seed = int(first.split("seed", 1)[1].split()[0])
    assert f"(fresh; --seed {seed} draws the same members; stored in '{directory}'" in first
    assert seed == stored_seed(directory)
    assert cli.main(command) == 0  # the same command, still without --seed: everything restored
    second = capsys.readouterr().out
    assert f"seed               {seed} (stored in '{directory}'" in second
    assert "0 members run, 2 restored from the checkpoint" in second
