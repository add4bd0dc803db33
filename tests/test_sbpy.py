"""Orbits and spins from sbpy's containers (optional extra ``sbpy``), offline on containers sbpy itself builds.

- ``Orbit.from_sbpy`` of Toutatis's published elements (tests/test_orbits.py's 2008 set) is the orbit of
  ``Orbit.from_elements`` to the bit at the epoch, whichever of sbpy's field names the row uses, and passes
  Earth on 2004-09-29 at the published 0.0104 au (5 %, as the elements orbit's own test); q and Tp in place
  of a and M give the same state to 1e-12 of the position (the mean anomaly from Kepler's third law).
- ``RotationState.from_sbpy`` of a Phys row is ``RotationState.from_pole`` of its fields, exactly, and
  gives its pole and period back through ``state.pole()`` to 1e-12.
- Rows without a field, a unit sbpy leaves to the user (rot_per), or of another container,
  are refused naming what is missing.
"""

import math
import warnings

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time
from astropy.utils.exceptions import AstropyDeprecationWarning

from spinorbit import RigidBody, RotationState
from spinorbit.quantities import QuantityInputError
from spinorbit.sbpy_tables import SbpyInputError
from spinorbit.scene import Orbit, SceneError

with warnings.catch_warnings():
    # sbpy 0.6 subclasses astropy's deprecated TestRunner at import (upstream; nothing of spinorbit's)
    warnings.filterwarnings("ignore", "The TestRunner", AstropyDeprecationWarning)
    sbpy_data = pytest.importorskip("sbpy.data")

EPOCH = Time(2454797.5, format="jd", scale="tdb")  # JPL SBDB elements of Toutatis, 2008-11-27
ELEMENTS = dict(a=2.5321 * u.au, e=0.6288, inc=0.4460 * u.deg, raan=124.30 * u.deg, argp=278.75 * u.deg,
                mean_anomaly=5.1220 * u.deg)


def _sbpy_orbit(**names):
    """An sbpy Orbit of the elements, under the field names given (sbpy's canonical ones by default)."""
    fields = {"a": "a", "e": "e", "i": "i", "Omega": "Omega", "w": "w", "M": "M", **names}
    values = {"a": ELEMENTS["a"], "e": ELEMENTS["e"], "i": ELEMENTS["inc"], "Omega": ELEMENTS["raan"],
              "w": ELEMENTS["argp"], "M": ELEMENTS["mean_anomaly"]}
    table = {"targetname": ["4179 Toutatis"], "epoch": Time([EPOCH.jd], format="jd", scale="tdb")}
    table.update({fields[k]: [v.value] * v.unit if isinstance(v, u.Quantity) else [v] for k, v in values.items()})
    return sbpy_data.Orbit.from_dict(table)


def _state_au(orbit):
    r, v = orbit.relative_state("sun", EPOCH)
    return r.to_value(u.au)[0], v.to_value(u.au / u.day)[0]


@pytest.mark.parametrize("names", [{}, {"i": "incl", "Omega": "node", "w": "argper", "a": "sma"}])
def test_orbit_from_sbpy_is_the_orbit_of_its_elements(names):
    from_sbpy = Orbit.from_sbpy(_sbpy_orbit(**names))
    direct = Orbit.from_elements(**ELEMENTS, epoch=EPOCH, name="4179 Toutatis")
    assert from_sbpy.name == "4179 Toutatis"
    for got, expected in zip(_state_au(from_sbpy), _state_au(direct)):
        np.testing.assert_array_equal(got, expected)


