"""``spinorbit torque-free``: exact free rotation of a rigid body from given moments, attitude and spin."""

from __future__ import annotations

import argparse
import math

from spinorbit.cli import CommandError
from spinorbit.commands import _inputs as check
from spinorbit.commands._spin_options import FORMS, READ, add_spin_arguments, spin_state, spin_values
from spinorbit.commands._common import (Progress, check_output_paths, number, plot_format, quantity, unit,
                                        write_plot_output, write_table_output)

NAME = "torque-free"
SUMMARY = "exact torque-free rotation for given moments of inertia and spin"
DESCRIPTION = """\
Propagate the free rotation of a rigid body exactly (Fukushima's canonical elements: no numerical
integration, no step-size error). Give the principal moments about the body x, y, z axes (kg m^2 or
plain ratios, any order), the body angular velocity, and optionally the attitude as 3-1-3 Euler
angles. Prints the rotation mode (SAM/LAM), its sense, the rotation class (PA when the wobble
amplitude is at most --pa-threshold: then one sidereal period P; else the periods P_psi (rotation)
and P_phi (precession)) and E/E0; writes the attitude and spin at each output time to an ECSV table.

Conventions (docs/conventions.md): quaternions are scalar first (w, x, y, z) and take body axes to
inertial axes; Euler angles are passive 3-1-3, R = R3(psi) R1(theta) R3(phi), inertial -> body."""
EXAMPLES = """\
examples:
  # (4179) Toutatis (Takahashi et al. 2013): long-axis mode, P_psi = 5.37 d, P_phi = 7.41 d
  spinorbit torque-free --moments 3.0836 3.235 1 --omega 14.51 33.529 -98.709 \\
      --euler313 145.498 65.865 241.524 --span 100 d --step 0.1 d --output toutatis.ecsv

  # spin in rad/s, 1000 output times over a year, with a plot (needs: pip install 'spinorbit[plot]')
  spinorbit torque-free --moments 1 2 2.5 --omega 1e-4 0 3e-4 --omega-unit rad/s \\
      --span 1 yr --n-times 1000 --output run.ecsv --plot run.png

exit status: 0 on success; 2 with a one-line message if the input is wrong or an output file
cannot be written (nothing is left half-written)."""

