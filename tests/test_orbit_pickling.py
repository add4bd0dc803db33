"""An Orbit and a Scene cross process boundaries with their physics (issue 36, class 6).

REBOUND pickles a simulation as its binary, without the compiled extra forces' pointer: a pickled
REBOUND orbit ran without Earth's J2 and EIH, silently (the contrast is measured below). An
:class:`~spinorbit.scene.Orbit` now pickles to its description and is rebuilt on arrival; the runs
are compared bit for bit: after pickle and cloudpickle round trips, in a spawn-started process pool,
and on a real Dask ``LocalCluster`` of worker processes with ``make_scene`` shipped by value with
its cached orbit (as a script's ``__main__`` is). A ``make_scene`` a worker cannot load is reported
with its own cause.
"""

import concurrent.futures
import multiprocessing
import pickle
import sys

import cloudpickle
import numpy as np
import pytest
import rebound
from astropy import units as u

import _orbit_members as members
from spinorbit.ensemble import Ensemble
from spinorbit.scene import Orbit, Scene, SceneError

ROWS = [dict(phase=0.4 * k) for k in range(4)]
COMPARED = ("q_w", "q_x", "q_y", "q_z", "omega_x", "omega_y", "omega_z", "P_psi", "energy_ratio")
OUTCOMES = ("P_psi", "P_phi", "energy_ratio", "pole_ra", "pole_dec", "error_estimate")


def table_bits(table):
    return {name: np.asarray(u.Quantity(table[name]).value).tobytes() for name in COMPARED}


def outcome_bits(table):
    return {name: np.asarray(u.Quantity(table[name]).value).tobytes() for name in OUTCOMES}


@pytest.fixture(scope="module")
def scene_and_result():
    scene = members.member(0.3)
    return scene, scene.run()


@pytest.fixture(scope="module")
def serial():
    return Ensemble(members.member, ROWS, chunk_size=2).run(executor="serial")


@pytest.mark.parametrize("module", [pickle, cloudpickle], ids=["pickle", "cloudpickle"])
def test_a_scene_on_a_rebound_orbit_pickles_to_the_same_physics(scene_and_result, module):
    scene, result = scene_and_result
    assert result.plan.route == "one-way" and result.plan.kept == ("earth",)  # the orbit matters here
    copy = module.loads(module.dumps(scene))
    assert copy.orbit.simulation is not scene.orbit.simulation
    assert table_bits(copy.run().table) == table_bits(result.table)


def test_rebounds_own_pickling_would_have_changed_the_spin(scene_and_result):
    # What the Orbit no longer does: REBOUND's binary alone, its extra forces lost (REBOUND only warns).
    scene, result = scene_and_result
    with pytest.warns(RuntimeWarning, match="reset function pointers"):
        raw = pickle.loads(pickle.dumps(scene.orbit.simulation))
    lossy = Scene(scene.state, scene.epoch, scene.times, perturbers=("earth",),
                  orbit=Orbit("rebound", scene.orbit.name, simulation=raw), tolerance=0.01 * u.arcsec).run()
    change = abs(lossy.table["P_psi"][-1] - result.table["P_psi"][-1]).to_value(u.h)
    assert change > 1e-4  # measured 1.5e-3 h: Earth's J2 at 60 000 km, lost with the force pointer


def test_an_orbit_with_forces_spinorbit_cannot_carry_refuses_to_be_pickled():
    sim = rebound.Simulation()
    sim.units = ("AU", "day", "Msun")
    sim.add(m=1.0)
    sim.add(a=1.0)
    sim.particles[0].name, sim.particles[1].name = "sun", "rock"
    sim.additional_forces = lambda reb_sim: None  # a Python force: no copy can carry it
    orbit = Orbit.rebound(sim, "rock")
    with pytest.raises(SceneError, match="the orbit of 'rock' cannot be pickled .*forces or hooks spinorbit did not"):
        pickle.dumps(orbit)


def test_a_spawn_started_pool_gives_the_serial_bits(scene_and_result, serial):
    scene, result = scene_and_result
    with concurrent.futures.ProcessPoolExecutor(max_workers=1, mp_context=multiprocessing.get_context("spawn")) as pool:
        remote = pool.submit(members.run_table, scene).result()  # the Scene itself crosses
        table = Ensemble(members.member, ROWS, chunk_size=2).run(executor=pool)
    assert table_bits(remote) == table_bits(result.table)
    assert outcome_bits(table) == outcome_bits(serial)


def test_make_scene_shipped_by_value_with_its_cached_orbit_gives_the_serial_bits_on_dask(serial, dask_client):
    # The script: make_scene in __main__ (here: registered to go by value), its orbit cached in a
    # dict that this process filled (it builds the first member), so the Orbit travels inside the function.
    members.orbit()
    cloudpickle.register_pickle_by_value(members)
    try:
        table = Ensemble(members.member, ROWS, chunk_size=2).run(executor=dask_client)
    finally:
        cloudpickle.unregister_pickle_by_value(members)
    assert not any(table["error"]) and outcome_bits(table) == outcome_bits(serial)


def test_a_make_scene_the_workers_cannot_load_is_reported_with_its_cause(dask_client, tmp_path, monkeypatch):
    # a module only this process can import (the workers started before its directory was on the path)
    (tmp_path / "only_here_members.py").write_text("import _orbit_members\n\n\ndef member(phase):\n"
                                                   "    return _orbit_members.member(phase)\n")
    monkeypatch.syspath_prepend(str(tmp_path))
    import only_here_members

    missing = Ensemble(only_here_members.member, ROWS[:2], chunk_size=2)
    try:
        table = missing.run(executor=dask_client)
    finally:
        sys.modules.pop("only_here_members", None)
    assert [f["type"] for f in missing.failures] == ["ModuleNotFoundError"] * 2
    assert "No module named 'only_here_members'" in missing.failures[0]["message"]
    assert "could not be loaded in the worker process" in str(table["error"][0])
    # a name the workers' copy of the module does not have
    def ghost(phase):
        return members.member(phase)

    ghost.__module__, ghost.__qualname__ = members.__name__, "ghost"  # found there here, by reference
    monkeypatch.setattr(members, "ghost", ghost, raising=False)
    absent = Ensemble(members.ghost, ROWS[:2], chunk_size=2)
    absent.run(executor=dask_client)
    assert [f["type"] for f in absent.failures] == ["AttributeError"] * 2
    assert "ghost" in absent.failures[0]["message"]
