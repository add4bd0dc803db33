"""``spinorbit asteroid``: the user's own asteroid — elements, moments, a spin state at its epoch — as a planned Scene.

The scene comes from a TOML file (``--scene``, read with :mod:`tomllib`) and/or options; an option
given on the command line wins over the file. Every quantity is text that astropy reads
(``"2.5 au"``, ``"8 h"``, ``"45 deg/h"``); docs/cli.md shows a complete file
(``examples/asteroid_scene.toml``).
"""

from __future__ import annotations

import argparse

from spinorbit.commands import _inputs as check
from spinorbit.commands._common import check_outputs, number
from spinorbit.commands._scene_file import read_scene_file
from spinorbit.commands._scene_command import (add_scene_arguments, check_run_options, pa_threshold, run_and_report,
                                               span_and_times, state_motion_line)
from spinorbit.commands._spin_options import add_spin_arguments, spin_state, spin_values

NAME = "asteroid"
SUMMARY = "your own asteroid: orbit from elements, moments, spin state at an epoch (planned scene, TOML or options)"
DESCRIPTION = """\
Propagate the spin of an asteroid of your own: its orbit from heliocentric osculating elements at
an epoch (integrated in REBOUND among the DE421 planets with EIH 1PN and Earth J2, optional
non-gravitational A1/A2/A3), its principal moments (any scale: only the ratios matter for the
torques) and its spin state (attitude as passive 3-1-3 Euler angles of the body relative to the
ecliptic J2000 or ICRF, and the body angular velocity) at the state's own epoch. The run starts at
--start (default: the spin epoch) and lasts --span; the state is propagated from its epoch forwards
or backwards to the output times.

Give the scene as a TOML file (--scene; examples/asteroid_scene.toml) and/or as options; options
win. A planner decides, within --tolerance, which perturbers can be dropped and which integrator
runs; --plan prints those decisions and stops."""
EXAMPLES = """\
examples:
  spinorbit asteroid --scene examples/asteroid_scene.toml --plan
  spinorbit asteroid --scene examples/asteroid_scene.toml --span 1 yr --output mine.ecsv
  spinorbit asteroid --elements 2.2 0.15 4 80 30 10 --epoch 2020-01-01 --moments 0.6 0.9 1 \\
      --euler313 10 40 70 --omega 0 0 1080 --span 30 d

exit status: 0 on success; 2 with a one-line message if the input is wrong or an output file
cannot be written (nothing is left half-written)."""

