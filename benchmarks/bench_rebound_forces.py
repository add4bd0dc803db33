"""Cost of extra forces in REBOUND: raw cfunc pointer vs the same code behind a Python thunk.

One year of the 11-body DE421 system (IAS15) from J2000, four ways, in one process:
1. no extra forces (Newtonian baseline);
2. spinorbit's cfunc (EIH + Earth J2) as a raw pointer in ``sim._additional_forces``;
3. the *same compiled cfunc* called from a Python callback set with the public
   ``sim.additional_forces`` property (each call goes C → Python → C);
4. a pure-Python callback that only touches ``sim.contents.N`` (the least any Python callback does):
   the floor of the Python route, whatever the physics.
Run: ``python benchmarks/bench_rebound_forces.py``; writes its table into docs/performance.md
(``--no-write``: print only).
"""

import ctypes
import sys
import time
from pathlib import Path

from astropy.time import Time

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import Timing, machine_line, write_section  # noqa: E402
from spinorbit.coupling.rebound import extra_forces, simulation  # noqa: E402

J2000 = Time(2451545.0, format="jd", scale="tdb")
YEAR = 365.25


def _run(mode, repeats=5):
    """(Timing of one simulated year, steps) of one way of adding the forces."""
    samples, calls = [], 0
    for _ in range(repeats):
        sim = simulation.simulation_from_de421(J2000)
        if mode in ("cfunc", "thunk"):
            extra_forces.install_extra_forces(sim)
        if mode == "thunk":
            compiled = extra_forces.extra_forces_cfunc.ctypes  # same machine code, called from Python

            def thunk(sim_pointer, compiled=compiled):
                compiled(ctypes.cast(sim_pointer, ctypes.POINTER(ctypes.c_uint64)))

            sim.additional_forces = thunk
        if mode == "python":
            def force(sim_pointer):
                sim_pointer.contents.N  # noqa: B018  (the cheapest possible Python work)
            sim.additional_forces = force
            sim.force_is_velocity_dependent = 1
        start = time.perf_counter()
        sim.integrate(YEAR)
        samples.append(time.perf_counter() - start)
        calls = sim.steps_done
    return Timing(tuple(samples)), calls


def main(argv=None):
    write = "--no-write" not in (sys.argv[1:] if argv is None else argv)
    _run("cfunc", repeats=1)  # compile / load the cache outside the timing
    rows = []
    baseline, _ = _run("none")
    for mode, label in [
        ("none", "Newtonian only"),
        ("cfunc", "EIH + Earth J2, raw cfunc pointer"),
        ("thunk", "EIH + Earth J2, same cfunc called from a Python callback"),
        ("python", "empty Python callback (floor of any Python force)"),
    ]:
        timing, steps = _run(mode)
        rows.append(f"| {label} | {timing.median * 1e3:.1f} ({timing.min * 1e3:.1f}–{timing.max * 1e3:.1f}) | {steps} "
                    f"| {timing.median / baseline.median:.2f} |")
    table = "\n".join(
        [
            "## Extra forces in REBOUND: raw cfunc pointer vs Python callbacks",
            "",
            machine_line(),
            "One year, 11 DE421 bodies, IAS15, median (min–max) of 5 (`benchmarks/bench_rebound_forces.py`).",
            "",
            "| forces | wall time (ms, median (min–max)) | steps | × Newtonian (medians) |",
            "|---|---:|---:|---:|",
            *rows,
        ]
    )
    print(table)
    if write:
        write_section("rebound_forces", table)


if __name__ == "__main__":
    main()
