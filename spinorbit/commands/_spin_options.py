"""A spin state given as it is published, on the command line and in the scene file (issue 35).

Three forms, each one set of options (and the scene file's ``[spin]`` keys of the same names):

- **Euler angles and spin**: ``--euler313 PHI THETA PSI [unit]`` (passive 3-1-3 angles of the body
  relative to the frame) and ``--omega WX WY WZ [unit]`` (body angular velocity), as before.
- **Principal-axis rotator** (DAMIT; :meth:`spinorbit.RotationState.from_pole`): ``--pole LON LAT
  [unit]``, ``--period P [unit]`` (sidereal) and ``--phase PHI0 [unit]`` (the rotation angle at the
  spin epoch, default 0 deg).
- **Tumbler** (Pravec et al. 2005, Kaasalainen 2001; :meth:`spinorbit.RotationState.from_tumbling`):
  ``--tumbling P_PSI P_PHI [unit]``, ``--momentum LON LAT [unit]`` (the angular momentum's
  direction), ``--euler-zxz PHI0 THETA0 PSI0 [unit]`` (z-x-z angles of the body in the momentum's
  frame) and ``--mode SAM|LAM`` (default: from the body's z axis).

Every option takes its numbers and then a unit; a number alone is in the unit its ``--help`` names
(deg, h, deg/day). The frame of the angles (``--spin-frame``, ``[spin] frame``) is the ecliptic J2000
by default, or ICRF. A form given on the command line wins over the file's; two forms in one place
are refused.
"""

from __future__ import annotations

from spinorbit.cli import CommandError
from spinorbit.commands import _inputs as check

#: Each form's keys (the scene file's names; the option is ``--`` + the key with ``-`` for ``_``) and which are
#: optional.
FORMS = {
    "euler313": ("euler313", "omega"),
    "pole": ("pole", "period", "phase"),
    "tumbling": ("tumbling", "momentum", "euler_zxz", "mode"),
}
OPTIONAL = ("phase", "mode")
#: How each key is read: (number of values, unit, default unit of plain numbers on the command line, example).
READ = {
    "euler313": (3, "deg", "deg", "10 40 70 deg"),
    "omega": (3, "deg / d", "deg/day", "0 0 1080 deg/day"),
    "pole": (2, "deg", "deg", "30 -40 deg"),
    "period": (1, "h", "h", "8 h"),
    "phase": (1, "deg", "deg", "0 deg"),
    "tumbling": (2, "h", "h", "263 27.38 h"),
    "momentum": (2, "deg", "deg", "250 -75 deg"),
    "euler_zxz": (3, "deg", "deg", "10 30 20 deg"),
}
#: The modes a tumbler may be given in.
MODES = ("SAM", "LAM")


def option(key: str) -> str:
    return "--" + key.replace("_", "-")


def add_spin_arguments(group, omega_help: str = "body angular velocity WX WY WZ in the moments' axes, then a unit "
                       "(default deg/day), e.g. '0 0 1080 deg/day', '0 0 45 deg/h'",
                       euler313_help: str = "attitude: passive 3-1-3 Euler angles PHI THETA PSI of the body relative "
                       "to --spin-frame, then a unit (default deg), e.g. '10 40 70 deg'") -> None:
    """The three forms' options, on an argparse group (a command may say more of the first form's two)."""
    group.add_argument("--euler313", nargs="+", metavar="ANGLE", help=euler313_help)
    group.add_argument("--omega", nargs="+", metavar="RATE", help=omega_help)
    group.add_argument("--pole", nargs="+", metavar="ANGLE",
                       help="principal-axis rotator (DAMIT): spin pole LON LAT in --spin-frame, then a unit (default "
                       "deg), e.g. '30 -40 deg'; with --period and --phase")
    group.add_argument("--period", nargs="+", metavar="TIME",
                       help="with --pole: sidereal rotation period, then a unit (default h), e.g. '8 h', '0.3 d'")
    group.add_argument("--phase", nargs="+", metavar="ANGLE",
                       help="with --pole: rotation angle phi0 at the spin epoch (DAMIT), then a unit (default deg); "
                       "default 0 deg")
    group.add_argument("--tumbling", nargs="+", metavar="TIME",
                       help="tumbler (Pravec et al. 2005): periods P_PSI P_PHI, then a unit (default h), e.g. "
                       "'263 27.38 h'; with --momentum, --euler-zxz and --mode")
    group.add_argument("--momentum", nargs="+", metavar="ANGLE",
                       help="with --tumbling: direction LON LAT of the angular momentum in --spin-frame, then a unit "
                       "(default deg)")
    group.add_argument("--euler-zxz", nargs="+", metavar="ANGLE",
                       help="with --tumbling: z-x-z Euler angles PHI0 THETA0 PSI0 of the body in the momentum's frame "
                       "at the spin epoch (Kaasalainen 2001), then a unit (default deg)")
    group.add_argument("--mode", choices=MODES,
                       help="with --tumbling: short- or long-axis mode (default: SAM if the body's z axis has the "
                       "largest moment, LAM if the smallest)")


