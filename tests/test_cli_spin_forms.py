"""Spin states as they are published, on the command line and in the scene file (issue 35).

``--pole LON LAT --period P [--phase]`` is :meth:`RotationState.from_pole`, ``--tumbling P_PSI P_PHI
--momentum LON LAT --euler-zxz PHI0 THETA0 PSI0 [--mode]`` is :meth:`RotationState.from_tumbling`, and
every option takes a unit. Each is checked against the API: the state written in the first row of
``spinorbit torque-free``'s table (the exact free flow at t = 0 returns its input to rounding) is the
API's state, and the API's inverse (``pole()``, ``tumbling_parameters()``) gives back what was typed.
"""

import astropy.units as u
import numpy as np
import pytest
from _offline import no_network  # noqa: F401
from astropy.table import Table
from astropy.time import Time

from spinorbit import RigidBody, RotationState, cli
from spinorbit.commands._scene_file import read_scene_file
from spinorbit.commands._spin_options import spin_state, spin_values

EPOCH = "2020-01-01T00:00:00"
#: The first row against the API: the free flow at t = 0 (Fukushima's elements there and back) returns
#: the state to a few ulp (tests/test_cli.py, INITIAL_STATE_TOLERANCE); the ECSV text round-trips floats.
FIRST_ROW_TOLERANCE = 1e-12
#: Degrees and hours typed against those the inverse returns: the same ulp-level round trip, in the
#: units typed (1e-12 of 360 deg, 1e-12 relative for a period).
ROUND_TRIP_DEG, ROUND_TRIP_RELATIVE = 360e-12, 1e-12


def first_row_state(capsys, tmp_path, moments, *spin):
    path = tmp_path / "run.ecsv"
    argv = ["torque-free", "--moments", *moments, *spin, "--epoch", EPOCH, "--span", "1", "d", "--n-times", "2",
            "--output", str(path)]
    assert cli.main(argv) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    table = Table.read(path)
    q = np.array([table[f"q_{c}"][0] for c in "wxyz"])
    omega = np.array([table[f"omega_{c}"][0] for c in "xyz"])
    return q, omega, table.meta, out


def assert_same_state(q, omega, state):
    sign = 1.0 if np.dot(q, state.quaternion) >= 0 else -1.0  # q and -q are one attitude
    np.testing.assert_allclose(sign * q, state.quaternion, rtol=0, atol=FIRST_ROW_TOLERANCE)
    expected = state.angular_velocity.to_value(u.rad / u.day)
    np.testing.assert_allclose(omega, expected, rtol=0, atol=FIRST_ROW_TOLERANCE * np.abs(expected).max())


def test_pole_period_phase_on_the_command_line_is_from_pole(capsys, tmp_path):
    body = RigidBody([1.0, 1.2, 1.5])
    q, omega, meta, out = first_row_state(capsys, tmp_path, ["1", "1.2", "1.5"], "--pole", "30", "-40", "deg",
                                          "--period", "8", "h", "--phase", "10", "deg")
    api = RotationState.from_pole(body, 30 * u.deg, -40 * u.deg, 8 * u.h, Time(EPOCH, scale="tdb"), phase=10 * u.deg)
    assert_same_state(q, omega, api)
    assert meta["spin_form"] == "pole" and meta["pole_deg"] == [30.0, -40.0] and meta["period_h"] == 8.0
    back = RotationState(body, q, omega * u.rad / u.day).pole()
    assert back.pole_lon.to_value(u.deg) == pytest.approx(30.0, abs=ROUND_TRIP_DEG)
    assert back.pole_lat.to_value(u.deg) == pytest.approx(-40.0, abs=ROUND_TRIP_DEG)
    assert back.phase.to_value(u.deg) == pytest.approx(10.0, abs=ROUND_TRIP_DEG)
    assert back.period.to_value(u.h) == pytest.approx(8.0, rel=ROUND_TRIP_RELATIVE)
    assert "P = 0.3333 d (sidereal, principal-axis rotator)" in out


