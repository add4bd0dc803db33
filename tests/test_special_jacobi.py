"""sn, cn, dn, am and K against 40-digit mpmath, including the hard corners of the parameter."""

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from _elliptic_reference import amplitude, exact_parameter, relative_error, sncndn
from spinorbit import special

pytestmark = pytest.mark.validation

# sn, cn, dn are bounded, so their error is absolute. The reduction u = 2jK + r uses K in
# double-double, so the ε·|u| phase floor of a plain reduction (1e-10 at u = 1e6) is gone; the
# target still allows a slow growth with |u| for the rounding of r itself.
def jacobi_abs_tol(u):
    return 1e-14 * max(1.0, abs(u) / 1000.0)


# am grows like πu/(2K): a double cannot hold it closer than half an ulp (ulp(1e6) = 1.2e-10), so
# the tolerance adds two ulps of the value to the Jacobi target.
def am_abs_tol(u, value):
    return jacobi_abs_tol(u) + 2.0 * math.ulp(abs(value))


# K: full relative accuracy from the double-double AGM.
K_REL_TOL = 1e-14

# (m, mc) pairs with the exact complementary parameter as a caller would supply it.
NEAR_ONE_BELOW = [(1.0 - mc, mc) for mc in (0.5, 1e-3, 1e-8, 1e-12, 1e-15)]
NEAR_ONE_ABOVE = [(1.0 + d, -d) for d in (2.0**-50, 2.0**-40, 1e-3, 1.0, 99.0)]
SMALL_M = [(0.0, 1.0), (1e-12, 1.0 - 1e-12), (0.3, 0.7)]
PARAMETERS = SMALL_M + NEAR_ONE_BELOW + [(1.0, 0.0)] + NEAR_ONE_ABOVE
ARGUMENTS = [0.0, 1e-8, 0.3, 1.7, 10.0, -123.4, 1e3, 3e4, -1e5, 1e6]


def _check_jacobi(u, m, mc):
    sn, cn, dn = special.ellipj(u, m, mc=mc)
    ref = sncndn(u, m, mc)
    tol = jacobi_abs_tol(u)
    for name, value, exact in zip(("sn", "cn", "dn"), (sn, cn, dn), ref):
        assert abs(value - exact) <= tol, (name, u, m, mc, float(value - exact))
    a = special.am(u, m, mc=mc)
    a_ref = amplitude(u, m, mc)
    assert abs(a - a_ref) <= am_abs_tol(u, a), ("am", u, m, mc, float(a - a_ref))


@pytest.mark.parametrize("m, mc", PARAMETERS)
def test_jacobi_grid_against_mpmath(m, mc):
    for u in ARGUMENTS:
        _check_jacobi(u, m, mc)


@given(
    u=st.floats(-1e6, 1e6),
    log_mc=st.floats(-15.5, 0.0),
    above_one=st.booleans(),
)
def test_jacobi_random_against_mpmath(u, log_mc, above_one):
    d = 10.0**log_mc
    if above_one:
        m = 1.0 + d * 50.0  # m ∈ (1, 51]; 1 − m is exact for m ≥ 0.5
        mc = 1.0 - m
    else:
        mc = d
        m = 1.0 - mc
    if mc == 0.0:
        return
    _check_jacobi(u, m, mc)


def test_separatrix_has_no_overflow_past_355():
    # scipy's ellipj returns NaN at m = 1 for u > 355.6 (scipy issue 8480).
    sn, cn, dn = special.ellipj(np.array([355.0, 400.0, 1e6]), 1.0)
    assert np.all(sn == 1.0) and np.all(cn >= 0.0) and np.all(np.isfinite(dn))


def test_am_is_continuous_across_half_periods():
    # am(u + 2K) = am(u) + π: no 2π jumps near the atan2 branch cut.
    m, mc = 1.0 - 1e-10, 1e-10
    big_k = special.ellipk(m, mc=mc)
    u = np.linspace(-7.0 * big_k, 7.0 * big_k, 20001)
    steps = np.diff(special.am(u, m, mc=mc))
    assert np.all(steps > 0.0) and np.all(steps < 0.1)


@pytest.mark.parametrize("m, mc", PARAMETERS)
def test_ellipk_against_mpmath(m, mc):
    value = special.ellipk(m, mc=mc)
    mm = exact_parameter(m, mc)
    if mm == 1:
        assert value == math.inf
        return
    exact = mp.ellipk(mm) if mm < 1 else mp.ellipk(1 / mm) / mp.sqrt(mm)
    assert relative_error(value, exact) <= K_REL_TOL, (m, mc)
    if mm > 1:  # the real part of mpmath's complex K(m)
        assert relative_error(value, mp.re(mp.ellipk(mm))) <= K_REL_TOL
