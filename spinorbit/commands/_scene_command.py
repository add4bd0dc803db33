"""What the asteroid commands share: Scene options, the planned run with a progress bar, ECSV and PNG."""

from __future__ import annotations

import argparse
import contextlib
import threading

from spinorbit.cli import CommandError
from spinorbit.commands import _inputs as check
from spinorbit.commands._common import Progress, plot_format, write_plot_output, write_table_output

#: Seconds of planning before its progress bar shows (issue 15: plans of long runs take tens of seconds).
PLAN_PROGRESS_DELAY_S = 1.0
#: Most output times a command accepts (each row builds a RotationState for the periods).
MAX_TIMES = 100_000
#: Closest output times accepted (days): a float of TDB days since J2000 resolves ~1e-12 d in 1992-2029.
MIN_SPACING_DAYS = 1e-9


def add_scene_arguments(parser: argparse.ArgumentParser, span_default: str, perturbers_default) -> None:
    """Options common to the asteroid scene commands."""
    run = parser.add_argument_group("scene")
    run.add_argument("--span", nargs="+", default=span_default.split(), metavar="SPAN",
                     help=f"how long to run, e.g. '4 d', '1 yr' (a number alone is days; default {span_default})")
    run.add_argument("--n-times", default=200, metavar="N",
                     help="number of evenly spaced output times (default 200)")
    run.add_argument("--end-only", action="store_true",
                     help="only the final state (the planner then asks for no dense output)")
    run.add_argument("--tolerance", nargs="+", default=["1", "arcsec"], metavar="ANGLE",
                     help="attitude tolerance of the whole run, e.g. '1 arcsec' (default), '1e-6 rad'")
    run.add_argument("--perturbers", nargs="+", default=list(perturbers_default), metavar="BODY",
                     help=f"bodies whose torque may act (default: {' '.join(perturbers_default)}); the planner "
                     "drops those that cannot matter and says why")
    run.add_argument("--plan", action="store_true", help="print the plan (decisions and reasons) and stop")
    run.add_argument("--no-skip", action="store_true",
                     help="run the reference plan: every perturber, the orbits as given, nothing skipped")
    files = parser.add_argument_group("output files")
    files.add_argument("--output", metavar="FILE.ecsv", help="write the result table (time, attitude, spin, pole, "
                       "obliquity, periods; docs/conventions.md 'Output tables') as ECSV (FILE.ecsv) or CSV (FILE.csv)")
    files.add_argument("--plot", metavar="FILE.png", help="plot periods, pole, obliquity and mode against the date, "
                       "encounters marked (needs matplotlib; .png, .pdf or .svg)")


def _where(args, option: str) -> str:
    """The option's name, or the scene-file key it came from (``args.sources``, set by ``spinorbit asteroid``)."""
    return getattr(args, "sources", {}).get(option, option)


def check_run_options(args, max_days: float):
    """(span, n_times): --tolerance, --span and --n-times checked before any work (no orbit built yet)."""
    import astropy.units as u

    tolerance(args)
    span = check.quantity(_where(args, "--span"), args.span, "d", "4 d", default_unit="d", low=0.0, high=max_days,
                          low_open=True)
    days = span.to_value(u.day)
    n_times = check.integer(_where(args, "--n-times"), args.n_times, "200", low=2, high=MAX_TIMES)
    if days / n_times < MIN_SPACING_DAYS:
        raise CommandError(f"--span {' '.join(args.span)} with --n-times {n_times} spaces the output times by "
                           f"{days / n_times:.3g} d, below the {MIN_SPACING_DAYS:g} d that TDB days since J2000 resolve; "
                           "give a longer --span or fewer --n-times.")
    return span, n_times


def span_and_times(args, start, max_days: float):
    """(span Quantity, output Time(s)) from --span, --n-times and --end-only, starting at ``start``."""
    import astropy.units as u
    import numpy as np

    span, n_times = check_run_options(args, max_days)
    days = span.to_value(u.day)
    if args.end_only:
        return span, start + days * u.day
    # the first row is the start itself (the output schema), then evenly to the end
    return span, start + np.linspace(0.0, days, n_times) * u.day


def tolerance(args):
    """The --tolerance angle, in the range the Scene accepts (checked here, before the orbit is built)."""
    return check.quantity(_where(args, "--tolerance"), args.tolerance, "rad", "1 arcsec", default_unit="arcsec",
                          low=1e-12, high=0.1, advice="That is 2e-7 to 2e4 arcsec.")


def run_scene(scene, args):
    """Plan (or the reference plan with --no-skip), print it with --plan, else run with a progress bar."""
    import sys
    import time

    clock = time.perf_counter()
    if sys.stderr.isatty():  # planning samples the orbits (an N-body run): say so before the wait
        print("planning (sampling the orbits) ...", file=sys.stderr, flush=True)
    planning = Progress(100, "planning", delay=PLAN_PROGRESS_DELAY_S)
    with _ticking(planning):  # the survey samples the orbits for seconds without a fraction to report
        try:
            plan = scene.plan(skip=not args.no_skip, progress=_advancing(planning))
        finally:
            planning.close()
    args.plan_seconds = time.perf_counter() - clock
    if args.plan:
        print(plan)
        return None
    progress = Progress(100, "running")
    try:
        result = scene.run(plan, progress=_advancing(progress))
    finally:
        progress.close()
    return result