def _read(key: str, value, from_file: bool):
    """The value of one key, from the command line's words or the file, as Quantities (or the mode's name)."""
    where = f"[spin] {key}" if from_file else option(key)
    if key == "mode":
        return check.choice(where, value, MODES)
    count, unit, default_unit, example = READ[key]
    plain = None if from_file else default_unit
    if count == 1:
        return check.quantity(where, value, unit, example, default_unit=plain)
    return check.vector(where, value, unit, example, count=count, default_unit=plain)


def _form_of(given: dict, place: str):
    """The one form whose keys ``given`` has (None if none); two forms in one place are refused."""
    forms = [form for form, keys in FORMS.items() if any(key in given for key in keys)]
    if len(forms) > 1:
        shown = [", ".join(option(k) if place == "the command line" else k for k in FORMS[f] if k in given)
                 for f in forms]
        raise CommandError(f"{place} gives two spin forms ({'; '.join(shown)}); give one: --euler313 with --omega, "
                           "--pole with --period, or --tumbling with --momentum and --euler-zxz.")
    return forms[0] if forms else None


def spin_values(args, table: dict) -> tuple[str, dict]:
    """(form, values): the spin form and its checked values, the command line's form winning over the file's.

    ``table`` is the scene file's ``[spin]`` table, already read by :func:`read_spin_key` (empty
    without a file).
    """
    given = {key: getattr(args, key) for keys in FORMS.values() for key in keys if getattr(args, key, None) is not None}
    form = _form_of(given, "the command line")
    filed = {key: value for key, value in table.items() if any(key in keys for keys in FORMS.values())}
    file_form = _form_of(filed, "[spin]")
    values = {key: _read(key, value, False) for key, value in given.items()}
    if form is None or form == file_form:  # the file completes what the command line leaves out
        form = form or file_form
        values = {**filed, **values}
    if form is None:
        raise CommandError("the spin state is missing: give --euler313 with --omega, --pole with --period, or "
                           "--tumbling with --momentum and --euler-zxz (or the same keys in the file's [spin]).")
    missing = [key for key in FORMS[form] if key not in values and key not in OPTIONAL]
    if missing:
        raise CommandError(f"the {form} spin form is missing {', '.join(option(k) for k in missing)} (or [spin] "
                           f"{', '.join(missing)}); see --help.")
    return form, values


def read_spin_key(key: str, value):
    """A ``[spin]`` key of the scene file that belongs to a form, checked (the scene file's schema calls this)."""
    return _read(key, value, True)


def spin_state(body, form: str, values: dict, epoch, frame: str):
    """The RotationState of the form's values at ``epoch`` (ICRF attitude), the angles in ``frame``."""
    import astropy.units as u

    from spinorbit import RotationState
    from spinorbit.frames import icrf_to_ecliptic_matrix
    from spinorbit.spin_forms import SpinFormError

    if form == "euler313":
        state = RotationState.from_euler313(body, *values["euler313"], values["omega"])
        if frame == "ecliptic":  # v_body = R_ecl v_ecl = R_ecl E v_icrf
            state = RotationState.from_matrix(body, state.attitude_matrix @ icrf_to_ecliptic_matrix(), values["omega"])
        return state.with_epoch(epoch)
    for key in ("period", "tumbling"):
        if key in values and not (values[key] > 0 * u.s).all():
            raise CommandError(f"{option(key)} expects positive periods; got {values[key]}.")
    try:
        if form == "pole":
            return RotationState.from_pole(body, *values["pole"], values["period"], epoch,
                                           phase=values.get("phase", 0 * u.deg), frame=frame)
        return RotationState.from_tumbling(body, *values["tumbling"], *values["momentum"], *values["euler_zxz"], epoch,
                                           mode=values.get("mode"), frame=frame)
    except SpinFormError as error:  # the API's words, said to be about this form's options
        keys = ", ".join(option(key) for key in FORMS[form])
        raise CommandError(f"{keys}: {error}") from None