def _state_by_hand(gm, au_km):
    """Toutatis's heliocentric ICRF state from the elements, built here: Kepler's equation by Newton, the
    perifocal ellipse, R3(-Omega) R1(-i) R3(-w) onto JPL's ecliptic, R1(-eps) with the IAU 1976 obliquity
    84381.448 arcsec (Lieske et al. 1977) onto the ICRF equator (JPL's ecliptic has no frame bias).
    In the simulation's au, DE421's (``au_km`` km; IAU 2012's 149597870.700 km is 2.5e-12 longer)."""
    a, e = ELEMENTS["a"].to_value(u.km) / au_km, ELEMENTS["e"]
    inc, node, argp, mean = (ELEMENTS[k].to_value(u.rad) for k in ("inc", "raan", "argp", "mean_anomaly"))
    big_e = mean
    for _ in range(50):
        big_e -= (big_e - e * math.sin(big_e) - mean) / (1 - e * math.cos(big_e))
    root = math.sqrt(1 - e * e)
    r_pf = a * np.array([math.cos(big_e) - e, root * math.sin(big_e), 0.0])
    v_pf = math.sqrt(gm / a) / (1 - e * math.cos(big_e)) * np.array([-math.sin(big_e), root * math.cos(big_e), 0.0])

    def rz(t):
        return np.array([[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0], [0, 0, 1]])

    def rx(t):
        return np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])

    turn = rx(math.radians(84381.448 / 3600)) @ rz(node) @ rx(inc) @ rz(argp)
    return turn @ r_pf, turn @ v_pf


def test_orbit_from_sbpy_is_the_state_built_by_hand_from_its_elements():
    from spinorbit.ephemeris import de421_constants

    position, velocity = _state_au(Orbit.from_sbpy(_sbpy_orbit()))
    constants = de421_constants()
    hand_r, hand_v = _state_by_hand(constants.gm["sun"], constants.au_km)
    # float64 through ~20 operations (Kepler's equation, three rotations, REBOUND's barycentric round trip):
    # a few 1e-16 each; 1e-13 of |r| and |v| leaves room (measured 1.1e-16 and 1.6e-16)
    assert np.abs(position - hand_r).max() < 1e-13 * np.linalg.norm(hand_r)
    assert np.abs(velocity - hand_v).max() < 1e-13 * np.linalg.norm(hand_v)


def test_orbit_from_sbpy_kepler_is_the_kepler_orbit_of_its_elements():
    from_sbpy = Orbit.from_sbpy(_sbpy_orbit(), kepler=True)
    direct = Orbit.kepler(**ELEMENTS, epoch=EPOCH, name="4179 Toutatis")
    assert (from_sbpy.kind, from_sbpy.name) == ("kepler", "4179 Toutatis")
    assert from_sbpy.kepler_elements == direct.kepler_elements
    with pytest.raises(SceneError, match="takes no non_gravitational"):
        Orbit.from_sbpy(_sbpy_orbit(), kepler=True, non_gravitational={"A2": -2.9e-14 * u.au / u.day**2})


def test_orbit_from_sbpy_passes_earth_at_the_published_2004_approach():
    when, distance = Orbit.from_sbpy(_sbpy_orbit()).closest_approach("earth", Time("2004-09-01", scale="tdb"),
                                                                       Time("2004-10-30", scale="tdb"))
    assert distance.to_value(u.au) == pytest.approx(0.0104, rel=0.05)  # the published distance, 2-3 digits
    assert abs((when - Time("2004-09-29T12:00", scale="utc")).to_value(u.day)) < 0.5 + 1e-3


def test_perihelion_distance_and_time_stand_in_for_a_and_m():
    a, e = ELEMENTS["a"], ELEMENTS["e"]
    motion = math.sqrt(__import__("spinorbit.ephemeris", fromlist=["x"]).de421_constants().gm["sun"]
                       / a.to_value(u.au) ** 3)  # rad/day
    perihelion = EPOCH - (ELEMENTS["mean_anomaly"].to_value(u.rad) / motion) * u.day
    table = {"targetname": ["4179 Toutatis"], "epoch": Time([EPOCH.jd], format="jd", scale="tdb"),
             "q": [a.value * (1 - e)] * u.au, "e": [e], "i": [0.4460] * u.deg, "Omega": [124.30] * u.deg,
             "w": [278.75] * u.deg, "Tp": Time([perihelion.jd], format="jd", scale="tdb")}
    got = _state_au(Orbit.from_sbpy(sbpy_data.Orbit.from_dict(table)))
    expected = _state_au(Orbit.from_elements(**ELEMENTS, epoch=EPOCH))
    # Tp as one JD double carries 5e-10 d (an ulp of 2.45e6 d), 1e-11 au at Toutatis's 0.017 au/d (measured 1.0e-12)
    assert np.abs(got[0] - expected[0]).max() < 1e-11 * np.linalg.norm(expected[0])


