"""Every benchmark in one command: the published figures (full), or a smoke run of each (``--quick``).

::

    PYTHONPATH=$PWD python benchmarks/run_all.py            # regenerate every section of docs/
    PYTHONPATH=$PWD python benchmarks/run_all.py --quick    # each script on small inputs, print only
    PYTHONPATH=$PWD python benchmarks/run_all.py --quick --only bench_state_table.py

Each script runs in its own process (``sys.executable``, ``PYTHONPATH`` = this checkout), one after
the other, so a failure in one is reported and the others still run. The summary gives each script's
wall time and exit status; the exit status is 1 if any failed. A quick run never writes docs/: each
quick argument list makes its script print only (``tests/test_benchmarks.py`` checks that every
script in benchmarks/ is listed here, and runs the quick mode).

Two scripts compare this checkout with another revision and need it named: ``before_after.py``
(``--base OLD_CHECKOUT``) runs in full mode only when ``--base`` is given here; ``bench_startup.py``
measures this checkout alone unless ``--before REV`` is given. Their quick runs use this checkout as
its own base.

**Ratios with their bars.** Every performance goal of docs/performance.md is a ratio to a peer or a
floor measured in the same run (absolute rates on the shared machines move by 1.5× from run to run);
each script prints one ``ratio: …`` line per goal (``_report.ratio_goal``), and the summary lists them
all, each with the bar it is held to and whether it is met.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
HERE = Path(__file__).resolve().parent
RATIO_PREFIX = "ratio: "  # _report.RATIO_PREFIX (not imported: run_all must run without the package's imports)


@dataclass(frozen=True)
class Benchmark:
    """One script: its arguments for the published run and for the smoke run (which must not write)."""

    script: str
    full: tuple = ()
    quick: tuple = ("--quick",)


#: Every runnable script of benchmarks/, in the order they run (cheap ones first).
BENCHMARKS = (
    Benchmark("bench_state_table.py", quick=("--repeat", "1", "--no-write")),
    Benchmark("bench_scene_skips.py", quick=("--repeat", "1", "--no-write")),
    Benchmark("bench_rebound_forces.py", quick=("--no-write",)),
    Benchmark("bench_elliptic.py"),
    Benchmark("accuracy_elliptic.py"),
    Benchmark("accuracy_photometry.py", quick=("--no-write",)),
    Benchmark("bench_photometry.py", quick=("--repeat", "1", "--size", "1000", "--no-write")),
    Benchmark("wobble_detectability.py", quick=("--quick",)),
    Benchmark("accuracy_symmetric_permanent.py", quick=("--no-write",)),
    Benchmark("accuracy_torque_free.py"),
    Benchmark("bench_torque_free.py"),
    Benchmark("bench_coupling_routes.py"),
    Benchmark("toutatis_validation.py", quick=("--n-times", "50", "--no-write")),
    Benchmark("moon_validation.py"),
    Benchmark("bench_coupled_outputs.py"),
    Benchmark("cli_examples.py"),
    Benchmark("yarkovsky_validation.py", quick=("--quick", "--no-write")),
    Benchmark("bad_input.py", quick=("--no-write",)),
    Benchmark("bench_ensemble.py", quick=("--members", "4", "--efficiency-members", "4",
                                          "--efficiency-repeats", "2", "--no-write")),
    Benchmark("bench_batch.py", quick=("--quick",)),
    Benchmark("thermal_validation.py", quick=("--no-write",)),
    Benchmark("thermal_scene.py", quick=("--repeat", "1", "--no-write")),
    Benchmark("damping_validation.py", quick=("--no-write",)),
    Benchmark("stm_accuracy.py", quick=("--no-write",)),
    Benchmark("bench_stm.py", quick=("--repeat", "1", "--no-write")),
    Benchmark("fit_toutatis.py", quick=("--no-write",)),
    Benchmark("didymos_report.py", quick=("--no-write",)),
    Benchmark("dart_report.py", quick=("--no-write", "--members", "4")),
    Benchmark("bench_binary.py", quick=("--repeat", "1", "--no-write")),
    Benchmark("bench_averaged.py"),
    Benchmark("stability.py"),
    Benchmark("work_precision.py", full=("--averaged",)),
    Benchmark("bench_startup.py", quick=("--repeat", "1", "--cold-repeat", "0", "--no-write")),
    Benchmark("before_after.py", quick=("--base", str(ROOT), "--rounds", "1", "--repeat", "1", "--no-write")),
)
#: Modules of benchmarks/ that other scripts import and that measure nothing themselves.
LIBRARY_MODULES = ("_report.py", "peers.py", "scenes.py", "chaotic.py", "encounter_kepler.py", "run_all.py")


def arguments(benchmark: Benchmark, quick: bool, base: str | None, before: str | None):
    """The script's argument list for this mode, or None when it cannot run (with no revision to compare)."""
    if quick:
        return list(benchmark.quick)
    if benchmark.script == "before_after.py":
        return None if base is None else ["--base", base]
    if benchmark.script == "bench_startup.py" and before is not None:
        return ["--before", before]
    return list(benchmark.full)