def test_a_number_alone_is_in_the_unit_help_names(capsys, tmp_path):
    """--period 8 is 8 h, --pole 30 -40 is in deg: the units --help states; 480 min is the same period."""
    typed = first_row_state(capsys, tmp_path, ["1", "1.2", "1.5"], "--pole", "30", "-40", "--period", "8")
    minutes = first_row_state(capsys, tmp_path, ["1", "1.2", "1.5"], "--pole", "0.5235987755982988",
                              "-0.6981317007977318", "rad", "--period", "480", "min")
    np.testing.assert_allclose(typed[0], minutes[0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(typed[1], minutes[1], rtol=4e-16)  # 8 h and 480 min: each a rounding of 1/3 d
    assert "--pole" in cli.build_parser()._subparsers._group_actions[0].choices["torque-free"].format_help()


def test_tumbling_on_the_command_line_is_the_published_apophis(capsys, tmp_path):
    """Pravec et al. (2014)'s Apophis typed as published: the data module's state (built by from_tumbling)."""
    from spinorbit.data.asteroids import APOPHIS_STATE_EPOCH, apophis_rotation_state

    api = apophis_rotation_state()
    published = api.tumbling_parameters()
    angles = [repr(float(angle.to_value(u.deg))) for angle in (published.phi0, published.theta0, published.psi0)]
    path = tmp_path / "apophis.ecsv"
    argv = ["torque-free", "--moments", "0.61", "0.965", "1", "--tumbling", "263", "27.38", "h", "--momentum", "250",
            "-75", "deg", "--euler-zxz", *angles, "deg", "--mode", "SAM", "--epoch", APOPHIS_STATE_EPOCH.tdb.isot,
            "--span", "1", "d", "--n-times", "2", "--output", str(path)]
    assert cli.main(argv) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    table = Table.read(path)
    q = np.array([table[f"q_{c}"][0] for c in "wxyz"])
    omega = np.array([table[f"omega_{c}"][0] for c in "xyz"])
    assert_same_state(q, omega, api)
    assert "mode               SAM" in out and "P_psi = 10.9583 d" in out  # 263 h
    back = RotationState(api.body, q, omega * u.rad / u.day).tumbling_parameters()
    assert back.p_psi.to_value(u.h) == pytest.approx(263.0, rel=ROUND_TRIP_RELATIVE)
    assert back.p_phi.to_value(u.h) == pytest.approx(27.38, rel=ROUND_TRIP_RELATIVE)
    assert back.momentum_lon.to_value(u.deg) == pytest.approx(250.0, abs=ROUND_TRIP_DEG)
    assert back.momentum_lat.to_value(u.deg) == pytest.approx(-75.0, abs=ROUND_TRIP_DEG)
    assert table.meta["tumbling_h"] == [263.0, 27.38] and table.meta["mode_given"] == "SAM"


@pytest.mark.parametrize("spin, words", [
    (["--pole", "30", "-40"], "the pole spin form is missing --period"),
    (["--pole", "30", "-40", "--period", "8", "h", "--omega", "0", "0", "1"], "two spin forms (--omega; --pole, --period)"),
    (["--pole", "30", "-40", "--period", "-8", "h"], "--period expects positive periods"),
    (["--pole", "30", "-40", "--period", "8", "kg"], "--period expects a time such as '8 h'"),
    (["--pole", "30", "-95", "--period", "8", "h"], "pole_lat expects a latitude in [-90°, 90°]"),
    (["--pole", "30", "--period", "8", "h"], "--pole expects 2 numbers and a unit of angle"),
    (["--tumbling", "263", "27.38", "h", "--momentum", "250", "-75"], "missing --euler-zxz"),
    (["--tumbling", "263", "27.38", "Hz", "--momentum", "250", "-75", "--euler-zxz", "0", "30", "0"],
     "--tumbling expects 2 numbers and a unit of time"),
    (["--tumbling", "263", "27.38", "--momentum", "250", "-75", "--euler-zxz", "0", "30", "0"],
     "theta0 = 30.0 deg is not the nutation angle"),
])
def test_bad_spin_forms_are_one_line(capsys, spin, words):
    status = cli.main(["torque-free", "--moments", "0.61", "0.965", "1", *spin])
    err = capsys.readouterr().err
    assert status == 2 and words in err and len(err.strip().splitlines()) == 1, err


# -- the scene file ---------------------------------------------------------------------------------

SPIN_TABLES = {
    "pole": '[spin]\nepoch = "2020-03-01T00:00:00"\npole = ["30 deg", "-40 deg"]\nperiod = "8 h"\nphase = "10 deg"\n',
    "pole in one string": '[spin]\nepoch = "2020-03-01T00:00:00"\npole = "30 -40 deg"\nperiod = "480 min"\n'
                          'phase = "10 deg"\n',
    "tumbling": '[spin]\nepoch = "2020-03-01T00:00:00"\ntumbling = ["263 h", "27.38 h"]\nmomentum = "250 -75 deg"\n'
                'euler_zxz = ["62.373763573 deg", "{theta0!r} deg", "0 deg"]\nmode = "SAM"\n',
}


def apophis_theta0_deg():
    """θ0 of Apophis's motion at ψ0 = 0 (it follows from the periods, the moments and ψ0: Kaasalainen 2001)."""
    from spinorbit.data.asteroids import apophis_rotation_state

    return float(apophis_rotation_state().tumbling_parameters().theta0.to_value(u.deg))


class Options:
    """The command line's spin options, none given (what argparse leaves when the file says it all)."""

    euler313 = omega = pole = period = phase = tumbling = momentum = euler_zxz = mode = None

    def __init__(self, **given):
        self.__dict__.update(given)


@pytest.mark.parametrize("case", sorted(SPIN_TABLES))
def test_scene_file_spin_forms_are_the_api(tmp_path, case):
    path = tmp_path / "scene.toml"
    path.write_text(SPIN_TABLES[case].replace("{theta0!r}", repr(apophis_theta0_deg())))
    table = read_scene_file(str(path))["spin"]
    body = RigidBody([0.61, 0.965, 1.0])
    epoch = Time("2020-03-01T00:00:00", scale="tdb")
    form, values = spin_values(Options(), table)
    state = spin_state(body, form, values, table["epoch"], "ecliptic")
    if form == "pole":
        api = RotationState.from_pole(body, 30 * u.deg, -40 * u.deg, 8 * u.h, epoch, phase=10 * u.deg)
        atol = 4e-16 if case == "pole" else 1e-15  # 480 min: another rounding of 1/3 d
    else:
        api = RotationState.from_tumbling(body, 263 * u.h, 27.38 * u.h, 250 * u.deg, -75 * u.deg,
                                          62.373763573 * u.deg, apophis_theta0_deg() * u.deg, 0 * u.deg, epoch,
                                          mode="SAM")
        atol = 0.0  # the same numbers into the same function
    assert state.epoch == epoch
    np.testing.assert_allclose(state.quaternion, api.quaternion, rtol=0, atol=atol)
    np.testing.assert_allclose(state.angular_velocity.value, api.angular_velocity.value, rtol=atol * 2, atol=0)


def test_the_command_line_form_wins_and_the_file_completes_it(tmp_path):
    path = tmp_path / "scene.toml"
    path.write_text(SPIN_TABLES["pole"])
    table = read_scene_file(str(path))["spin"]
    form, values = spin_values(Options(period=["6", "h"]), table)  # the file's pole and phase, the option's period
    assert form == "pole" and values["period"] == 6 * u.h and values["phase"] == 10 * u.deg
    form, values = spin_values(Options(euler313=["0", "0", "0"], omega=["0", "0", "1080"]), table)
    assert form == "euler313" and "pole" not in values  # another form on the command line replaces the file's


@pytest.mark.parametrize("text, words", [
    ('[spin]\npole = "30 -40 deg"\nomega = "0 0 1 deg/h"\n', "[spin] gives two spin forms (omega; pole)"),
    ('[spin]\npole = "30 -40 deg"\nperiod = 8\n', "[spin] period expects a time such as '8 h'; got the integer 8"),
    ('[spin]\npole = [30, -40]\nperiod = "8 h"\n', "[spin] pole expects 2 numbers and a unit of angle"),
    ('[spin]\ntumbling = "263 27.38 h"\nmomentum = "250 -75 deg"\neuler_zxz = "0 30 0 deg"\nmode = "sam"\n',
     "[spin] mode expects one of 'SAM', 'LAM'; got the string 'sam'"),
])
def test_bad_spin_tables_name_the_key(tmp_path, text, words):
    from spinorbit import InputError

    path = tmp_path / "scene.toml"
    path.write_text(text)
    with pytest.raises(InputError) as refused:
        spin_values(Options(), read_scene_file(str(path))["spin"])
    assert words in str(refused.value)


def test_asteroid_takes_the_pole_form(capsys):
    """The issue's 8 h body as DAMIT publishes it: the planned scene starts from from_pole's state."""
    argv = ["asteroid", "--elements", "1.5", "0.2", "10", "80", "30", "10", "--epoch", "2020-01-01", "--moments", "1",
            "1.2", "1.5", "--pole", "30", "-40", "deg", "--period", "8", "h", "--span", "2", "d", "--perturbers", "sun",
            "--plan"]
    assert cli.main(argv) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "8.0000 h" in out and "forward leg" in out  # the period typed, in the spin state's line


def test_the_example_scene_s_pole_alternative_reads(tmp_path):
    """examples/asteroid_scene.toml shows the pole form in comments: uncommented, it is a valid scene."""
    from pathlib import Path

    example = (Path(__file__).resolve().parent.parent / "examples" / "asteroid_scene.toml").read_text()
    lines = [line for line in example.splitlines() if not line.startswith(("euler313 =", "omega ="))]
    lines = [line[4:] if line.startswith("#   ") else line for line in lines]
    path = tmp_path / "pole.toml"
    path.write_text("\n".join(lines))
    scene = read_scene_file(str(path))
    form, values = spin_values(Options(), scene["spin"])
    state = spin_state(RigidBody(scene["body"]["moments"]), form, values, scene["spin"]["epoch"], "ecliptic")
    assert form == "pole" and state.sidereal_period.to_value(u.h) == pytest.approx(8.0, rel=1e-14)


def test_the_spin_form_commands_in_the_docs_run(capsys):
    """docs/cli.md, "Spin forms": each spinorbit command of its example block runs as printed."""
    import re
    import shlex
    from pathlib import Path

    page = (Path(__file__).resolve().parent.parent / "docs" / "cli.md").read_text()
    section = page.split("### Spin forms", 1)[1].split("\n### ", 1)[0]
    block = re.search(r"```bash\n(.*?)```", section, re.S)[1].replace("\\\n", " ")
    commands = [shlex.split(line)[1:] for line in block.splitlines() if line.startswith("spinorbit ")]
    assert len(commands) == 2
    for argv in commands:
        assert cli.main(argv) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert "P = 0.3333 d (sidereal, principal-axis rotator)" in out and "P_psi = 10.9583 d" in out


def test_help_names_the_unit_of_every_quantity_option():
    """Every option that takes a number with a unit says in --help what a number alone means."""
    parser = cli.build_parser()
    commands = parser._subparsers._group_actions[0].choices
    unnamed = []
    for name, sub in commands.items():
        for action in sub._actions:
            words = action.nargs == "+" and action.dest != "perturbers"
            if words and not ("a number alone is" in action.help or "default deg" in action.help
                              or "default h" in action.help or "unit" in action.help):
                unnamed.append(f"{name} {action.option_strings[0]}")
    assert unnamed == []
