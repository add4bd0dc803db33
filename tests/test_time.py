"""spinorbit.time: Time ↔ TDB days since J2000, two-float form, errors."""

import datetime as dt

import astropy.units as u
import numpy as np
import pytest
from _offline import no_network  # noqa: F401  (autouse socket guard)
from astropy.time import Time
from hypothesis import given
from hypothesis import strategies as st

from spinorbit.time import (
    FLOAT_DAYS_RESOLUTION_1900_2100,
    J2000_JD_TDB,
    TimeScaleError,
    tdb_day_and_fraction,
    tdb_days,
    time_from_tdb_days,
)

#: Round trips must be exact to this (ns). The two-float path is exact to ~1e-6 ns; 1 ns is the
#: requirement a user can state, and leaves room for astropy's internal two-sum renormalisation.
ROUND_TRIP_TOLERANCE_NS = 1.0

DAYS_1900 = -36524.5  # 1900-01-01 12:00 TDB, days since J2000
DAYS_2100 = 36525.5


def test_j2000_is_zero():
    t = Time(J2000_JD_TDB, format="jd", scale="tdb")
    assert tdb_days(t) == (0.0, 0.0)
    assert tdb_day_and_fraction(t) == (0.0, 0.0)


def test_utc_epoch_includes_tt_minus_utc():
    # 2000-01-01T12:00:00 UTC is 64.184 s (32 leap s + 32.184 s) + a 0.1 ms periodic TDB term later.
    days, _ = tdb_days(Time("2000-01-01T12:00:00", scale="utc"))
    assert days * 86400.0 == pytest.approx(64.184, abs=2e-3)


@given(
    day=st.integers(min_value=int(DAYS_1900), max_value=int(DAYS_2100)),
    fraction=st.floats(min_value=-0.5, max_value=0.5),
    scale=st.sampled_from(["tdb", "tt", "tai", "tcb", "tcg"]),
)
def test_round_trip_1900_2100_to_a_nanosecond(day, fraction, scale):
    original = Time(J2000_JD_TDB + day, fraction, format="jd", scale=scale)
    days, remainder = tdb_days(original)
    back = time_from_tdb_days(days, remainder, scale=scale)
    assert back.scale == scale
    assert abs((back - original).to_value(u.ns)) <= ROUND_TRIP_TOLERANCE_NS


@given(days=st.floats(min_value=DAYS_1900, max_value=DAYS_2100))
def test_float_days_precision_statement(days):
    # A plain float of TDB days since J2000 in 1900–2100 is within FLOAT_DAYS_RESOLUTION_1900_2100
    # of the exact time; the remainder is what is missing, bounded by half a unit in the last place.
    t = time_from_tdb_days(days, 1e-7)  # 8.6 ms off-grid, so the remainder is not trivially zero
    core, remainder = tdb_days(t)
    assert abs(remainder) <= np.spacing(abs(core)) / 2.0 or core == 0.0
    assert abs(remainder) <= FLOAT_DAYS_RESOLUTION_1900_2100
    assert FLOAT_DAYS_RESOLUTION_1900_2100 * 86400e6 < 0.32  # µs: the documented figure


def test_arrays_and_utc_round_trip():
    utc = Time(["1972-01-01T00:00:00", "1998-12-31T23:59:60", "2016-12-31T23:59:60.5"], scale="utc")
    days, remainder = tdb_days(utc)
    assert days.shape == remainder.shape == (3,)
    back = time_from_tdb_days(days, remainder, scale="utc")
    assert np.all(np.abs((back - utc).to_value(u.ns)) <= ROUND_TRIP_TOLERANCE_NS)
    assert back[1].isot == "1998-12-31T23:59:60.000"  # the leap second survives


