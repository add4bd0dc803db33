"""Catalogue of bad inputs across the public API (issue 7): each gets a specific exception whose
message says what was expected and what arrived.

Each case is (label, call, exception type, pattern the message must contain). The pattern is chosen
to show the *arrived* value or the *expected* form, so a vague "invalid input" would fail the test.
CLI cases live in tests/test_cli.py (exit code 2, one line, no file left behind).
"""

import datetime
import math

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState, special
from spinorbit import time as so_time
from spinorbit.body import InvalidBodyError
from spinorbit.core import SingularElementsError, andoyer_to_canonical, canonical_to_andoyer, torque_free_states_many
from spinorbit.core.dynamics import make_model
from spinorbit.core.integrate_quaternion import integrate_quaternion
from spinorbit.ephemeris import EphemerisRangeError, UnknownBodyError, barycentric_state, moon_orientation
from spinorbit.state import InvalidStateError

BODY = RigidBody([1.0, 2.0, 2.5])
IDENTITY = [1.0, 0.0, 0.0, 0.0]
STATE = np.array([1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 0.3])
J2000 = Time("2000-01-01T12:00:00", scale="tdb")


def model():
    return make_model((1.0, 2.0, 2.5))


CATALOGUE = [
    # --- rigid bodies
    ("moment NaN", lambda: RigidBody([1.0, math.nan, 2.0]), InvalidBodyError, "finite"),
    ("moment inf", lambda: RigidBody([1.0, math.inf, 2.0]), InvalidBodyError, "finite"),
    ("moment zero", lambda: RigidBody([0.0, 1.0, 1.0]), InvalidBodyError, "positive"),
    ("moment negative", lambda: RigidBody([-1.0, 2.0, 2.0]), InvalidBodyError, r"-1\.0"),
    ("two moments", lambda: RigidBody([1.0, 2.0]), InvalidBodyError, r"\(2,\)"),
    ("four moments", lambda: RigidBody([1.0, 2.0, 3.0, 4.0]), InvalidBodyError, r"\(4,\)"),
    ("moments text", lambda: RigidBody("abc"), TypeError, "'abc'"),
    ("triangle inequality", lambda: RigidBody([1.0, 1.0, 3.0]), InvalidBodyError, "A \\+ B ≥ C"),
    ("moments in metres", lambda: RigidBody([1.0, 2.0, 2.5] * u.m), u.UnitTypeError, "kg m"),
    ("mass in metres", lambda: RigidBody([1.0, 2.0, 2.5], mass=3 * u.m), u.UnitTypeError, "mass unit"),
    ("radius in kg", lambda: RigidBody([1.0, 2.0, 2.5], radius=3 * u.kg), u.UnitTypeError, "length unit"),
    # --- rotation states
    ("quaternion of 3", lambda: RotationState(BODY, [1.0, 0.0, 0.0], [1, 0, 0]), InvalidStateError, r"\(3,\)"),
    ("zero quaternion", lambda: RotationState(BODY, [0.0] * 4, [1, 0, 0]), InvalidStateError, "= 0.0"),
    ("non-unit quaternion", lambda: RotationState(BODY, [2.0, 0, 0, 0], [1, 0, 0]), InvalidStateError, "= 2.0"),
    ("NaN quaternion", lambda: RotationState(BODY, [math.nan, 0, 0, 1], [1, 0, 0]), InvalidStateError, "nan"),
    ("NaN spin", lambda: RotationState(BODY, IDENTITY, [1.0, math.nan, 0]), InvalidStateError, "nan"),
    ("spin of 2", lambda: RotationState(BODY, IDENTITY, [1.0, 0.0]), InvalidStateError, r"\(2,\)"),
    ("spin in m/s", lambda: RotationState(BODY, IDENTITY, [1.0, 0, 0] * u.m / u.s), u.UnitTypeError, "m / s"),
    ("body not a RigidBody", lambda: RotationState([1, 2, 3], IDENTITY, [1, 0, 0]), TypeError, "list"),
    ("reflection matrix", lambda: RotationState.from_matrix(BODY, np.diag([1.0, 1, -1]), [1, 0, 0]), InvalidStateError, "det"),
    ("sheared matrix", lambda: RotationState.from_matrix(BODY, [[1, 0.1, 0], [0, 1, 0], [0, 0, 1]], [1, 0, 0]), InvalidStateError, "not a rotation"),
    ("matrix 2x2", lambda: RotationState.from_matrix(BODY, np.eye(2), [1, 0, 0]), InvalidStateError, r"\(2, 2\)"),
    ("zero spin has no mode", lambda: RotationState(BODY, IDENTITY, [0, 0, 0]).mode, InvalidStateError, "zero spin"),
    ("Andoyer |L| > G", lambda: RotationState.from_andoyer(BODY, 2.0, 1.0, 0.0, 0, 0, 0), InvalidStateError, "L=2.0"),
    ("unknown reference", lambda: RotationState(BODY, IDENTITY, [0.1, 0.2, 1]).canonical_elements(reference="icrs"), ValueError, "'icrs'"),
    ("elements of a permanent rotation", lambda: RotationState(BODY, IDENTITY, [0, 1.0, 0]).canonical_elements(), SingularElementsError, "permanent rotation"),
    # --- paper-named core maps
    ("unordered moments", lambda: andoyer_to_canonical(0.3, 1, 0.2, 0.1, 0.2, 0.3, 2.0, 1.0, 2.5), ValueError, "A ≤ B ≤ C"),
    ("G negative", lambda: andoyer_to_canonical(0.3, -1, 0.2, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, "G ≤ 0"),
    ("|H| > G", lambda: andoyer_to_canonical(0.3, 1, 1.2, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, r"\|H\|"),
    ("NaN angle", lambda: andoyer_to_canonical(0.3, 1, 0.2, math.nan, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, "nan"),
    ("shapes do not broadcast", lambda: andoyer_to_canonical([0.3, 0.2], 1, [0.2, 0.1, 0], 0, 0, 0, 1.0, 2.0, 2.5), ValueError, r"L\(2,\)"),
    ("|S| above Z", lambda: canonical_to_andoyer(1.5, 1.0, 0.2, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, r"\[√\(A/C\) Z, Z\]"),
    ("Z zero", lambda: canonical_to_andoyer(0.5, 0.0, 0.0, 0.1, 0.2, 0.3, 1.0, 2.0, 2.5), ValueError, "Z ≤ 0"),
    # --- torque-free arrays
    ("torque-free unordered moments", lambda: torque_free_states_many(np.array([IDENTITY]), np.array([[1, 0, 0.0]]), (2.0, 1.0, 3.0), [0.0]), ValueError, "A ≤ B ≤ C"),
    ("torque-free mismatched states", lambda: torque_free_states_many(np.array([IDENTITY]), np.zeros((2, 3)), (1.0, 2.0, 3.0), [0.0]), ValueError, r"\(2, 3\)"),
    # --- elliptic functions
    ("m negative", lambda: special.ellipj(0.3, -0.1), ValueError, "m = -0.1"),
    ("mc inconsistent", lambda: special.ellipj(0.3, 0.5, mc=0.1), ValueError, "mc = 0.1"),
    ("elliptic shapes", lambda: special.ellipj([0.1, 0.2], [0.1, 0.2, 0.3]), ValueError, r"u\(2,\)"),
    ("divergent characteristic", lambda: special.ellippi(1.5, 0.3, 0.5), ValueError, "n = 1.5"),
    # --- integrators and models
    ("rtol negative", lambda: integrate_quaternion(STATE, 0.0, np.array([1.0]), model(), rtol=-1), ValueError, "got -1"),
    ("rtol absurdly small", lambda: integrate_quaternion(STATE, 0.0, np.array([1.0]), model(), rtol=1e-30), ValueError, "1e-30"),
    ("output times not increasing", lambda: integrate_quaternion(STATE, 0.0, np.array([2.0, 1.0]), model()), ValueError, r"\[2.0, 1.0\]"),
    ("NaN in state", lambda: integrate_quaternion(np.r_[1, 0, 0, math.nan, 0.1, 0.2, 0.3], 0.0, np.array([1.0]), model()), ValueError, "nan"),
    ("zero quaternion in state", lambda: integrate_quaternion(np.r_[0, 0, 0, 0, 0.1, 0.2, 0.3], 0.0, np.array([1.0]), model()), ValueError, "non-zero quaternion"),
    ("negative moments in model", lambda: make_model((-1.0, 2.0, 3.0)), ValueError, "-1.0"),
    # --- time and ephemeris
    ("time as a float", lambda: so_time.tdb_days(2451545.0), TypeError, "float"),
    ("naive datetime", lambda: so_time.tdb_days(datetime.datetime(2000, 1, 1)), TypeError, "time scale"),
    ("unknown body", lambda: barycentric_state("vulcan", J2000), UnknownBodyError, "'vulcan'"),
    ("time after DE421", lambda: barycentric_state("earth", Time("2300-01-01", scale="tdb")), EphemerisRangeError, "1899-12-04 to 2200-02-01"),
    ("libration before DE421", lambda: moon_orientation(Time("1800-01-01", scale="tdb")), EphemerisRangeError, "outside DE421"),
]


def test_catalogue_has_at_least_forty_cases():
    assert len(CATALOGUE) >= 40


@pytest.mark.parametrize("label, call, error, pattern", CATALOGUE, ids=[c[0] for c in CATALOGUE])
def test_bad_input_is_refused_with_a_specific_message(label, call, error, pattern):
    with pytest.raises(error, match=pattern):
        call()
