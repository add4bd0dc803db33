"""The TOML scene file of ``spinorbit asteroid``: read, every key checked, before any work.

:func:`read_scene_file` decodes the file (UTF-8, as TOML requires), parses it with :mod:`tomllib`
and checks each key with the validation layer (:mod:`spinorbit.commands._inputs`): a key the schema
does not know is refused (a typo is not silently ignored), and every value is converted to what the
command needs (Quantities, Times, numbers) or refused with an :class:`spinorbit.InputError` that
names the key as ``[table] key``. docs/cli.md shows a complete file (``examples/asteroid_scene.toml``).
"""

from __future__ import annotations

from spinorbit.commands import _inputs as check
from spinorbit.commands._spin_options import FORMS, read_spin_key
from spinorbit.core.errors import InputError

#: Most output times a scene accepts (as spinorbit.commands._scene_command.MAX_TIMES).
MAX_TIMES = 100_000
#: The orbit's frames (Orbit.from_elements) and the spin state's.
ORBIT_FRAMES = ("ecliptic", "ecliptic-iau2006", "icrf")
SPIN_FRAMES = ("ecliptic", "icrf")


def _moments(where, value):
    """Three positive numbers (the principal moments, any scale)."""
    if not isinstance(value, (list, tuple)) or len(value) != 3:
        raise InputError(where, "a list of three principal moments such as [0.7, 0.9, 1.0]", check.shown(value),
                         "Write the three numbers as a TOML list.")
    return [check.number(where, item, "[0.7, 0.9, 1.0]", low=0.0, low_open=True) for item in value]


def _angle(where, value):
    return check.quantity(where, value, "deg", "30 deg")


def _non_gravitational(where, value):
    if not isinstance(value, dict):
        raise InputError(where, "a table of A1, A2, A3 such as A2 = \"-2.9e-14 AU / d2\"", check.shown(value))
    unknown = sorted(set(value) - {"A1", "A2", "A3"})
    if unknown:
        raise InputError(where, "the keys A1, A2, A3", f"the key {unknown[0]!r}")
    return {key: check.quantity(f"[orbit.non_gravitational] {key}", text, "AU / d2", "-2.9e-14 AU / d2")
            for key, text in value.items()}


#: Each table's keys and the check that reads each value (``where`` is "[table] key").
SCHEMA = {
    "orbit": {
        "epoch": check.time,
        "a": lambda where, value: check.quantity(where, value, "au", "2.5 au", low=0.0, low_open=True),
        "e": lambda where, value: check.number(where, value, "0.25", low=0.0, high=1.0, high_open=True,
                                               advice="spinorbit asteroid takes elliptic orbits."),
        "inc": _angle, "raan": _angle, "argp": _angle, "mean_anomaly": _angle,
        "frame": lambda where, value: check.choice(where, value, ORBIT_FRAMES),
        "non_gravitational": _non_gravitational,
    },
    "body": {"moments": _moments},
    "spin": {  # the spin forms' keys: spinorbit.commands._spin_options
        "epoch": check.time,
        "frame": lambda where, value: check.choice(where, value, SPIN_FRAMES),
        **{key: (lambda where, value, key=key: read_spin_key(key, value)) for keys in FORMS.values() for key in keys},
    },
    "run": {
        "start": check.time,
        "span": lambda where, value: check.quantity(where, value, "d", "120 d", low=0.0, low_open=True),
        "n_times": lambda where, value: check.integer(where, value, "240", low=2, high=MAX_TIMES),
        "end_only": check.boolean,
        "perturbers": lambda where, value: check.names(where, value, "['sun', 'earth']"),
        "tolerance": lambda where, value: check.quantity(where, value, "arcsec", "1 arcsec", low=0.0, low_open=True),
        "pa_threshold": lambda where, value: check.quantity(where, value, "deg", "1 deg", low=0.0, high=90.0,
                                                            high_open=True),
        "output": lambda where, value: check.text(where, value, "example_nea.ecsv"),
        "plot": lambda where, value: check.text(where, value, "example_nea.png"),
    },
}


def read_scene_file(path: str) -> dict:
    """The scene file as ``{"name": str, table: {key: checked value}}``; InputError naming the key otherwise."""
    import tomllib

    try:
        with open(path, "rb") as handle:
            data = handle.read()
    except OSError as error:
        raise InputError("--scene", "a readable TOML file", f"'{path}', which cannot be read ({error.strerror})",
                         "Check the path.") from None
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as error:
        raise InputError("--scene", "a TOML file (UTF-8 text)", f"'{path}', whose byte {error.start} is not UTF-8 "
                         "text", "Give the scene's .toml file, not a binary one.") from None
    try:
        scene = tomllib.loads(text)
    except tomllib.TOMLDecodeError as error:
        raise InputError("--scene", "a valid TOML file", f"'{path}', which is not valid TOML ({error})",
                         "See examples/asteroid_scene.toml for the form.") from None
    checked = {}
    for table, values in scene.items():
        if table == "name":
            checked["name"] = check.text("name", values, "Example NEA")
            continue
        if table not in SCHEMA:
            raise InputError("--scene", f"the tables {', '.join(f'[{name}]' for name in SCHEMA)} and the key name",
                             f"the table or key {table!r} in '{path}'")
        if not isinstance(values, dict):
            raise InputError(f"[{table}]", f"a table with keys {', '.join(SCHEMA[table])}", check.shown(values))
        unknown = sorted(set(values) - set(SCHEMA[table]))
        if unknown:
            raise InputError(f"[{table}]", f"some of the keys {', '.join(SCHEMA[table])}",
                             f"the unknown keys {unknown}", "Check the spelling.")
        checked[table] = {key: SCHEMA[table][key](f"[{table}] {key}", value) for key, value in values.items()}
    return checked
