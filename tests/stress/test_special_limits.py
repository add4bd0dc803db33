"""spinorbit.special at the limits of its domain (issue 14, class 6), against mpmath at 40+ digits.

hypothesis draws the parameter log-uniformly over m ∈ [1e-300, 1e300] (both sides of the separatrix)
and the argument log-uniformly up to the documented bound ``MAX_REDUCED_ARGUMENT`` (|u| max(1, √m)
≤ 2²⁸π, |φ| ≤ 2²⁸π); beyond it every function raises ``ArgumentRangeError``. The references
(tests/_elliptic_reference.py) get the exact double inputs and enough digits for the reduction
(40 + log10 of the argument).

Tolerances, each from the measured floor of the quantity (docs/elliptic.md):
* sn·max(1, √m), cn, dn: 1e-14 absolute (sn of m > 1 is bounded by 1/√m, so it is scaled back to O(1));
  measured ≤ 2.4e-15 up to an argument of 1e9 for m from 0.3 to 1e300. For m > 1 add ε·√m|u|: the
  functions are those of v = √m u, and the double m and the parameter 1 − mc it stands for
  (docs/elliptic.md: mc is taken as exact for m ≥ 0.5) differ by up to one ulp, which moves v by
  ½ε·v (found at m = 1e16, √m|u| = 1e3: 1.4e-14);
* am: the same plus 2 ulp of am (a double cannot hold a secular am closer);
* K, F, Π, pn: 1e-14 relative (F and Π of m > 1 only inside 99 % of the real range |φ| ≤ asin(1/√m),
  where the condition number is below 1e2).
"""

import math

import mpmath as mp
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spinorbit import special
from spinorbit.special import MAX_REDUCED_ARGUMENT, ArgumentRangeError

from tests._elliptic_reference import amplitude, ellippi, pn, sncndn

#: Draws per function in the default run; the slow variant draws 10× more.
EXAMPLES = 40
ABSOLUTE = 1e-14
EPS = np.finfo(float).eps
RELATIVE = 1e-14

log_m = st.floats(-300.0, 300.0)
log_w = st.floats(-3.0, math.log10(MAX_REDUCED_ARGUMENT))
sign = st.sampled_from([-1.0, 1.0])


def digits_for(argument):
    return 40 + max(0, int(math.log10(abs(argument) + 1.0)))


def parameter(exponent):
    m = 10.0 ** exponent
    return 1.0 if m == 1.0 else m


def argument_u(m, exponent, s):
    """u with |u| max(1, √m) = 10**exponent (just inside the domain at the top)."""
    w = min(10.0 ** exponent, MAX_REDUCED_ARGUMENT)
    return s * w / math.sqrt(max(m, 1.0))


def check_jacobi(log_parameter, log_argument, s):
    m = parameter(log_parameter)
    u = argument_u(m, log_argument, s)
    with mp.workdps(digits_for(u * math.sqrt(max(m, 1.0)))):
        reference = [float(x) for x in sncndn(u, m, 1.0 - m)]
        am_reference = float(amplitude(u, m, 1.0 - m))
    sn, cn, dn = special.ellipj(u, m)
    scale = math.sqrt(max(m, 1.0))
    tolerance = ABSOLUTE + (EPS * scale * abs(u) if m > 1 else 0.0)  # one ulp of the parameter (docstring)
    assert abs(sn - reference[0]) * scale <= tolerance, (u, m, sn, reference)
    assert abs(cn - reference[1]) <= tolerance and abs(dn - reference[2]) <= tolerance, (u, m, cn, dn, reference)
    got = special.am(u, m)
    assert abs(got - am_reference) <= tolerance + 2 * np.spacing(abs(am_reference)), (u, m, got, am_reference)


