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
                     help="attitude tolerance of the whole run, e.g. '1 arcsec' (default), '1e-6 rad' (a number alone is arcsec)")
    run.add_argument("--perturbers", nargs="+", default=list(perturbers_default), metavar="BODY",
                     help=f"bodies whose torque may act (default: {' '.join(perturbers_default)}); the planner "
                     "drops those that cannot matter and says why")
    run.add_argument("--pa-threshold", nargs="+", default=["1", "deg"], metavar="ANGLE",
                     help="wobble amplitude up to which a state is a principal-axis rotator (PA: one sidereal period; "
                     "above it SAM/LAM with P_psi, P_phi), e.g. '0.1 deg' (a number alone is deg); default 1 deg (docs/design.md "
                     "'PA or NPA')")
    run.add_argument("--plan", action="store_true", help="print the plan (decisions and reasons) and stop")
    run.add_argument("--no-skip", action="store_true",
                     help="run the reference plan: every perturber, the orbits as given, nothing skipped")
    files = parser.add_argument_group("output files")
    files.add_argument("--output", metavar="FILE.ecsv", help="write the result table (time, attitude, spin, pole, "
                       "obliquity, periods; docs/conventions.md 'Output tables') as ECSV (FILE.ecsv) or CSV (FILE.csv)")
    files.add_argument("--plot", metavar="FILE.png", help="plot against the date, encounters marked: a tumbler's "
                       "periods, pole, obliquity and class; a principal-axis rotator's pole drift (arcsec), obliquity "
                       "change, period residual and wobble (needs matplotlib; .png, .pdf or .svg)")


def _where(args, option: str) -> str:
    """The option's name, or the scene-file key it came from (``args.sources``, set by ``spinorbit asteroid``)."""
    return getattr(args, "sources", {}).get(option, option)


def check_run_options(args, max_days: float):
    """(span, n_times): --tolerance, --span and --n-times checked before any work (no orbit built yet)."""
    import astropy.units as u

    tolerance(args)
    pa_threshold(args)
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


def pa_threshold(args):
    """The --pa-threshold angle, checked to lie in [0°, 90°) (before the orbit is built): at 90° the separatrix
    would be PA."""
    return check.quantity(_where(args, "--pa-threshold"), getattr(args, "pa_threshold", ["1", "deg"]), "deg", "1 deg",
                          default_unit="deg", low=0.0, high=90.0, high_open=True,
                          advice="It is the wobble amplitude up to which a state is a principal-axis rotator.")


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

    scene = Scene(state, start, times, perturbers=tuple(args.perturbers), orbit=orbit, tolerance=tolerance(args),
                  pa_threshold=pa_threshold(args))
    result = run_scene(scene, args)
    if result is not None:
        mark_close_approaches(result, orbit, [p for p in args.perturbers if p != "sun"], start, times)
        for line in summary(result, period_unit, args.plan_seconds):
            print(line)
        write_outputs(args, result, name, title, period_unit)
    return 0


def mark_close_approaches(result, orbit, bodies, epoch, times) -> None:
    """Put the orbit's close approaches to ``bodies`` over the run (``epoch`` and the output ``times``) into
    the result table's meta.

    ``close_approaches``: {body: [{time (ISO TDB), distance_au, distance_km, speed_km_s}, ...]}, every
    minimum within :data:`spinorbit.scene.orbit.APPROACH_MAX_DISTANCE` (:meth:`Orbit.approaches`, each to
    1e-9 d); ``closest_approaches`` {body: the closest of them} replaces the route's estimate on its sample
    grid. A body the orbit cannot be measured against (not in its simulation) is left out.
    """
    from spinorbit.coupling.rebound import MissingBodyError
    from spinorbit.ephemeris import UnknownBodyError

    every = times.reshape(-1)
    start, end = min(epoch, every.min()), max(epoch, every.max())
    if orbit is None or not end > start:
        return
    found = {}
    for body in bodies:
        try:
            table = orbit.approaches(body, start, end)
        except (MissingBodyError, UnknownBodyError):
            continue
        found[body] = [{"time": row["time"].tdb.isot, "distance_au": float(row["distance"].value),
                        "distance_km": float(row["distance_km"].value), "speed_km_s": float(row["speed"].value)}
                       for row in table]
    meta = result.table.meta
    meta["close_approaches"] = found
    closest = dict(meta.get("closest_approaches") or {})
    closest.update({body: min(rows, key=lambda r: r["distance_au"]) for body, rows in found.items() if rows})
    meta["closest_approaches"] = closest


