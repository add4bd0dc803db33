"""Chaotic rotation of a Hyperion-like body: the sensitivity is measured, not hidden (issue 7).

Scene and method: ``benchmarks/chaotic.py`` (a 3-D variant of Wisdom, Peale & Mignard 1984:
(B − A)/C = 0.26, e = 0.1, Saturn a point mass). The quick version here runs forward–backward over
1–12 orbits (< 2 s); ``benchmarks/stability.py`` runs the long version and plots it in
``docs/stability.md``.

What is asserted, with the reason:

* the motion is chaotic: T_L from 100 renormalised orbits is finite and of the order of an orbit
  (measured 1.04–1.09 orbits for three directions of the initial offset), and the three directions
  agree within 20 % (an estimate of the largest exponent does not depend on the direction);
* DOP853's return error follows ε · exp(T/τ) with τ within a factor 2 of T_L (fitted 0.66–1.1 T_L
  depending on the span: the finite-time exponent of the first orbits is larger) and ε within a
  factor 10 of rtol (fitted 1.2 and 3.7 × rtol): the error is the tolerance amplified by the chaos;
* the symmetric splitting (time-reversible) has ε at rounding level (fitted 14 ulp) and the same
  exponential growth.
"""

import math

import numpy as np
import pytest

from benchmarks.chaotic import (
    ORBIT,
    exponential_fit,
    lyapunov_time,
    model,
    return_error,
)

EPS = np.finfo(float).eps
ORBITS = np.arange(1, 13)
OFFSETS = {
    "spin rate": np.array([0, 0, 0, 0, 0, 0, 1e-9]),
    "attitude": np.array([0, 0, 1e-9, 0, 0, 0, 0]),
    "spin axis": np.array([0, 0, 0, 0, 1e-9, 0, 0]),
}


@pytest.fixture(scope="module")
def lyapunov():
    return {name: lyapunov_time(100, offset) for name, offset in OFFSETS.items()}


def test_lyapunov_time_is_an_orbit_whatever_the_offset(lyapunov):
    times = np.array(list(lyapunov.values())) / ORBIT
    assert np.all((times > 0.5) & (times < 2.0)), times
    assert times.max() < 1.2 * times.min(), times


@pytest.mark.parametrize("rtol", [1e-9, 1e-12])
def test_dop853_return_error_is_tolerance_times_exp_t_over_tl(rtol, lyapunov):
    errors = [return_error("DOP853 (quaternion)", k * ORBIT, rtol, model()) for k in ORBITS]
    eps, tau = exponential_fit(ORBITS * ORBIT, errors)
    t_l = lyapunov["spin rate"]
    assert 0.5 * t_l < tau < 2.0 * t_l, (tau / t_l, errors)
    assert 0.1 * rtol < eps < 10 * rtol, (eps / rtol, errors)
    assert errors[-1] > 1e3 * errors[0]  # the growth is not hidden: three decades in 11 orbits


def test_symmetric_splitting_returns_to_rounding_times_exp_t_over_tl(lyapunov):
    errors = [return_error("SABA3 splitting", k * ORBIT, m=model()) for k in ORBITS]
    eps, tau = exponential_fit(ORBITS * ORBIT, errors)
    t_l = lyapunov["spin rate"]
    assert eps < 100 * EPS, (eps / EPS, errors)
    assert 0.5 * t_l < tau < 2.0 * t_l, (tau / t_l, errors)
    assert errors[0] < 100 * EPS  # one orbit: reversible to rounding


def test_elements_return_error_grows_but_stays_below_dop853_at_the_same_rtol():
    """Measured, not modelled: the element integrator's return error grows irregularly (fit τ ≈ 3 T_L
    over 1–8 orbits) and stays 100× below DOP853's at rtol 1e-12 (docs/stability.md)."""
    spans = [ORBIT, 12 * ORBIT]
    elements = [return_error("elements (hand-over)", t, 1e-12, model()) for t in spans]
    dop853 = [return_error("DOP853 (quaternion)", t, 1e-12, model()) for t in spans]
    assert elements[1] > elements[0]
    assert elements[1] < dop853[1]
    assert math.isfinite(elements[1])
