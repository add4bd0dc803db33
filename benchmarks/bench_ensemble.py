"""Ensembles: members per second of the Apophis encounter ensemble on 1 and 2 workers, and the scaling model.

The ensemble is :mod:`spinorbit.ensemble.apophis` (phase uniform on the free motion's torus, moment
ratios between the two published solutions, the Sun's, Earth's and Moon's torques on the published
REBOUND orbit, 1 arcsec), ``--members`` members with the default chunks. Timed: the whole
``Ensemble.run`` in this process (1 worker) and on a ``ProcessPoolExecutor`` of 2 workers, each
started fresh, so the 2-worker time includes the pool's start and each worker's first orbit. The
two tables are checked equal bit for bit.

The scaling model, T(W) = T_setup(W) + n · c / W + (n / chunk) · o / W, is written down from three
measured pieces: c, the per-member cost (the serial run's time per member after its first chunk);
o, the executor's overhead per task (a process pool's and a Dask LocalCluster's round trip of an
empty task, the median of 200); and the data moved per member (the pickled task and result bytes
of one chunk, divided by its members). T_setup(2) is measured as the 2-worker run's time before its
first chunk came back. The model's T(2) is compared with the measured one, and extrapolated to
more workers (a prediction, not a measurement).

Against heyoka (:func:`measure_peer`): heyoka cannot call REBOUND, so both engines integrate the
encounter on Keplerian orbits fitted to it (``encounter_kepler.py``: the Earth's geocentric
hyperbola, Apophis's heliocentric ellipse); each member's end attitude is compared with heyoka at
tol 1e-15, heyoka gets the loosest tolerance as accurate as spinorbit's worst member and its faster
compact mode, and ``ensemble_propagate_until`` is timed with threads and processes on 1 and 2 workers
next to spinorbit's Ensemble in this process, on a new pool and on a started pool.

Torque-free members (:func:`measure_free`): CPU per member of the array route
(``free_members_table``, with and without the flow's attitudes) and of the Scene route.

Usage::

    python benchmarks/bench_ensemble.py                 # writes the 'ensemble' section of docs/performance.md
    python benchmarks/bench_ensemble.py --no-write      # print only
"""

from __future__ import annotations

import argparse
import concurrent.futures
import os
import pickle
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np
from _report import interleaved_timings, machine_line, write_section

MEMBERS = 48
TASKS = 200


def _empty(x):
    return x


def task_overhead(pool):
    """Median seconds of one empty task's round trip through ``pool`` (submitted one after another)."""
    pool.submit(_empty, 0).result()  # warm
    samples = []
    for i in range(TASKS):
        start = time.perf_counter()
        pool.submit(_empty, i).result()
        samples.append(time.perf_counter() - start)
    return statistics.median(samples)


def timed_run(ensemble, executor):
    first = []
    clock = time.perf_counter()

    def progress(done, total):
        if done and not first:
            first.append(time.perf_counter() - clock)

    table = ensemble.run(executor=executor, progress=progress)
    return table, time.perf_counter() - clock, first[0] if first else float("nan")


def measure(members):
    from spinorbit.ensemble import Ensemble
    from spinorbit.ensemble.apophis import apophis_member, apophis_parameters, encounter_orbit
    from spinorbit.ensemble.ensemble import build_member

    load_before = os.getloadavg()[0]
    parameters = apophis_parameters(members, seed=2029)
    encounter_orbit()  # the orbit of this process, as a worker builds its own: not in the serial timing
    # compile or load from the numba cache both routes (the Scene's and the batch one), so that neither timed
    # run below pays it and the forked workers start as warm as this process
    build_member(apophis_member, Ensemble(apophis_member, parameters).member_parameters(0)).run()
    Ensemble(apophis_member, parameters[:1]).run(executor="serial")
    from spinorbit.ensemble.process_memo import clear_process_samplings

    clear_process_samplings()  # each timed run samples the orbit once per process, as a fresh run does
    serial = Ensemble(apophis_member, parameters)
    table_1, wall_1, first_1 = timed_run(serial, "serial")
    clear_process_samplings()  # the pool's workers start from this process (fork): not from its samplings
    chunk = serial.chunk_size
    per_member = (wall_1 - first_1) / (members - chunk)
    pooled = Ensemble(apophis_member, parameters)
    table_2, wall_2, first_2 = timed_run(pooled, 2)
    same = all(np.asarray(getattr(table_1[n], "value", table_1[n])).tobytes()
               == np.asarray(getattr(table_2[n], "value", table_2[n])).tobytes() for n in table_1.colnames)
    from spinorbit.ensemble.ensemble import run_chunk

    shipped = [(i, serial.member_parameters(i)) for i in serial.chunk_members(0)]
    sent = len(pickle.dumps((apophis_member, shipped, None, False)))
    returned = len(pickle.dumps(run_chunk(apophis_member, shipped)))
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        overhead_pool = task_overhead(pool)
    overhead_dask = None
    try:
        from spinorbit.ensemble.executors import DaskExecutor, dask_client

        client = dask_client(workers=2)
        try:
            overhead_dask = task_overhead(DaskExecutor(client))
        finally:
            cluster = client.cluster
            client.close()
            cluster.close()
    except ImportError:
        pass
    return dict(members=members, chunk=chunk, wall_1=wall_1, wall_2=wall_2, first_2=first_2, per_member=per_member,
                same=same, sent=sent / len(shipped), returned=returned / len(shipped), overhead_pool=overhead_pool,
                overhead_dask=overhead_dask, load=(load_before, os.getloadavg()[0]))


