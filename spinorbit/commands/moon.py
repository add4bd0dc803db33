"""``spinorbit moon``: the lunar physical libration from any date in DE421, integrated with the orbits."""

from __future__ import annotations

import argparse
import math
import os
import sys

from spinorbit.cli import CommandError
from spinorbit.commands import _inputs as check
from spinorbit.commands._common import (Progress, check_output_path, check_outputs, number, plot_format, quantity,
                                        write_plot_output, write_table_output)

#: The models (spinorbit.coupling.moon.MOON_MODELS, repeated so that --help does not import REBOUND).
MOON_MODELS = ("de421", "rigid", "core-corrected")

NAME = "moon"
SUMMARY = "lunar physical libration from DE421 at any date, coupled to the orbits, compared with DE421"
DESCRIPTION = """\
Integrate the Moon's rotation (quaternion + angular velocity, degree 2-4 lunar gravity field from the
DE421 constants, torques from the Sun, planets and Earth) together with the orbits (REBOUND's BS,
point masses + EIH 1PN + Earth J2 + the lunar figure's back-reaction), starting from DE421 at --start
(default J2000; any date in DE421's 1899-12-04 .. 2200-02-01, the run ending inside it too), and
compare the attitude with DE421's librations at every output time.

Models: 'de421' (default) is DE421's own lunar rotation model (mantle with tidal and rotational
distortion, fluid core, Earth J2 on the lunar figure), driven one-way by DE421's orbits and started
from DE421's mantle at --start (the core carried there from DE421's epoch 1969); 'rigid' uses DE421's total
moments; 'core-corrected' removes the fluid core's share of the polar moment (IFAC) from the moments
the mantle's Euler equations see. The two rigid models run fully coupled in REBOUND
(docs/coupling.md).

--output writes the Moon table (ECSV): time (TDB), the model's 3-1-3 angles phi, theta, psi (rad)
and physical librations tau, rho, I_sigma (arcsec), DE421's values of the same suffixed _de421, and
the attitude difference (docs/conventions.md "Physical librations").

The last line printed is 'max attitude difference vs DE421: <x> arcsec over <span>'."""
EXAMPLES = """\
examples:
  spinorbit moon                                   # 1 year, DE421's mantle-and-core model
  spinorbit moon --span 20 yr --model rigid --step 5 d --output moon.ecsv --plot moon.png
  spinorbit moon --start 1950-01-01 --span 100 yr --step 10 d --output moon1950.ecsv
  spinorbit moon --span 50 yr --checkpoint moon.ckpt --output moon.ecsv   # killed? then:
  spinorbit moon --span 50 yr --resume moon.ckpt --output moon.ecsv

exit status: 0 on success; 2 with a one-line message if the input is wrong or an output file
cannot be written (nothing is left half-written)."""