#: Output times are computed in chunks of this many, so the progress bar can move.
CHUNK = 20_000
#: Refuse runs whose table would not fit comfortably in memory (8 columns of float64).
MAX_TIMES = 10_000_000


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number of output times, got '{text}'") from None
    if not 2 <= value <= MAX_TIMES:
        raise argparse.ArgumentTypeError(f"expected between 2 and {MAX_TIMES} output times, got {value}")
    return value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Declare the options of ``spinorbit torque-free``."""
    body = parser.add_argument_group("body and initial state")
    body.add_argument(
        "--moments", nargs=3, type=number, required=True, metavar=("IX", "IY", "IZ"),
        help="principal moments of inertia about the body x, y, z axes (kg m^2 or ratios; any order)",
    )
    add_spin_arguments(
        body,
        omega_help="body angular velocity components WX WY WZ along x, y, z, then optionally their unit: "
        "'14.51 33.529 -98.709' (deg/day, or --omega-unit), '1e-4 0 3e-4 rad/s'",
        euler313_help="initial attitude: passive 3-1-3 Euler angles PHI THETA PSI of the body relative to "
        "--spin-frame (default ICRF), then a unit (default deg); default 0 0 0, body = inertial axes",
    )
    body.add_argument(
        "--omega-unit", metavar="UNIT",
        help="unit of --omega's numbers when they have none, any astropy angular-velocity unit: deg/day "
        "(default), rad/s, deg/h, cycle/d, ...",
    )
    body.add_argument(
        "--spin-frame", choices=("ecliptic", "icrf"),
        help="frame of the spin's angles: ICRF for --euler313, ecliptic J2000 for --pole and --momentum (as "
        "published) unless given",
    )
    times = parser.add_argument_group("output times")
    times.add_argument(
        "--epoch", default="2000-01-01T12:00:00", metavar="TIME",
        help="date of the initial state, ISO in TDB (default J2000.0); the table's time column starts there",
    )
    times.add_argument(
        "--span", nargs="+", default=["100", "d"], metavar="SPAN",
        help="how long to propagate, e.g. '100 d', '2 yr', '36 h' (a number alone is days; default 100 d); "
        "negative goes back in time",
    )
    body.add_argument(
        "--pa-threshold", nargs="+", default=["1", "deg"], metavar="ANGLE",
        help="wobble amplitude up to which the state is a principal-axis rotator (PA: one sidereal period; above "
        "it SAM/LAM with P_psi, P_phi), e.g. '0.1 deg' (a number alone is deg); default 1 deg (docs/design.md "
        "'PA or NPA')",
    )
    spacing = times.add_mutually_exclusive_group()
    spacing.add_argument("--step", nargs="+", metavar="STEP", help="spacing of output times, e.g. '1 d' (a number alone is days; default 1 d)")
    spacing.add_argument("--n-times", type=_count, metavar="N", help="number of evenly spaced output times instead")
    files = parser.add_argument_group("output files")
    files.add_argument("--output", metavar="FILE.ecsv", help="write the table (time, attitude, spin, pole, periods; "
                       "docs/conventions.md 'Output tables') as ECSV (FILE.ecsv) or CSV (FILE.csv)")
    files.add_argument("--plot", metavar="FILE.png", help="plot against the date: a tumbler's periods, pole and "
                       "class; a principal-axis rotator's pole drift (arcsec), period residual and wobble (needs "
                       "matplotlib; .png, .pdf or .svg)")


def _offsets(args):
    """Output times (days from the initial state) as a float array."""
    import numpy as np

    span = quantity("--span", args.span, "d", "time", "100 d").to_value("d")
    if span == 0:
        raise CommandError("--span expects a non-zero duration such as '100 d'; got 0.")
    if args.n_times is not None:
        return np.linspace(0.0, span, args.n_times)
    step = quantity("--step", args.step or ["1", "d"], "d", "time", "1 d").to_value("d")
    if step <= 0:
        raise CommandError(f"--step expects a positive spacing such as '1 d'; got {' '.join(args.step)}.")
    count = math.floor(abs(span) / step + 1e-9) + 1
    if count > MAX_TIMES:
        raise CommandError(
            f"--span {' '.join(args.span)} with --step {' '.join(args.step or ['1', 'd'])} gives {float(count):.3g} output times, "
            f"more than {MAX_TIMES}; use a larger --step or --n-times."
        )
    return math.copysign(step, span) * np.arange(count)


def _epoch(text, offsets):
    """The --epoch Time (TDB), checked with the last output time: both must be dates the table can hold."""
    epoch = check.time("--epoch", text)
    end = epoch.jd1 + epoch.jd2 + float(offsets[-1])
    check.check_date("--span", end, f"a last output time {offsets[-1]:.6g} d from --epoch",
                     "Shorten --span: the table's time column holds dates as ISO text.")
    return epoch


def _state(args, epoch):
    """(RotationState at ``epoch``, the spin form, its checked values) from the spin options given."""
    from spinorbit import InvalidBodyError, RigidBody

    if args.omega is not None:
        if len(args.omega) > 3 and args.omega_unit is not None:
            raise CommandError(f"--omega '{' '.join(args.omega)}' has its unit and --omega-unit gives another; "
                               "give the unit once.")
        if args.omega_unit is not None:
            omega_unit = unit("--omega-unit", args.omega_unit, "angular velocity", "deg/day or rad/s")
            args.omega = [*args.omega, *omega_unit.to_string().split()]
        other_forms = [key for form, keys in FORMS.items() if form != "euler313" for key in keys]
        if args.euler313 is None and all(getattr(args, key) is None for key in other_forms):
            args.euler313 = ["0", "0", "0"]  # the documented default: body axes on the inertial axes
    try:
        body = RigidBody(args.moments)
    except InvalidBodyError as error:
        raise CommandError(f"--moments: {error}") from None
    form, values = spin_values(args, {})
    if form == "euler313":
        if not values["omega"].value.any():
            raise CommandError("--omega expects a non-zero angular velocity; got 0 0 0 (a body at rest has no "
                               "rotation).")
    frame = args.spin_frame or ("icrf" if form == "euler313" else "ecliptic")
    return spin_state(body, form, values, epoch, frame), form, values


def _given(form, values) -> dict:
    """The spin as given, for the table's metadata: each key's values in its unit (omega in the unit given)."""
    meta = {"spin_form": form}
    for key, value in values.items():
        if key == "mode":
            meta["mode_given"] = value
        elif key == "omega":
            meta["omega_xyz"], meta["omega_unit"] = value.value.tolist(), value.unit.to_string()
        else:
            unit_name = READ[key][1]
            meta[f"{key}_{unit_name}"] = value.to_value(unit_name).tolist()
    return meta


def _summary(state, threshold) -> list[str]:
    big_a, big_b, big_c = state.body.principal_moments
    rotation_class = state.rotation_class(threshold)
    lines = [
        f"principal moments  A, B, C = {big_a:.6g}, {big_b:.6g}, {big_c:.6g}",
        f"mode               {state.mode}, sense {state.sense}",
        f"rotation class     {rotation_class}: wobble amplitude {state.wobble_amplitude.to_value('deg'):.4g} deg "
        f"({'at most' if rotation_class == 'PA' else 'more than'} --pa-threshold {threshold:g}; docs/conventions.md, "
        "'Wobble and rotation class')",
    ]
    if rotation_class == "PA":  # one rotation: its split into a wobble below the threshold and a spin is not reported
        lines.append(f"period             P = {state.sidereal_period.to_value('d'):.4f} d (sidereal, principal-axis "
                     "rotator)")
    else:
        p_psi, p_phi = state.periods
        lines += [f"periods            P_psi = {p_psi.to_value('d'):.4f} d (rotation), "
                  f"P_phi = {p_phi.to_value('d'):.4f} d (precession)",
                  f"sidereal period    {state.sidereal_period.to_value('d'):.4f} d (docs/conventions.md, 'Periods')"]
    lines.append(f"E/E0               {state.energy_ratio:.6f}")
    return lines


def _propagate(state, offsets):
    import astropy.units as u
    import numpy as np

    progress = Progress(len(offsets), "propagating")
    quaternions, omegas = [], []
    try:
        for start in range(0, len(offsets), CHUNK):
            q, omega = state.propagate_torque_free(offsets[start : start + CHUNK] * u.day)
            quaternions.append(q)
            omegas.append(omega)
            progress.advance(len(q))
    finally:
        progress.close()
    return _continuous(np.concatenate(quaternions)), np.concatenate(omegas)


def _continuous(quaternions):
    """Choose the sign of each quaternion (q and -q are one attitude) so the series has no jumps."""
    import numpy as np

    dots = np.einsum("ij,ij->i", quaternions[1:], quaternions[:-1])
    signs = np.cumprod(np.where(dots < 0, -1.0, 1.0))
    quaternions[1:] *= signs[:, None]
    return quaternions


def _pa_threshold(args):
    """The --pa-threshold angle, checked to lie in [0°, 90°) (at 90° the separatrix would be PA)."""
    return check.quantity("--pa-threshold", args.pa_threshold, "deg", "1 deg", default_unit="deg", low=0.0, high=90.0,
                          high_open=True, advice="It is the wobble amplitude up to which a state is a principal-axis "
                          "rotator.")


def _table(args, state, epoch, offsets, quaternions, omegas, given, threshold):
    """The output schema's table (docs/conventions.md, "Output tables") of the run, with the inputs in meta."""
    import astropy.units as u
    from astropy.table import Table

    from spinorbit import __version__
    from spinorbit.state_table import as_schema_time, classify_rows, schema_meta, table_columns

    p_psi, p_phi = state.periods
    table = Table()
    table["time"] = as_schema_time(epoch + offsets * u.day)
    columns = table_columns(state.body, quaternions, omegas.to_value(u.rad / u.day), motion=state)
    for name, column in columns.items():
        table[name] = column
    table.meta.update(schema_meta(epoch, "exact torque-free rotation (Fukushima's canonical elements, paper eq. 12)"))
    classify_rows(table, threshold)
    table.meta.update({
        "software": f"spinorbit {__version__} torque-free",
        "moments_xyz": list(args.moments),
        **given,
        "mode": state.mode,
        "sense": state.sense,
        "P_psi_d": float(p_psi.to_value(u.day)),
        "P_phi_d": float(p_phi.to_value(u.day)),
        "sidereal_period_d": float(state.sidereal_period.to_value(u.day)),
        "wobble_amplitude_deg": float(state.wobble_amplitude.to_value(u.deg)),
        "rotation_class": state.rotation_class(threshold),
        "E_over_E0": state.energy_ratio,
        "conventions": (
            "quaternion scalar first (w, x, y, z), body axes -> inertial (ICRF), sign continuous in time; "
            "omega in body axes, rad/day; Euler angles passive 3-1-3, R = R3(psi) R1(theta) R3(phi)"
        ),
    })
    return table


