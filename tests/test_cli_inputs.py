"""The validation layer of the command line and the scene file (issue 36, classes 2 and 7).

Every bad value ends the command with exit status 2 and one line that names the option or key, what
was expected and what arrived, before any work: these runs are refused within a second or two, long
before an N-body run or a propagation could start.
"""

import datetime
import pickle
import time
from pathlib import Path

import numpy as np
import pytest
from _offline import no_network  # noqa: F401

from spinorbit import InputError, SpinorbitError, cli
from spinorbit.commands import _inputs as check
from spinorbit.commands._scene_file import read_scene_file

SCENE_FILE = Path(__file__).resolve().parent.parent / "examples" / "asteroid_scene.toml"
#: Seconds a refusal may take: the imports and the checks, no orbit built (Orbit.from_elements alone
#: integrates for seconds; a Didymos or Apophis run for tens).
BEFORE_ANY_WORK_S = 2.0


@pytest.fixture(scope="module", autouse=True)
def imported():
    """The commands' modules imported once, so the clock below times the checks, not the first import."""
    import spinorbit.binary  # noqa: F401
    import spinorbit.coupling.moon  # noqa: F401
    import spinorbit.data.asteroids  # noqa: F401
    import spinorbit.data.didymos  # noqa: F401
    import spinorbit.ensemble  # noqa: F401
    import spinorbit.scene  # noqa: F401


def refusal(capsys, argv):
    """(status, the one error line) of ``spinorbit argv``, checked to come before any work."""
    begin = time.perf_counter()
    try:
        status = cli.main(argv)
    except SystemExit as exit_info:  # argparse's own checks
        status = exit_info.code
    elapsed = time.perf_counter() - begin
    out, err = capsys.readouterr()
    lines = err.strip().splitlines()
    assert status == cli.EXIT_USAGE, (out, err)
    assert len(lines) == 1 and "Traceback" not in err, err
    assert elapsed < BEFORE_ANY_WORK_S, f"refused after {elapsed:.1f} s: some work ran first"
    return lines[0]


# -- the error type ---------------------------------------------------------------------------------


def test_input_error_names_where_expected_got_and_advice_and_pickles():
    error = InputError("--rtol", "a number in [1e-15, 1)", "the string '-1'", "Try 1e-12.")
    assert isinstance(error, SpinorbitError) and isinstance(error, ValueError)
    assert str(error) == "--rtol expects a number in [1e-15, 1); got the string '-1'. Try 1e-12."
    copy = pickle.loads(pickle.dumps(error))
    assert (copy.where, copy.expected, copy.got, copy.advice, str(copy)) == \
        (error.where, error.expected, error.got, error.advice, str(error))
    assert isinstance(cli.CommandError("a whole message."), InputError)
    assert str(pickle.loads(pickle.dumps(cli.CommandError("a whole message.")))) == "a whole message."


def test_what_arrived_is_described_without_numpy_reprs():
    assert check.shown([np.int64(1), np.float64(2.5)]) == "the list [1, 2.5]"
    assert check.shown(np.float64(4.5)) == "the float 4.5"
    assert check.shown("sun") == "the string 'sun'"
    assert check.shown(True) == "the boolean true"
    assert check.shown({"a": 1}) == "a table with keys ['a']"
    assert check.arrived("--span", ["1", "yr"]) == "'1 yr'"


