"""Start-up: imports, a warm ``spinorbit moon`` and a first run with an empty numba cache, in fresh processes.

Run: ``python benchmarks/bench_startup.py [--before REV] [--repeat N] [--cold-repeat N]`` from the
checkout's root. Every measurement is a new Python process (what a user's shell starts), timed from
outside with ``time.perf_counter`` (wall) and ``RUSAGE_CHILDREN`` (CPU, user + system). The commands
run interleaved, round after round, so that all of them see the same load of the shared machine; the
report gives the median and the min–max of the rounds.

- ``import spinorbit.core``, ``import spinorbit``, ``from spinorbit.scene import Scene``;
- ``spinorbit moon`` (default options: the "de421" model, one year from J2000, daily comparisons),
  warm: numba's cache filled by an untimed first run;
- the same command cold, as after a fresh install: ``NUMBA_CACHE_DIR`` and ``SPINORBIT_CACHE_DIR``
  point at new empty directories, so every kernel the run needs is compiled. Such a run also reports
  the seconds numba spent compiling each top-level kernel (its ``numba:compile`` events);
- where a warm run's time goes: one process that times each stage in turn.

``--before REV`` measures the git revision ``REV`` too (exported with ``git archive`` into a temporary
directory), interleaved with this checkout, so the table shows before and after on the same load.
Writes the section ``startup`` of ``docs/performance.md`` unless ``--no-write``.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks._report import Timing, machine_line, ratio_goal, write_section  # noqa: E402

#: The goals of issue 18 as ratios of wall medians to a floor command timed in the same rounds (issue 39:
#: absolute times on the shared machines move by 1.5× from run to run): {command: (floor command, bar)}.
#: Each bar is issue 18's absolute goal (0.2 s, 1 s, 30 s) over its floor in the run that met it
#: (0.02 s, 0.03 s, 0.76 s), rounded: 10×, 30×, 40×.
GOALS = {"import spinorbit.core": ("python -c pass (interpreter floor)", 10.0),
         "spinorbit moon (warm)": ("import spinorbit", 30.0),
         "spinorbit moon (cold cache)": ("spinorbit moon (warm)", 40.0)}

COMMANDS = {
    "python -c pass (interpreter floor)": ["-c", "pass"],
    "import spinorbit.core": ["-c", "import spinorbit.core"],
    "import spinorbit": ["-c", "import spinorbit"],
    "from spinorbit.scene import Scene": ["-c", "from spinorbit.scene import Scene"],
    "spinorbit moon (warm)": ["-m", "spinorbit", "moon"],
}

#: A cold run, reporting numba's compile seconds per top-level kernel (argv[1]: JSON output path).
COLD_RUN = r"""
import json, sys, time
from numba.core import event

started, compiled, depth = {}, {}, [0]

class Compiles(event.Listener):
    def on_start(self, ev):
        started[id(ev.data["dispatcher"]), str(ev.data["args"])] = time.perf_counter()
        depth[0] += 1

    def on_end(self, ev):
        depth[0] -= 1
        function = ev.data["dispatcher"].py_func
        seconds = time.perf_counter() - started[id(ev.data["dispatcher"]), str(ev.data["args"])]
        if depth[0] == 0:
            name = f"{function.__module__}.{function.__qualname__}"
            compiled[name] = compiled.get(name, 0.0) + seconds

event.register("numba:compile", Compiles())
from spinorbit import cli
import contextlib, io
with contextlib.redirect_stdout(io.StringIO()):
    status = cli.main(["moon"])
json.dump({"status": status, "compiled": compiled}, open(sys.argv[1], "w"))
"""

#: One warm ``spinorbit moon`` run, stage by stage (prints a JSON dict of seconds).
STAGES = r"""
import json, time
marks, last = {}, [time.perf_counter()]

def mark(name):
    now = time.perf_counter()
    marks[name] = now - last[0]
    last[0] = now