def summary(result, period_unit: str, plan_seconds: float = 0.0) -> list[str]:
    """Lines: the plan in brief, the state before and after, the error estimate."""
    import astropy.units as u

    plan, table = result.plan, result.table
    lines = [f"plan               {plan.route}, orbits from {plan.orbit_source}, integrator {plan.integrator}",
             f"perturbers         kept {', '.join(plan.kept) or 'none'}; dropped {', '.join(plan.dropped) or 'none'}"]
    if "rotation_class" in table.colnames:
        for label, row in (("first", table[0]), ("last", table[-1])):
            lines.append(f"{label:5s} {row['time'].tdb.iso[:16]} TDB  {motion_line(row, period_unit)}")
    from spinorbit.scene.orbit import APPROACH_MAX_DISTANCE

    limit = APPROACH_MAX_DISTANCE.to_value(u.au)
    for body, rows in (table.meta.get("close_approaches") or {}).items():
        if rows:
            best = min(rows, key=lambda r: r["distance_au"])
            lines.append(f"closest approach   {body} {best['time'][:16].replace('T', ' ')} TDB, {best['distance_au']:.5f} au "
                         f"({best['distance_km']:.4g} km), {len(rows)} within {limit:g} au in the span")
        else:
            lines.append(f"closest approach   {body}: none within {limit:g} au in the span")
    parts = ", ".join(f"{k} {v.to_value(u.arcsec):.2g}" for k, v in result.error_parts.items())
    lines.append(f"wall time          {plan_seconds + result.wall_seconds:.2f} s (plan {plan_seconds:.2f} s, "
                 f"run {result.wall_seconds:.2f} s)")
    lines.append(f"error estimate     {result.error_estimate.to_value(u.arcsec):.3g} arcsec ({parts})")
    if not result.tolerance_met:
        lines.append(f"tolerance NOT met  the estimate exceeds the tolerance "
                     f"{result.plan.tolerance_rad * 206264.80624709636:.3g} arcsec (long spans: the integration "
                     "error of double precision grows with the number of rotations); loosen --tolerance or shorten --span")
    return lines


def motion_line(row, period_unit: str) -> str:
    """A table row's motion as an observer reports it: "PA, P = 8.0000 h" for a principal-axis rotator, else
    "SAM, P_psi = …, P_phi = …, P_sid = …"; then the wobble amplitude and E/E0."""
    import astropy.units as u

    def hours(name):
        return f"{u.Quantity(getattr(row[name], 'unmasked', row[name])).to_value(period_unit):.4f} {period_unit}"

    if row["rotation_class"] == "PA":
        periods = f"PA, P = {hours('sidereal_period')}"
    else:
        periods = (f"{row['rotation_class']}, P_psi = {hours('P_psi')}, P_phi = {hours('P_phi')}, "
                   f"P_sid = {hours('sidereal_period')}")
    wobble = u.Quantity(row["wobble_amplitude"]).to_value(u.deg)
    return f"{periods}  wobble {wobble:.3g} deg  E/E0 = {row['energy_ratio']:.5f}"


def state_motion_line(state, threshold, period_unit: str) -> str:
    """:func:`motion_line` of a RotationState (the state a command starts from), at ``threshold``."""
    p_psi, p_phi = state.periods
    return motion_line({"rotation_class": state.rotation_class(threshold), "sidereal_period": state.sidereal_period,
                        "P_psi": p_psi, "P_phi": p_phi, "wobble_amplitude": state.wobble_amplitude,
                        "energy_ratio": state.energy_ratio}, period_unit)


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

    meta = result.table.meta  # every close approach when the command measured them, else the route's closest
    plot_rotation(result.table, path, title, plot_format(name or path),
                  encounters=meta.get("close_approaches") or meta.get("closest_approaches"))