#: The options that stand for check_run's arguments (its messages name them).
OPTION_NAMES = {"model": "--model", "start": "--start", "span": "--span", "step": "--step"}
#: Most comparison times (rows) a run may have (50 yr at a 0.1 d step). Each is an integration stop
#: and a DE421 evaluation; more is refused before the run (with the count and the knob, --step).
MAX_COMPARISON_TIMES = 200_000


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``spinorbit moon``."""
    run = parser.add_argument_group("model and span")
    run.add_argument("--start", default="2000-01-01T12:00:00", metavar="DATE",
                     help="first output time, ISO date (TDB) or JD number, inside DE421 (default J2000.0)")
    run.add_argument("--span", nargs="+", default=["1", "yr"], metavar="SPAN",
                     help="how long to integrate from --start, e.g. '1 yr' (default), '20 yr', '200 d' (a number alone is days); "
                          "the run must end inside DE421 (2200-01-31)")
    run.add_argument("--step", nargs="+", default=["1", "d"], metavar="STEP",
                     help="spacing of the comparison times, e.g. '12 h' (a number alone is days; default 1 d; at least 1 min)")
    run.add_argument("--model", choices=MOON_MODELS, default="de421",
                     help="de421: mantle + fluid core + tides on DE421's orbits (default); rigid / "
                          "core-corrected: rigid Moon with the whole Moon's / the mantle's moments, in REBOUND")
    run.add_argument("--one-way", action="store_true",
                     help="rigid models: do not let the lunar figure act back on the orbits "
                          "(default: fully coupled); the de421 model is always one-way")
    files = parser.add_argument_group("output files")
    files.add_argument("--output", metavar="FILE.ecsv",
                       help="write the Moon table (time, Euler angles, physical librations, DE421's, difference) as ECSV (FILE.ecsv) or CSV (FILE.csv)")
    files.add_argument("--plot", metavar="FILE.png", help="plot the difference and the libration (FILE.png, .pdf or .svg; needs matplotlib)")
    long_runs = parser.add_argument_group("long runs")
    long_runs.add_argument("--checkpoint", metavar="PATH",
                           help="write a checkpoint (orbits + rotation + results so far) to PATH during the run")
    long_runs.add_argument("--checkpoint-every", type=number, default=60.0, metavar="SECONDS",
                           help="wall-clock seconds between checkpoints (default 60)")
    long_runs.add_argument("--resume", metavar="PATH",
                           help="continue the interrupted run whose checkpoint is PATH (same options); it "
                                "ends bit for bit where the uninterrupted run would, and keeps checkpointing to "
                                "PATH unless --checkpoint names another file")


def start_day(text: str) -> float:
    """``--start`` as TDB days since J2000: an ISO date/time (TDB) or a Julian date number."""
    from spinorbit.time import tdb_day_and_fraction

    day, fraction = tdb_day_and_fraction(check.time("--start", text, julian=True))
    return float(day) + float(fraction)


def plot_comparison(comparison, path: str, title: str) -> None:
    """PNG: attitude difference (top) and the physical librations τ, ρ, Iσ (bottom), arcsec."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    years = (comparison.times - comparison.times[0]) / 365.25
    figure = Figure(figsize=(9, 7), layout="constrained")
    FigureCanvasAgg(figure)
    top, bottom = figure.subplots(2, 1, sharex=True)
    top.plot(years, comparison.attitude_difference_arcsec, "k", label="total angle")
    for i, axis in enumerate("xyz"):
        top.plot(years, comparison.body_difference_arcsec[:, i], lw=0.8, label=f"about mantle {axis}")
    top.set_ylabel("model - DE421 [arcsec]")
    top.set_title(title)
    top.legend(fontsize="small")
    for label, librations, style in (("DE421", comparison.librations_de421, "-"),
                                     ("model", comparison.librations_model, "--")):
        for i, name in enumerate(("tau", "rho", "I sigma")):
            bottom.plot(years, librations[:, i], style, color=f"C{i}", lw=0.8, label=f"{name} ({label})")
    bottom.set_ylabel("physical libration [arcsec]")
    bottom.set_xlabel(f"years since {_start_label(comparison.times[0])}")
    bottom.legend(fontsize="small")
    figure.savefig(path, format=plot_format(path), dpi=120)


def _start_label(day: float) -> str:
    from spinorbit.time import time_from_tdb_days

    return time_from_tdb_days(float(day)).tdb.iso[:10] + " TDB"


def _checkpoint_schedule(args, span_days: float, step_days: float, start: float = 0.0):
    """The checkpoint schedule of ``--checkpoint``/``--resume`` and the settings a resume must match."""
    from spinorbit.runs.checkpoint import CheckpointSchedule

    settings = {"command": NAME, "model": args.model, "coupled": not args.one_way, "span_days": span_days,
                "step_days": step_days}
    if start != 0.0:  # runs from J2000 keep the settings (and checkpoints) they always had
        settings["start_day"] = start
    if args.resume is not None and not os.path.isfile(args.resume):
        what = "is not a regular file" if os.path.exists(args.resume) else "does not exist"
        raise CommandError(f"--resume expects an existing checkpoint file; '{args.resume}' {what}. "
                           "Give the --checkpoint file of the interrupted run.")
    if not (math.isfinite(args.checkpoint_every) and args.checkpoint_every > 0):  # checked even when unused
        raise CommandError(f"--checkpoint-every expects a positive number of seconds, got {args.checkpoint_every!r}.")
    path = args.checkpoint if args.checkpoint is not None else args.resume
    if path is None:
        return None, settings
    check_output_path("--checkpoint", path)
    return CheckpointSchedule(path, every_seconds=args.checkpoint_every), settings