import numpy
mark("numpy")
import astropy.units, astropy.time
mark("astropy (units, time)")
import numba
mark("numba import")
# numba.np.arraymath imports this at target set-up to find BLAS: timed apart, it is part of the floor.
import scipy.linalg.cython_blas
mark("scipy.linalg (numba's BLAS check at target set-up)")
from spinorbit.core.math.rotations import euler313_to_attitude
euler313_to_attitude(0.1, 0.2, 0.3)
mark("numba's CPU target set-up (rest) + first cached kernel")
import spinorbit.commands.moon
from spinorbit.coupling.moon import compare_model_with_de421
mark("spinorbit's moon modules")
comparison = compare_model_with_de421("de421", 365.25, 1.0)
total = time.perf_counter() - last[0]
marks["DE421 orbit sampling"] = comparison.sampling_seconds
marks["integration (one year)"] = comparison.wall_seconds
marks["other kernels' cache loads, set-up, DE421 comparison"] = (
    total - comparison.sampling_seconds - comparison.wall_seconds)
from spinorbit.coupling.moon import carry_core_angular_velocity
begin = time.perf_counter()
carry_core_angular_velocity(0.0)
marks["lunar core carried 1969 -> J2000 (now shipped; was on every run)"] = time.perf_counter() - begin
print(json.dumps(marks))
"""


#: Where the measured processes keep their Python bytecode. An installed package has its ``.pyc``
#: files (pip compiles them); a shell with ``PYTHONDONTWRITEBYTECODE`` set would instead recompile
#: every spinorbit module in every run, which a user does not pay. Kept outside the checkout.
BYTECODE_DIR = tempfile.mkdtemp(prefix="spinorbit-bench-pyc-")


def _run(checkout: Path, argv, env=None):
    """(wall s, CPU s) of one fresh ``python argv`` importing ``checkout``'s package."""
    environment = {key: value for key, value in os.environ.items() if key != "PYTHONDONTWRITEBYTECODE"}
    environment.update({"PYTHONPATH": str(checkout), "PYTHONPYCACHEPREFIX": BYTECODE_DIR, **(env or {})})
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run([sys.executable, *argv], cwd=checkout, env=environment, check=True,
                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def _cold(checkout: Path):
    """(wall s, CPU s, {kernel: compile s}) of one ``spinorbit moon`` with empty caches."""
    with tempfile.TemporaryDirectory() as numba_cache, tempfile.TemporaryDirectory() as own_cache:
        report = Path(own_cache) / "compiled.json"
        wall, cpu = _run(checkout, ["-c", COLD_RUN, str(report)],
                         {"NUMBA_CACHE_DIR": numba_cache, "SPINORBIT_CACHE_DIR": own_cache})
        return wall, cpu, json.loads(report.read_text())["compiled"]


def _export(revision: str) -> Path:
    """``revision`` of this repository as a plain directory (``git archive``; the repository is unchanged)."""
    target = Path(tempfile.mkdtemp(prefix="spinorbit-before-"))
    archive = subprocess.run(["git", "archive", revision], cwd=ROOT, check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(target)], input=archive, check=True)
    return target


def measure(checkouts: dict, repeat: int, cold_repeat: int) -> dict:
    """Interleaved timings: {checkout label: {command: (wall Timing, CPU Timing)}}, compile and stage tables."""
    load_before = os.getloadavg()[0]
    for checkout in checkouts.values():  # fill numba's cache (and the Python bytecode) untimed
        _run(checkout, COMMANDS["spinorbit moon (warm)"])
    walls = {label: {name: [] for name in [*COMMANDS, "spinorbit moon (cold cache)"]} for label in checkouts}
    cpus = {label: {name: [] for name in walls[label]} for label in checkouts}
    compiled = {label: [] for label in checkouts}
    for round_ in range(max(repeat, cold_repeat)):
        for label, checkout in checkouts.items():
            if round_ < repeat:
                for name, argv in COMMANDS.items():
                    wall, cpu = _run(checkout, argv)
                    walls[label][name].append(wall)
                    cpus[label][name].append(cpu)
            if round_ < cold_repeat:
                wall, cpu, kernels = _cold(checkout)
                walls[label]["spinorbit moon (cold cache)"].append(wall)
                cpus[label]["spinorbit moon (cold cache)"].append(cpu)
                compiled[label].append(kernels)
    timings = {label: {name: (Timing(tuple(walls[label][name])), Timing(tuple(cpus[label][name])))
                       for name in walls[label] if walls[label][name]} for label in checkouts}
    stages = {}
    for label, checkout in checkouts.items():
        if label != "after":
            continue
        runs = []
        for _ in range(max(1, repeat)):
            environment = {key: value for key, value in os.environ.items() if key != "PYTHONDONTWRITEBYTECODE"}
            environment.update({"PYTHONPATH": str(checkout), "PYTHONPYCACHEPREFIX": BYTECODE_DIR})
            out = subprocess.run([sys.executable, "-c", STAGES], cwd=checkout, env=environment, check=True,
                                 capture_output=True, text=True).stdout
            runs.append(json.loads(out.strip().splitlines()[-1]))
        stages = {name: Timing(tuple(run[name] for run in runs)) for name in runs[0]}
    return {"timings": timings, "compiled": compiled, "stages": stages, "load": (load_before, os.getloadavg()[0])}