def model(m, workers, setup):
    chunks = -(-m["members"] // m["chunk"])
    return setup + m["members"] * m["per_member"] / workers + chunks * m["overhead_pool"] / workers


def markdown(m):
    predicted_2 = model(m, 2, m["first_2"] - m["chunk"] * m["per_member"])
    lines = ["## Ensembles (`benchmarks/bench_ensemble.py`)", "", machine_line(), "",
             f"The Apophis encounter ensemble (`spinorbit.ensemble.apophis`, {m['members']} members, chunks of "
             f"{m['chunk']}), each run fresh:", "",
             "| workers | wall (s) | members/s | parallel efficiency |", "|---|---|---|---|",
             f"| 1 (in this process) | {m['wall_1']:.2f} | {m['members'] / m['wall_1']:.2f} | 1 |",
             f"| 2 (process pool, started in the run) | {m['wall_2']:.2f} | {m['members'] / m['wall_2']:.2f} | "
             f"{m['wall_1'] / (2 * m['wall_2']):.2f} |", "",
             f"The two tables are {'the same bits' if m['same'] else 'NOT the same bits'} in every float column.",
             "", "Scaling model T(W) = T_setup(W) + n c / W + (n / chunk) o / W, from measured pieces:", "",
             f"- per-member cost c = {m['per_member'] * 1e3:.0f} ms (the serial run after its first chunk);",
             f"- overhead per task o = {m['overhead_pool'] * 1e3:.2f} ms (process pool, empty task, median of {TASKS})"
             + (f", {m['overhead_dask'] * 1e3:.2f} ms (Dask LocalCluster)" if m['overhead_dask'] else "") + ";",
             f"- data moved per member: {m['sent']:.0f} bytes out, {m['returned']:.0f} bytes back (pickled);",
             f"- T_setup(2) = {m['first_2'] - m['chunk'] * m['per_member']:.2f} s: the pool's start and each worker's "
             "first sampling of the orbit before its first chunk (the workers are forked from this process, which "
             "has built the orbit; a worker samples it once and keeps it for its later chunks).", "",
             f"Model T(2) = {predicted_2:.2f} s against {m['wall_2']:.2f} s measured. The model assumes two free "
             f"cores; the 1-minute load average was {m['load'][0]:.1f} before and {m['load'][1]:.1f} after the "
             "measurement (other processes on the machine's cores). The model does not include that load, and this "
             "measurement cannot separate it from other causes of the gap. With the same setup and free cores the "
             "model predicts " + ", ".join(f"{w} workers {model(m, w, m['first_2'] - m['chunk'] * m['per_member']):.1f} s"
                                           for w in (4, 16, 64)) + " (extrapolated, not measured; it ignores the "
             "last chunk's tail, which grows as the chunks per worker fall). The task overhead and the data moved "
             "are small against c, so on free cores the efficiency is set by the setup against the run's length."]
    return "\n".join(lines)


# ------------------------------------------------------------------------------------ torque-free members

FREE_MEMBERS = 1_000_000
FREE_SCENES = 2000


def _free_arrays(n, seed=5):
    rng = np.random.default_rng(seed)
    moments = np.stack([rng.uniform(0.5, 0.9, n), rng.uniform(0.9, 0.99, n), np.ones(n)], axis=1)
    quaternions = rng.normal(size=(n, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1)[:, None]
    return moments, quaternions, rng.normal(size=(n, 3)) * 2.0


def free_scene(i):
    """Torque-free member i as a Scene (the per-member route), the same states as :func:`_free_arrays`."""
    from astropy import units as u

    from spinorbit import RigidBody, RotationState
    from spinorbit.scene import Scene
    from spinorbit.data.asteroids import APOPHIS_STATE_EPOCH

    moments, quaternions, omegas = _FREE_SCENE_ARRAYS
    state = RotationState(RigidBody(moments[i]), quaternions[i], omegas[i] * u.rad / u.day)
    return Scene(state, APOPHIS_STATE_EPOCH, APOPHIS_STATE_EPOCH + 3.0 * u.day)


_FREE_SCENE_ARRAYS = _free_arrays(FREE_SCENES)


def measure_free():
    """CPU seconds per member of the torque-free routes: arrays (with and without attitudes), Scenes."""
    from spinorbit.ensemble import Ensemble, free_members_table
    from spinorbit.ensemble.free import torque_free_rows

    from astropy import units as u

    moments, quaternions, omegas = _free_arrays(FREE_MEMBERS)
    omegas, elapsed = omegas * u.rad / u.day, 3.0 * u.day
    free_members_table(moments[:4], quaternions[:4], omegas[:4], elapsed, attitudes=True)  # compile / cache load
    timings, _ = interleaved_timings(
        [lambda: free_members_table(moments, quaternions, omegas, elapsed),
         lambda: free_members_table(moments, quaternions, omegas, elapsed, attitudes=True)], 3,
        clock=time.process_time)
    scenes = [free_scene(i) for i in range(FREE_SCENES)]
    rows_cpu, _ = interleaved_timings([lambda: torque_free_rows(scenes)], 3, clock=time.process_time)
    whole, _ = interleaved_timings([lambda: Ensemble(free_scene, [dict(i=i) for i in range(FREE_SCENES)]).run(
        executor="serial")], 3, clock=time.process_time)
    return dict(arrays=timings[0].median / FREE_MEMBERS, arrays_flow=timings[1].median / FREE_MEMBERS,
                rows=rows_cpu[0].median / FREE_SCENES, ensemble=whole[0].median / FREE_SCENES)


def markdown_free(f):
    return "\n".join([
        "### Torque-free members", "",
        f"CPU per member (median of 3, interleaved), {FREE_MEMBERS:,} members as arrays "
        "(`spinorbit.ensemble.free_members_table`, random moments, attitudes and spins) and "
        f"{FREE_SCENES:,} as Scenes (`Ensemble(make_scene, ...)`, the same states):", "",
        "| route | µs per member | members/s |", "|---|---|---|",
        f"| arrays: outcome columns (constants of the motion, the pole) | {f['arrays'] * 1e6:.2f} | "
        f"{1 / f['arrays']:.3g} |",
        f"| arrays, with the exact flow to the outcome time (attitudes, pole from the flowed state) | "
        f"{f['arrays_flow'] * 1e6:.2f} | {1 / f['arrays_flow']:.3g} |",
        f"| Scenes already built: their rows (`torque_free_rows`, one vectorised call) | {f['rows'] * 1e6:.1f} | "
        f"{1 / f['rows']:.3g} |",
        f"| `Ensemble.run` of Scenes (make_scene, a RotationState and a Scene per member, then the rows) | "
        f"{f['ensemble'] * 1e6:.0f} | {1 / f['ensemble']:.3g} |", "",
        "A member's numbers are the same bits on every route and in any batch (`tests/test_ensemble_free.py`). "
        "Building a Scene per member costs far more than its outcome; a study of millions of torque-free "
        "members passes its states as arrays."])


# ------------------------------------------------------------------------------------ heyoka's ensemble

PEER_MEMBERS = 64
PEER_REPEATS = 5
REFERENCE_TOL = 1e-15
HEYOKA_TOLS = (1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12)


def _attitude_error(q, reference):
    """Rotation angle (rad) between unit quaternions (rows), sign-blind: 4 asin(|q ∓ q_ref| / 2)."""
    d = np.minimum(np.linalg.norm(q - reference, axis=1), np.linalg.norm(q + reference, axis=1))
    return 4.0 * np.arcsin(np.minimum(d / 2.0, 1.0))


def _propagate_each(ta, setter, n, t_end):
    out = np.empty((n, 7))
    for i in range(n):
        setter(ta, i)
        ta.propagate_until(t_end)
        out[i] = ta.state[:7]
    out[:, :4] /= np.linalg.norm(out[:, :4], axis=1)[:, None]
    return out


def _timed_ensemble(ensemble_run):
    clock = time.perf_counter()
    result = ensemble_run()
    return time.perf_counter() - clock, result


def measure_peer(members):
    """spinorbit's Ensemble and heyoka's ensemble_propagate_until on the Kepler encounter, at equal accuracy."""
    import heyoka as hy
    from astropy.table import QTable

    import encounter_kepler as ek
    from spinorbit.ensemble import Ensemble
    from spinorbit.ensemble.apophis import apophis_parameters
    from spinorbit.ensemble.ensemble import run_chunk
    from spinorbit.ensemble.process_memo import clear_process_samplings
    from spinorbit.state_table import QUATERNION_COLUMNS

    load = [os.getloadavg()[0]]
    earth, sun = ek.encounter_orbits()
    rows = [dict(row, earth=earth, sun=sun) for row in ek.state_rows(apophis_parameters(members, seed=2029))]
    parameters = QTable({k: [r[k] for r in rows] for k in rows[0]})
    t0, t_end = ek.span_days()
    states, pars, _ = ek.heyoka_members(rows, earth, sun)
    setter = ek.MemberSetter(states, pars, t0)
    reference = _propagate_each(ek.heyoka_integrator(earth, sun, REFERENCE_TOL), setter, members, t_end)

    # spinorbit: the members' own Scene runs (the ensemble's bits) against the reference, untimed
    run_chunk(ek.kepler_member, [(0, rows[0])])  # compile / cache load, the orbit's sampling of this process
    ends = [ek.kepler_member(**row).run().table[-1] for row in rows]
    spin_q = np.array([[float(end[c]) for c in QUATERNION_COLUMNS] for end in ends])
    spin_error = _attitude_error(spin_q, reference[:, :4])

    # heyoka: the loosest tolerance whose worst member is as accurate as spinorbit's worst member
    errors = {}
    for tol in HEYOKA_TOLS:
        errors[tol] = _attitude_error(_propagate_each(ek.heyoka_integrator(earth, sun, tol), setter, members,
                                                      t_end)[:, :4], reference[:, :4])
        if errors[tol].max() <= spin_error.max():
            break
    tol = next((t for t in HEYOKA_TOLS if t in errors and errors[t].max() <= spin_error.max()), HEYOKA_TOLS[-1])
    modes = {mode: ek.heyoka_integrator(earth, sun, tol, compact_mode=mode) for mode in (False, True)}
    mode_cpu, _ = interleaved_timings([lambda m=m: _propagate_each(modes[m], setter, members, t_end)
                                       for m in (False, True)], 3, clock=time.process_time)
    # the ensemble copies the integrator per member: its faster mode is timed on the ensemble itself
    mode_ensemble, _ = interleaved_timings([lambda m=m: hy.ensemble_propagate_until(
        modes[m], t_end, members, setter, algorithm="thread", max_workers=1) for m in (False, True)], 3)
    compact = mode_ensemble[1].median < mode_ensemble[0].median
    ta = modes[compact]
    import copy

    copy_s, _ = interleaved_timings([lambda: copy.deepcopy(ta)], 20)  # what the thread ensemble does per member

    # the floor under spinorbit's Scenes: the core integrator alone on the plan's model, rtol and samples
    from spinorbit.core import integrate_quaternion, make_model

    first = ek.kepler_member(**rows[0])
    result = first.run()
    samples = first.sample_perturbers("user", list(result.plan.kept), first.sample_tolerance)
    rtol = result.stats["rtol"]

    def core_loop():
        out = np.empty((members, 7))
        for i, row in enumerate(rows):
            model = make_model((row["i1_i3"], row["i2_i3"], 1.0), samples.sources())
            out[i] = integrate_quaternion(states[i, :7], t0, np.array([t_end]), model, rtol=rtol)[-1]
        return out

    core_cpu, (core_states,) = interleaved_timings([core_loop], 3, clock=time.process_time, warm_up=True)
    core_error = _attitude_error(core_states[:, :4] / np.linalg.norm(core_states[:, :4], axis=1)[:, None],
                                 reference[:, :4])

    stages = measure_stages(ek, rows[:Ensemble(ek.kepler_member, parameters).chunk_size])

    # the batch route's rows are the Scene runs' integration: their poles, bit for bit
    batch_table = Ensemble(ek.kepler_member, parameters).run(executor="serial")
    scene_pole = np.array([[float(end[c].to_value("deg")) for c in ("pole_ra", "pole_dec")] for end in ends])
    batch_pole = np.stack([batch_table[c].to_value("deg") for c in ("pole_ra", "pole_dec")], axis=1)
    batch_is_scene = batch_pole.tobytes() == scene_pole.tobytes()
    routes = batch_table.meta["member_routes"]

    # one new pool (its start, each worker's imports, compilation cache and sampling), timed once
    chunk = Ensemble(ek.kepler_member, parameters).chunk_size
    clear_process_samplings()
    fresh, table_2 = _timed_ensemble(lambda: Ensemble(ek.kepler_member, parameters).run(executor=2))
    clear_process_samplings()  # a process's first member samples the orbits (survey and run), the later reuse them
    cold, _ = _timed_ensemble(lambda: Ensemble(ek.kepler_member, parameters[:1]).run(executor="serial"))
    warm, _ = _timed_ensemble(lambda: Ensemble(ek.kepler_member, parameters[:1]).run(executor="serial"))
    sampling = cold - warm
    # interleaved rounds, every process warm (compiled, the orbit sampled): spinorbit's batch route in this
    # process and on a started pool of 2, its per-member route here; heyoka's threads and processes, 1 and 2
    with concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool:
        warm_workers(pool, rows[0])  # both workers imported and compiled, the orbit sampled
        engines = {("batch", 1): lambda: Ensemble(ek.kepler_member, parameters).run(executor="serial"),
                   ("batch", 2): lambda: Ensemble(ek.kepler_member, parameters).run(executor=pool),
                   ("member", 1): lambda: Ensemble(ek.kepler_member, parameters, route="member").run(executor="serial")}
        for algorithm in ("thread", "process"):
            for workers in (1, 2):
                engines[algorithm, workers] = (lambda a=algorithm, w=workers: hy.ensemble_propagate_until(
                    ta, t_end, members, setter, algorithm=a, max_workers=w))
        timings, results = interleaved_timings(list(engines.values()), PEER_REPEATS)
    timed = dict(zip(engines, timings))
    table_1, pooled = results[0], results[1]
    same = all(np.asarray(getattr(table_1[n], "value", table_1[n])).tobytes()
               == np.asarray(getattr(t[n], "value", t[n])).tobytes() for t in (pooled, table_2) for n in table_1.colnames)
    batch_cpu, batch_error, lanes = _heyoka_batch(ek, earth, sun, tol, compact, states, pars, t0, t_end, reference)
    shipped = [(i, rows[i]) for i in range(chunk)]
    sent = len(pickle.dumps((ek.kepler_member, shipped, None, False))) / chunk
    returned = len(pickle.dumps(run_chunk(ek.kepler_member, shipped))) / chunk
    load.append(os.getloadavg()[0])
    return dict(members=members, chunk=chunk, timed=timed, fresh=fresh, tol=tol, compact=compact,
                spin_error=spin_error, heyoka_error=errors[tol], same=same, per_member=timed["batch", 1].median / members,
                sent=sent, returned=returned, load=load, heyoka_cpu=mode_cpu[int(compact)].median / members,
                core_cpu=core_cpu[0].median / members, core_error=core_error, rtol=rtol, batch_cpu=batch_cpu,
                copy_s=copy_s[0].median, stages=stages, batch_error=batch_error, lanes=lanes, routes=routes,
                batch_is_scene=batch_is_scene, sampling=sampling,
                repeats=len(timings[0].samples))


def measure_stages(ek, rows, repeats=3):
    """CPU ms per member of each stage of the batch route on one chunk of Kepler members, warm, sharing one
    sampling as a worker does (:mod:`spinorbit.ensemble.batch`).

    Stages: building the member (``make_scene``: RotationState and Scene); the group plan (the leader's
    Scene plan, made once per process: divided here among one chunk's members); the member's own bounds (κ from the vectorised
    free flow, the worst-attitude bound of each perturber); its models and the integration (the run and
    its check at 10× the rtol in one batch call); its outcome row from the end state.
    """
    from spinorbit.core.integrators.batch_quaternion import integrate_quaternion_batch
    from spinorbit.ensemble import batch
    from spinorbit.ensemble.ensemble import build_member
    from spinorbit.scene.bounds import attitude_sensitivities
    from spinorbit.scene.sampling import SharedSamples

    shared = SharedSamples()  # what a worker's chunk holds once the orbit is sampled
    leader = build_member(ek.kepler_member, rows[0])
    with leader.sharing_samples(shared):
        leader.run()

    def chunk():
        spent = dict(build=0.0, plan=0.0, bounds=0.0, integration=0.0, rows=0.0)
        clock = time.process_time()
        scenes = [build_member(ek.kepler_member, row) for row in rows]
        spent["build"] += time.process_time() - clock
        clock = time.process_time()
        with scenes[0].sharing_samples(shared):
            plan = scenes[0].plan()
            survey = batch._survey(scenes[0], plan)
            sources, _, _ = batch._kept_sources(scenes[0], plan)
        spent["plan"] += time.process_time() - clock
        clock = time.process_time()
        kappas = attitude_sensitivities([s.state for s in scenes], scenes[0].span_days)
        moments = np.array([s.state.body.principal_moments for s in scenes])
        momenta = np.array([s.state.body.moment_values * s.state.angular_velocity.value for s in scenes])
        batch._member_bounds(survey, scenes[0].output_days[-1], moments, momenta, kappas)
        spent["bounds"] += time.process_time() - clock
        clock = time.process_time()
        y0s = np.array([s.state.core_state() for s in scenes])
        n = len(scenes)
        ends, _, _ = batch._integrate(plan.integrator, integrate_quaternion_batch, [s.state.body for s in scenes],
                                      y0s, scenes[0].epoch_day, float(scenes[0].output_days[-1]),
                                      batch._models(moments, sources), np.full(n, plan.rtol),
                                      np.full(n, plan.integration_share_rad))
        spent["integration"] += time.process_time() - clock
        clock = time.process_time()
        batch._rows(scenes, ends, None, moments, momenta)
        spent["rows"] += time.process_time() - clock
        return spent

    rounds = [chunk() for _ in range(repeats)]
    return {k: statistics.median(r[k] for r in rounds) / len(rows) for k in rounds[0]}


def _heyoka_batch(ek, earth, sun, tol, compact, states, pars, t0, t_end, reference):
    """heyoka's batch mode (``taylor_adaptive_batch``, the recommended SIMD width, its own step per lane)
    over the members, lanes filled in member order: (CPU per member, attitude errors, lanes)."""
    import heyoka as hy

    lanes = hy.recommended_simd_size()
    n = states.shape[0]
    ta = hy.taylor_adaptive_batch(ek.heyoka_system(earth, sun), np.zeros((13, lanes)), tol=tol,
                                  compact_mode=compact, pars=np.zeros((9, lanes)))

    def run():
        out = np.empty((n, 7))
        for start in range(0, n, lanes):
            index = [min(start + k, n - 1) for k in range(lanes)]  # the last batch padded with its last member
            ta.set_time(np.full(lanes, t0))
            ta.state[:] = states[index].T
            ta.pars[:] = pars[index].T
            ta.propagate_until(t_end)
            out[start:start + lanes] = ta.state[:7].T[:min(lanes, n - start)]
        out[:, :4] /= np.linalg.norm(out[:, :4], axis=1)[:, None]
        return out

    timing, (out,) = interleaved_timings([run], 3, clock=time.process_time, warm_up=True)
    return timing[0].median / n, _attitude_error(out[:, :4], reference[:, :4]), lanes


def _burn(n):
    total = 0
    for i in range(n):
        total += i * i
    return total


def machine_efficiency(pool_1, pool_2, n=4_000_000):
    """The machine's own parallel efficiency now: the same pure-Python loop twice on the started worker of
    ``pool_1``, then once on each of the 2 started workers of ``pool_2`` (what two workers of any engine get
    from the cores now, measured the way the ensemble's efficiency is)."""
    pool_1.submit(_burn, 10).result()
    clock = time.perf_counter()
    pool_1.submit(_burn, n).result()
    pool_1.submit(_burn, n).result()
    serial = time.perf_counter() - clock
    list(pool_2.map(_burn, [10, 10]))
    clock = time.perf_counter()
    list(pool_2.map(_burn, [n, n]))
    return serial / (2 * (time.perf_counter() - clock))


EFFICIENCY_MEMBERS = 24
EFFICIENCY_REPEATS = 7
#: Heavier members for the parallel-efficiency goal (members of ≥ 50 ms): 500 days after the perigee at 0.01 arcsec,
#: about 60 ms each here (a margin over 50 ms, so that a faster machine still tests the goal's members).
HEAVY = dict(span=1000.0, tolerance_arcsec=0.01)


def measure_efficiency(members=EFFICIENCY_MEMBERS, repeats=EFFICIENCY_REPEATS):
    """One started worker against two started workers for members of ≥ 50 ms, interleaved.

    Efficiency is T(1 worker) / (2 T(2 workers)) with both pools of the same kind (worker processes, warm:
    compiled, the orbit sampled), so the ratio compares the same work on one and on two cores and not a
    worker against this process. Each round also runs the ensemble in this process (``executor="serial"``)
    and the pure-Python calibration (:func:`machine_efficiency`), one after the other, so every column of
    a round sees nearly the same load. A new pool (its start, imports and sampling included) is timed once.
    """
    from astropy.table import QTable

    import encounter_kepler as ek
    from spinorbit.ensemble import Ensemble
    from spinorbit.ensemble.apophis import apophis_parameters
    from spinorbit.ensemble.process_memo import clear_process_samplings

    load = [os.getloadavg()[0]]
    earth, sun = ek.encounter_orbits()
    rows = [dict(row, earth=earth, sun=sun, **HEAVY) for row in ek.state_rows(apophis_parameters(members, seed=7))]
    parameters = QTable({k: [r[k] for r in rows] for k in rows[0]})
    clear_process_samplings()
    fresh, _ = _timed_ensemble(lambda: Ensemble(ek.kepler_member, parameters).run(executor=2))
    Ensemble(ek.kepler_member, parameters[:1]).run(executor="serial")  # this process warm, the orbit sampled
    serial, one, two, machine, tables = [], [], [], [], []
    with concurrent.futures.ProcessPoolExecutor(max_workers=1) as pool_1, \
            concurrent.futures.ProcessPoolExecutor(max_workers=2) as pool_2:
        warm_workers(pool_1, rows[0], workers=1)
        warm_workers(pool_2, rows[0])
        for _ in range(repeats):
            for times, executor in ((serial, "serial"), (one, pool_1), (two, pool_2)):
                seconds, table = _timed_ensemble(lambda: Ensemble(ek.kepler_member, parameters).run(executor=executor))
                times.append(seconds)
                tables.append(table)
            machine.append(machine_efficiency(pool_1, pool_2))
    same = all(np.asarray(getattr(t[n], "value", t[n])).tobytes()
               == np.asarray(getattr(tables[0][n], "value", tables[0][n])).tobytes()
               for t in tables[1:] for n in tables[0].colnames)
    load.append(os.getloadavg()[0])
    efficiency = [a / (2 * b) for a, b in zip(one, two)]
    return dict(members=members, serial=statistics.median(serial), one=statistics.median(one), fresh=fresh,
                warm=statistics.median(two), serial_all=serial, one_all=one, warm_all=two,
                efficiency=efficiency, machine=machine, same=same, load=load, repeats=repeats,
                chunk=Ensemble(ek.kepler_member, parameters).chunk_size)


def markdown_efficiency(e, overhead_pool):
    c = e["one"] / e["members"]
    model = e["members"] * c / 2 + -(-e["members"] // e["chunk"]) * overhead_pool / 2
    relative = [a / b for a, b in zip(e["efficiency"], e["machine"])]
    median = statistics.median(e["efficiency"])
    verdict = ("met" if median >= 0.9 else f"missed by {0.9 - median:.2f}")
    return "\n".join([
        "### Parallel efficiency for members of ≥ 50 ms", "",
        f"The same Kepler encounter with heavier members (to {HEAVY['span'] / 2:.0f} days after the perigee at "
        f"{HEAVY['tolerance_arcsec']:g} arcsec), {e['members']} members in chunks of {e['chunk']}, every process warm; {e['repeats']} rounds, each the "
        "ensemble in this process, on a started pool of 1 worker, on a started pool of 2, and the machine's own "
        "2-worker efficiency (the same pure-Python loop twice on the one worker, then once on each of the two: "
        "`machine_efficiency`), one after the other. Parallel efficiency = T(1 worker) / (2 T(2 workers)), "
        "both pools of worker processes:", "",
        "| round | this process (s) | 1 worker (s) | 2 workers (s) | parallel efficiency | the machine's | relative |",
        "|---|---|---|---|---|---|---|"]
        + [f"| {k + 1} | {e['serial_all'][k]:.2f} | {e['one_all'][k]:.2f} | {e['warm_all'][k]:.2f} | "
           f"{e['efficiency'][k]:.2f} | {e['machine'][k]:.2f} | {relative[k]:.2f} |" for k in range(e["repeats"])] + ["",
        f"Median (min–max) of the {e['repeats']} rounds: parallel efficiency {median:.2f} "
        f"({min(e['efficiency']):.2f}–{max(e['efficiency']):.2f}), the machine's {statistics.median(e['machine']):.2f} "
        f"({min(e['machine']):.2f}–{max(e['machine']):.2f}), relative {statistics.median(relative):.2f} "
        f"({min(relative):.2f}–{max(relative):.2f}). The goal (≥ 0.9 at 2 workers) is {verdict} by the median.", "",
        f"c = {c * 1e3:.0f} ms per member (median round on 1 worker; {e['serial'] / e['members'] * 1e3:.0f} ms in "
        f"this process). The model n c / 2 + (n / chunk) o / 2 predicts {model:.2f} s on two free cores against "
        f"the median {e['warm']:.2f} s. A new pool (its start and each worker's imports, compilation cache and "
        f"sampling included) took {e['fresh']:.2f} s once. The tables of every run are "
        f"{'the same bits' if e['same'] else 'NOT the same bits'}. The 1-minute load average was "
        f"{e['load'][0]:.2f} before and {e['load'][1]:.2f} after. Where the machine's own efficiency is below 1 "
        "the two cores are not both free (other work on the host), and no engine's two workers can do better "
        "than that column; 'relative' divides it out."])


def warm_workers(pool, row, workers=2, attempts=10):
    """Warm every worker of ``pool`` (:func:`_warm_worker`), until each of the ``workers`` processes has run one:
    two warm-ups submitted together may both land on the same worker, leaving the other cold for round 1."""
    seen = set()
    for _ in range(attempts):
        seen.update(f.result() for f in [pool.submit(_warm_worker, row) for _ in range(workers)])
        if len(seen) >= workers:
            return seen
    raise RuntimeError(f"only {len(seen)} of {workers} workers took a warm-up in {attempts} attempts")


def _warm_worker(row):
    """A worker's first member (imports, numba cache, the orbit's sampling), run and thrown away, by both
    routes (the Scene's integrator and the batch one)."""
    import encounter_kepler as ek
    from spinorbit.ensemble.ensemble import run_chunk

    time.sleep(0.2)  # keep this worker busy so that the pool hands the next warm-up to the other
    run_chunk(ek.kepler_member, [(0, row)])
    ek.kepler_member(**row).run()
    return os.getpid()


def stages_text(p):
    """Where a member's CPU goes on the batch route, stage by stage (:func:`measure_stages`)."""
    st = p["stages"]
    total = sum(v for k, v in st.items() if k != "plan")
    return (f"CPU per member by stage of the batch route, in a warm chunk of {p['chunk']} sharing one sampling "
            f"(median of 3): {total * 1e3:.2f} ms in all besides the plan; the group plan (member 0's Scene plan, "
            f"made once per process and kept for its later chunks) {st['plan'] * 1e3:.2f} ms per member of one "
            f"chunk; building the member (`make_scene`: its RotationState and "
            f"Scene) {st['build'] * 1e3:.2f} ms; the member's own bounds (κ from one vectorised free flow, the worst-attitude "
            f"bound of each perturber) {st['bounds'] * 1e3:.2f} ms; its model and integration (the run and its check "
            f"at 10× the rtol in one `integrate_quaternion_batch` call) {st['integration'] * 1e3:.2f} ms; its outcome "
            f"row from the end state {st['rows'] * 1e3:.2f} ms.")


def _label(key):
    return {("batch", 1): "spinorbit `Ensemble`, batch route, in this process",
            ("batch", 2): "spinorbit `Ensemble`, batch route, pool already started",
            ("member", 1): "spinorbit `Ensemble`, per-member route (`route=\"member\"`), in this process"}.get(
        key, f"heyoka `ensemble_propagate_until`, {key[0]} pool")


def markdown_peer(p, overhead_pool):
    n = p["members"]
    timed = p["timed"]
    heyoka = {k: t for k, t in timed.items() if k[0] in ("thread", "process")}
    best_key = max(heyoka, key=lambda k: n / heyoka[k].median)
    best_heyoka = n / heyoka[best_key].median
    best_spin_key = max((("batch", 1), ("batch", 2)), key=lambda k: n / timed[k].median)
    best_spin = n / timed[best_spin_key].median
    lines = [
        "### Against heyoka's ensemble propagation", "",
        f"The Apophis encounter ensemble on Keplerian orbits (`benchmarks/encounter_kepler.py`): {n} members "
        "(rotation phase and moment ratios as in `spinorbit.ensemble.apophis`), 5 days before the 2029 perigee to "
        "2 days after it, under the degree-2 torques of the Earth on its geocentric hyperbola and the Sun on "
        "Apophis's heliocentric ellipse, both fitted to the REBOUND encounter orbit at the perigee (the Moon left "
        "out by both). heyoka cannot call REBOUND; it gets the Sun from `kepE` and the Earth from the two-body "
        "ODE in its state, the moment ratios as runtime parameters (one compiled integrator), and its faster "
        f"mode (compact mode {'on' if p['compact'] else 'off'}). spinorbit runs each member as a Scene "
        "(Earth and Sun as EphemerisPerturbers of the same Kepler states, sampled once per process) at 1 arcsec, "
        f"by the batch route (`spinorbit.ensemble.batch`, chunks of {p['chunk']}: members {p['routes']}) and, "
        "for comparison, by the per-member route.",
        "",
        f"Accuracy against heyoka at tol {REFERENCE_TOL:g} (the attitude at the end, per member): spinorbit "
        f"worst {p['spin_error'].max():.2e} rad, median {np.median(p['spin_error']):.2e} rad; heyoka at tol "
        f"{p['tol']:g} (the loosest of {', '.join(f'{t:g}' for t in HEYOKA_TOLS)} whose worst member is as "
        f"accurate) worst {p['heyoka_error'].max():.2e} rad, median {np.median(p['heyoka_error']):.2e} rad. "
        "spinorbit's attitudes are those of each member's own Scene run; the batch route's rows are "
        + ("the same integration (their poles the same bits, checked here)." if p["batch_is_scene"] else
           "NOT the same bits as the Scene runs' poles here."),
        "",
        f"Wall time of the whole ensemble, every process warm (compiled, the orbits sampled), {p['repeats']} "
        "interleaved rounds: median (min–max).", "",
        "| engine | workers | wall (s) | members/s (median) | against heyoka's best |", "|---|---|---|---|---|"]
    for key, t in timed.items():
        workers = key[1]
        lines.append(f"| {_label(key)} | {workers} | {t.median:.3f} ({t.min:.3f}–{t.max:.3f}) | "
                     f"{n / t.median:.0f} | {n / t.median / best_heyoka:.2f} |")
    lines += [f"| spinorbit `Ensemble`, batch route, new process pool (its start, imports and sampling; once) | 2 | "
              f"{p['fresh']:.2f} | {n / p['fresh']:.0f} | {n / p['fresh'] / best_heyoka:.2f} |",
              f"| heyoka batch mode (`taylor_adaptive_batch`, {p['lanes']} lanes), CPU | 1 | {n * p['batch_cpu']:.3f} | "
              f"{1 / p['batch_cpu']:.0f} | {1 / p['batch_cpu'] / best_heyoka:.2f} |",
              f"| *floor:* spinorbit's core DOP853 alone, member after member on the Scene's model and rtol "
              f"({p['rtol']:.2g}), CPU | 1 | {n * p['core_cpu']:.3f} | {1 / p['core_cpu']:.0f} | "
              f"{1 / p['core_cpu'] / best_heyoka:.2f} |",
              f"| *floor:* heyoka's integrator alone, reused member after member, CPU | 1 | {n * p['heyoka_cpu']:.3f} | "
              f"{1 / p['heyoka_cpu']:.0f} | {1 / p['heyoka_cpu'] / best_heyoka:.2f} |"]
    ratio = best_spin / best_heyoka
    speedup = timed["member", 1].median / timed["batch", 1].median
    lines += [
        "", f"The serial, pooled and new-pool tables are {'the same bits' if p['same'] else 'NOT the same bits'}. "
        f"The 1-minute load average was {p['load'][0]:.2f} before and {p['load'][1]:.2f} after (the 2 cores are "
        "shared with other work). A process's first member also samples the two orbits (survey and run): "
        f"{p['sampling']:.2f} s once per process, not in the rows above except the new pool's.", "",
        f"The batch route runs a member {speedup:.1f}× faster than the per-member route. The goal (≥ 1.5× "
        f"heyoka's ensemble throughput at equal accuracy) is "
        + (f"met: spinorbit's best ({_label(best_spin_key)}) is {ratio:.2f}× heyoka's best ({_label(best_key)}, "
           f"{best_key[1]} worker{'s' if best_key[1] > 1 else ''}). " if ratio >= 1.5 else
           f"missed: spinorbit's best ({_label(best_spin_key)}, {best_spin:.0f} members/s) is {ratio:.2f}× heyoka's "
           f"best ({_label(best_key)}, {best_key[1]} worker{'s' if best_key[1] > 1 else ''}, {best_heyoka:.0f} members/s), a factor "
           f"{1.5 / ratio:.2f} short. ")
        + stages_text(p) + f" The integration is {100 * p['stages']['integration'] / sum(v for k, v in p['stages'].items() if k != 'plan'):.0f}% "
        f"of it: two DOP853 integrations per member (the run and its a posteriori check), each costing about the "
        f"core floor above ({p['core_cpu'] * 1e3:.2f} ms of CPU against heyoka's integrator alone "
        f"{p['heyoka_cpu'] * 1e3:.2f} ms). heyoka's thread ensemble copies the integrator once per member "
        f"(`deepcopy`, {p['copy_s'] * 1e3:.2f} ms, median of 20) and runs the member's generator in Python. What "
        "is left to gain is mostly in the integrator (a batch Taylor method may replace DOP853 through "
        "`Ensemble(batch_integrators=...)`) and in building the Scene per member.", "",
        f"Scaling model of the batch route on a started pool: T(W) = n c / W + (n / chunk) o / W with "
        f"c = {p['per_member'] * 1e3:.2f} ms (the serial batch run's median time per member), o = "
        f"{overhead_pool * 1e3:.2f} ms (an empty task's round trip) and chunks of {p['chunk']}: T(2) = "
        f"{n * p['per_member'] / 2 + -(-n // p['chunk']) * overhead_pool / 2:.3f} s predicted, "
        f"{timed['batch', 2].median:.3f} s measured (parallel efficiency "
        f"{timed['batch', 1].median / (2 * timed['batch', 2].median):.2f}). Data moved per member: "
        f"{p['sent']:.0f} bytes out (the orbits travel as parameter strings), {p['returned']:.0f} bytes back."]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--members", type=int, default=MEMBERS)
    parser.add_argument("--peer-members", type=int, default=PEER_MEMBERS)
    parser.add_argument("--efficiency-members", type=int, default=EFFICIENCY_MEMBERS)
    parser.add_argument("--efficiency-repeats", type=int, default=EFFICIENCY_REPEATS)
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/performance.md")
    args = parser.parse_args(argv)
    measured = measure(args.members)
    text = "\n\n".join([markdown(measured), markdown_peer(measure_peer(args.peer_members), measured["overhead_pool"]),
                         markdown_efficiency(measure_efficiency(args.efficiency_members, args.efficiency_repeats), measured["overhead_pool"]),
                         markdown_free(measure_free())])
    print(text)
    if not args.no_write:
        print(f"wrote {write_section('ensemble', text)}")


if __name__ == "__main__":
    main()
