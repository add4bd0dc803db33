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

Not measured here: heyoka's ``ensemble_propagate_until`` on the same physics (issue 17 asks for it;
the encounter's torques from a REBOUND orbit have no heyoka formulation in ``benchmarks/peers.py``).

Usage::

    python benchmarks/bench_ensemble.py                 # writes the 'ensemble' section of docs/performance.md
    python benchmarks/bench_ensemble.py --no-write      # print only
"""

from __future__ import annotations

import argparse
import concurrent.futures
import pickle
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

import numpy as np
from _report import machine_line, write_section

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

    import os

    load_before = os.getloadavg()[0]
    parameters = apophis_parameters(members, seed=2029)
    encounter_orbit()  # the orbit of this process, as a worker builds its own: not in the serial timing
    build_member(apophis_member, Ensemble(apophis_member, parameters).member_parameters(0)).run()  # compile/warm
    serial = Ensemble(apophis_member, parameters)
    table_1, wall_1, first_1 = timed_run(serial, "serial")
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
             "own orbit (an N-body run) before its first chunk.", "",
             f"Model T(2) = {predicted_2:.2f} s against {m['wall_2']:.2f} s measured. The model assumes two free "
             f"cores; the 1-minute load average was {m['load'][0]:.1f} before and {m['load'][1]:.1f} after the "
             "measurement (other processes on the machine's cores). The model does not include that load, and this "
             "measurement cannot separate it from other causes of the gap. With the same setup and free cores the "
             "model predicts " + ", ".join(f"{w} workers {model(m, w, m['first_2'] - m['chunk'] * m['per_member']):.1f} s"
                                           for w in (4, 16, 64)) + " (extrapolated, not measured; it ignores the "
             "last chunk's tail, which grows as the chunks per worker fall). The task overhead and the data moved "
             "are small against c, so on free cores the efficiency is set by the setup against the run's length.", "",
             "heyoka's `ensemble_propagate_until` on the same physics is not measured (no heyoka formulation of the "
             "REBOUND-orbit torques in `benchmarks/peers.py` yet)."]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--members", type=int, default=MEMBERS)
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/performance.md")
    args = parser.parse_args(argv)
    text = markdown(measure(args.members))
    print(text)
    if not args.no_write:
        print(f"wrote {write_section('ensemble', text)}")


if __name__ == "__main__":
    main()
