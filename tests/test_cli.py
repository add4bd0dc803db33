"""The ``spinorbit`` command line: the Toutatis run, its ECSV table, --help, and errors in words."""

import io
import os
import re
import subprocess
import sys
from pathlib import Path

import astropy.units as u
import numpy as np
import pytest
from _offline import no_network  # noqa: F401
from astropy.table import Table
from astropy.time import Time

from spinorbit import cli
from spinorbit import RigidBody, RotationState
from spinorbit.commands import _common
from spinorbit.commands import torque_free

ROOT = Path(__file__).resolve().parents[1]

# (4179) Toutatis, Takahashi et al. (2013), as in README.md and tests/test_state.py.
TOUTATIS = ["--moments", "3.0836", "3.235", "1", "--omega", "14.51", "33.529", "-98.709",
            "--euler313", "145.498", "65.865", "241.524"]
P_PSI_D, P_PHI_D = 5.369, 7.412
PERIOD_TOLERANCE_D = 1e-3  # the published periods are given to 1e-3 d
# The one output schema (docs/conventions.md, "Output tables"), the same as the API's torque-free table.
COLUMNS = ["time", "q_w", "q_x", "q_y", "q_z", "omega_x", "omega_y", "omega_z", "pole_ra", "pole_dec", "pole_lon",
           "pole_lat", "mode", "energy_ratio", "P_psi", "P_phi", "sidereal_period", "wobble_amplitude", "rotation_class"]
# The first row is the input state itself: the exact flow at t = 0 must return it to rounding.
INITIAL_STATE_TOLERANCE = 1e-12


def run_cli(capsys, *args):
    status = cli.main(["torque-free", *args])
    out, err = capsys.readouterr()
    return status, out, err


def periods(stdout):
    match = re.search(r"P_psi = ([\d.]+) d .* P_phi = ([\d.]+) d", stdout)
    assert match, stdout
    return float(match[1]), float(match[2])


# -- the Toutatis run -----------------------------------------------------------------------------


def test_toutatis_summary_in_process(capsys, tmp_path):
    status, out, err = run_cli(capsys, *TOUTATIS, "--output", str(tmp_path / "t.ecsv"))
    assert status == 0, err
    assert err == ""
    assert re.search(r"mode\s+LAM, sense -A", out)
    p_psi, p_phi = periods(out)
    assert p_psi == pytest.approx(P_PSI_D, abs=PERIOD_TOLERANCE_D)
    assert p_phi == pytest.approx(P_PHI_D, abs=PERIOD_TOLERANCE_D)


def test_toutatis_ecsv_reads_back_with_columns_units_and_initial_state(capsys, tmp_path):
    path = tmp_path / "toutatis.ecsv"
    status, _, err = run_cli(capsys, *TOUTATIS, "--span", "10", "d", "--step", "0.5 d", "--output", str(path))
    assert status == 0, err
    table = Table.read(path, format="ascii.ecsv")
    assert table.colnames == COLUMNS
    assert len(table) == 21
    assert isinstance(table["time"], Time) and table["time"].scale == "tdb"
    assert table["time"][0] == Time("2000-01-01T12:00:00", scale="tdb")  # --epoch default, the first row
    assert table["omega_x"].unit == u.rad / u.day and table["P_psi"].unit == u.h and table["pole_lat"].unit == u.deg
    assert all(table[f"q_{c}"].unit is None for c in "wxyz")
    assert table.meta["mode"] == "LAM" and table.meta["sense"] == "-A"
    assert table.meta["frame"] == "ICRF" and table.meta["epoch"] == "2000-01-01T12:00:00.000" and table.meta["model"]
    np.testing.assert_allclose((table["time"] - table["time"][0]).to_value(u.day), np.arange(21) * 0.5, atol=1e-9)

    q = np.column_stack([table[f"q_{c}"] for c in "wxyz"])
    omega = np.column_stack([table[f"omega_{c}"] for c in "xyz"]) * u.rad / u.day
    np.testing.assert_allclose(np.linalg.norm(q, axis=1), 1.0, atol=INITIAL_STATE_TOLERANCE)
    np.testing.assert_allclose(omega[0].to_value(u.deg / u.day), [14.51, 33.529, -98.709], rtol=INITIAL_STATE_TOLERANCE)
    assert table["P_psi"][0] == pytest.approx(P_PSI_D * 24, abs=PERIOD_TOLERANCE_D * 24)
    body = RigidBody([3.0836, 3.235, 1.0])
    state = RotationState.from_euler313(body, 145.498 * u.deg, 65.865 * u.deg, 241.524 * u.deg,
                                        [14.51, 33.529, -98.709] * u.deg / u.day)
    assert abs(np.dot(q[0], state.quaternion)) == pytest.approx(1.0, abs=INITIAL_STATE_TOLERANCE)
    # q and -q are one attitude; the table keeps the sign continuous (no jumps between rows)
    assert np.all(np.einsum("ij,ij->i", q[1:], q[:-1]) > 0)


