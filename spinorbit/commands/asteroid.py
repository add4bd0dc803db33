"""``spinorbit asteroid``: the user's own asteroid — elements, moments, a spin state at its epoch — as a planned Scene.

The scene comes from a TOML file (``--scene``, read with :mod:`tomllib`) and/or options; an option
given on the command line wins over the file. Every quantity is text that astropy reads
(``"2.5 au"``, ``"8 h"``, ``"45 deg/h"``); docs/cli.md shows a complete file
(``examples/asteroid_scene.toml``).
"""

from __future__ import annotations

import argparse

from spinorbit.commands._common import check_outputs
from spinorbit.commands._scene_command import (add_scene_arguments, pa_threshold, run_and_report, span_and_times,
                                               state_motion_line)

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
#: The scene file's tables and their keys (anything else is refused, so a typo is not silently ignored).
SCENE_KEYS = {
    "name": None,
    "orbit": ("epoch", "a", "e", "inc", "raan", "argp", "mean_anomaly", "frame", "non_gravitational"),
    "body": ("moments",),
    "spin": ("epoch", "euler313", "omega", "frame"),
    "run": ("start", "span", "n_times", "end_only", "perturbers", "tolerance", "pa_threshold", "output", "plot"),
}
#: Options read as plain numbers and their units (the TOML file takes any astropy unit instead).
ELEMENT_UNITS = ("au", "", "deg", "deg", "deg", "deg")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``spinorbit asteroid``."""
    parser.add_argument("--scene", metavar="FILE.toml", help="the scene as TOML (tables orbit, body, spin, run)")
    parser.add_argument("--name", help="the asteroid's name (default: the file's, or 'asteroid')")
    orbit = parser.add_argument_group("orbit (heliocentric osculating elements)")
    orbit.add_argument("--elements", nargs=6, type=float, metavar=("A_AU", "E", "INC", "RAAN", "ARGP", "M"),
                       help="a (au), e, and i, node, argument of perihelion, mean anomaly (deg)")
    orbit.add_argument("--epoch", metavar="TIME", help="the elements' epoch, TDB (ISO, e.g. 2020-01-01T00:00)")
    orbit.add_argument("--frame", choices=("ecliptic", "ecliptic-iau2006", "icrf"),
                       help="what the elements' angles refer to (default ecliptic: J2000 as JPL SBDB and the MPC give elements; ecliptic-iau2006: astropy's)")
    spin = parser.add_argument_group("body and spin state")
    spin.add_argument("--moments", nargs=3, type=float, metavar=("A", "B", "C"), help="principal moments (ratios)")
    spin.add_argument("--euler313", nargs=3, type=float, metavar=("PHI", "THETA", "PSI"),
                      help="attitude: passive 3-1-3 Euler angles of the body relative to --spin-frame (deg)")
    spin.add_argument("--omega", nargs=3, type=float, metavar=("WX", "WY", "WZ"),
                      help="body angular velocity (deg/day) in the moments' axes")
    spin.add_argument("--spin-epoch", metavar="TIME", help="the spin state's epoch, TDB (default: the elements')")
    spin.add_argument("--spin-frame", choices=("ecliptic", "icrf"), help="the attitude's frame (default ecliptic)")
    parser.add_argument("--start", metavar="TIME", help="first output time's origin, TDB (default: the spin epoch)")
    add_scene_arguments(parser, "30 d", ("sun", "earth"))


def _read_scene(path):
    """The TOML file as a dict, each table checked for unknown keys."""
    import tomllib

    from spinorbit.cli import CommandError

    try:
        with open(path, "rb") as handle:
            scene = tomllib.load(handle)
    except OSError as error:
        raise CommandError(f"--scene cannot read {path!r}: {error.strerror}.") from None
    except tomllib.TOMLDecodeError as error:
        raise CommandError(f"--scene expects a TOML file; {path!r} is not valid TOML: {error}.") from None
    for table, value in scene.items():
        if table not in SCENE_KEYS:
            raise CommandError(f"--scene: unknown table or key {table!r}; expected {tuple(SCENE_KEYS)}.")
        if SCENE_KEYS[table] is not None:
            if not isinstance(value, dict):
                raise CommandError(f"--scene: [{table}] expects a table with keys {SCENE_KEYS[table]}.")
            unknown = sorted(set(value) - set(SCENE_KEYS[table]))
            if unknown:
                raise CommandError(f"--scene: [{table}] has unknown keys {unknown}; expected some of {SCENE_KEYS[table]}.")
    return scene


def _quantity(where, text, physical_type, example):
    import astropy.units as u

    from spinorbit.cli import CommandError

    try:
        value = u.Quantity(text)
    except (TypeError, ValueError):
        value = None
    if value is None or value.unit.physical_type != physical_type:
        raise CommandError(f"{where} expects a {physical_type} such as {example!r}; got {text!r}.")
    return value


def _time(where, text):
    from astropy.time import Time

    from spinorbit.cli import CommandError

    try:
        return Time(text, scale="tdb")
    except (TypeError, ValueError):
        raise CommandError(f"{where} expects a TDB time such as '2020-01-01T00:00:00'; got {text!r}.") from None


def _required(where, value):
    from spinorbit.cli import CommandError

    if value is None:
        raise CommandError(f"{where} is missing: give it in the scene file or as an option (spinorbit asteroid --help).")
    return value


def scene_inputs(args):
    """(name, orbit, state, epoch, start): the Orbit, the ICRF RotationState at its epoch and the run's start."""
    import astropy.units as u
    import numpy as np

    from spinorbit import RigidBody, RotationState
    from spinorbit.cli import CommandError
    from spinorbit.frames import icrf_to_ecliptic_matrix
    from spinorbit.scene import Orbit

    scene = _read_scene(args.scene) if args.scene else {}
    orbit_table, spin_table = scene.get("orbit", {}), scene.get("spin", {})
    name = args.name or scene.get("name") or "asteroid"
    keys = ("a", "e", "inc", "raan", "argp", "mean_anomaly")
    if args.elements is not None:
        elements = [value * u.Unit(unit) if unit else value for value, unit in zip(args.elements, ELEMENT_UNITS)]
    else:
        elements = []
        for key, kind, example in zip(keys, ("length", None, "angle", "angle", "angle", "angle"),
                                      ("2.5 au", None, "5 deg", "80 deg", "30 deg", "10 deg")):
            value = _required(f"[orbit] {key}", orbit_table.get(key))
            elements.append(value if kind is None else _quantity(f"[orbit] {key}", value, kind, example))
    epoch = _time("--epoch / [orbit] epoch", _required("the elements' epoch (--epoch or [orbit] epoch)",
                                                       args.epoch or orbit_table.get("epoch")))
    terms = {key: _quantity(f"[orbit.non_gravitational] {key}", text, "acceleration", "-2.9e-14 AU / d2")
             for key, text in orbit_table.get("non_gravitational", {}).items()}
    from spinorbit.ephemeris import EphemerisRangeError

    try:
        orbit = Orbit.from_elements(*elements, epoch, frame=args.frame or orbit_table.get("frame", "ecliptic"),
                                    name=name, non_gravitational=terms or None)
    except EphemerisRangeError as error:
        raise CommandError(str(error)) from None
    moments = args.moments or _required("the moments (--moments or [body] moments)", scene.get("body", {}).get("moments"))
    body = RigidBody(list(map(float, moments)), name=name)
    if args.euler313 is not None:
        angles = [value * u.deg for value in args.euler313]
    else:
        angles = [_quantity("[spin] euler313", text, "angle", "40 deg")
                  for text in _required("the attitude (--euler313 or [spin] euler313)", spin_table.get("euler313"))]
    if args.omega is not None:
        omega = np.array(args.omega) * u.deg / u.day
    else:
        texts = _required("the angular velocity (--omega or [spin] omega)", spin_table.get("omega"))
        omega = u.Quantity([_quantity("[spin] omega", text, "angular speed", "45 deg / h") for text in texts])
    if len(angles) != 3 or omega.shape != (3,):
        raise CommandError("[spin] euler313 and omega expect three values each.")
    spin_epoch_text = args.spin_epoch or spin_table.get("epoch")
    spin_epoch = epoch if spin_epoch_text is None else _time("--spin-epoch / [spin] epoch", spin_epoch_text)
    frame = args.spin_frame or spin_table.get("frame", "ecliptic")
    if frame not in ("ecliptic", "icrf"):
        raise CommandError(f"[spin] frame expects 'ecliptic' or 'icrf'; got {frame!r}.")
    state = RotationState.from_euler313(body, *angles, omega)
    if frame == "ecliptic":  # v_body = R_ecl v_ecl = R_ecl E v_icrf
        state = RotationState.from_matrix(body, state.attitude_matrix @ icrf_to_ecliptic_matrix(), omega)
    start_text = args.start or scene.get("run", {}).get("start")
    start = spin_epoch if start_text is None else _time("--start / [run] start", start_text)
    return name, orbit, state, spin_epoch, start


def _apply_run_table(args, parser_defaults, run_table):
    """Fill the shared scene options from the file's [run] table where the command line left the default."""
    for key in SCENE_KEYS["run"]:
        if key not in run_table or key == "start":
            continue
        value = run_table[key]
        if getattr(args, key) != parser_defaults.get(key):
            continue  # given on the command line
        if key in ("span", "tolerance", "pa_threshold"):
            value = str(value).split()
        elif key == "perturbers":
            value = list(value)
        setattr(args, key, value)


def run(args) -> int:
    """Run ``spinorbit asteroid``; return the exit status."""
    defaults = argparse.ArgumentParser()
    add_arguments(defaults)
    if args.scene:
        _apply_run_table(args, vars(defaults.parse_args([])), _read_scene(args.scene).get("run", {}))
    check_outputs(args)
    name, orbit, state, epoch, start = scene_inputs(args)
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