def _plot(table, path, name):
    from spinorbit.commands._outputs import plot_rotation

    plot_rotation(table, path, f"torque-free rotation: {table.meta['mode']} {table.meta['sense']}", plot_format(name))


def _require_matplotlib():
    try:
        import matplotlib  # noqa: F401
    except ImportError:
        raise CommandError(
            "--plot needs matplotlib, which is not installed; install it with: pip install 'spinorbit[plot]'"
        ) from None


def run(args) -> int:
    """Run ``spinorbit torque-free``; return the exit status."""
    check_output_paths(args)
    if args.plot is not None:
        _require_matplotlib()
    offsets = _offsets(args)
    epoch = _epoch(args.epoch, offsets)
    state, form, values = _state(args, epoch)
    threshold = _pa_threshold(args)
    for line in _summary(state, threshold):
        print(line)
    quaternions, omegas = _propagate(state, offsets)
    table = _table(args, state, epoch, offsets, quaternions, omegas, _given(form, values), threshold)
    span = f"{offsets[-1]:g} d"
    if args.output is not None:
        write_table_output(args.output, table, f"{len(table)} rows over {span}")
    if args.plot is not None:
        write_plot_output(args.plot, lambda temporary: _plot(table, temporary, args.plot))
    if args.output is None and args.plot is None:
        print(f"propagated         {len(table)} times over {span}; give --output FILE.ecsv to keep them")
    return 0