def test_n_times_and_omega_unit(capsys, tmp_path):
    path = tmp_path / "run.ecsv"
    rad_per_s = (np.array([14.51, 33.529, -98.709]) * u.deg / u.day).to_value(u.rad / u.s)
    omega = [repr(float(w)) for w in rad_per_s]  # one is negative with an exponent (-1.99e-05)
    status, out, err = run_cli(capsys, "--moments", "3.0836", "3.235", "1", "--omega", *omega, "--omega-unit", "rad/s", "--euler313", "145.498", "65.865", "241.524",
                               "--span", "2 yr", "--n-times", "7", "--output", str(path))
    assert status == 0, err
    assert periods(out) == pytest.approx((P_PSI_D, P_PHI_D), abs=PERIOD_TOLERANCE_D)
    table = Table.read(path)
    assert len(table) == 7 and (table["time"][-1] - table["time"][0]).to_value(u.day) == pytest.approx(2 * 365.25)
    # the schema's unit whatever --omega-unit was: the rad/s input comes back as rad/day
    assert table["omega_x"].unit == u.rad / u.day
    assert table["omega_x"][0] == pytest.approx(float(omega[0]) * 86400.0, rel=1e-12)


def test_plot_is_a_png(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    path = tmp_path / "run.png"
    status, _, err = run_cli(capsys, *TOUTATIS, "--span", "20 d", "--plot", str(path))
    assert status == 0, err
    assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert [p.name for p in tmp_path.iterdir()] == ["run.png"]


def test_subprocess_python_m_spinorbit(tmp_path):
    path = tmp_path / "t.ecsv"
    result = subprocess.run([sys.executable, "-m", "spinorbit", "torque-free", *TOUTATIS, "--output", str(path)],
                            capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert result.returncode == 0, result.stderr
    assert "LAM" in result.stdout
    assert periods(result.stdout) == pytest.approx((P_PSI_D, P_PHI_D), abs=PERIOD_TOLERANCE_D)
    assert len(Table.read(path)) == 101


# -- help -----------------------------------------------------------------------------------------


def test_help_lists_commands_and_examples(capsys):
    with pytest.raises(SystemExit) as exit_info:
        cli.main(["--help"])
    assert exit_info.value.code == 0
    assert "torque-free" in capsys.readouterr().out
    with pytest.raises(SystemExit):
        cli.main(["torque-free", "--help"])
    out = capsys.readouterr().out
    for text in ("--moments", "--omega-unit", "--euler313", "--span", "--n-times", "--output", "--plot",
                 "examples:", "spinorbit torque-free --moments 3.0836 3.235 1", "exit status"):
        assert text in out


def test_every_command_module_is_registered():
    parser_help = cli.build_parser().format_help()
    for module in cli._command_modules():
        for attribute in ("NAME", "SUMMARY", "DESCRIPTION", "EXAMPLES", "add_arguments", "run"):
            assert hasattr(module, attribute), f"{module.__name__} lacks {attribute}"
        assert module.NAME in parser_help


# -- errors in words --------------------------------------------------------------------------------

VALID = ["--moments", "1", "2", "2.5", "--omega", "1", "2", "3"]
BAD_INPUT = {
    "negative moment": (["--moments", "-1", "2", "2.5", "--omega", "1", "2", "3"], "positive"),
    "triangle violated": (["--moments", "1", "1", "3", "--omega", "1", "2", "3"], "triangle inequality"),
    "non-numeric moment": (["--moments", "1", "two", "2.5", "--omega", "1", "2", "3"], "expected a number, got 'two'"),
    "two moments": (["--moments", "1", "2", "--omega", "1", "2", "3"], "expected 3 arguments"),
    "no spin": (["--moments", "1", "2", "2.5", "--omega", "0", "0", "0"], "non-zero angular velocity"),
    "infinite spin": (["--moments", "1", "2", "2.5", "--omega", "1", "inf", "3"], "finite number"),
    "minus infinite spin": (["--moments", "1", "2", "2.5", "--omega", "1", "-inf", "3"], "finite number"),
    "omega unit is a length": ([*VALID, "--omega-unit", "km"], "unit of angular velocity"),
    "omega unit unknown": ([*VALID, "--omega-unit", "furlongs"], "unit of angular velocity"),
    "span in kg": ([*VALID, "--span", "3", "kg"], "--span expects a time"),
    "span zero": ([*VALID, "--span", "0"], "non-zero duration"),
    "negative step": ([*VALID, "--step", "-1", "d"], "positive spacing"),
    "too many times": ([*VALID, "--span", "1e9", "d"], "output times"),
    "step and n-times": ([*VALID, "--step", "1", "--n-times", "5"], "not allowed with"),
    "missing omega": (["--moments", "1", "2", "2.5"], "the spin state is missing: give --euler313 with --omega"),
}


def assert_one_clean_line(status, err, expected):
    assert status == 2
    assert "Traceback" not in err
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("spinorbit torque-free: error:")
    assert expected in lines[0]


def run_expecting_usage_error(capsys, args):
    try:
        status = cli.main(["torque-free", *args])
    except SystemExit as exit_info:  # argparse's own checks exit from inside parse_args
        status = exit_info.code
    return status, capsys.readouterr().err


@pytest.mark.parametrize("case", sorted(BAD_INPUT))
def test_bad_input_is_one_line_exit_2_and_no_file(capsys, tmp_path, case):
    args, expected = BAD_INPUT[case]
    status, err = run_expecting_usage_error(capsys, [*args, "--output", str(tmp_path / "out.ecsv")])
    assert_one_clean_line(status, err, expected)
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("where", ["missing directory", "a directory"])
def test_unwritable_output_fails_before_the_run(capsys, tmp_path, where):
    target = tmp_path / "no" / "such" / "out.ecsv" if where == "missing directory" else tmp_path
    status, out, err = run_cli(capsys, *VALID, "--output", str(target))
    assert_one_clean_line(status, err, "--output")
    assert out == ""  # refused before any work was done
    assert list(tmp_path.iterdir()) == []


def test_failed_write_leaves_nothing_behind(capsys, tmp_path, monkeypatch):
    def half_write(self, path, **kwargs):
        Path(path).write_text("# %ECSV 1.0\n# half")
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(Table, "write", half_write)
    status, _, err = run_cli(capsys, *VALID, "--output", str(tmp_path / "out.ecsv"))
    assert_one_clean_line(status, err, "No space left on device")
    assert list(tmp_path.iterdir()) == []


def test_a_bug_keeps_its_traceback_and_leaves_no_file(capsys, tmp_path, monkeypatch):
    def broken(*args, **kwargs):
        raise RuntimeError("a bug")

    monkeypatch.setattr(torque_free, "_plot", broken)
    with pytest.raises(RuntimeError, match="a bug"):
        cli.main(["torque-free", *VALID, "--plot", str(tmp_path / "run.png")])
    assert list(tmp_path.iterdir()) == []


def test_plot_without_matplotlib_says_how_to_install(capsys, tmp_path, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # makes `import matplotlib` fail
    status, _, err = run_cli(capsys, *VALID, "--plot", str(tmp_path / "run.png"))
    assert_one_clean_line(status, err, "pip install 'spinorbit[plot]'")
    assert list(tmp_path.iterdir()) == []


def test_subprocess_bad_input_has_no_traceback(tmp_path):
    path = tmp_path / "out.ecsv"
    result = subprocess.run([sys.executable, "-m", "spinorbit", "torque-free", "--moments", "1", "1", "3",
                             "--omega", "1", "2", "3", "--output", str(path)],
                            capture_output=True, text=True, cwd=ROOT, timeout=300)
    assert_one_clean_line(result.returncode, result.stderr, "triangle inequality")
    assert result.stdout == ""
    assert not path.exists()


# -- progress bar -----------------------------------------------------------------------------------


class FakeTerminal(io.StringIO):
    def __init__(self, tty):
        super().__init__()
        self.tty = tty

    def isatty(self):
        return self.tty


@pytest.mark.parametrize("tty", [True, False])
def test_progress_bar_only_on_a_terminal_and_only_when_slow(monkeypatch, tty):
    clock = iter(np.arange(0.0, 100.0, 1.0))
    monkeypatch.setattr(_common.time, "monotonic", lambda: next(clock))
    stream = FakeTerminal(tty)
    progress = _common.Progress(10, "propagating", stream=stream)  # started at t = 0 s
    progress.advance(1)  # t = 1 s: too early to show anything
    assert stream.getvalue() == ""
    progress.advance(4)  # t = 2 s: slow enough
    progress.close()
    assert ("50%" in stream.getvalue() and stream.getvalue().endswith("\n")) is tty
    assert (stream.getvalue() == "") is not tty


def test_quick_run_draws_no_bar(capsys):
    status, _, err = run_cli(capsys, *VALID, "--n-times", "1000")
    assert status == 0 and err == ""


def test_worktree_first_on_path():
    # The subprocess tests run `python -m spinorbit` with cwd = this checkout; make sure that is the
    # package under test here too.
    assert Path(cli.__file__).resolve().is_relative_to(ROOT)
    assert os.path.samefile(Path(torque_free.__file__).parents[2], ROOT)


# ------------------------------------------------------------------------------------------------
# The asteroid scenes (spinorbit apophis, spinorbit toutatis): short spans keep these fast.


def test_apophis_scene_writes_ecsv_with_plan_and_error_estimate(capsys, tmp_path):
    path = tmp_path / "apophis.ecsv"
    status = cli.main(["apophis", "--span", "1", "d", "--n-times", "5", "--output", str(path)])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert "kept sun, earth, moon" in out and "error estimate" in out
    table = Table.read(path)
    assert len(table) == 5 and table["P_psi"].unit == u.h
    assert table.meta["error_estimate_arcsec"] <= table.meta["tolerance_arcsec"]
    # 7 h before perigee the published periods (263 h, 27.38 h) have moved by ~2 h; 12 h after it the
    # encounter has changed P_psi by tens of hours (measured 264.8 h and ~160 h).
    assert abs(table["P_psi"][0] - 263.0) < 5 and abs(table["P_phi"][0] - 27.38) < 1
    assert abs(table["P_psi"][-1] - 263.0) > 20
    assert "route one-way" in table.meta["plan"]


def test_apophis_plan_drops_the_planets_and_says_why(capsys):
    status = cli.main(["apophis", "--plan", "--span", "1", "d", "--perturbers", "sun", "earth", "moon", "jupiter"])
    out, _ = capsys.readouterr()
    assert status == 0
    assert re.search(r"perturber jupiter\s+dropped", out) and re.search(r"perturber earth\s+kept", out)
    assert "at most" in out and "arcsec" in out


def test_no_skip_prints_the_reference_plan(capsys):
    status = cli.main(["toutatis", "--plan", "--no-skip", "--span", "0.01", "d", "--tolerance", "100", "arcsec"])
    out, _ = capsys.readouterr()
    assert status == 0 and "reference plan" in out and "exact torque-free" not in out


def test_toutatis_scene_end_only_and_plot(capsys, tmp_path):
    pytest.importorskip("matplotlib")
    path, png = tmp_path / "t.ecsv", tmp_path / "t.png"
    status = cli.main(["toutatis", "--span", "2", "d", "--end-only", "--output", str(path), "--plot", str(png)])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert len(Table.read(path)) == 1
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert "LAM" in out


def test_toutatis_run_marks_its_close_approach_in_the_summary_ecsv_and_plot(capsys, tmp_path):
    # 60 d from 1992-11-09 hold the 1992-12-08 approach (0.024 au published; 0.0240 au on this orbit)
    path = tmp_path / "t.ecsv"
    status = cli.main(["toutatis", "--span", "60", "d", "--n-times", "3", "--tolerance", "100", "arcsec",
                       "--output", str(path)])
    out, err = capsys.readouterr()
    assert status == 0, err
    line = re.search(r"closest approach\s+earth 1992-12-08 \d\d:\d\d TDB, (0\.\d+) au \(([\d.e+]+) km\)", out)
    assert line and float(line[1]) == pytest.approx(0.024, rel=0.02), out
    assert float(line[2]) == pytest.approx(float(line[1]) * 1.495978707e8, rel=1e-4)
    meta = Table.read(path).meta
    (approach,) = meta["close_approaches"]["earth"]
    assert approach["time"].startswith("1992-12-08") and meta["closest_approaches"]["earth"] == approach


def test_toutatis_torque_free_when_the_tolerance_allows(capsys):
    status = cli.main(["toutatis", "--plan", "--span", "0.01", "d", "--tolerance", "100", "arcsec"])
    out, _ = capsys.readouterr()
    assert status == 0 and "exact torque-free solution" in out


@pytest.mark.parametrize("args, words", [
    (["apophis", "--span", "-1", "d"], "--span expects a time in (0, 730] d"),
    (["apophis", "--span", "1", "kg"], "--span expects a time"),
    (["toutatis", "--tolerance", "1", "m"], "--tolerance expects an angle"),
    (["toutatis", "--perturbers", "vulcan"], "vulcan"),
    (["toutatis", "--n-times", "1"], "--n-times expects a whole number in [2, 100000]"),
    (["toutatis", "--n-times", "4.5"], "--n-times expects a whole number in [2, 100000] such as 200; got '4.5'"),
])
def test_scene_commands_bad_input_in_words(capsys, args, words):
    status = cli.main(args)
    _, err = capsys.readouterr()
    assert status == 2 and words in err and "Traceback" not in err
    assert len(err.strip().splitlines()) == 1


# ------------------------------------------------------------------------------------------------
# spinorbit asteroid: the user's own asteroid from a TOML scene or options.

SCENE_FILE = Path(__file__).resolve().parent.parent / "examples" / "asteroid_scene.toml"
OWN_ASTEROID = ["asteroid", "--elements", "2.2", "0.15", "4", "80", "30", "10", "--epoch", "2020-01-01",
                "--moments", "0.6", "0.9", "1", "--euler313", "10", "40", "70", "--omega", "0", "0", "1080"]


def test_asteroid_scene_file_plans_with_both_legs(capsys):
    """The committed example scene: its spin epoch lies inside the outputs, so the plan has a backward
    and a forward leg, each with its perturber decisions."""
    status = cli.main(["asteroid", "--scene", str(SCENE_FILE), "--plan"])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert "backward leg" in out and "forward leg" in out and "perturber jupiter" in out
    assert "osculating elements a = 1.5 AU" in out and "A2 = -2.9e-14" in out


def test_asteroid_from_options_writes_ecsv_starting_at_the_spin_epoch(capsys, tmp_path):
    path = tmp_path / "mine.ecsv"
    status = cli.main([*OWN_ASTEROID, "--span", "5", "d", "--n-times", "10", "--output", str(path)])
    out, err = capsys.readouterr()
    assert status == 0, err
    table = Table.read(path)
    assert len(table) == 10 and table.meta["tolerance_met"]
    start = Time("2020-01-01", scale="tdb")
    assert abs((Time(table["time"][0]) - start).to_value(u.day)) < 1e-6  # the first row is the start (the schema)
    assert abs((Time(table["time"][-1]) - start).to_value(u.day) - 5.0) < 1e-6
    # an 8 h spin about C under the Sun's torque: a principal-axis rotator in every row (issue 35)
    assert re.search(r"^first .* TDB  PA, P = 8\.0000 h  wobble", out, re.M), out
    assert re.search(r"^last  .* TDB  PA, P = 8\.0000 h  wobble", out, re.M), out
    assert set(table["rotation_class"]) == {"PA"} and table.meta["pa_threshold"] == "1 deg"
    assert np.all(np.ma.getmaskarray(table["P_psi"])) and table["wobble_amplitude"].unit == u.deg


def test_asteroid_pa_threshold_zero_reports_the_hair_of_wobble_as_sam(capsys):
    status = cli.main([*OWN_ASTEROID, "--span", "5", "d", "--n-times", "3", "--pa-threshold", "0", "deg"])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert re.search(r"^first .* TDB  PA, P = 8\.0000 h", out, re.M)  # exactly about C: amplitude 0
    assert re.search(r"^last  .* TDB  SAM, P_psi = .* h, P_phi = .* h, P_sid = +8\.0000 h  wobble", out, re.M), out
    status = cli.main([*OWN_ASTEROID, "--span", "5", "d", "--pa-threshold", "90", "deg"])
    _, err = capsys.readouterr()
    assert status == 2 and "--pa-threshold expects an angle in [0, 90) deg" in err


def test_asteroid_options_win_over_the_scene_file(capsys):
    status = cli.main(["asteroid", "--scene", str(SCENE_FILE), "--plan", "--perturbers", "sun", "--span", "2", "d"])
    out, err = capsys.readouterr()
    assert status == 0, err
    assert "perturber sun" in out and "perturber jupiter" not in out


@pytest.mark.parametrize("change, words", [
    ({"--elements": ["2.2", "1.2", "4", "80", "30", "10"]}, "e expects an elliptic orbit"),
    ({"--elements": ["-2.2", "0.1", "4", "80", "30", "10"]}, "positive semi-major axis"),
    ({"--elements": ["2.2", "0.1", "200", "80", "30", "10"]}, "inc expects an inclination"),
    ({"--epoch": ["2250-01-01"]}, "DE421's span"),
    ({"--epoch": ["yesterday"]}, "expects a TDB date"),
    ({"--epoch": ["2190-01-01"], "--span": ["20", "yr"]}, "DE421's span"),
])
def test_asteroid_bad_options_in_words(capsys, change, words):
    argv = [*OWN_ASTEROID, "--span", "30", "d"]
    for option, values in change.items():
        k = argv.index(option)
        argv[k + 1:k + 1 + len(values)] = values
    status = cli.main(argv)
    _, err = capsys.readouterr()
    assert status == 2 and words in err and "Traceback" not in err and len(err.strip().splitlines()) == 1


def test_asteroid_bad_scene_files_in_words(capsys, tmp_path):
    typo = tmp_path / "typo.toml"
    typo.write_text(SCENE_FILE.read_text().replace("mean_anomaly =", "mean_anomally ="))
    broken = tmp_path / "broken.toml"
    broken.write_text("[orbit\na = 1")
    missing = tmp_path / "missing.toml"
    missing.write_text('[orbit]\nepoch = "2020-01-01"\na = "2 au"\n')
    for path, words in ((typo, "unknown keys ['mean_anomally']"), (broken, "not valid TOML"),
                        (missing, "[orbit] e is missing"), (tmp_path / "absent.toml", "cannot be read")):
        status = cli.main(["asteroid", "--scene", str(path), "--plan"])
        _, err = capsys.readouterr()
        assert status == 2 and words in err and "Traceback" not in err, (path, err)
