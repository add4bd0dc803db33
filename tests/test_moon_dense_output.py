"""Dense outputs of the REBOUND-coupled Moon (natural BS steps) against the cut-step run, real DE421."""

import numpy as np
import pytest

from spinorbit.coupling.dense_output import hermite_interpolate
from spinorbit.coupling.moon import compare_with_de421, moon_at_de421

#: Largest attitude difference (arcsec) allowed between the dense-output run and the run whose steps
#: end at every output. Why 1e-3″: it is below 1/200 of the smallest model–DE421 difference over the
#: year (core-corrected, 0.21″), and of the size of what neither run can do better than: the same BS
#: run (eps 1e-13) with end-only and daily outputs differs by 5e-4″ at day 365, and DE421's libration
#: series (the interpolation's reference) are smooth only within 8-day Chebyshev granules.
DENSE_OUTPUT_TOLERANCE_ARCSEC = 1e-3
#: And relative to each model's own difference from DE421 (rigid 1.5″, core-corrected 0.21″).
DENSE_OUTPUT_RELATIVE_TOLERANCE = 5e-3
ONE_YEAR_DAYS = 365.25


@pytest.mark.parametrize("model", ["rigid", "core-corrected"])
def test_dense_outputs_match_the_cut_step_run_at_every_output(model):
    dense = compare_with_de421(moon_at_de421(model=model), ONE_YEAR_DAYS, 1.0)
    cut = compare_with_de421(moon_at_de421(model=model), ONE_YEAR_DAYS, 1.0, cut_steps=True)
    np.testing.assert_array_equal(dense.times, cut.times)
    error = np.linalg.norm(dense.body_difference_arcsec - cut.body_difference_arcsec, axis=1)
    assert error.max() <= DENSE_OUTPUT_TOLERANCE_ARCSEC
    assert error.max() <= DENSE_OUTPUT_RELATIVE_TOLERANCE * cut.max_difference_arcsec
    # The Euler angles and librations follow the attitude (same sub-milliarcsecond level).
    assert np.abs(dense.librations_model - cut.librations_model).max() <= 2 * DENSE_OUTPUT_TOLERANCE_ARCSEC


def test_dense_route_takes_natural_steps():
    """~70 BS steps a year with daily outputs (the cut-step run takes one a day, 371)."""
    moon = moon_at_de421(model="rigid")
    start = moon.sim.steps_done
    seen = []
    compare_with_de421(moon, ONE_YEAR_DAYS, 1.0, progress=seen.append)
    assert moon.sim.steps_done - start < 100
    assert seen[-1] == 366 and seen == sorted(seen)


def test_hermite_interpolate_reproduces_polynomials_and_refuses_bad_input():
    nodes = np.array([0.0, 0.5, 2.0, 3.5, 6.0, 6.3])
    coefficients = np.random.default_rng(1).normal(size=8)
    poly = np.polynomial.Polynomial(coefficients)  # degree 7: exact for 4 nodes with first derivatives
    times = np.linspace(0.0, 6.3, 50)
    values = hermite_interpolate(nodes, poly(nodes)[:, None], (poly.deriv()(nodes)[:, None],), times, 4)
    np.testing.assert_allclose(values[:, 0], poly(times), rtol=1e-10, atol=1e-10 * np.abs(poly(times)).max())
    with pytest.raises(ValueError, match="times must lie in"):
        hermite_interpolate(nodes, poly(nodes)[:, None], (poly.deriv()(nodes)[:, None],), np.array([7.0]), 4)
    with pytest.raises(ValueError, match="at least nodes"):
        hermite_interpolate(nodes[:3], poly(nodes[:3])[:, None], (poly.deriv()(nodes[:3])[:, None],), times[:2], 4)


def test_the_cut_step_reference_itself_depends_on_the_output_schedule_at_that_level():
    """The reason for DENSE_OUTPUT_TOLERANCE_ARCSEC: two runs that both cut steps, one output at day 365
    against daily outputs, differ at day 365 by a few 1e-4″ (BS eps 1e-13): the reference is no better."""
    end_only = compare_with_de421(moon_at_de421(model="rigid"), 365.0, 365.0, cut_steps=True)
    daily = compare_with_de421(moon_at_de421(model="rigid"), 365.0, 1.0, cut_steps=True)
    spread = np.linalg.norm(end_only.body_difference_arcsec[-1] - daily.body_difference_arcsec[-1])
    assert 1e-4 < spread < DENSE_OUTPUT_TOLERANCE_ARCSEC


def test_a_span_of_fewer_steps_than_a_fit_needs_still_interpolates():
    """A body whose step has grown to ≈ 6 d, then compared over 3 days: two step ends, a cubic fit."""
    moon, twin = moon_at_de421(model="rigid"), moon_at_de421(model="rigid")
    for body in (moon, twin):
        compare_with_de421(body, 30.0, 30.0)  # the step grows to BS's natural one
    dense = compare_with_de421(moon, 3.0, 1.0)
    cut = compare_with_de421(twin, 3.0, 1.0, cut_steps=True)
    error = np.linalg.norm(dense.body_difference_arcsec - cut.body_difference_arcsec, axis=1)
    # Two nodes give a cubic: over a year of ≈ 6-day steps it leaves ≤ 0.013″ (dense_output.HERMITE_NODES).
    assert error.max() <= 0.02
