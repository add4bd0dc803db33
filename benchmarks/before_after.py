"""The same integrations timed in two checkouts, interleaved: did a change slow anything down?

Run: ``python benchmarks/before_after.py --base /path/to/old/checkout`` (from the new checkout's
root). Each round runs one worker process per checkout, alternating which goes first, so both see the
same machine load. A worker imports the package of its own checkout, reads the three work-precision
scenes (initial state, output times, model array: built once by this checkout's
``benchmarks/scenes.py`` and handed to both), calls each workload once to compile (or load numba's
cache), then times it ``--repeat`` times with ``time.process_time``. The workloads are imported from
the modules that own them; a base checkout from before the reorganisation into concept folders has
them at their flat paths, which the worker falls back to, so the very same calls run in both.

For each workload the report gives the median CPU per call with the min–max over all rounds and
repeats, the ratio of the medians (new / base), and the largest difference between the two
checkouts' final states (a reorganisation should change no number).

Writes the section ``before_after`` of ``docs/performance.md`` unless ``--no-write``.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks._report import machine_line, write_section  # noqa: E402

WORKER = r"""
import json, sys, time, warnings
import numpy as np
warnings.simplefilter("ignore")
sys.path.insert(0, sys.argv[1])
repeat = int(sys.argv[2])
try:
    from spinorbit.core.integrators.quaternion import integrate_quaternion
    from spinorbit.core.integrators.elements import integrate_elements
    from spinorbit.core.integrators.taylor import integrate_taylor
    from spinorbit.core.integrators.handover import integrate_with_handover
    from spinorbit.core.averaging.propagate import propagate_averaged
    from spinorbit.core.free_motion.flow import torque_free_states_many
except ModuleNotFoundError:  # a base checkout from before the concept folders (flat core)
    from spinorbit.core.integrate_quaternion import integrate_quaternion
    from spinorbit.core.integrate_elements import integrate_elements
    from spinorbit.core.integrate_taylor import integrate_taylor
    from spinorbit.core.integrate_handover import integrate_with_handover
    from spinorbit.core.propagate_averaged import propagate_averaged
    from spinorbit.core.torque_free import torque_free_states_many

class Scene:
    def __init__(self, data, name):
        for key in ("y0", "t0", "t_out", "model"):
            setattr(self, key, data[f"{name}_{key}"])
        self.t0 = float(self.t0)

data = np.load(sys.argv[3])
scenes = {name: Scene(data, name) for name in "abc"}
a = scenes["a"]
orbit = float(a.t_out[-1])
long_times = np.linspace(0.0, 100.0 * orbit, 101)[1:]
rng = np.random.default_rng(1)
n_states = 20000
quats = rng.normal(size=(n_states, 4)); quats /= np.linalg.norm(quats, axis=1)[:, None]
momenta = rng.normal(size=(n_states, 3))
free_times = np.linspace(0.0, 50.0, 5)

def final(result):
    if hasattr(result, "mean_elements"):
        return np.asarray(result.mean_elements, dtype=float)[-1].tolist()
    ys = result[0] if isinstance(result, tuple) else result
    return np.asarray(ys, dtype=float).reshape(-1)[-7:].tolist()

work = {}
for name in "abc":
    s = scenes[name]
    work[f"DOP853 quaternion, scene ({name}), rtol 1e-10"] = (
        lambda s=s: integrate_quaternion(s.y0, s.t0, s.t_out, s.model, rtol=1e-10))
    work[f"DOP853 elements, scene ({name}), rtol 1e-10"] = (
        lambda s=s: integrate_elements(s.y0, s.t0, s.t_out, s.model, rtol=1e-10))
    work[f"Taylor, scene ({name}), tol 1e-10"] = (
        lambda s=s: integrate_taylor(s.y0, s.t0, s.t_out, s.model, tol=1e-10))
work["hand-over, scene (a), rtol 1e-10"] = lambda: integrate_with_handover(a.y0, a.t0, a.t_out, a.model, rtol=1e-10)
work["averaged, scene (a) model, 100 orbits"] = lambda: propagate_averaged(a.y0, a.t0, long_times, a.model)
work["torque-free, 20000 states x 5 times"] = lambda: torque_free_states_many(quats, momenta, (2 / 3, 1.0, 2.0), free_times)

out = {}
for label, call in work.items():
    result = call()
    times = []
    for _ in range(repeat):
        start = time.process_time()
        call()
        times.append(time.process_time() - start)
    out[label] = {"times": times, "final": final(result)}
print(json.dumps(out))
"""


def save_scenes(path):
    from benchmarks.scenes import all_scenes

    arrays = {}
    for scene in all_scenes():
        for key in ("y0", "t0", "t_out", "model"):
            arrays[f"{scene.name}_{key}"] = np.asarray(getattr(scene, key), dtype=float)
    np.savez(path, **arrays)


def run_worker(tree, repeat, scenes_file):
    env = {**os.environ, "PYTHONPATH": str(tree), "NUMBA_NUM_THREADS": "1"}
    done = subprocess.run([sys.executable, "-c", WORKER, str(tree), str(repeat), str(scenes_file)], cwd=tree, env=env,
                          capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"worker in {tree} failed:\n{done.stderr[-3000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--base", required=True, type=Path, help="the old checkout (its package and benchmarks/)")
    parser.add_argument("--rounds", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--no-write", action="store_true", help="print only; do not touch docs/performance.md")
    args = parser.parse_args()
    trees = {"base": args.base.resolve(), "new": ROOT}
    samples = {"base": {}, "new": {}}
    finals = {}
    scenes_file = Path(tempfile.mkdtemp()) / "scenes.npz"
    save_scenes(scenes_file)
    for round_index in range(args.rounds):
        order = ("base", "new") if round_index % 2 == 0 else ("new", "base")
        for which in order:
            result = run_worker(trees[which], args.repeat, scenes_file)
            for label, entry in result.items():
                samples[which].setdefault(label, []).extend(entry["times"])
                finals.setdefault(label, {})[which] = entry["final"]
        print(f"round {round_index + 1}/{args.rounds} done", flush=True)

    rows = ["| workload | base: ms per call, median (min–max) | new: ms per call, median (min–max) | new / base (medians) | largest final-state difference |",
            "|---|---:|---:|---:|---:|"]
    for label in samples["base"]:
        base, new = np.array(samples["base"][label]) * 1e3, np.array(samples["new"][label]) * 1e3
        difference = float(np.max(np.abs(np.array(finals[label]["base"]) - np.array(finals[label]["new"]))))
        rows.append(f"| {label} | {np.median(base):.3f} ({base.min():.3f}–{base.max():.3f}) | "
                    f"{np.median(new):.3f} ({new.min():.3f}–{new.max():.3f}) | {np.median(new) / np.median(base):.3f} | "
                    f"{difference:.1e} |")
    table = "\n".join(rows)
    print(table)
    if not args.no_write:
        commit = subprocess.run(["git", "-C", str(trees["base"]), "rev-parse", "--short", "HEAD"],
                                capture_output=True, text=True).stdout.strip() or args.base.name
        body = (
            f"`python benchmarks/before_after.py --base OLD_CHECKOUT` ({args.rounds} rounds × {args.repeat} "
            "repeats per checkout, worker processes alternated, CPU time per call after a warm-up call; "
            f"base = commit {commit}). {machine_line()}\n\n" + table + "\n"
        )
        write_section("before_after", "### Old and new checkout, interleaved (`benchmarks/before_after.py`)\n\n" + body)


if __name__ == "__main__":
    main()