def _verdict(name: str, timings: dict) -> str:
    """The goal cell of command ``name``: its wall median over its floor's, against the bar ("" if none)."""
    if name not in GOALS:
        return ""
    floor, bar = GOALS[name]
    ratio = timings[name][0].median / timings[floor][0].median
    return f"÷ `{floor}` {ratio_goal(f'{name} / {floor} (wall)', ratio, bar, at_most=True)}"


def markdown(results: dict, repeat: int, cold_repeat: int, before: str | None) -> str:
    timings, compiled, stages = results["timings"], results["compiled"], results["stages"]
    labels = list(timings)
    lines = ["## Start-up (`benchmarks/bench_startup.py`)", "", machine_line(),
             f"Fresh processes, interleaved; median (min–max) of {repeat} rounds, cold runs of {cold_repeat}, "
             "each with empty `NUMBA_CACHE_DIR` and `SPINORBIT_CACHE_DIR`. Wall time; CPU (user + system) beside it."
             + (f" *before* is revision `{before}`, measured in the same rounds." if before else "")
             + " The machine's 1-minute load average was {:.1f} before and {:.1f} after (its 2 cores are shared; "
             "wall times grow with the load, CPU times less).".format(*results["load"]), ""]
    header = ("| command | " + " | ".join(f"{label} wall (s) | {label} CPU (s)" for label in labels)
              + " | goal (wall ÷ the floor's, same rounds) |")
    lines += [header, "|---|" + "---:|---:|" * len(labels) + "---|"]
    for name in timings[labels[-1]]:
        cells = []
        for label in labels:
            wall, cpu = timings[label].get(name, (None, None))
            cells += ["–", "–"] if wall is None else [wall.text(1.0, ".2f"), f"{cpu.median:.2f}"]
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {_verdict(name, timings[labels[-1]])} |")
    if stages:
        lines += ["", "Where a warm `spinorbit moon` spends its time (one process, stage by stage; median "
                  f"(min–max) of {repeat}):", "", "| stage | seconds |", "|---|---:|"]
        lines += [f"| {name} | {timing.text(1.0, '.3f')} |" for name, timing in stages.items()]
    for label in labels:
        if not compiled[label]:
            continue
        runs = compiled[label]
        names = sorted(runs[0], key=lambda n: -runs[0][n])
        lines += ["", f"Numba compile seconds per top-level kernel in a cold run ({label}; median of "
                  f"{len(runs)}):", "", "| kernel | seconds |", "|---|---:|"]
        lines += [f"| `{name}` | {np.median([run.get(name, 0.0) for run in runs]):.2f} |" for name in names]
        total = np.median([sum(run.values()) for run in runs])
        lines.append(f"| all | {total:.2f} |")
    return "\n".join(lines)


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=7, help="rounds of the warm commands (default 7)")
    parser.add_argument("--cold-repeat", type=int, default=2, help="cold runs per checkout (default 2)")
    parser.add_argument("--before", metavar="REV", help="also measure git revision REV, interleaved")
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/performance.md")
    args = parser.parse_args(argv)
    checkouts = {"before": _export(args.before)} if args.before else {}
    checkouts["after"] = ROOT
    try:
        results = measure(checkouts, args.repeat, args.cold_repeat)
    finally:
        if args.before:
            shutil.rmtree(checkouts["before"], ignore_errors=True)
        shutil.rmtree(BYTECODE_DIR, ignore_errors=True)
    text = markdown(results, args.repeat, args.cold_repeat, args.before)
    print(text)
    if not args.no_write:
        print(f"wrote {write_section('startup', text)}")


if __name__ == "__main__":
    main()
