"""The lunar physical libration from DE421 at J2000 against DE421's own librations (validation).

DE421's own model ("de421": mantle with tides, fluid core, Earth J2 on the figure, driven by DE421's
orbits, core carried from DE421's 1969 epoch): measured 0.00024″ over 1 yr, 0.0003″ over 5 yr,
0.0004″ over 20 yr — the remainder is at the level of DE421's Chebyshev fit of the librations.

Measured on this code (BS 1e-13, 11 bodies, EIH + Earth J2 on the orbits, degree 2–4 lunar field,
Sun, planets and Earth torquing the figure, daily comparison) over one year from J2000:
rigid 1.52″, core-corrected 0.207″ maximum attitude difference. The residual is physics DE421 has
and this model lacks (tidal and rotational distortion k2/τ, the core's oblateness and friction,
Earth's J2 acting on the lunar figure), not integration error: BS tolerances 1e-12 … 1e-15 give
1.5157″ / 0.2072″ alike (spread < 1e-4″).
"""

import numpy as np
import pytest

from spinorbit.coupling.moon import (
    compare_interior_with_de421,
    compare_with_de421,
    core_angular_velocity,
    moon_at_de421,
)
from spinorbit.ephemeris import de421_constants

pytestmark = pytest.mark.validation

ONE_YEAR_DAYS = 365.25
#: Rigid Moon with DE421's published (total) moments: measured 1.52″; the design target was ≈ 2″.
#: The bound is the target: a regression past it means the coupling or the field changed.
RIGID_ONE_YEAR_ARCSEC = 2.0
#: Mantle moments (fluid core's share IFAC·C removed): measured 0.207″; 0.3″ leaves ~50 % margin
#: for step-sequence differences between platforms while still failing if the core correction is lost
#: (that alone gives 1.5″).
CORE_CORRECTED_ONE_YEAR_ARCSEC = 0.3
#: Without degrees 3–4 the Moon drifts ~100″ a year (shared note): the comparison must see it.
DEGREE2_ONLY_AT_LEAST_ARCSEC = 20.0


@pytest.mark.parametrize(
    ("model", "bound"),
    [("rigid", RIGID_ONE_YEAR_ARCSEC), ("core-corrected", CORE_CORRECTED_ONE_YEAR_ARCSEC)],
)
def test_one_year_attitude_against_de421(model, bound):
    comparison = compare_with_de421(moon_at_de421(model=model), ONE_YEAR_DAYS, step_days=1.0)
    assert comparison.attitude_difference_arcsec[0] < 1e-6  # same initial attitude
    assert comparison.max_difference_arcsec < bound
    # The libration itself is followed: φ and θ differ from DE421 by ≤ the attitude bound (+ margin
    # for the 3-1-3 angles' amplification near θ ≈ 24°).
    difference = comparison.angles_model[:, :2] - comparison.angles_de421[:, :2]
    assert np.max(np.abs(difference)) * 206264.806 < 2.0 * bound


#: DE421's model, 1 year: measured 0.00024″. The bound 0.002″ is 1 % of the core-corrected rigid
#: model's 0.207″ (so the new model must beat the old by ≥ 100×, measured ~860×) and 8× the measured
#: value, room for platform step sequences; a lost term fails it (measured at 1 yr with one term off:
#: k2 = 0 0.159″, τ = 0 0.260″, k_v = 0 0.067″, spherical core 0.133″, no Earth J2 0.011″, core
#: started with the mantle's spin 0.149″ — docs/coupling.md's ablation table).
DE421_MODEL_ONE_YEAR_ARCSEC = 0.002


def test_de421_model_beats_the_rigid_models_at_one_year():
    comparison = compare_interior_with_de421(ONE_YEAR_DAYS, step_days=1.0)
    assert comparison.attitude_difference_arcsec[0] < 1e-6
    assert comparison.max_difference_arcsec < DE421_MODEL_ONE_YEAR_ARCSEC
    assert DE421_MODEL_ONE_YEAR_ARCSEC < 0.01 * 0.207