def run(names=None, quick: bool = False, base: str | None = None, before: str | None = None, stream=None,
        ratios=None):
    """Run the chosen scripts; returns [(script, status or None if skipped, wall seconds)].

    Each script's output is passed on to ``stream`` (default sys.stdout) line by line; its goal lines
    (``_report.RATIO_PREFIX``) are appended to ``ratios`` as (script, line) when a list is given.
    """
    stream = sys.stdout if stream is None else stream
    chosen = [b for b in BENCHMARKS if names is None or b.script in names]
    unknown = set(names or ()) - {b.script for b in BENCHMARKS}
    if unknown:
        raise SystemExit(f"run_all: unknown benchmark(s) {sorted(unknown)}; expected some of "
                         f"{[b.script for b in BENCHMARKS]}.")
    environment = {**os.environ, "PYTHONPATH": os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")])}
    results = []
    for benchmark in chosen:
        argv = arguments(benchmark, quick, base, before)
        if argv is None:
            print(f"== {benchmark.script}: skipped (give --base OLD_CHECKOUT to compare with it)", file=stream,
                  flush=True)
            results.append((benchmark.script, None, 0.0))
            continue
        print(f"== {benchmark.script} {' '.join(argv)}", file=stream, flush=True)
        begin = time.perf_counter()
        with subprocess.Popen([sys.executable, str(HERE / benchmark.script), *argv], cwd=ROOT, env=environment,
                              stdout=subprocess.PIPE, text=True, bufsize=1) as process:
            for line in process.stdout:
                stream.write(line)
                stream.flush()
                if ratios is not None and line.startswith(RATIO_PREFIX):
                    ratios.append((benchmark.script, line[len(RATIO_PREFIX):].strip()))
        status = process.returncode
        results.append((benchmark.script, status, time.perf_counter() - begin))
    return results


def summary(results, ratios=()) -> str:
    """The scripts' status table, then every goal's ratio with its bar (as the scripts printed them)."""
    lines = ["| script | status | wall (s) |", "|---|---|---:|"]
    for script, status, wall in results:
        text = "skipped" if status is None else ("ok" if status == 0 else f"failed ({status})")
        lines.append(f"| {script} | {text} | {wall:.1f} |")
    if ratios:
        lines += ["", "| script | goal = ratio (bar): verdict |", "|---|---|"]
        lines += [f"| {script} | {line} |" for script, line in ratios]
    return "\n".join(lines)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small inputs, print only (a smoke test)")
    parser.add_argument("--only", nargs="+", metavar="SCRIPT", help="run only these scripts (file names)")
    parser.add_argument("--base", help="old checkout for before_after.py (full mode)")
    parser.add_argument("--before", help="git revision bench_startup.py also measures (full mode)")
    parser.add_argument("--list", action="store_true", help="list the scripts and their arguments, run nothing")
    args = parser.parse_args(argv)
    if args.list:
        for benchmark in BENCHMARKS:
            argv_ = arguments(benchmark, args.quick, args.base, args.before)
            print(benchmark.script, "(skipped)" if argv_ is None else " ".join(argv_))
        return 0
    ratios = []
    results = run(args.only, args.quick, args.base, args.before, ratios=ratios)
    print(summary(results, ratios))
    return 1 if any(status not in (0, None) for _, status, _ in results) else 0


if __name__ == "__main__":
    sys.exit(main())