@pytest.mark.parametrize("checker, value, words", [
    (lambda v: check.number("--rtol", v, "1e-12", low=1e-15, high=1.0, high_open=True), "0",
     "--rtol expects a finite number in [1e-15, 1) such as 1e-12; got '0'"),
    (lambda v: check.number("x", v, "1"), "1e400", "got the string '1e400'"),
    (lambda v: check.number("x", v, "1"), "1e-400", "underflows to 0"),
    (lambda v: check.number("x", v, "1"), True, "got the boolean true"),
    (lambda v: check.integer("[run] n_times", v, "240", low=2), 4.0, "a whole number ≥ 2 such as 240; got the float 4.0"),
    (lambda v: check.integer("n", v, "2"), "1_000", "got the string '1_000'"),
    (lambda v: check.seed("--seed", v), "-3", "--seed expects a whole number ≥ 0"),
    (lambda v: check.scheduler_address("--scheduler", v), "localhost", "a Dask scheduler address"),
    (lambda v: check.scheduler_address("--scheduler", v), "tcp://h:99999", "a Dask scheduler address"),
    (lambda v: check.scheduler_address("--scheduler", v), "http://h:8786", "a Dask scheduler address"),
    (lambda v: check.names("[run] perturbers", v, "['sun']"), "sun", "got the string 'sun'. Write a list"),
    (lambda v: check.names("[run] perturbers", v, "['sun']"), ["sun", 3], "got the list ['sun', 3]"),
    (lambda v: check.text("[run] output", v, "a.ecsv"), 5, "got the integer 5"),
    (lambda v: check.quantity("[spin] period", v, "h", "8 h"), 8, "got the integer 8. Write the unit"),
    (lambda v: check.quantity("--span", v, "d", "1 yr", default_unit="d"), ["3", "kg"], "kg is a unit of mass"),
    (lambda v: check.vector("--omega", v, "deg/d", "0 0 1 deg/d"), ["0", "0", "1", "Hz"], "write turns per time"),
    (lambda v: check.vector("--omega", v, "deg/d", "0 0 1 deg/d"), ["0", "0", "1", "2"], "Give 3 numbers, then"),
    (lambda v: check.vector("[spin] omega", v, "deg/d", "0 0 1 deg/d"), [0, 0, 1], "got the list [0, 0, 1]"),
    (lambda v: check.time("[orbit] epoch", v), 20200101, "a TDB date such as"),
    (lambda v: check.time("[orbit] epoch", v), "12000-01-01", "got the string '12000-01-01'"),
    (lambda v: check.time("--start", v, julian=True), "1e12", "dates in the years 1 to 9999"),
    (lambda v: check.time("[orbit] epoch", v),
     datetime.datetime(2020, 1, 1, tzinfo=datetime.timezone.utc), "without a zone"),
])
def test_each_checker_refuses_in_words(checker, value, words):
    with pytest.raises(InputError) as refused:
        checker(value)
    assert words in str(refused.value)
    assert "np." not in str(refused.value)


def test_checkers_return_what_the_command_needs():
    import astropy.units as u

    assert check.number("--rtol", ["1e-12"], "1e-12") == 1e-12
    assert check.integer("n", "240", "240") == 240
    assert check.quantity("--period", ["8"], "h", "8 h", default_unit="h") == 8 * u.h
    omega = check.vector("--omega", ["0", "0", "45", "deg", "/", "h"], "deg/d", "0 0 1 deg/d")
    assert omega.unit == u.deg / u.h and list(omega.value) == [0, 0, 45]
    listed = check.vector("[spin] omega", ["0 deg/h", "0 deg / h", "1080 deg/d"], "deg/d", "0 0 1 deg/d")
    np.testing.assert_allclose(listed.to_value(u.deg / u.d), [0, 0, 1080], rtol=1e-15)
    assert check.time("[orbit] epoch", datetime.date(2020, 1, 1)).tdb.isot == "2020-01-01T00:00:00.000"
    assert check.time("--start", "2451545.0", julian=True).tdb.isot == "2000-01-01T12:00:00.000"
    assert check.scheduler_address("--scheduler", "tcp://[::1]:8786") == "tcp://[::1]:8786"


# -- the scene file ---------------------------------------------------------------------------------


def scene_with(tmp_path, old, new, name="scene.toml"):
    text = SCENE_FILE.read_text()
    assert old in text
    path = tmp_path / name
    path.write_text(text.replace(old, new))
    return path


def test_the_example_scene_reads_into_quantities_and_times():
    import astropy.units as u

    scene = read_scene_file(str(SCENE_FILE))
    assert scene["name"] == "Example NEA"
    assert scene["orbit"]["a"] == 1.5 * u.au and scene["orbit"]["e"] == 0.25
    assert scene["body"]["moments"] == [0.7, 0.9, 1.0]
    assert scene["spin"]["omega"].to_value(u.deg / u.h)[2] == pytest.approx(45, rel=1e-15)
    assert scene["run"]["n_times"] == 240 and scene["run"]["perturbers"] == ["sun", "earth", "moon", "jupiter"]
    assert scene["run"]["start"].tdb.isot == "2020-01-01T00:00:00.000"