def check_integrals(log_parameter, log_argument, s, log_f):
    m = parameter(log_parameter)
    n = -(10.0 ** log_f)
    exact_m = mp.mpf(m)
    with mp.workdps(40):
        k_reference = mp.ellipk(exact_m) if m < 1 else mp.ellipk(1 / exact_m) / mp.sqrt(exact_m)
    if m != 1.0:
        assert abs(special.ellipk(m) - float(k_reference)) <= RELATIVE * float(k_reference)
    if m < 1.0:
        phi = s * min(10.0 ** log_argument, MAX_REDUCED_ARGUMENT)
    else:
        with mp.workdps(40):
            phi = s * float(0.99 * mp.asin(1 / mp.sqrt(exact_m))) * min(1.0, 10.0 ** (log_argument - 9))
    with mp.workdps(digits_for(phi)):
        f_reference = mp.ellipf(mp.mpf(phi), exact_m)
        pi_reference = ellippi(mp.mpf(n), phi, exact_m)
    for got, reference in ((special.ellipf(phi, m), f_reference), (special.ellippi(n, phi, m), pi_reference)):
        assert abs(got - float(reference)) <= RELATIVE * abs(float(reference)) + 1e-300, (phi, n, m, got, reference)
    u = argument_u(m, log_argument, s)
    with mp.workdps(digits_for(u * math.sqrt(max(m, 1.0)))):
        pn_reference = pn(u, mp.mpf(n), m, 1.0 - m)
    got = special.pn(u, n, m)
    assert abs(got - float(pn_reference)) <= RELATIVE * abs(float(pn_reference)) + 1e-300, (u, n, m, got)


@settings(max_examples=EXAMPLES)
@given(log_m, log_w, sign)
def test_jacobi_functions_over_the_whole_documented_domain(log_parameter, log_argument, s):
    check_jacobi(log_parameter, log_argument, s)


@settings(max_examples=EXAMPLES)
@given(log_m, log_w, sign, st.floats(-6.0, 6.0))
def test_integrals_over_the_whole_documented_domain(log_parameter, log_argument, s, log_f):
    check_integrals(log_parameter, log_argument, s, log_f)


@pytest.mark.slow
@settings(max_examples=10 * EXAMPLES)
@given(log_m, log_w, sign, st.floats(-6.0, 6.0))
def test_special_functions_over_the_documented_domain_thorough(log_parameter, log_argument, s, log_f):
    check_jacobi(log_parameter, log_argument, s)
    check_integrals(log_parameter, log_argument, s, log_f)


@pytest.mark.parametrize("m", [1e-300, 0.3, 1 - 1e-12, 1.0, 1 + 1e-12, 2.0, 1e100, 1e300])
@pytest.mark.parametrize("call, name", [
    (lambda x, m: special.ellipj(x, m), "u"), (lambda x, m: special.am(x, m), "u"),
    (lambda x, m: special.pn(x, -2.0, m), "u"), (lambda x, m: special.ellipf(x, m), "phi"),
    (lambda x, m: special.ellippi(-2.0, x, m), "phi"),
])
def test_beyond_the_domain_every_function_raises(m, call, name):
    scale = math.sqrt(max(m, 1.0)) if name == "u" else 1.0
    for reduced in (MAX_REDUCED_ARGUMENT * 1.0001, 1e18, 1e300, math.inf):
        with pytest.raises(ArgumentRangeError, match=f"{name}| = .*documented domain"):
            call(-reduced / scale if reduced < math.inf else -math.inf, m)
        with pytest.raises(ArgumentRangeError):
            call(np.array([0.5, reduced / scale]), m)
    inside = MAX_REDUCED_ARGUMENT * 0.999 / scale if name == "u" or m < 1 else 0.5 * math.asin(1 / math.sqrt(m))
    assert np.all(np.isfinite(call(inside, m)))


def test_pi_of_a_huge_parameter_keeps_the_cubed_sine():
    # Found by the sweep above: Π(φ, −3 | 1e220) lost its R_J term (s³ underflowed: s ≤ 1/√m) and was
    # 2.7 % low; the term is now formed as (g s²)(s/3).
    m, n = 1e220, -3.0
    phi = 0.5 * math.asin(1.0 / math.sqrt(m))
    with mp.workdps(60):
        reference = float(ellippi(mp.mpf(n), phi, mp.mpf(m)))
    assert abs(special.ellippi(n, phi, m) - reference) <= RELATIVE * reference
