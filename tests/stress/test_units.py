"""Units that mean what the user meant (issue 14, class 2), tested on the API and the CLI the same way.

hypothesis draws a unit from frequencies (refused: docs/conventions.md, "Units"), turns and angles per
time (converted, cycles with 2π), and wrong physical types, and a value. The API
(``RotationState``, ``propagate_torque_free``, ``RigidBody``, the Euler-angle constructor) and the
command line (``--omega-unit``, ``--span``, ``--step``) must then agree: both refuse, naming the
argument, the expected unit and what arrived; or both accept with the same number of rad/day, which
is checked against the unit's definition written out here (1 cycle = 2π rad, 1 deg = π/180 rad).
"""

import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy.table import Table
from hypothesis import given, settings
from hypothesis import strategies as st

from spinorbit import RigidBody, RotationState
from spinorbit.quantities import QuantityInputError

from tests.stress._cli import run_cli


BODY = RigidBody([1.0, 2.0, 2.5])
IDENTITY = [1.0, 0.0, 0.0, 0.0]
#: rad/day per unit, written from the definitions (not from astropy), for the rates that are accepted.
RATES = {"rad/d": 1.0, "rad/s": 86400.0, "deg/d": math.pi / 180, "deg/h": 24 * math.pi / 180,
         "cycle/d": 2 * math.pi, "cycle/s": 2 * math.pi * 86400, "cycle/h": 48 * math.pi,
         "arcsec/yr": math.pi / 180 / 3600 / 365.25}
FREQUENCIES = ["Hz", "1/d", "1/s", "kHz", "1/yr", "mHz"]
WRONG = ["m", "kg", "m/s", "d", "rad", "deg", "", "kg m2", "rad/m"]
#: days per unit, from the definitions, for time offsets.
DAYS = {"d": 1.0, "h": 1 / 24, "s": 1 / 86400, "yr": 365.25, "min": 1 / 1440}
EXAMPLES = 60


def assert_refusal_names(message, name, expected, arrived):
    assert name in message and expected in message and arrived in message, message


@settings(max_examples=EXAMPLES)
@given(st.sampled_from(sorted(RATES) + FREQUENCIES + WRONG), st.floats(1e-3, 1e3) | st.floats(-1e3, -1e-3))
def test_spin_units_are_read_alike_by_the_api_and_the_cli(unit_text, value):
    unit = u.Unit(unit_text) if unit_text else u.dimensionless_unscaled
    kind = "rate" if unit_text in RATES else "frequency" if unit_text in FREQUENCIES else "wrong"
    try:
        state = RotationState(BODY, IDENTITY, [value, 0.0, 0.0] * unit)
        api = None
    except QuantityInputError as error:
        api = str(error)
    with tempfile.TemporaryDirectory() as directory:
        output = Path(directory) / "run.ecsv"
        status, err = run_cli(["torque-free", "--moments", "1", "2", "2.5", "--omega", repr(value), "0", "0",
                               "--omega-unit", unit_text or "''", "--span", "1", "d", "--n-times", "2",
                               "--output", str(output)])
        if kind == "rate":
            assert api is None and status == 0, (api, err)
            expected = value * RATES[unit_text]
            assert state.angular_velocity.to_value(u.rad / u.day) == pytest.approx([expected, 0, 0], rel=1e-14)
            table = Table.read(output, format="ascii.ecsv")
            back = (table["omega_x"][0] * table["omega_x"].unit).to_value(u.rad / u.day, u.dimensionless_angles())
            assert back == pytest.approx(expected, rel=1e-12)  # the CLI's table: same spin, in --omega-unit
            return
    assert api is not None and status == 2, (kind, api, err)
    assert len(err.splitlines()) == 1 and err.startswith("spinorbit torque-free: error: --omega-unit")
    if kind == "frequency":
        for message, name in ((api, "angular_velocity"), (err, "--omega-unit")):
            assert_refusal_names(message, name, "cycle /", "frequency")
            assert "2π" in message
    else:
        assert_refusal_names(api, "angular_velocity", "rad / d", str(unit) if unit_text else "dimensionless")
        assert "angular velocity" in err and "--omega-unit" in err