def test_orbit_rows_that_cannot_be_read_are_refused():
    with pytest.raises(SbpyInputError, match="expects an sbpy.data.Orbit"):
        Orbit.from_sbpy({"a": 2.5 * u.au})
    with pytest.raises(SbpyInputError, match="row expects an integer index into the 1 row"):
        Orbit.from_sbpy(_sbpy_orbit(), row=3)
    # (a bare 'a' or a float epoch never arrives: sbpy itself refuses its known fields without unit or Time)
    no_anomaly = sbpy_data.Orbit.from_dict({"a": [2.5321] * u.au, "e": [0.6288], "i": [0.446] * u.deg,
                                            "Omega": [124.3] * u.deg, "w": [278.75] * u.deg,
                                            "epoch": Time([EPOCH.jd], format="jd", scale="tdb")})
    with pytest.raises(SbpyInputError, match="no mean anomaly 'M' and no time of perihelion 'Tp'"):
        Orbit.from_sbpy(no_anomaly)


def _phys(**fields):
    return sbpy_data.Phys.from_dict({"targetname": ["test body"], **fields})


def test_spin_from_sbpy_phys_is_from_pole_of_its_fields_and_gives_them_back():
    body = RigidBody([1.0, 1.2, 1.5])
    phys = _phys(rot_per=[8.0] * u.hour, pole_lon=[80.0] * u.deg, pole_lat=[30.0] * u.deg, P=[4.03] * u.yr)
    state = RotationState.from_sbpy(body, phys, EPOCH, phase=15 * u.deg)
    direct = RotationState.from_pole(body, 80 * u.deg, 30 * u.deg, 8 * u.hour, EPOCH, phase=15 * u.deg)
    np.testing.assert_array_equal(state.quaternion, direct.quaternion)  # the same call underneath
    np.testing.assert_array_equal(state.angular_velocity, direct.angular_velocity)
    back = state.pole()
    assert back.pole_lon.to_value(u.deg) == pytest.approx(80.0, abs=1e-12 * 360)
    assert back.pole_lat.to_value(u.deg) == pytest.approx(30.0, abs=1e-12 * 360)
    assert back.period.to_value(u.hour) == pytest.approx(8.0, rel=1e-12)  # P (orbital, 4.03 yr) is not read
    icrf = RotationState.from_sbpy(body, _phys(rotation_period=[8.0] * u.hour, pole_ra=[10.0] * u.deg,
                                               pole_dec=[-20.0] * u.deg), EPOCH)
    assert icrf.pole(frame="icrf").pole_lon.to_value(u.deg) == pytest.approx(10.0, abs=1e-10)


def test_phys_rows_without_a_spin_are_refused_naming_the_fields():
    body = RigidBody([1.0, 1.2, 1.5])
    with pytest.raises(SbpyInputError, match="no rotation period .*'P' is sbpy's orbital period"):
        RotationState.from_sbpy(body, _phys(P=[4.03] * u.yr, pole_lon=[80.0] * u.deg, pole_lat=[30.0] * u.deg), EPOCH)
    with pytest.raises(SbpyInputError, match="no spin pole: give pole_lon and pole_lat"):
        RotationState.from_sbpy(body, _phys(rot_per=[8.0] * u.hour), EPOCH)
    with pytest.raises(QuantityInputError, match="sbpy field 'rot_per' expects a time Quantity .*bare"):
        RotationState.from_sbpy(body, _phys(rot_per=[8.0], pole_lon=[80.0] * u.deg, pole_lat=[30.0] * u.deg), EPOCH)
    with pytest.raises(SbpyInputError, match="expects an sbpy.data.Phys"):
        RotationState.from_sbpy(body, _sbpy_orbit(), EPOCH)
