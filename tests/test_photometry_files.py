"""Photometric data in and out: ALCDEF and DAMIT files written to each format's published layout, a user's
TimeSeries, and the specific errors of bad data.

tests/data/alcdef_example.txt follows the ALCDEF standard (STARTMETADATA … ENDMETADATA, DATA=JD|MAG|MAGERR
[|AIRMASS] … ENDDATA; a PIPE block with air masses and comments, a TAB block reduced by one UCORMAG);
tests/data/damit_example.txt follows DAMIT's lc layout (count; 'points flag'; JD, intensity, Sun and Earth
asteroid-centric ecliptic vectors in au).
"""

from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy.time import Time
from astropy.timeseries import TimeSeries

from spinorbit.frames import icrf_to_ecliptic
from spinorbit.photometry import (
    ALCDEFError,
    DAMITFormatError,
    MissingUncertaintyError,
    ObservationSpanError,
    UnknownFilterError,
    photometric_observations,
    read_alcdef,
    read_damit,
    write_alcdef,
    write_damit,
)

DATA = Path(__file__).parent / "data"
ALCDEF = (DATA / "alcdef_example.txt").read_text()


def test_alcdef_file_reads_to_its_specification():
    table = read_alcdef(DATA / "alcdef_example.txt")
    assert len(table) == 5 and list(table["session"]) == [0, 0, 0, 1, 1]
    assert table["time"].scale == "utc"
    assert table["time"][0].jd == pytest.approx(2456271.68512, abs=1e-9)
    assert list(table["filter"]) == ["V", "V", "V", "R", "R"]
    assert list(table["observer"]) == ["696", "696", "696", "G96", "G96"]
    assert table["magnitude"][1].to_value(u.mag) == pytest.approx(12.398, abs=1e-12)
    assert table["magnitude_error"][2].to_value(u.mag) == pytest.approx(0.013, abs=1e-12)
    # REDUCEDMAGS=AVERAGE: UCORMAG = −3.125 was added; the apparent magnitude is MAG − UCORMAG.
    assert table["magnitude"][3].to_value(u.mag) == pytest.approx(9.102 + 3.125, abs=1e-12)
    assert table["airmass"][0] == pytest.approx(1.215) and np.isnan(table["airmass"][4])
    first = table.meta["sessions"][0]
    assert first["OBJECTNAME"] == "Toutatis" and len(first["COMMENT"]) == 2 and first["PHASE"] == "+25.4"


def test_alcdef_round_trip(tmp_path):
    table = read_alcdef(ALCDEF)
    path = write_alcdef(table, tmp_path / "out.txt", metadata={"CONTACTNAME": "spinorbit test"})
    again = read_alcdef(path)
    assert np.max(np.abs((again["time"] - table["time"]).to_value(u.s))) < 1e-3  # 8 decimals of JD
    assert np.allclose(again["magnitude"].value, table["magnitude"].value, atol=5e-6)
    assert np.allclose(again["magnitude_error"].value, table["magnitude_error"].value, atol=5e-6)
    assert list(again["filter"]) == list(table["filter"]) and list(again["observer"]) == list(table["observer"])
    assert again.meta["sessions"][1]["REDUCEDMAGS"] == "NONE"  # written apparent, as read
    assert again.meta["sessions"][0]["CONTACTNAME"] == "spinorbit test"


@pytest.mark.parametrize("edit, error, match", [
    (lambda t: t.replace("|0.012|1.215", ""), MissingUncertaintyError, "MAGERR"),
    (lambda t: t.replace("FILTER=R", "FILTER=Q"), UnknownFilterError, "Q"),
    (lambda t: t.replace("LTCAPP=NONE\nREDUCEDMAGS=AVERAGE", "LTCAPP=POINT\nREDUCEDMAGS=AVERAGE"), ALCDEFError, "light time"),
    (lambda t: t.replace("REDUCEDMAGS=AVERAGE", "REDUCEDMAGS=POINT"), ALCDEFError, "point by point"),
    (lambda t: t.rsplit("ENDDATA", 1)[0], ALCDEFError, "no ENDDATA"),
    (lambda t: t.replace("DATA=2456271.68512", "DATA=2600000.5"), ObservationSpanError, "DE421"),
    (lambda t: t.replace("|12.398|", "|12.3x8|"), ALCDEFError, "not a number"),
])
def test_bad_alcdef_files_get_specific_errors(edit, error, match):
    with pytest.raises(error, match=match):
        read_alcdef(edit(ALCDEF))


def test_damit_file_reads_to_its_specification(tmp_path):
    table = read_damit(DATA / "damit_example.txt")
    assert len(table) == 5 and list(table["session"]) == [0, 0, 0, 1, 1]
    assert list(table["calibrated"]) == [False] * 3 + [True] * 2
    assert table["time"].scale == "tdb" and table["time"][3].jd == pytest.approx(2452300.5, abs=1e-9)
    assert table["brightness"][0] == pytest.approx(1.0213)
    ecliptic = icrf_to_ecliptic(table["observer_vector"].to_value(u.au))
    assert np.allclose(ecliptic[0], [0.8, 0.5, 0.1], atol=1e-15)
    path = write_damit(table.copy(), tmp_path / "lc.txt", calibrated=False)
    again = read_damit(path)
    assert np.allclose(again["sun_vector"].value, table["sun_vector"].value, atol=1e-12)
    assert np.allclose(again["brightness"], table["brightness"], rtol=1e-10)
    with pytest.raises(DAMITFormatError, match="2 points announced, 1 follow|more lines"):
        read_damit("1\n2 0\n2452254.2 1.0 1 0 0 0 1 0\n")
    with pytest.raises(DAMITFormatError, match="flag 0"):
        read_damit("1\n1 3\n2452254.2 1.0 1 0 0 0 1 0\n")


def test_a_users_timeseries_becomes_observations():
    series = TimeSeries(time=Time("2024-05-01T00:00", scale="utc") + np.arange(4) * u.hour)
    series["mag"] = [15.1, 15.3, 15.2, 15.0] * u.mag
    series["mag_err"] = [0.02, 0.02, 0.03, 0.02] * u.mag
    table = photometric_observations(series, magnitude="mag", magnitude_error="mag_err", filter="SR")
    assert list(table["filter"]) == ["SR"] * 4 and list(table["observer"]) == ["earth"] * 4
    with pytest.raises(MissingUncertaintyError, match="uncertainty"):
        photometric_observations(series, magnitude="mag", magnitude_error="sigma", filter="SR")
    with pytest.raises(UnknownFilterError, match="no filter column"):
        photometric_observations(series, magnitude="mag", magnitude_error="mag_err")
    series["mag_err"][1] = np.nan * u.mag
    with pytest.raises(MissingUncertaintyError, match="row 1"):
        photometric_observations(series, magnitude="mag", magnitude_error="mag_err", filter="SR")
