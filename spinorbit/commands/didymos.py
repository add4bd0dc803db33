"""``spinorbit didymos``: Didymos and Dimorphos in the full two-body problem, with a DART-like impact."""

from __future__ import annotations

import argparse
import math

from spinorbit.cli import CommandError
from spinorbit.commands import _inputs as check
from spinorbit.commands._common import Progress, check_outputs, write_plot_output, write_table_output

NAME = "didymos"
SUMMARY = "Didymos-Dimorphos full two-body problem (mutual potential to order 4) and a DART-like impact"
DESCRIPTION = """\
Propagate the binary asteroid (65803) Didymos - Dimorphos as two rigid figures that feel each
other (mutual potential by inertia integrals to --order, Hou, Scheeres & Xin 2017): the relative
orbit, both attitudes and both spins, with DOP853. The set-up is the GUBAS example case
(../shared/data/didymos_gubas_case.json; docs/binary.md says which number is derived and why):
Dimorphos a 103.16 x 79.35 x 66.13 m ellipsoid, synchronous, 1.20 km from a spherical Didymos
spinning in 2.260 h, density 2.2031 g/cm^3.

Prints the mutual orbit period, Dimorphos's free and forced libration (periods with the run's
resolution P^2/T, and amplitudes, from the periodogram of its libration angle), its rotation mode in
Fukushima's canonical elements, and the energy and angular-momentum drift. A run too short to
resolve the two libration lines (about 26 orbits are needed) says so and prints no lines; a pair
that the impact unbinds is reported as unbound, with no period. With --impact the same run is repeated after an
impulsive change of Dimorphos's velocity, dv = beta m v / M_Dimorphos, against its orbital motion
(DART: 579.4 kg at 6.1449 km/s, beta = 3.61 by default), and the excited libration or tumbling is
reported."""
EXAMPLES = """\
examples:
  spinorbit didymos                                  # 100 orbits, order 4
  spinorbit didymos --impact --beta 3.61 --orbits 200 --output didymos.ecsv --plot didymos.png
  spinorbit didymos --impact --impact-elevation 30 --order 2

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
                       help="mutual-potential order 0..4 (default 4, the GUBAS case's; 2 = point mass + inertia tensors)")
    model.add_argument("--orbits", type=_positive_count, default=100, metavar="N",
                       help="span in mutual orbits of 11.92 h (default 100: enough to separate the libration lines)")
    model.add_argument("--per-orbit", type=_positive_count, default=40, metavar="N",
                       help="output times per orbit (default 40)")
    model.add_argument("--rtol", default=1e-12, metavar="RTOL", help="DOP853 relative tolerance (default 1e-12)")
    model.add_argument("--libration", default=0.0, metavar="DEG",
                       help="Dimorphos turned this many degrees from the line to Didymos at the start (default 0)")
    impact = parser.add_argument_group("DART-like impact at t = 0")
    impact.add_argument("--impact", action="store_true", help="also run after an impulsive velocity change of Dimorphos")
    impact.add_argument("--beta", default=3.61, metavar="BETA",
                        help="momentum enhancement (default 3.61, Cheng et al. 2023)")
    impact.add_argument("--impactor-mass", default=579.4, metavar="KG", help="impactor mass in kg (default 579.4)")
    impact.add_argument("--impactor-speed", default=6.1449, metavar="KM_S",
                        help="impactor speed in km/s (default 6.1449)")
    impact.add_argument("--impact-elevation", default=0.0, metavar="DEG",
                        help="angle of the impactor's velocity out of the orbit plane (default 0: in the plane, head-on)")
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
        f"principal-axis at the rest, max E/E0 - 1 = {energy_excess:.3g}"
        + (f", P_psi = {p_psi.to_value(u.h):.3f} h, P_phi = {p_phi.to_value(u.h):.3f} h" if tumbling else ""),
        f"  drift                    |dE/E| = {e_rel.max():.2e} (|dE/U| = {e_potential.max():.2e}), "
        f"|dH/H| = {run.angular_momentum_drift().max():.2e}",
        f"  steps                    {run.stats['accepted']} accepted, {run.stats['rejected']} rejected",
    ]
    print("\n".join(lines))


def _orbit_lines(run):
    """The mutual period and the libration lines, each with its resolution, or why the run cannot give them."""
    import astropy.units as u

    from spinorbit.core.binary.errors import UnresolvedPeriodError

    def short(error):
        # A run too short for a period: say so and how long it must be, instead of printing the wrong line.
        hint = ""
        if error.required_span is not None:
            hint = f" Here: --orbits {math.ceil(error.required_span / _nominal_period_s())} or more."
        return f"  not resolved             {error}{hint}"

    try:
        period = run.mutual_period()
    except UnresolvedPeriodError as error:
        return [short(error)]
    lines = [f"  mutual orbit period      {period.to_value(u.h):.5f} h"]
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
    """The nominal mutual period of the set-up (s): the unit of --orbits."""
    import astropy.units as u

    from spinorbit.data.didymos import RELATIVE_SPEED, SEPARATION

    return (2 * math.pi * SEPARATION / RELATIVE_SPEED).to_value(u.s)


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
    args.beta = check.number("--beta", args.beta, "3.61", low=0.0,
                             advice="beta is the momentum enhancement, ≥ 1 in practice.")
    args.impactor_mass = check.number("--impactor-mass", args.impactor_mass, "579.4", low=0.0, low_open=True)
    args.impactor_speed = check.number("--impactor-speed", args.impactor_speed, "6.1449", low=0.0, low_open=True)
    args.impact_elevation = check.number("--impact-elevation", args.impact_elevation, "30", low=-90.0, high=90.0)


def run(args) -> int:
    """Run ``spinorbit didymos``; return the exit status."""
    import astropy.units as u
    import numpy as np

    from spinorbit.binary import momentum_impulse, propagate
    from spinorbit.core.errors import SpinorbitError
    from spinorbit.data.didymos import RELATIVE_SPEED, SEPARATION, didymos_state

    check_outputs(args)
    check_options(args)
    rows = args.orbits * args.per_orbit + 1
    if rows > MAX_ROWS:
        raise CommandError(f"--orbits {args.orbits} with --per-orbit {args.per_orbit} gives {rows} output rows, more than "
                           f"{MAX_ROWS}; lower one of them.")
    if args.per_orbit < 8:
        raise CommandError(f"--per-orbit expects at least 8 output times per orbit to resolve the libration, got "
                           f"{args.per_orbit}.")
    try:
        state = didymos_state(order=args.order, libration=args.libration * u.deg)
    except SpinorbitError as error:
        raise CommandError(f"--order: {error}") from None
    system = state.system
    period = (2 * math.pi * SEPARATION / RELATIVE_SPEED).to(u.s)
    times = np.linspace(0.0, args.orbits, rows) * period
    print(f"Didymos            sphere, radius {system.primary.semi_axes_m[0]:.1f} m, mass {system.primary.mass.value:.4e} kg")
    print(f"Dimorphos          ellipsoid {' x '.join(f'{a:g}' for a in system.secondary.semi_axes_m)} m, mass "
          f"{system.secondary.mass.value:.4e} kg")
    print(f"model              mutual potential to order {args.order}; contact distance "
          f"{system.contact_distance.to_value(u.m):.1f} m; DOP853 rtol {args.rtol:g}")
    cases = [("nominal", state)]
    if args.impact:
        elevation = math.radians(args.impact_elevation)
        direction = -state.velocity.value / np.linalg.norm(state.velocity.value)
        velocity = (direction * math.cos(elevation) + np.array([0.0, 0.0, math.sin(elevation)])) * args.impactor_speed
        dv = momentum_impulse(args.impactor_mass * u.kg, velocity * u.km / u.s, args.beta, system.secondary.mass)
        print(f"impact             dv = {np.linalg.norm(dv.value) * 1e3:.4f} mm/s (beta {args.beta:g}, "
              f"{args.impactor_mass:g} kg at {args.impactor_speed:g} km/s, elevation {args.impact_elevation:g} deg)")
        cases.append(("after impact", state.with_velocity_change(dv)))
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
    if args.output is not None:
        write_table_output(args.output, _table(runs), f"{rows} rows over {args.orbits} orbits")
    if args.plot is not None:
        write_plot_output(args.plot, lambda temporary: _plot(runs, temporary))
    return 0