def run(args) -> int:
    """Run ``spinorbit moon``; return the exit status."""
    from spinorbit.coupling.moon import (
        EphemerisRangeError,
        OutputStepError,
        check_run,
        compare_model_with_de421,
        comparison_table,
    )
    from spinorbit.runs.checkpoint import CheckpointError, CheckpointWriteError

    check_outputs(args)
    span = quantity("--span", args.span, "d", "time", "1 yr")
    step = quantity("--step", args.step, "d", "time", "1 d").to_value("d")
    span_days = span.to_value("d")
    start = start_day(args.start)
    try:  # the checks are the API's, written with the options' names
        check_run(args.model, start, span_days, step, names=OPTION_NAMES)
    except (EphemerisRangeError, OutputStepError, ValueError) as error:
        raise CommandError(str(error)) from None
    count = int(span_days / step + 1e-9) + 1
    if count > MAX_COMPARISON_TIMES:
        raise CommandError(f"--span {' '.join(args.span)} with --step {' '.join(args.step)} gives {count:.3g} "
                           f"comparison times, more than {MAX_COMPARISON_TIMES}; "
                           f"use a larger --step (at least {span_days / (MAX_COMPARISON_TIMES - 1):.3g} d) or a shorter --span.")
    schedule, settings = _checkpoint_schedule(args, span_days, step, start)
    if schedule is not None and args.model == "de421":
        raise CommandError("--checkpoint/--resume apply to the REBOUND-coupled models (--model rigid or "
                           "core-corrected); the de421 model runs in a few hundredths of a second per simulated year and needs none.")
    progress = Progress(count, "integrating")
    done = [0]

    def advance(n):
        progress.advance(n - done[0])
        done[0] = n

    try:
        comparison = compare_model_with_de421(args.model, span_days, step, coupled=not args.one_way,
                                              progress=advance, schedule=schedule, resume=args.resume,
                                              settings=settings, start_day=start)
    except CheckpointError as error:  # name the option whose file it is
        option = "--checkpoint" if isinstance(error, CheckpointWriteError) else "--resume"
        raise CommandError(f"{option}: {error}") from None
    except KeyboardInterrupt:
        if schedule is not None and os.path.exists(schedule.path):
            print(f"{args._prog}: the last checkpoint is '{schedule.path}'; continue with the same options and "
                  f"--resume {schedule.path}", file=sys.stderr)
        raise
    finally:
        progress.close()
    span_text = f"{span.value:g} {span.unit.to_string()}"
    coupling = "one-way on DE421's orbits" if args.model == "de421" or args.one_way else "fully coupled"
    print(f"model              {args.model}, {coupling}")
    print(f"wall time          {comparison.wall_seconds:.2f} s "
          f"({comparison.wall_seconds / (span_days / 365.25):.3f} s per simulated year)")
    if comparison.sampling_seconds:
        print(f"orbit sampling     {comparison.sampling_seconds:.2f} s (DE421 positions before the run)")
    print(f"final difference   {comparison.attitude_difference_arcsec[-1]:.5f} arcsec")
    if args.output is not None:
        table = comparison_table(comparison, args.model, args.model != "de421" and not args.one_way)
        write_table_output(args.output, table, f"{len(table)} rows")
    if args.plot is not None:
        write_plot_output(args.plot, lambda temporary: plot_comparison(comparison, temporary,
                                                                       f"Moon vs DE421, {args.model}, {span_text}"))
    print(f"max attitude difference vs DE421: {comparison.max_difference_arcsec:.5f} arcsec over {span_text}")
    return 0