@contextlib.contextmanager
def _ticking(progress, every_s: float = 0.25):
    """Within the block, a background thread redraws ``progress`` every ``every_s`` (its clock moves on)."""
    stop = threading.Event()

    def tick():
        while not stop.wait(every_s):
            progress.tick()

    thread = threading.Thread(target=tick, name="spinorbit-progress", daemon=True)
    thread.start()
    try:
        yield progress
    finally:
        stop.set()
        thread.join()


def _advancing(progress):
    """A fraction callback (Scene.plan / Scene.run) that moves a 100-item :class:`Progress`."""
    done = [0]

    def advance(fraction):
        step = int(100 * fraction) - done[0]
        if step > 0:
            progress.advance(step)
            done[0] += step

    return advance


def run_and_report(args, state, start, times, orbit, name: str, title: str, period_unit: str) -> int:
    """Build the Scene from the shared options, run it (or print its plan), print the summary, write files."""
    from spinorbit.scene import Scene

    scene = Scene(state, start, times, perturbers=tuple(args.perturbers), orbit=orbit, tolerance=tolerance(args))
    result = run_scene(scene, args)
    if result is not None:
        for line in summary(result, period_unit, args.plan_seconds):
            print(line)
        write_outputs(args, result, name, title, period_unit)
    return 0


def summary(result, period_unit: str, plan_seconds: float = 0.0) -> list[str]:
    """Lines: the plan in brief, the state before and after, the error estimate."""
    import astropy.units as u

    plan, table = result.plan, result.table
    lines = [f"plan               {plan.route}, orbits from {plan.orbit_source}, integrator {plan.integrator}",
             f"perturbers         kept {', '.join(plan.kept) or 'none'}; dropped {', '.join(plan.dropped) or 'none'}"]
    if "P_psi" in table.colnames:
        for label, row in (("first", table[0]), ("last", table[-1])):
            lines.append(f"{label:5s} {row['time'].tdb.iso[:16]} TDB  {row['mode']:3s}  "
                         f"P_psi = {row['P_psi'].to_value(period_unit):9.4f} {period_unit}  "
                         f"P_phi = {row['P_phi'].to_value(period_unit):9.4f} {period_unit}  "
                         f"P_sid = {row['sidereal_period'].to_value(period_unit):9.4f} {period_unit}  "
                         f"E/E0 = {row['energy_ratio']:.5f}")
    parts = ", ".join(f"{k} {v.to_value(u.arcsec):.2g}" for k, v in result.error_parts.items())
    lines.append(f"wall time          {plan_seconds + result.wall_seconds:.2f} s (plan {plan_seconds:.2f} s, "
                 f"run {result.wall_seconds:.2f} s)")
    lines.append(f"error estimate     {result.error_estimate.to_value(u.arcsec):.3g} arcsec ({parts})")
    if not result.tolerance_met:
        lines.append(f"tolerance NOT met  the estimate exceeds the tolerance "
                     f"{result.plan.tolerance_rad * 206264.80624709636:.3g} arcsec (long spans: the integration "
                     "error of double precision grows with the number of rotations); loosen --tolerance or shorten --span")
    return lines


def ecsv_table(result, name: str, period_unit: str = "h"):
    """The result table as a plain astropy Table for ECSV: the API's columns and units (the output
    schema, periods in h whatever ``period_unit`` the summary prints), the plan in ``meta``."""
    from spinorbit import __version__
    from spinorbit.commands._outputs import ecsv_table as schema_ecsv

    return schema_ecsv(result.table, {
        "software": f"spinorbit {__version__} {name}",
        "model": f"spinorbit {name}: {result.table.meta.get('model', '')}",
        "route": result.plan.route,
        "orbits": result.plan.orbit_source,
        "perturbers_kept": list(result.plan.kept),
        "perturbers_dropped": list(result.plan.dropped),
        "tolerance_arcsec": result.plan.tolerance_rad * 206264.80624709636,
        "error_estimate_arcsec": float(result.error_estimate.to_value("arcsec")),
        "tolerance_met": result.tolerance_met,
        "plan": str(result.plan),
        "conventions": "quaternion scalar first (w, x, y, z), body axes -> ICRF; omega in body axes; "
                       "docs/conventions.md 'Output tables'",
    })


def write_outputs(args, result, name: str, title: str, period_unit: str) -> None:
    """ECSV and plot, each atomically."""
    if args.output is not None:
        table = ecsv_table(result, name, period_unit)
        write_table_output(args.output, table, f"{len(table)} rows")
    if args.plot is not None:
        write_plot_output(args.plot, lambda temporary: plot(result, temporary, title, period_unit, args.plot))


def plot(result, path: str, title: str, period_unit: str = "h", name: str | None = None) -> None:
    """Periods, pole, obliquity and mode against the date, the run's closest approaches marked."""
    from spinorbit.commands._outputs import plot_rotation

    plot_rotation(result.table, path, title, plot_format(name or path),
                  encounters=result.table.meta.get("closest_approaches"))