def test_future_utc_warns_dubious_year_but_tdb_does_not():
    # ERFA flags UTC beyond its leap-second knowledge as a "dubious year"; that is real information
    # for the user, so the library lets it through. A TDB time of the same date needs no leap seconds.
    from erfa import ErfaWarning

    with pytest.warns(ErfaWarning, match="dubious year"):
        tdb_days(Time("2090-06-01T00:00:00", scale="utc"))
    tdb_days(Time("2090-06-01T00:00:00", scale="tdb"))


@pytest.mark.parametrize(
    "bad, match",
    [
        (dt.datetime(2000, 1, 1), "datetime without a time scale"),
        (dt.datetime(2000, 1, 1, tzinfo=dt.timezone.utc), "timezone-aware datetime"),
        (np.datetime64("2000-01-01"), "datetime without a time scale"),
        (2451545.0, "expected an astropy.time.Time; got float"),
        ("2000-01-01", "expected an astropy.time.Time; got str"),
    ],
)
def test_non_time_input_is_refused_with_advice(bad, match):
    with pytest.raises(TypeError, match=match):
        tdb_days(bad)


def test_local_scale_is_refused():
    with pytest.raises(TimeScaleError, match="'local'"):
        tdb_days(Time(0.0, format="jd", scale="local"))


def test_unknown_output_scale_is_refused():
    with pytest.raises(TimeScaleError, match="unknown output time scale 'tdt'"):
        time_from_tdb_days(0.0, scale="tdt")


def test_quantity_days_are_refused():
    with pytest.raises(TypeError, match="strip units"):
        time_from_tdb_days(3.0 * u.day)


@pytest.mark.parametrize("value", [2462240.407, [2451545.0, 2462240.407, 2488069.5], [[2451545.25], [2415020.75]]])
def test_day_and_fraction_read_the_same_doubles_as_astropys_jd1_jd2(value):
    # tdb_day_and_fraction reads the stored jd1/jd2 (not astropy's reshaping properties): the same bits,
    # scalar and array, and it sees a Time changed in place
    time = Time(value, format="jd", scale="tdb")
    offset = time.jd1 - 2451545.0
    day = np.round(offset + time.jd2)
    expected = (day, (offset - day) + time.jd2)
    got = tdb_day_and_fraction(time)
    assert all(np.asarray(g).tobytes() == np.asarray(e).tobytes() and np.shape(g) == np.shape(e)
               for g, e in zip(got, expected))
    if time.isscalar:
        assert isinstance(got[0], float)
        time[()] = Time(2451546.0, format="jd", scale="tdb")
        assert tdb_day_and_fraction(time) == (1.0, 0.0)


@pytest.mark.parametrize("make", [
    lambda t: t, lambda t: t.reshape(3, 4), lambda t: t.reshape(3, 4)[:, 1:], lambda t: t[::-2], lambda t: t[5],
    lambda t: Time(t[4:8], scale="utc"),  # 1960-2100 only: UTC outside it warns of a dubious year
])
def test_stored_doubles_are_astropys_public_jd1_jd2(make):
    # _stored_jd reads astropy's stored doubles only where they are the public jd1/jd2 (views, slices,
    # reshapes, scalars, converted scales): the same bits and shape either way
    from spinorbit.time import _stored_jd

    time = make(Time(np.linspace(2415020.5, 2488069.5, 12) + 0.123, format="jd", scale="tdb"))
    time = Time(time, scale="tdb")
    jd1, jd2 = _stored_jd(time)
    assert np.asarray(jd1).tobytes() == np.asarray(time.jd1).tobytes() and np.shape(jd1) == time.shape
    assert np.asarray(jd2).tobytes() == np.asarray(time.jd2).tobytes() and np.shape(jd2) == time.shape


def test_masked_time_takes_the_public_properties():
    from spinorbit.time import _stored_jd

    time = Time([2451545.0, 2451546.5], format="jd", scale="tdb")
    time[1] = np.ma.masked
    jd1, _ = _stored_jd(time)
    assert np.ma.is_masked(jd1)