def test_core_at_de421_epoch_is_the_published_one_and_is_carried_elsewhere():
    constants = de421_constants()
    epoch = constants.moon_epoch_jd_tdb - 2451545.0
    assert core_angular_velocity(epoch) == tuple(constants.core_omega_at_epoch)
    # The fluid core's spin keeps its direction in space while the mantle's turns (1.5° from the
    # ecliptic pole, precessing in 18.6 yr): carried to J2000 its mantle-frame tilt has turned.
    carried = np.array(core_angular_velocity(0.0))
    published = np.array(constants.core_omega_at_epoch)
    # Its rate changes only through the friction k_v/C_c ≈ 2e-5 /day acting on |ω_c − ω| ≈ 0.007 rad/day.
    assert abs(np.linalg.norm(carried) - np.linalg.norm(published)) < 1e-3 * np.linalg.norm(published)
    assert np.linalg.norm(carried[:2] - published[:2]) > 1e-3


def test_comparison_detects_a_missing_degree_three_field():
    comparison = compare_with_de421(moon_at_de421(model="core-corrected", degree=2), ONE_YEAR_DAYS, 5.0)
    assert comparison.max_difference_arcsec > DEGREE2_ONLY_AT_LEAST_ARCSEC


def test_cli_moon_last_line_and_files(tmp_path, capsys):
    from astropy.table import Table

    from spinorbit import cli

    table_path, plot_path = tmp_path / "moon.ecsv", tmp_path / "moon.png"
    status = cli.main(["moon", "--span", "30", "d", "--model", "rigid", "--output", str(table_path),
                       "--plot", str(plot_path)])
    assert status == 0
    last = capsys.readouterr().out.strip().splitlines()[-1]
    assert last.startswith("max attitude difference vs DE421: ") and last.endswith(" arcsec over 30 d")
    table = Table.read(table_path, format="ascii.ecsv")
    assert len(table) == 31 and table["attitude_difference"].unit == "arcsec"
    assert table.colnames[:7] == ["time", "phi", "theta", "psi", "tau", "rho", "I_sigma"]
    assert table["time"].scale == "tdb" and table["time"][0].jd == 2451545.0
    assert table["tau"].unit == "arcsec" and table["psi_de421"].unit == "rad"
    assert plot_path.stat().st_size > 0


def test_cli_moon_from_a_start_date(tmp_path, capsys):
    import astropy.units as u
    from astropy.table import QTable

    from spinorbit import cli

    table_path = tmp_path / "moon.ecsv"
    assert cli.main(["moon", "--model", "rigid", "--start", "1950-01-01", "--span", "10", "d",
                     "--output", str(table_path)]) == 0
    table = QTable.read(table_path, format="ascii.ecsv")
    assert table["time"][0].tdb.iso.startswith("1950-01-01") and len(table) == 11
    assert np.max(np.abs((table["psi"] - table["psi_de421"]).to_value(u.arcsec))) < 1.0