@pytest.mark.parametrize("old, new, words", [
    ("moments = [0.7, 0.9, 1.0]", 'moments = "0.7 0.9 1"',
     "[body] moments expects a list of three principal moments such as [0.7, 0.9, 1.0]; got the string '0.7 0.9 1'"),
    ("moments = [0.7, 0.9, 1.0]", "moments = [0.7, -0.9, 1.0]", "[body] moments expects a finite number > 0"),
    ("n_times = 240", "n_times = 240.5", "[run] n_times expects a whole number in [2, 100000] such as 240; got the "
     "float 240.5"),
    ('output = "example_nea.ecsv"', "output = 5", "[run] output expects text such as 'example_nea.ecsv'; got the "
     "integer 5"),
    ('perturbers = ["sun", "earth", "moon", "jupiter"]', 'perturbers = "sun"',
     "[run] perturbers expects a list of names such as ['sun', 'earth']; got the string 'sun'"),
    ('span = "120 d"', "span = 120", "[run] span expects a time"),
    ('span = "120 d"', 'span = "120 kg"', "[run] span expects a time"),
    ('a = "1.5 au"', 'a = "1.5 s"', "[orbit] a expects a length"),
    ('epoch = "2020-01-01T00:00:00"', 'epoch = "2020-13-01"', "[orbit] epoch expects a TDB date"),
    ("e = 0.25", "e = 1.5", "[orbit] e expects a finite number in [0, 1)"),
    ('frame = "ecliptic"             # "ecliptic" (J2000', 'frame = "galactic"   # (', "[orbit] frame expects one of"),
    ('omega = ["0 deg / h", "0 deg / h", "45 deg / h"]', 'omega = ["0 deg / h", "45 deg / h"]',
     "[spin] omega expects 3 numbers and a unit"),
    ('omega = ["0 deg / h", "0 deg / h", "45 deg / h"]', 'omega = "0 0 1 Hz"', "write turns per time as cycle/d"),
    ('euler313 = ["30 deg", "20 deg", "0 deg"]', "euler313 = [30, 20, 0]", "[spin] euler313 expects 3 numbers"),
    ('A2 = "-2.9e-14 AU / d2"', 'A4 = "-2.9e-14 AU / d2"', "expects the keys A1, A2, A3; got the key 'A4'"),
    ("mean_anomaly =", "mean_anomally =", "[orbit] expects some of the keys"),
    ('tolerance = "1 arcsec"', "tolerance = true", "[run] tolerance expects an angle"),
    ("[run]", "[runs]", "the table or key 'runs'"),
    ('name = "Example NEA"', "name = 7", "name expects text"),
])
def test_bad_scene_files_are_refused_naming_the_key(capsys, tmp_path, old, new, words):
    path = scene_with(tmp_path, old, new)
    line = refusal(capsys, ["asteroid", "--scene", str(path), "--plan"])
    assert line.startswith("spinorbit asteroid: error: ") and words in line, line
    assert "np." not in line


def test_binary_junk_as_the_scene_file_names_the_file(capsys, tmp_path):
    path = tmp_path / "junk.toml"
    path.write_bytes(bytes(range(128, 256)) * 3)
    line = refusal(capsys, ["asteroid", "--scene", str(path), "--plan"])
    assert f"--scene expects a TOML file (UTF-8 text); got '{path}', whose byte 0 is not UTF-8 text" in line


def test_an_unquoted_toml_date_is_a_tdb_date(tmp_path):
    path = scene_with(tmp_path, 'epoch = "2020-03-01T00:00:00"', "epoch = 2020-03-01T00:00:00")
    assert read_scene_file(str(path))["spin"]["epoch"].tdb.isot == "2020-03-01T00:00:00.000"