@settings(max_examples=EXAMPLES)
@given(st.sampled_from(sorted(DAYS) + FREQUENCIES + WRONG), st.floats(0.01, 100.0))
def test_time_units_are_read_alike_by_the_api_and_the_cli(unit_text, value):
    unit = u.Unit(unit_text) if unit_text else u.dimensionless_unscaled
    state = RotationState(BODY, IDENTITY, [0.1, 0.2, 0.3] * u.rad / u.day)
    try:
        quaternions, _ = state.propagate_torque_free([0.0, value] * unit)
        api = None
    except QuantityInputError as error:
        api = str(error)
    span = [repr(value), unit_text] if unit_text else [repr(value)]
    status, err = run_cli(["torque-free", "--moments", "1", "2", "2.5", "--omega", "0.1", "0.2", "0.3",
                           "--span", *span, "--n-times", "2"])
    if unit_text in DAYS or unit_text == "":  # a number alone is days, on both sides
        days = value * DAYS.get(unit_text, 1.0)
        if unit_text == "":
            assert api is not None and "dt" in api  # a dimensionless Quantity is not a plain number of days
            assert status == 0
            return
        assert api is None and status == 0, (api, err)
        plain, _ = state.propagate_torque_free([0.0, days] * u.day)
        assert np.abs(quaternions - plain).max() < 1e-12
        return
    assert api is not None and status == 2, (unit_text, api, err)
    assert_refusal_names(api, "dt", "time", str(unit))
    assert len(err.splitlines()) == 1 and "--span expects a time" in err and f"'{value!r} {unit_text}'" in err


QUANTITY_ARGUMENTS = [
    ("moments", "moment of inertia", lambda q: RigidBody([1.0, 2.0, 2.5] * q)),
    ("mass", "mass", lambda q: RigidBody([1.0, 2.0, 2.5], mass=q)),
    ("radius", "length", lambda q: RigidBody([1.0, 2.0, 2.5], radius=q)),
    ("angular_velocity", "angular velocity", lambda q: RotationState(BODY, IDENTITY, [1.0, 0.0, 0.0] * q)),
    ("angular_momentum", "angular velocity", lambda q: RotationState.from_angular_momentum(BODY, IDENTITY,
                                                                                           [1.0, 0.0, 0.0] * q)),
    ("theta", "angle", lambda q: RotationState.from_euler313(BODY, 0.1 * u.rad, 1.0 * q, 0.2 * u.rad,
                                                             [1.0, 0, 0] * u.rad / u.day)),
    ("dt", "time", lambda q: RotationState(BODY, IDENTITY, [1.0, 0.0, 0.0] * u.rad / u.day)
     .propagate_torque_free([1.0] * q)),
]
PHYSICAL = {"moment of inertia": "kg m2", "mass": "kg", "length": "km", "angular velocity": "rad/s",
            "angle": "deg", "time": "h"}


@settings(max_examples=EXAMPLES)
@given(st.sampled_from(QUANTITY_ARGUMENTS), st.sampled_from(sorted(PHYSICAL.values()) + ["m/s", "Hz", "1/d", "J"]))
def test_every_quantity_argument_of_the_wrong_type_names_itself_the_unit_and_what_arrived(argument, unit_text):
    name, physical_type, call = argument
    unit = u.Unit(unit_text)
    if unit.physical_type == u.Unit(PHYSICAL[physical_type]).physical_type:
        call(1.0 * unit)  # the right physical type is accepted
        return
    with pytest.raises(QuantityInputError) as info:
        call(1.0 * unit)
    message = str(info.value)
    assert message.startswith(f"{name}: ") and physical_type in message and str(unit) in message, message


def test_one_cycle_per_day_is_two_pi_radians_per_day_everywhere():
    state = RotationState(BODY, IDENTITY, [1.0, 0.0, 0.0] * u.cycle / u.day)
    assert state.angular_velocity.to_value(u.rad / u.day)[0] == 2 * math.pi
    with pytest.raises(QuantityInputError, match=r"got \[1\. 0\. 0\.\] Hz, a frequency.*cycle / d"):
        RotationState(BODY, IDENTITY, [1.0, 0.0, 0.0] * u.Hz)