def test_cli_moon_default_is_the_de421_model(capsys):
    from spinorbit import cli

    assert cli.main(["moon", "--span", "30", "d"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0].split()[1] == "de421,"
    value = float(lines[-1].removeprefix("max attitude difference vs DE421: ").removesuffix(" arcsec over 30 d"))
    assert value < DE421_MODEL_ONE_YEAR_ARCSEC  # 30 days inside the 1-year run: measured 0.00018″


def test_cli_moon_refuses_a_span_past_the_model_range(capsys, tmp_path):
    # The run must end inside DE421 (2200-02-01 less a day): 201 yr from J2000 ends in 2201.
    from spinorbit import cli

    output = tmp_path / "moon.ecsv"
    assert cli.main(["moon", "--span", "201", "yr", "--output", str(output)]) == cli.EXIT_USAGE
    error = capsys.readouterr().err.strip()
    assert "past DE421's last usable date" in error and "shorten the span" in error
    assert len(error.splitlines()) == 1 and not output.exists()


@pytest.mark.parametrize(("arguments", "expected"), [
    (["--start", "1899-06-01"], "--start: expected a date between 1899-12-05"),
    (["--start", "2200-03-01"], "--start: expected a date between"),
    (["--start", "2199-06-01", "--span", "1", "yr"], "past DE421's last usable date"),
    (["--step", "10", "s"], "--step: expected an output spacing from 1 min"),
    (["--step", "2", "yr"], "--step: expected an output spacing from 1 min"),
    (["--start", "yesterday"], "--start expects a TDB date such as"),
    (["--span", "1e9", "yr"], "--span: a run of 3.6525e+11 d from 2000-01-01 12:00:00.000 TDB ends at JD 3.65"),
])
def test_cli_moon_bad_input_is_one_line_before_any_work(capsys, tmp_path, arguments, expected):
    import time

    from spinorbit import cli

    output = tmp_path / "moon.ecsv"
    begin = time.perf_counter()
    assert cli.main(["moon", "--model", "rigid", *arguments, "--output", str(output)]) == cli.EXIT_USAGE
    # Before any work: no REBOUND simulation (its set-up alone takes longer) and no file.
    assert time.perf_counter() - begin < 2.0
    error = capsys.readouterr().err.strip()
    assert expected in error and len(error.splitlines()) == 1 and not output.exists()


def test_api_bad_input_raises_specific_errors():
    import astropy.units as u
    from astropy.time import Time

    from spinorbit.coupling.moon import OutputStepError, moon_librations
    from spinorbit.ephemeris import EphemerisRangeError

    with pytest.raises(EphemerisRangeError, match="start: expected a date between"):
        moon_librations("de421", Time("1850-01-01", scale="tdb"), 1 * u.d)
    with pytest.raises(EphemerisRangeError, match="shorten the span to at most"):
        moon_librations("rigid", Time("2190-01-01", scale="tdb"), 20 * u.yr)
    with pytest.raises(OutputStepError, match="from 1 min"):
        moon_librations("core-corrected", None, 10 * u.d, 1 * u.s)
    with pytest.raises(TypeError, match="start: expected a scalar astropy Time"):
        moon_librations("rigid", "2000-01-01", 10 * u.d)
    with pytest.raises(TypeError, match="span: expected a scalar time Quantity"):
        moon_librations("rigid", None, 10 * u.m)
    with pytest.raises(ValueError, match="model: expected one of"):
        moon_librations("elastic", None, 10 * u.d)


#: Starts across DE421 (near both ends, DE421's own epoch, the Apollo 11 landing) for every model, 30
#: days each. Bounds: de421 the 1-year bound; rigid models 0.3″ over 30 d (measured 0.08–0.13″ at
#: 1900 and 2199; a start taken from another date or without DE421's rates is off by degrees).
START_DATES = ("1899-12-06", "1969-07-20", "2199-12-01")
THIRTY_DAY_BOUNDS_ARCSEC = {"de421": DE421_MODEL_ONE_YEAR_ARCSEC, "rigid": 0.3, "core-corrected": 0.3}
#: The de421 model from late dates carries DE421's core from 1969 (≈ 20 s for 2199): slow there.
SLOW_STARTS = {("de421", "2199-12-01")}


@pytest.mark.parametrize(("start", "model"), [
    pytest.param(start, model, marks=[pytest.mark.slow] if (model, start) in SLOW_STARTS else [])
    for start in START_DATES for model in ("de421", "rigid", "core-corrected")])
def test_any_start_date_against_de421(model, start):
    import astropy.units as u
    from astropy.time import Time

    from spinorbit.coupling.moon import moon_librations

    table = moon_librations(model, Time(start, scale="tdb"), 30 * u.d, 1 * u.d)
    assert len(table) == 31 and table.colnames[0] == "time"
    assert abs((table["time"][0] - Time(start, scale="tdb")).to_value(u.s)) < 1e-3
    assert table.meta["epoch"].startswith(start) and table.meta["frame"] == "ICRF"
    difference = table["attitude_difference"].to_value(u.arcsec)
    assert difference[0] < 1e-6 and difference.max() < THIRTY_DAY_BOUNDS_ARCSEC[model]
    # Angles on one branch: model − DE421 is the small difference (ψ itself is thousands of rad).
    bound = 3.0 * THIRTY_DAY_BOUNDS_ARCSEC[model]
    for name in ("phi", "theta", "psi", "tau", "rho", "I_sigma"):
        assert np.max(np.abs((table[name] - table[name + "_de421"]).to_value(u.arcsec))) < bound, name
    assert np.max(np.abs(table["tau_de421"].to_value(u.arcsec))) < 400.0


#: Longer spans (slow): bounds ≈ 15 % above the measured maxima (rigid 6.92″ / 11.3″,
#: core-corrected 0.857″ / 1.38″), so that a regression shows while step-sequence noise does not.
LONG_SPAN_BOUNDS_ARCSEC = {
    ("rigid", 5): 8.0, ("core-corrected", 5): 1.0,
    ("rigid", 20): 13.0, ("core-corrected", 20): 1.6,
}
#: DE421's model (slow): measured 0.0003″ (5 yr) and 0.0004″ (20 yr); 0.002″ as at 1 year, well
#: inside the 0.01″ goal.
DE421_MODEL_LONG_SPAN_ARCSEC = 0.002


@pytest.mark.slow
@pytest.mark.parametrize("years", [5, 20])
def test_long_span_de421_model(years):
    comparison = compare_interior_with_de421(years * ONE_YEAR_DAYS, 5.0)
    assert comparison.max_difference_arcsec < DE421_MODEL_LONG_SPAN_ARCSEC


@pytest.mark.slow
@pytest.mark.parametrize(("model", "years"), sorted(LONG_SPAN_BOUNDS_ARCSEC))
def test_long_span_attitude_against_de421(model, years):
    step = 5.0 if years == 5 else 10.0
    comparison = compare_with_de421(moon_at_de421(model=model), years * ONE_YEAR_DAYS, step)
    assert comparison.max_difference_arcsec < LONG_SPAN_BOUNDS_ARCSEC[(model, years)]


def test_checkpoints_are_refused_for_the_de421_model(tmp_path):
    """The one entry point dispatches checkpoints to the coupled models only; de421 says so at once."""
    from spinorbit.runs.checkpoint import CheckpointSchedule
    from spinorbit.coupling.moon import compare_model_with_de421

    with pytest.raises(ValueError, match="checkpoints apply to the REBOUND-coupled models"):
        compare_model_with_de421("de421", 2.0, schedule=CheckpointSchedule(str(tmp_path / "run.ckpt")))
    assert not (tmp_path / "run.ckpt").exists()


#: 100 yr from J2000, step 10 d (benchmarks/moon_validation.py, docs/validation.md): measured de421
#: 0.0018″, rigid 15.05″, core-corrected 12.59″; bounds ≈ 15 % above (0.0025″ for de421: its
#: difference is at DE421's fit level, 0.0007″ of margin).
HUNDRED_YEAR_BOUNDS_ARCSEC = {"de421": 0.0025, "rigid": 17.5, "core-corrected": 14.5}


@pytest.mark.slow
@pytest.mark.parametrize("model", sorted(HUNDRED_YEAR_BOUNDS_ARCSEC))
def test_hundred_years_against_de421(model):
    from spinorbit.coupling.moon import compare_model_with_de421

    comparison = compare_model_with_de421(model, 100 * ONE_YEAR_DAYS, 10.0)
    assert comparison.max_difference_arcsec < HUNDRED_YEAR_BOUNDS_ARCSEC[model]
    # The table's angles stay on DE421's branch for a century (ψ has turned 1337 times).
    assert np.max(np.abs(comparison.angles_model - comparison.angles_de421)) < 1e-3


#: BS tolerances 1e-12 … 1e-15 move the one-year difference by < 1e-4″ (module docstring): a step
#: sequence that reaches each output in one step must agree with the cut one within that.
STEP_SEQUENCE_SPREAD_ARCSEC = 1e-4


def test_daily_outputs_take_one_bs_step_a_day(monkeypatch):
    """Cut-step route (checkpointed runs): REBOUND restores dt to the last full step after an output;
    without the growth of ``long_run.reach_in_one_step`` every day took a full and a cut step
    (measured 2 per day)."""
    import spinorbit.coupling.long_run as long_run

    days = 30

    def run():
        moon = moon_at_de421(model="rigid")
        start = moon.sim.steps_done
        comparison = compare_with_de421(moon, days, step_days=1.0, cut_steps=True)
        return moon.sim.steps_done - start, comparison

    steps, comparison = run()
    monkeypatch.setattr(long_run, "OUTPUT_STEP_GROWTH", 1.0)  # the former behaviour: no growth
    steps_cut, comparison_cut = run()
    assert steps_cut >= 2 * days - 2
    assert steps <= days + 8  # the first day's steps from the 0.001-day starting step, then one a day
    difference = np.abs(comparison.attitude_difference_arcsec - comparison_cut.attitude_difference_arcsec)
    assert 0.0 < np.max(difference) < STEP_SEQUENCE_SPREAD_ARCSEC
