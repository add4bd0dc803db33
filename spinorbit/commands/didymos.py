"""``spinorbit didymos``: Didymos and Dimorphos from the published system, and DART's period change."""

from __future__ import annotations

import argparse
import math

from spinorbit.cli import CommandError
from spinorbit.commands import _inputs as check
from spinorbit.commands._common import Progress, check_outputs, write_plot_output, write_table_output

NAME = "didymos"
SUMMARY = "Didymos-Dimorphos from the published system (full two-body problem) and DART's period change"
DESCRIPTION = """\
Propagate the binary asteroid (65803) Didymos - Dimorphos as two rigid figures that feel each
other (mutual potential by inertia integrals to --order, Hou, Scheeres & Xin 2017): the relative
orbit, both attitudes and both spins, with DOP853. The set-up is the published system
(spinorbit.data.dart; docs/binary.md): Didymos the oblate spheroid of Naidu et al. 2024 (394 m
equatorial, 290 m polar radius), Dimorphos the 177 x 174 x 116 m ellipsoid of Daly et al. 2023 at
2.4 g/cm^3, synchronous on a circular orbit at 1.206 km, the system's mass fitted so that the
full model goes round in the measured 11.921473 h.

Prints the mutual orbit (mean sidereal period, eccentricity, apsidal precession), Dimorphos's free
and forced libration (periods with the run's resolution P^2/T, and amplitudes, from the periodogram
of its libration angle), its rotation mode in Fukushima's canonical elements, and the energy and
angular-momentum drift. A run too short to resolve the two libration lines (about 45 orbits are
needed: the free libration takes ~51 h) says so and prints no lines; a pair that the impact unbinds
is reported as unbound, with no period. With
--impact the same run is repeated after DART's impulse on Dimorphos and the line 'period change
<value> min' gives the mean sidereal period after it minus 11.921473 h. The impulse is the
along-track velocity change --dv (default -2.63 mm/s, Naidu et al. 2024), or, with --beta, the
momentum beta m U / M of DART's mass and speed along --impact-elevation (Cheng et al. 2023's eq. 1
with the ejecta's recoil along U)."""
EXAMPLES = """\
examples:
  spinorbit didymos --impact                         # Naidu et al. 2024's dv = -2.63 mm/s, 100 orbits
  spinorbit didymos --impact --dv -2.70 mm/s --orbits 20
  spinorbit didymos --impact --beta 3.61 --impact-elevation 30 --output didymos.ecsv --plot didymos.png

exit status: 0 on success; 2 with a one-line message if the input is wrong or an output file
cannot be written (nothing is left half-written)."""

#: Cap on the output rows (100 per orbit over 10^4 orbits).
MAX_ROWS = 1_000_000


