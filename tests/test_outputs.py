"""The one output schema across API and commands, the plots' content, plan progress and the compile notice."""

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from astropy import units as u
from astropy.table import Table
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.scene import FixedPerturber, Orbit, Scene
from spinorbit.state_table import CLASS_COLUMNS, MOTION_COLUMNS, OMEGA_COLUMNS, POLE_COLUMNS, QUATERNION_COLUMNS

ROOT = Path(__file__).resolve().parents[1]
SCHEMA = ["time", *QUATERNION_COLUMNS, *OMEGA_COLUMNS, *POLE_COLUMNS]
EPOCH = Time("2020-01-01T00:00:00", scale="tdb")


def _state():
    return RotationState.from_euler313(RigidBody([0.61, 0.965, 1.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg,
                                       [5, 3, 40] * u.deg / u.hour)


def test_torque_free_scene_table_starts_at_the_epoch_with_the_schema():
    times = EPOCH + np.linspace(0.0, 10.0, 11) * u.day
    result = Scene(_state(), EPOCH, times).run()
    table = result.table
    assert table.colnames == [*SCHEMA, *MOTION_COLUMNS, *CLASS_COLUMNS]
    assert table["time"].scale == "tdb" and table["time"][0] == EPOCH
    # the first row is the state itself
    assert np.allclose(np.stack([table[c] for c in QUATERNION_COLUMNS], axis=1)[0] * np.sign(table["q_w"][0]),
                       _state().quaternion * np.sign(_state().quaternion[0]), atol=1e-15)
    assert table.meta["epoch"] == EPOCH.isot and table.meta["frame"] == "ICRF" and "torque-free" in table.meta["model"]
    assert table["P_psi"].unit == u.h and table["pole_ra"].unit == u.deg and table["omega_x"].unit == u.rad / u.day


def test_scene_with_an_orbit_has_the_obliquity_against_the_orbit_plane():
    # a circular barycentric orbit; the obliquity is to the *heliocentric* plane: body minus DE421's Sun
    # (the Sun's own barycentric motion tilts it by ~0.02° from the circle's +z)
    from spinorbit.ephemeris import barycentric_state_au
    from spinorbit.pole import obliquity_deg, orbit_normals
    from spinorbit.scene.inputs import tdb_day_array

    orbit = Orbit.circular(2.5 * u.au)
    times = EPOCH + np.linspace(0.0, 2.0, 5) * u.day
    table = Scene(_state(), EPOCH, times, perturbers=("sun",), orbit=orbit, tolerance=1e3 * u.arcsec).run().table
    assert "obliquity" in table.colnames and table.colnames.index("obliquity") == table.colnames.index("mode") - 1
    days = tdb_day_array(times)
    (r, v), (sun_r, sun_v) = orbit.function(days), barycentric_state_au("sun", days)
    ra, dec = (np.radians(table[c].to_value(u.deg)) for c in ("pole_ra", "pole_dec"))
    poles = np.stack([np.cos(dec) * np.cos(ra), np.cos(dec) * np.sin(ra), np.sin(dec)], axis=1)
    expected = obliquity_deg(poles, orbit_normals(r - sun_r, v - sun_v))
    # the normals come from the Sun sampled relative to the body (1e-10), linearly between knots:
    # within 1e-5 deg (tests/test_pole.py)
    assert np.abs(table["obliquity"].to_value(u.deg) - expected).max() < 1e-5


def test_plan_reports_progress():
    fractions = []
    times = EPOCH + np.linspace(0.5, 2.0, 4) * u.day
    scene = Scene(_state(), EPOCH, times, perturbers=("sun", "jupiter"), orbit=Orbit.circular(2.5 * u.au))
    scene.plan(progress=fractions.append)
    assert fractions[0] == 0.0 and fractions[-1] == 1.0 and len(fractions) >= 3
    assert fractions == sorted(fractions)


@pytest.mark.parametrize("extension", ["png", "pdf", "svg"])
def test_plot_shows_dates_periods_pole_obliquity_and_encounters(tmp_path, extension):
    pytest.importorskip("matplotlib")
    from spinorbit.commands._outputs import plot_rotation

    times = EPOCH + np.linspace(0.0, 5.0, 30) * u.day
    near = FixedPerturber("companion", 1e-9 * u.au**3 / u.day**2, [0.01, 0, 0] * u.au)
    table = Scene(_state(), EPOCH, times, perturbers=(near,), tolerance=1e3 * u.arcsec).run().table
    table["obliquity"] = 30 * u.deg
    path = tmp_path / f"run.{extension}"
    plot_rotation(table, str(path), "test", extension,
                  encounters={"earth": {"time": (EPOCH + 2 * u.day).isot, "distance_au": 0.01}})
    data = path.read_bytes()
    assert data[:4] in (b"\x89PNG", b"%PDF", b"<?xm")
    if extension == "svg":
        text = data.decode()
        for words in ("period [h]", "pole [deg]", "obliquity [deg]", "date (TDB)", "earth 0.01 au", "2020-Jan"):
            assert words in text or words.replace(" ", "") in text.replace(" ", ""), words


def test_plot_of_a_principal_axis_rotator_shows_what_changed(tmp_path):
    """Every row PA: pole drift (arcsec east and north of the start), obliquity change, period residual, wobble."""
    pytest.importorskip("matplotlib")
    from spinorbit.commands._outputs import plot_rotation, pole_offsets_arcsec

    spin = 2 * np.pi * u.rad / (8 * u.h)
    state = RotationState(RigidBody([0.61, 0.965, 1.0]), [0.8, 0.6, 0, 0], [0, 0, 1] * spin)
    near = FixedPerturber("companion", 1e-9 * u.au**3 / u.day**2, [0.01, 0.003, 0.002] * u.au)
    times = EPOCH + np.linspace(0.0, 5.0, 30) * u.day
    table = Scene(state, EPOCH, times, perturbers=(near,), tolerance=1e-2 * u.arcsec).run().table
    assert set(table["rotation_class"]) == {"PA"}
    table["obliquity"] = np.linspace(30, 30.001, len(table)) * u.deg
    east, north = pole_offsets_arcsec(table)
    # the offsets are the pole's angle from the start to first order: |(east, north)| = the angle
    start = np.radians([table["pole_lon"][0].to_value(u.deg), table["pole_lat"][0].to_value(u.deg)])
    lon, lat = (table[name].to(u.rad).value for name in ("pole_lon", "pole_lat"))
    haversine = np.sin((lat - start[1]) / 2) ** 2 + np.cos(lat) * np.cos(start[1]) * np.sin((lon - start[0]) / 2) ** 2
    angle = np.degrees(2 * np.arcsin(np.sqrt(haversine))) * 3600  # accurate at small angles, unlike arccos
    assert abs(east[0]) < 1e-9 and abs(north[0]) < 1e-9 and np.max(angle) > 0.01
    # tangent-plane offsets against the great-circle angle: equal to (angle)² ~ 1e-14 relative here
    assert np.allclose(np.hypot(east, north), angle, rtol=1e-9, atol=1e-9)
    path = tmp_path / "pa.svg"
    plot_rotation(table, str(path), "PA", "svg")
    text = path.read_text().replace(" ", "")
    for words in ("pole drift [arcsec]", "obliquity − 30.0000°", "[ms]", "wobble", "PA in every row", "date (TDB)"):
        assert words.replace(" ", "") in text, words
    assert "period[h]" not in text


def test_compile_notice_on_a_cold_cache_only(tmp_path):
    """A fresh NUMBA_CACHE_DIR: the first run says it compiles, the second (warm) says nothing. stderr here
    is a pipe (``capture_output``), as for a run logged to a file: the notice is printed there too, since
    that is where a silent first run of ~25 s most needs explaining; ``SPINORBIT_COMPILE_NOTICE=0`` silences it."""
    module = tmp_path / "kernel_module.py"
    module.write_text(textwrap.dedent("""
        import numba
        @numba.njit(cache=True)
        def twice(x):
            return 2 * x
    """))
    code = ("import sys; sys.path[:0] = [%r, %r]\n"
            "assert not sys.stderr.isatty()\n"
            "from spinorbit.commands._compile_notice import compile_notice\n"
            "with compile_notice():\n"
            "    import kernel_module; kernel_module.twice(2.0)\n")

    def run(cache, switch=None):
        env = {key: value for key, value in os.environ.items() if key != "SPINORBIT_COMPILE_NOTICE"}
        env["NUMBA_CACHE_DIR"] = str(tmp_path / cache)
        if switch is not None:
            env["SPINORBIT_COMPILE_NOTICE"] = switch
        result = subprocess.run([sys.executable, "-c", code % (str(tmp_path), str(ROOT))],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env, timeout=120)
        assert result.returncode == 0, result.stderr
        return result.stderr

    first, second = run("cache"), run("cache")
    assert "compiling the numba kernels" in first and len(first.strip().splitlines()) == 1
    assert second == ""
    assert run("other cache", switch="0") == ""  # cold, but silenced


@pytest.mark.slow
def test_cli_compile_notice_cold_then_silent(tmp_path):
    """The real command on a pseudo-terminal with an empty cache (≈ 20 s of compiling), then warm."""
    import pty

    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"), "PYTHONPATH": str(ROOT)}
    env.pop("SPINORBIT_COMPILE_NOTICE", None)  # silenced for the rest of the suite (tests/conftest.py)
    command = [sys.executable, "-m", "spinorbit", "torque-free", "--moments", "1", "2", "3", "--omega", "1", "2", "30"]

    def stderr_on_a_terminal():
        primary, secondary = pty.openpty()
        result = subprocess.run(command, stdout=subprocess.DEVNULL, stderr=secondary, env=env, timeout=600, cwd=tmp_path)
        os.close(secondary)
        chunks = []
        while True:
            try:
                chunk = os.read(primary, 4096)
            except OSError:
                break
            if not chunk:
                break
            chunks.append(chunk)
        os.close(primary)
        assert result.returncode == 0
        return b"".join(chunks).decode()

    cold, warm = stderr_on_a_terminal(), stderr_on_a_terminal()
    assert "compiling the numba kernels" in cold and "compiling" not in warm


def test_command_ecsv_has_the_api_columns(tmp_path):
    from spinorbit import cli

    path = tmp_path / "t.ecsv"
    assert cli.main(["torque-free", "--moments", "1", "2", "3", "--omega", "1", "2", "30", "--span", "3", "d",
                     "--epoch", "2024-05-01T00:00:00", "--output", str(path)]) == 0
    table = Table.read(path)
    assert table.colnames == [*SCHEMA, *MOTION_COLUMNS, *CLASS_COLUMNS]
    assert isinstance(table["time"], Time) and table["time"][0] == Time("2024-05-01T00:00:00", scale="tdb")
    assert table.meta["epoch"] == "2024-05-01T00:00:00.000" and table.meta["frame"] == "ICRF"


def test_a_principal_axis_rotator_through_a_scene_keeps_its_8_h():
    """Issue 15's case end to end: spin about the short axis C, 8 h. Torque-free, every row is a permanent
    rotation (P_sid = 8 h); under a weak torque the rows leave the axis by a hair, mathematically tumblers with
    that wobble (finite P_ψ: the definition, docs/conventions.md), but reported as what an observer sees: PA
    with P_sid = 8 h to the size of the torque's effect, the P_ψ/P_φ split masked (issue 35). At threshold 0
    the rows are SAM with the small-wobble limits."""
    spin = 2 * np.pi * u.rad / (8 * u.h)
    state = RotationState(RigidBody([0.61, 0.965, 1.0]), [1, 0, 0, 0], [0, 0, 1] * spin)
    times = EPOCH + np.linspace(0.0, 5.0, 6) * u.day
    scene = Scene(state, EPOCH, times)
    assert "exactly along the A or C axis" in str(scene.plan())
    table = scene.run().table
    assert set(table["mode"]) == {"permanent rotation"} and set(table["rotation_class"]) == {"PA"}
    assert np.all(table["P_psi"].mask) and np.all(np.isinf(table["P_psi"].unmasked))
    assert np.allclose(table["P_phi"].unmasked.to_value(u.h), 8.0, rtol=1e-14)
    assert np.allclose(table["sidereal_period"].to_value(u.h), 8.0, rtol=1e-14)
    near = FixedPerturber("companion", 1e-12 * u.au**3 / u.day**2, [0.01, 0.003, 0.002] * u.au)
    torqued = Scene(state, EPOCH, times, perturbers=(near,), tolerance=1e-3 * u.arcsec).run().table
    assert torqued["mode"][0] == "permanent rotation" and set(torqued["mode"][1:]) == {"SAM"}
    assert set(torqued["rotation_class"]) == {"PA"} and np.all(torqued["P_psi"].mask)
    assert np.all(torqued["wobble_amplitude"][1:].to_value(u.rad) < 1e-9)
    exact = Scene(state, EPOCH, times, perturbers=(near,), tolerance=1e-3 * u.arcsec, pa_threshold=0 * u.deg).run().table
    assert list(exact["rotation_class"]) == ["PA", *["SAM"] * 5] and not np.any(exact["P_psi"].mask[1:])
    # off the axis by ≤ 2.5e-10 rad (measured): P_sid stays 8 h to the rounding of |ω| (measured 1.2e-14
    # relative), while P_ψ, P_φ are the small-wobble limits about C, 2π/ν₀ and 2π/(|ω| + ν₀) with
    # ν₀ = |ω| C √((a − c)(b − c)) (52.54 h, 6.943 h here), to (wobble)² ~ 1e-19
    assert np.allclose(exact["sidereal_period"].to_value(u.h), 8.0, rtol=1e-12)
    a, b, c = (1 / m for m in (0.61, 0.965, 1.0))
    nu0 = np.sqrt((a - c) * (b - c))  # ν₀/|ω|, since G = C|ω| with C = 1
    assert np.allclose(exact["P_psi"][1:].unmasked.to_value(u.h), 8.0 / nu0, rtol=1e-12)
    assert np.allclose(exact["P_phi"][1:].unmasked.to_value(u.h), 8.0 / (1 + nu0), rtol=1e-12)


def test_command_planning_shows_a_progress_bar_on_a_terminal(monkeypatch):
    """spinorbit's scene commands draw the planning bar on a terminal once planning passes its delay."""
    import argparse
    import io

    from spinorbit.commands import _scene_command

    class Terminal(io.StringIO):
        def isatty(self):
            return True

    stderr = Terminal()
    monkeypatch.setattr(sys, "stderr", stderr)
    monkeypatch.setattr(_scene_command, "PLAN_PROGRESS_DELAY_S", 0.0)
    times = EPOCH + np.linspace(0.0, 2.0, 5) * u.day
    scene = Scene(_state(), EPOCH, times, perturbers=("sun", "jupiter"), orbit=Orbit.circular(2.5 * u.au))
    args = argparse.Namespace(no_skip=False, plan=True)
    assert _scene_command.run_scene(scene, args) is None  # --plan: printed, not run
    drawn = stderr.getvalue()
    assert "planning [" in drawn and "100%" in drawn and drawn.endswith("\n")