def test_a_scene_value_refused_after_reading_names_its_key(capsys, tmp_path):
    """[run] span is read into --span; the command's own cap (50 yr) then names the key, not the option."""
    path = scene_with(tmp_path, 'span = "120 d"', 'span = "60 yr"')
    line = refusal(capsys, ["asteroid", "--scene", str(path), "--plan"])
    assert "[run] span expects a time in (0, 18262.5] d" in line


# -- options ----------------------------------------------------------------------------------------


@pytest.mark.parametrize("argv, words", [
    (["didymos", "--rtol", "-1"], "--rtol expects a finite number in [1e-15, 1) such as 1e-12; got '-1'"),
    (["didymos", "--rtol", "0"], "--rtol expects a finite number in [1e-15, 1)"),
    (["didymos", "--impact", "--impactor-mass", "-5"], "--impactor-mass expects a finite number > 0"),
    (["didymos", "--impact", "--impactor-speed", "0"], "--impactor-speed expects a finite number > 0"),
    (["didymos", "--order", "7"], "--order expects a whole number in [0, 4]"),
    (["apophis", "--members", "2", "--scheduler", "notanaddress"], "--scheduler expects a Dask scheduler address"),
    (["apophis", "--members", "2", "--seed", "-3"], "--seed expects a whole number ≥ 0 such as 12345; got '-3'"),
    (["apophis", "--members", "0"], "--members expects a whole number in [1, 1000000]"),
    (["torque-free", "--moments", "1", "2", "3", "--omega", "0", "0", "1", "--span", "1e9", "yr", "--n-times", "3"],
     "--span expects dates in the years 1 to 9999"),
    (["torque-free", "--moments", "1", "2", "3", "--omega", "0", "0", "1", "--epoch", "12000-01-01"],
     "--epoch expects a TDB date such as '2020-01-01T00:00:00'; got '12000-01-01'"),
    (["torque-free", "--moments", "1", "2", "3", "--omega", "0", "0", "1", "rad/s", "--omega-unit", "deg/h"],
     "give the unit once"),
    (["torque-free", "--moments", "1", "2", "3", "--omega", "0", "0", "1", "Hz"], "write turns per time"),
    (["moon", "--span", "1e9", "yr"], "--span: a run of 3.6525e+11 d"),
    (["moon", "--start", "1e12"], "--start expects dates in the years 1 to 9999"),
])
def test_bad_options_are_refused_before_any_work(capsys, tmp_path, argv, words):
    output = tmp_path / "out.ecsv"
    line = refusal(capsys, [*argv, "--output", str(output)])
    assert words in line, line
    assert not output.exists()


def test_omega_takes_its_unit_after_the_numbers(capsys):
    """--omega 1e-4 0 3e-4 rad/s is --omega 1e-4 0 3e-4 --omega-unit rad/s, to the bit."""
    import re

    outputs = []
    for omega in (["1e-4", "0", "3e-4", "rad/s"], ["1e-4", "0", "3e-4", "--omega-unit", "rad/s"]):
        assert cli.main(["torque-free", "--moments", "1", "2", "2.5", "--omega", *omega, "--span", "1", "d"]) == 0
        outputs.append(re.sub(r"\d+ times", "", capsys.readouterr().out))
    assert outputs[0] == outputs[1] and "P_psi" in outputs[0]


def test_a_perturber_string_is_not_read_letter_by_letter():
    from spinorbit.scene.errors import SceneError
    from spinorbit.scene.inputs import validate_perturbers

    with pytest.raises(SceneError, match=r"got the string 'sun'. Write a sequence, even of one name: \('sun',\)"):
        validate_perturbers("sun", None)


def test_mesh_errors_show_plain_numbers():
    from spinorbit.core.model.polyhedron import InvalidMeshError, check_closed_mesh

    pyramid = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 1]])
    open_faces = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])  # a square pyramid without its base
    with pytest.raises(InvalidMeshError) as refused:
        check_closed_mesh(pyramid, open_faces)
    assert "belong to [1] faces" in str(refused.value) and "np." not in str(refused.value)
    vertices = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]])
    inverted = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    with pytest.raises(InvalidMeshError) as refused:
        check_closed_mesh(vertices, inverted)
    assert "signed volume is -0.1666" in str(refused.value) and "np." not in str(refused.value)