#: The longest run the command accepts (DE421 covers 1900-2200; decades take minutes).
MAX_SPAN_DAYS = 50 * 365.25
#: Options read as plain numbers and their units (the TOML file takes any astropy unit instead).
ELEMENT_UNITS = ("au", "", "deg", "deg", "deg", "deg")
#: The [run] keys and the options they stand for (an option given on the command line wins).
RUN_OPTIONS = ("span", "n_times", "end_only", "perturbers", "tolerance", "pa_threshold", "output", "plot")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``spinorbit asteroid``."""
    parser.add_argument("--scene", metavar="FILE.toml", help="the scene as TOML (tables orbit, body, spin, run)")
    parser.add_argument("--name", help="the asteroid's name (default: the file's, or 'asteroid')")
    orbit = parser.add_argument_group("orbit (heliocentric osculating elements)")
    orbit.add_argument("--elements", nargs=6, type=number, metavar=("A_AU", "E", "INC", "RAAN", "ARGP", "M"),
                       help="a (au), e, and i, node, argument of perihelion, mean anomaly (deg)")
    orbit.add_argument("--epoch", metavar="TIME", help="the elements' epoch, TDB (ISO, e.g. 2020-01-01T00:00)")
    orbit.add_argument("--frame", choices=("ecliptic", "ecliptic-iau2006", "icrf"),
                       help="what the elements' angles refer to (default ecliptic: J2000 as JPL SBDB and the MPC give elements; ecliptic-iau2006: astropy's)")
    spin = parser.add_argument_group("body and spin state")
    spin.add_argument("--moments", nargs=3, type=number, metavar=("A", "B", "C"), help="principal moments (ratios)")
    add_spin_arguments(spin)
    spin.add_argument("--spin-epoch", metavar="TIME", help="the spin state's epoch, TDB (default: the elements')")
    spin.add_argument("--spin-frame", choices=("ecliptic", "icrf"),
                      help="the frame of the spin's angles (attitude, pole, momentum direction): ecliptic J2000 "
                      "(default) or ICRF")
    parser.add_argument("--start", metavar="TIME", help="first output time's origin, TDB (default: the spin epoch)")
    add_scene_arguments(parser, "30 d", ("sun", "earth"))


def _required(where, value):
    from spinorbit.cli import CommandError

    if value is None:
        raise CommandError(f"{where} is missing: give it in the scene file or as an option (spinorbit asteroid --help).")
    return value


def scene_inputs(args, scene=None):
    """(name, orbit, state, epoch, start): the Orbit, the ICRF RotationState at its epoch and the run's start.

    ``scene`` is the checked scene file (:func:`~spinorbit.commands._scene_file.read_scene_file`);
    every option is checked here, before any work.
    """
    import astropy.units as u

    from spinorbit import RigidBody
    from spinorbit.cli import CommandError
    from spinorbit.ephemeris import EphemerisRangeError
    from spinorbit.scene import Orbit

    scene = scene if scene is not None else (read_scene_file(args.scene) if args.scene else {})
    orbit_table, spin_table = scene.get("orbit", {}), scene.get("spin", {})
    run_table = scene.get("run", {})
    name = args.name or scene.get("name") or "asteroid"
    keys = ("a", "e", "inc", "raan", "argp", "mean_anomaly")
    if args.elements is not None:
        elements = [value * u.Unit(unit) if unit else value for value, unit in zip(args.elements, ELEMENT_UNITS)]
    else:
        elements = [_required(f"[orbit] {key}", orbit_table.get(key)) for key in keys]
    epoch = check.time("--epoch", args.epoch) if args.epoch is not None else \
        _required("the elements' epoch (--epoch or [orbit] epoch)", orbit_table.get("epoch"))
    moments = args.moments or _required("the moments (--moments or [body] moments)", scene.get("body", {}).get("moments"))
    body = RigidBody(list(moments), name=name)
    spin_epoch = check.time("--spin-epoch", args.spin_epoch) if args.spin_epoch is not None else \
        spin_table.get("epoch", epoch)
    form, values = spin_values(args, spin_table)
    state = spin_state(body, form, values, spin_epoch, args.spin_frame or spin_table.get("frame", "ecliptic"))
    start = check.time("--start", args.start) if args.start is not None else run_table.get("start", spin_epoch)
    # the spin state and the times checked first: the orbit's set-up integrates it
    try:
        orbit = Orbit.from_elements(*elements, epoch, frame=args.frame or orbit_table.get("frame", "ecliptic"),
                                    name=name, non_gravitational=orbit_table.get("non_gravitational") or None)
    except EphemerisRangeError as error:
        raise CommandError(str(error)) from None
    return name, orbit, state, spin_epoch, start


def _apply_run_table(args, parser_defaults, run_table):
    """Fill the shared scene options from the file's checked [run] table where the command line left the default.

    ``args.sources`` records which options came from the file, so a later refusal names the key.
    """
    args.sources = getattr(args, "sources", {})
    for key in RUN_OPTIONS:
        if key not in run_table or getattr(args, key) != parser_defaults.get(key):
            continue  # not in the file, or given on the command line
        value = run_table[key]
        if key in ("span", "tolerance", "pa_threshold"):
            value = [repr(float(value.value)), *value.unit.to_string().split()]
        setattr(args, key, value)
        args.sources[f"--{key.replace('_', '-')}"] = f"[run] {key}"


def run(args) -> int:
    """Run ``spinorbit asteroid``; return the exit status."""
    defaults = argparse.ArgumentParser()
    add_arguments(defaults)
    scene = read_scene_file(args.scene) if args.scene else {}
    _apply_run_table(args, vars(defaults.parse_args([])), scene.get("run", {}))
    check_outputs(args)
    check_run_options(args, MAX_SPAN_DAYS)  # before the orbit is integrated
    name, orbit, state, epoch, start = scene_inputs(args, scene)
    span, times = span_and_times(args, start, MAX_SPAN_DAYS)
    print(f"orbit              {orbit.description}")
    print(f"spin state         at {epoch.tdb.iso[:19]} TDB: {state_motion_line(state, pa_threshold(args), 'h')}")
    from spinorbit.cli import CommandError
    from spinorbit.ephemeris import EphemerisRangeError

    try:
        return run_and_report(args, state, epoch, times, orbit, NAME,
                              f"{name}: {span.value:g} {span.unit} from {start.tdb.iso[:10]}", "h")
    except EphemerisRangeError as error:
        raise CommandError(str(error)) from None