def _positive_count(text):
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got '{text}'") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"expected a whole number ≥ 1, got {value}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``spinorbit didymos``."""
    model = parser.add_argument_group("model and run")
    model.add_argument("--order", default=4, metavar="N",
                       help="mutual-potential order 0..4 (default 4; 2 = point masses + inertia tensors)")
    model.add_argument("--orbits", type=_positive_count, default=100, metavar="N",
                       help="span in mutual orbits of 11.921473 h (default 100: enough to separate the libration lines)")
    model.add_argument("--per-orbit", type=_positive_count, default=40, metavar="N",
                       help="output times per orbit (default 40)")
    model.add_argument("--rtol", default=1e-12, metavar="RTOL", help="DOP853 relative tolerance (default 1e-12)")
    model.add_argument("--libration", default=0.0, metavar="DEG",
                       help="Dimorphos turned this many degrees from the line to Didymos at the start (default 0)")
    impact = parser.add_argument_group("DART's impact at t = 0")
    impact.add_argument("--impact", action="store_true", help="also run after an impulsive velocity change of Dimorphos")
    impulse = impact.add_mutually_exclusive_group()
    impulse.add_argument("--dv", nargs="+", default=None, metavar="DV",
                         help="Dimorphos's along-track velocity change, e.g. '-2.63 mm/s' (a number alone is mm/s; "
                              "negative: against its motion; default -2.63 mm/s, Naidu et al. 2024)")
    impulse.add_argument("--beta", default=None, metavar="BETA",
                         help="momentum enhancement instead of --dv: dv = beta m U / M with DART's mass and speed "
                              "(3.61: Cheng et al. 2023 for 2.4 g/cm^3)")
    impact.add_argument("--impactor-mass", default=None, metavar="KG",
                        help="with --beta: impactor mass in kg (default 579.4, Cheng et al. 2023)")
    impact.add_argument("--impactor-speed", default=None, metavar="KM_S",
                        help="with --beta: impactor speed relative to Dimorphos in km/s (default 6.1449)")
    impact.add_argument("--impact-elevation", default=0.0, metavar="DEG",
                        help="angle of the impulse out of the orbit plane (default 0: in the plane, against the motion)")
    files = parser.add_argument_group("output files")
    files.add_argument("--output", metavar="FILE.ecsv", help="write the run (time, relative orbit, libration, "
                       "Dimorphos's canonical elements and mode) as ECSV or CSV")
    files.add_argument("--plot", metavar="FILE.png", help="plot libration and drifts (needs matplotlib; .png, .pdf, .svg)")


def _report(label, run):
    import astropy.units as u

    e_rel, e_potential = run.energy_drift()
    tumbling, energy_excess, p_psi, p_phi = run.tumbling_summary()
    unbound = run.unbound_reason()
    if unbound is not None:
        # An escaping pair has no orbit period and no libration: say so instead of fitting lines to it.
        orbit_lines = [f"  unbound                  {unbound}; no mutual period or libration"]
    else:
        orbit_lines = _orbit_lines(run)
    lines = [
        f"{label}",
        *orbit_lines,
        f"  Dimorphos rotation       non-principal-axis (SAM/LAM) at {100 * tumbling:.0f} % of the output times, "
        f"principal-axis at the rest, max E/E0 - 1 = {energy_excess:.3g}, max wobble "
        f"{run.secondary_wobble().max().to_value(u.deg):.3g} deg (tumbling above 1 deg)"
        + (f", P_psi = {p_psi.to_value(u.h):.3f} h, P_phi = {p_phi.to_value(u.h):.3f} h" if tumbling else ""),
        f"  drift                    |dE/E| = {e_rel.max():.2e} (|dE/U| = {e_potential.max():.2e}), "
        f"|dH/H| = {run.angular_momentum_drift().max():.2e}",
        f"  steps                    {run.stats['accepted']} accepted, {run.stats['rejected']} rejected",
    ]
    print("\n".join(lines))


def _orbit_lines(run):
    """The mean mutual orbit and the libration lines, each with its resolution, or why the run cannot give them."""
    import astropy.units as u

    from spinorbit.core.binary.errors import UnresolvedPeriodError

    def short(error):
        # A run too short for a period: say so and how long it must be, instead of printing the wrong line.
        hint = ""
        if error.required_span is not None:
            # (rounded up, less a hair: a span of exactly 3 periods asks for 3 orbits, not 4)
            hint = f" Here: --orbits {math.ceil(error.required_span / _nominal_period_s() - 1e-6)} or more."
        return f"  not resolved             {error}{hint}"

    try:
        orbit = run.mutual_orbit()
    except UnresolvedPeriodError as error:
        return [short(error)]
    apsides = ("circular" if orbit.apsidal_rate is None else
               f"eccentricity {orbit.eccentricity:.4f}, apsidal precession {orbit.apsidal_rate.to_value(u.deg / u.day):.2f} "
               "deg/day")
    lines = [f"  mutual orbit             mean sidereal period {orbit.sidereal_period.to_value(u.h):.6f} h, mean "
             f"separation {orbit.mean_separation.to_value(u.m):.1f} m, {apsides}"]
    try:
        parts = run.libration_components()
    except UnresolvedPeriodError as error:
        return [*lines, short(error), f"  max |libration|          {abs(run.libration()).max().to_value(u.deg):.4f} deg"]
    return [
        *lines,
        f"  free libration           period {parts.free_period.to_value(u.h):.4f} ± {parts.free_resolution.to_value(u.h):.2g} h, "
        f"amplitude {parts.free_amplitude.to_value(u.deg):.4f} deg",
        f"  forced libration         period {parts.forced_period.to_value(u.h):.4f} ± {parts.forced_resolution.to_value(u.h):.2g} h, "
        f"amplitude {parts.forced_amplitude.to_value(u.deg):.4f} deg (fit residual {parts.residual_rms.to_value(u.deg):.2g} "
        "deg rms)",
        "                           (± one resolution P²/T of the run's periodogram)",
        f"  max |libration|          {abs(run.libration()).max().to_value(u.deg):.4f} deg",
    ]


def _nominal_period_s():
    """The pre-impact mutual period (s): the unit of --orbits."""
    import astropy.units as u

    from spinorbit.data.dart import PERIOD_BEFORE

    return PERIOD_BEFORE.to_value(u.s)


def _impulse(args, state):
    """(Δv Quantity (3,) on the inertial axes, its description) from --dv or --beta and --impact-elevation."""
    import astropy.units as u
    import numpy as np

    from spinorbit.binary import momentum_impulse
    from spinorbit.data.dart import DART_MASS, DART_SPEED, DV_NAIDU

    if args.beta is None and (args.impactor_mass is not None or args.impactor_speed is not None):
        raise CommandError("--impactor-mass and --impactor-speed make the impulse from --beta: add --beta (3.61: "
                           "Cheng et al. 2023), or give the velocity change itself with --dv.")
    velocity = state.velocity.to_value(u.m / u.s)
    along = velocity / np.linalg.norm(velocity)
    elevation = math.radians(args.impact_elevation)
    # against the motion, tilted by the elevation towards the orbit normal (+z)
    backwards = -along * math.cos(elevation) + np.array([0.0, 0.0, math.sin(elevation)])
    if args.beta is None:
        dv = DV_NAIDU if args.dv is None else args.dv
        size = dv.to_value(u.m / u.s)
        if size > 0 and args.impact_elevation != 0.0:
            raise CommandError(f"--dv expects the along-track change, negative against the motion, with "
                               f"--impact-elevation; got {dv:g} with an elevation of {args.impact_elevation:g} deg. "
                               "Give a negative --dv (the impulse's size is |dv| / cos(elevation)).")
        # the along-track component is the given dv; out of the plane the impulse is longer by 1/cos
        delta_v = abs(size) / math.cos(elevation) * (backwards if size < 0 else along) * u.m / u.s
        source = " (Naidu et al. 2024)" if args.dv is None else ""
        text = f"along-track dv = {size * 1e3:.4f} mm/s{source}, elevation {args.impact_elevation:g} deg"
    else:
        mass = DART_MASS.to_value(u.kg) if args.impactor_mass is None else args.impactor_mass
        speed = DART_SPEED.to_value(u.km / u.s) if args.impactor_speed is None else args.impactor_speed
        delta_v = momentum_impulse(mass * u.kg, backwards * speed * u.km / u.s, args.beta, state.system.secondary.mass)
        text = (f"beta {args.beta:g}, {mass:g} kg at {speed:g} km/s, elevation "
                f"{args.impact_elevation:g} deg: |dv| = {np.linalg.norm(delta_v.to_value(u.mm / u.s)):.4f} mm/s, "
                f"along-track {float(np.dot(delta_v.to_value(u.mm / u.s), along)):.4f} mm/s")
    return delta_v, text


def _table(runs):
    import astropy.units as u
    from astropy.table import QTable

    from spinorbit.core.binary.equations import POSITION
    from spinorbit.core.binary.libration import COL_ENERGY_RATIO, COL_LIBRATION, COL_MODE, COL_S

    table = QTable()
    for label, run in runs:
        rotation = run.secondary_rotation()
        prefix = "" if label == "nominal" else "impact_"
        if not prefix:
            table["time"] = run.times.to(u.h)
        table[prefix + "separation"] = run.states[:, POSITION:POSITION + 3] * u.m
        table[prefix + "libration"] = (rotation[:, COL_LIBRATION] * u.rad).to(u.deg)
        for j, name in enumerate(("S", "Z", "H", "s", "z", "h")):
            table[prefix + name] = rotation[:, COL_S + j]
        table[prefix + "mode"] = rotation[:, COL_MODE].astype(int)
        table[prefix + "energy_ratio"] = rotation[:, COL_ENERGY_RATIO]
    table.meta["description"] = ("Didymos-Dimorphos full two-body run (spinorbit didymos); separation of Dimorphos from "
                                 "Didymos on inertial axes; libration modulo 180 deg; S, Z, H in kg m^2/s, s, z, h in rad; "
                                 "mode 1 SAM, -1 LAM, 0 principal axis")
    return table


def _plot(runs, path):
    import astropy.units as u
    import matplotlib
    import numpy as np

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    figure, (top, bottom) = plt.subplots(2, 1, figsize=(8, 6), sharex=True)
    for label, run in runs:
        hours = run.times.to_value(u.h)
        top.plot(hours, run.libration().to_value(u.deg), lw=0.7, label=label)
        # Running maxima: the worst drift so far, readable where the raw values flicker at rounding level.
        bottom.semilogy(hours[1:], np.maximum.accumulate(run.energy_drift()[0][1:]) + 1e-17, lw=0.9,
                        label=f"max |dE/E| {label}")
        bottom.semilogy(hours[1:], np.maximum.accumulate(run.angular_momentum_drift()[1:]) + 1e-17, lw=0.9, ls="--",
                        label=f"max |dH/H| {label}")
    top.set_ylabel("Dimorphos libration (deg)")
    top.legend(loc="upper right", fontsize=8)
    bottom.set_ylabel("relative drift")
    bottom.set_xlabel("time (h)")
    bottom.legend(loc="lower right", fontsize=7)
    figure.tight_layout()
    figure.savefig(path, format=path.rsplit(".", 1)[-1] if "." in path else "png")
    plt.close(figure)


def check_options(args) -> None:
    """Every number in range before any work (the validation layer, :mod:`spinorbit.commands._inputs`)."""
    args.order = check.integer("--order", args.order, "4", low=0, high=4)
    # DOP853 in double precision: the binary propagator's own range (spinorbit.core.binary.propagate)
    args.rtol = check.number("--rtol", args.rtol, "1e-12", low=1e-15, high=1.0, high_open=True,
                             advice="Double precision cannot do better than 1e-15.")
    args.libration = check.number("--libration", args.libration, "10", low=-180.0, high=180.0)
    if args.dv is not None:
        args.dv = check.quantity("--dv", args.dv, "mm/s", "-2.63 mm/s", default_unit="mm/s")
    if args.beta is not None:
        args.beta = check.number("--beta", args.beta, "3.61", low=0.0,
                                 advice="beta is the momentum enhancement, ≥ 1 in practice.")
    if args.impactor_mass is not None:
        args.impactor_mass = check.number("--impactor-mass", args.impactor_mass, "579.4", low=0.0, low_open=True)
    if args.impactor_speed is not None:
        args.impactor_speed = check.number("--impactor-speed", args.impactor_speed, "6.1449", low=0.0, low_open=True)
    args.impact_elevation = check.number("--impact-elevation", args.impact_elevation, "30", low=-90.0, high=90.0,
                                         high_open=True, low_open=True)


def run(args) -> int:
    """Run ``spinorbit didymos``; return the exit status."""
    import astropy.units as u
    import numpy as np

    from spinorbit.binary import propagate
    from spinorbit.binary.system import G_SI
    from spinorbit.core.errors import SpinorbitError
    from spinorbit.data.dart import PERIOD_BEFORE, PERIOD_CHANGE_INITIAL_NAIDU, PERIOD_CHANGE_THOMAS, dart_state, dart_system

    check_outputs(args)
    check_options(args)
    rows = args.orbits * args.per_orbit + 1
    if rows > MAX_ROWS:
        raise CommandError(f"--orbits {args.orbits} with --per-orbit {args.per_orbit} gives {rows} output rows, more than "
                           f"{MAX_ROWS}; lower one of them.")
    if args.per_orbit < 8:
        raise CommandError(f"--per-orbit expects at least 8 output times per orbit to resolve the libration, got "
                           f"{args.per_orbit}.")
    if not args.impact and (args.dv is not None or args.beta is not None):
        raise CommandError("--dv and --beta describe the impact: add --impact to run it.")
    try:
        system = dart_system(order=args.order)
    except SpinorbitError as error:
        raise CommandError(f"--order: {error}") from None
    state = dart_state(system, libration=args.libration * u.deg)
    times = np.linspace(0.0, args.orbits, rows) * PERIOD_BEFORE.to(u.s)
    equatorial, _, polar = system.primary.semi_axes_m
    print(f"Didymos            oblate spheroid {equatorial:g} x {polar:g} m (Naidu et al. 2024), mass "
          f"{system.primary.mass.value:.4e} kg (fitted to the period)")
    print(f"Dimorphos          ellipsoid {' x '.join(f'{2 * a:g}' for a in system.secondary.semi_axes_m)} m (Daly et al. "
          f"2023), mass {system.secondary.mass.value:.4e} kg")
    print(f"orbit              circular at {state.separation[0].to_value(u.km):g} km, period "
          f"{PERIOD_BEFORE.to_value(u.h):.6f} h; G(mA + mB) = {(system.primary.mass + system.secondary.mass).value * G_SI:.5f} m^3/s^2")
    print(f"model              mutual potential to order {args.order}; contact distance "
          f"{system.contact_distance.to_value(u.m):.1f} m; DOP853 rtol {args.rtol:g}")
    cases = [("nominal", state)]
    if args.impact:
        delta_v, text = _impulse(args, state)
        print(f"impact             {text}")
        cases.append(("after impact", state.with_velocity_change(delta_v)))
    runs = []
    progress = Progress(len(cases), "propagating")
    try:
        for label, case in cases:
            try:
                runs.append((label, propagate(case, times, rtol=args.rtol)))
            except SpinorbitError as error:
                raise CommandError(f"{label}: {error}") from None
            progress.advance(1)
    finally:
        progress.close()
    for label, result in runs:
        _report(label, result)
    if args.impact and runs[1][1].unbound_reason() is not None:
        print("period change  none: the pair is unbound after the impact")
    elif args.impact:
        change = (runs[1][1].mutual_orbit().sidereal_period - runs[0][1].mutual_orbit().sidereal_period).to(u.min)
        print(f"period change  {change.value:.3f} min")
        print(f"  mean sidereal period over the {args.orbits} orbits after the impact minus before; measured "
              f"{PERIOD_CHANGE_THOMAS.value:.1f} +- 1.0 min (3 sigma, Thomas et al. 2023), "
              f"{PERIOD_CHANGE_INITIAL_NAIDU.value:g} min +- 16 s right after the impact (Naidu et al. 2024)")
    if args.output is not None:
        write_table_output(args.output, _table(runs), f"{rows} rows over {args.orbits} orbits")
    if args.plot is not None:
        write_plot_output(args.plot, lambda temporary: _plot(runs, temporary))
    return 0
