"""The lunar physical libration from DE421 at J2000 against DE421's own librations (validation).

Measured on this code (BS 1e-13, 11 bodies, EIH + Earth J2 on the orbits, degree 2–4 lunar field,
Sun, planets and Earth torquing the figure, daily comparison) over one year from J2000:
rigid 1.52″, core-corrected 0.207″ maximum attitude difference. The residual is physics DE421 has
and this model lacks (tidal and rotational distortion k2/τ, the core's oblateness and friction,
Earth's J2 acting on the lunar figure), not integration error: BS tolerances 1e-12 … 1e-15 give
1.5157″ / 0.2072″ alike (spread < 1e-4″).
"""

import numpy as np
import pytest

from spinorbit.coupling.moon import compare_with_de421, moon_at_de421

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
    assert plot_path.stat().st_size > 0


def test_cli_moon_refuses_a_span_past_the_model_range(capsys):
    from spinorbit import cli

    assert cli.main(["moon", "--span", "200", "yr"]) == cli.EXIT_USAGE
    assert "up to 50 yr" in capsys.readouterr().err


#: Longer spans (slow): bounds ≈ 15 % above the measured maxima (rigid 6.92″ / 11.3″,
#: core-corrected 0.857″ / 1.38″), so that a regression shows while step-sequence noise does not.
LONG_SPAN_BOUNDS_ARCSEC = {
    ("rigid", 5): 8.0, ("core-corrected", 5): 1.0,
    ("rigid", 20): 13.0, ("core-corrected", 20): 1.6,
}


@pytest.mark.slow
@pytest.mark.parametrize(("model", "years"), sorted(LONG_SPAN_BOUNDS_ARCSEC))
def test_long_span_attitude_against_de421(model, years):
    step = 5.0 if years == 5 else 10.0
    comparison = compare_with_de421(moon_at_de421(model=model), years * ONE_YEAR_DAYS, step)
    assert comparison.max_difference_arcsec < LONG_SPAN_BOUNDS_ARCSEC[(model, years)]
