"""The Jacobian ∂(L, G, H, l, g, h)/∂(S, Z, H, s, z, h) (paper section 4) against an independent reference.

Reference: the paper's backward map, eqs. (7)–(8), written out here again in mpmath at 50 digits
(``reference_andoyer``) — sn, cn, dn from ``mpmath.ellipfun``, am by period reduction, pn(u, −f|m) as
Π(am u, −f|m) with ``mpmath.ellippi`` (checked against the quadrature of its definition
∫₀ᵘ du′/(1 + f sn²) in ``test_reference_pn_is_the_quadrature``), and for m > 1 the reciprocal-modulus
transformation — then differentiated by central differences in 50-digit arithmetic. None of the
package's elliptic kernels is used by the reference.

Independent of any reference: the symplectic condition Jᵀ Ω J = Ω, and the 23 identically zero
components.

Error metric. Each component is compared relative to the larger of its own magnitude and its natural
unit Y_i / X_j, with Y = (Z, Z, Z, 1, 1, 1) for (L, G, H, l, g, h) and X = (Z, Z, Z, 1/κ, 1, 1) for
(S, Z, H, s, z, h), κ = the elliptic argument per unit s (u/s in SAM, v/s in LAM). A component that
passes through zero (∂L/∂s at sn cn = 0, say) is then held to an absolute error at its natural unit,
which is what its rounding error is proportional to.
"""

import math

import mpmath as mp
import numpy as np
import pytest
from _mp_reference import secular_am, secular_pi

from spinorbit.core.elements.andoyer import andoyer_from_attitude
from spinorbit.core.elements.canonical import (
    FLIP_B,
    MO_ARG_PER_S,
    elliptic_constants,
    inertia_constants,
    motion_from_elements,
    state_from_elements,
)
from spinorbit.core.math.elliptic import parameter_constants
from spinorbit.core.elements.jacobian import (
    ZERO_COMPONENTS,
    andoyer_jacobian,
    andoyer_jacobian_many,
    associate_integrals,
    canonical_gradient,
    jacobi_parameter_derivatives,
    pn_parameter_derivative,
)

DIGITS = 50
# Central-difference step (relative to the input's natural unit): truncation ~ STEP² · J''' and
# rounding ~ 10^-DIGITS / STEP, both far below 1e-20 of the derivative even where J''' ~ 1e18
# (third derivatives near the separatrix grow like 1/m_c³).
STEP = mp.mpf("1e-18")

# Away from the separatrix: a few hundred ulp. The components are sums of O(1) terms evaluated with
# ~1e-15 relative error each, and the secular terms (∝ u) carry the argument's own rounding ε·u.
TOLERANCE = 2e-13
# Input conditioning. The package receives S as a double and forms d = a S²/Z², d − c and b − d from
# it; where those differences are small (near the separatrix, spin near C for B ≈ C, nearly symmetric
# bodies) one ulp of S moves the exact Jacobian by far more than 1e-13 (up to 7e-4 relative at
# m_c = 1e-6, f = 1e-6). No evaluation can beat that, so the allowance is this many times the
# measured change of the *reference* Jacobian under a one-ulp change of S (d is formed with ~2
# roundings, each difference with one more).
CONDITIONING_ULPS = 8
# Jᵀ Ω J − Ω, relative to the largest |J|² product (rounding of 6-term sums of products).
SYMPLECTIC_TOLERANCE = 1e-14

OMEGA = np.block([[np.zeros((3, 3)), np.eye(3)], [-np.eye(3), np.zeros((3, 3))]])


# --------------------------------------------------------------------------------------------------
# Independent mpmath reference: the paper's eqs. (7)–(8)
# --------------------------------------------------------------------------------------------------


def body(f):
    """Moments (A, B, C) with a = 2, c = 1 and the given f = (a − b)/(b − c), as floats."""
    b = 1.0 + 1.0 / (1.0 + f)
    return 0.5, 1.0 / b, 1.0


def abc(moments):
    """Exact a, b, c of the float moments (the package forms its differences from the same floats)."""
    return tuple(1 / mp.mpf(x) for x in moments)


def reference_working(big_s, big_z, s, moments):
    """(L, l, g − z) of eq. (7) for S > 0, in mpmath."""
    a, b, c = abc(moments)
    d = a * big_s**2 / big_z**2
    m = (a - b) * (d - c) / ((a - d) * (b - c))
    f = (a - b) / (b - c)
    u = mp.sqrt((a - d) * (b - c) / (a * d)) * s
    if m < 1:
        sn, cn, dn = (mp.ellipfun(k, u, m) for k in ("sn", "cn", "dn"))
        am = secular_am(u, m)
        pn = secular_pi(am, -f, m)
    else:
        # reciprocal modulus (DLMF 22.17): v = √m u, μ = 1/m
        mu = 1 / m
        v = mp.sqrt(m) * u
        sn_v, cn_v, dn_v = (mp.ellipfun(k, v, mu) for k in ("sn", "cn", "dn"))
        sn, cn, dn = sn_v / mp.sqrt(m), dn_v, cn_v
        am = mp.atan2(sn, cn)  # bounded for m > 1 (cn(u|m) = dn(v|μ) > 0)
        pn = secular_pi(secular_am(v, mu), -f / m, mu) / mp.sqrt(m)
    big_l = mp.sqrt((a - d) / (a - c)) * big_z * dn
    l = mp.pi / 2 - am - mp.atan(f * sn * cn / (mp.sqrt(1 + f) + 1 + f * sn**2))
    g_minus_z = (c * u + (a - c) * pn) / mp.sqrt((a - d) * (b - c))
    return big_l, l, g_minus_z


def reference_andoyer(elements, moments, cache):
    """(L, G, H, l, g, h) of the elements (eqs. 7–8); S < 0 through the B-flip (module docstring of
    spinorbit.core.elements.jacobian). ``cache`` memoizes the elliptic part on (S, Z, s)."""
    big_s, big_z, big_h, s, z, h = elements
    sense = -1 if big_s < 0 else 1
    key = (big_s, big_z, s)
    if key not in cache:
        cache[key] = reference_working(sense * big_s, big_z, sense * s, moments)
    big_l, l, g_minus_z = cache[key]
    if sense < 0:
        return [-big_l, big_z, big_h, -l, g_minus_z + z + mp.pi, h]
    return [big_l, big_z, big_h, l, g_minus_z + z, h]


def reference_jacobian(elements, moments, scales):
    """Central differences of reference_andoyer in DIGITS-digit arithmetic, step STEP · scale."""
    with mp.workdps(DIGITS):
        base = [mp.mpf(x) for x in elements]
        cache = {}
        jac = np.zeros((6, 6))
        for j in range(6):
            step = STEP * mp.mpf(scales[j])
            plus, minus = list(base), list(base)
            plus[j] += step
            minus[j] -= step
            hi = reference_andoyer(plus, moments, cache)
            lo = reference_andoyer(minus, moments, cache)
            for i in range(6):
                jac[i, j] = float((hi[i] - lo[i]) / (2 * step))
    return jac


# --------------------------------------------------------------------------------------------------
# Test points
# --------------------------------------------------------------------------------------------------


def elements_for(m, f, periods, sense=1.0, z=0.4, h=-1.1):
    """Elements with parameter ≈ m for the body of ``f``, at ``periods`` half-periods of the argument."""
    moments = body(f)
    ic = inertia_constants(*moments)
    a, c = ic[0], ic[2]
    # m = f (d − c)/(a − d) ⇒ d = (m a + f c)/(m + f), written from the differences
    d = c + m * (a - c) / (m + f)
    big_z = 1.3
    big_s = big_z * math.sqrt(d / a)
    mo = motion_from_elements(big_s, big_z, ic)
    kappa = mo[MO_ARG_PER_S]
    mk, _ = elliptic_constants(mo)
    half_period = mk[8] + mk[9]  # 2K of the argument actually used (u in SAM, v in LAM)
    s = periods * half_period / kappa
    elements = np.array([sense * big_s, big_z, 0.7, sense * s, z, h])
    return elements, moments, kappa


SAM_PARAMETERS = (1e-8, 0.3, 0.9, 1.0 - 1e-6)
LAM_PARAMETERS = (1.0 + 1e-6, 1.5, 10.0, 1e6)
F_VALUES = (1e-6, 1.0, 1e6)
# Half periods of the argument: small, generic, beyond several periods.
PHASES = (0.013, 0.61, 7.37)


def natural_units(elements, kappa):
    big_z = abs(elements[1])
    y = np.array([big_z, big_z, big_z, 1.0, 1.0, 1.0])
    x = np.array([big_z, big_z, big_z, 1.0 / kappa, 1.0, 1.0])
    return y, x


def component_errors(jac, ref, elements, kappa):
    y, x = natural_units(elements, kappa)
    unit = y[:, None] / x[None, :]
    return np.abs(jac - ref) / np.maximum(np.abs(ref), unit)


def one_ulp_sensitivity(elements, moments, kappa, ref):
    """Largest change of the exact Jacobian (error metric above) when S moves by one ulp."""
    moved = elements.copy()
    moved[0] = np.nextafter(elements[0], 2 * elements[0])
    ref_moved = reference_jacobian(moved, moments, natural_units(elements, kappa)[1])
    return component_errors(ref_moved, ref, elements, kappa).max()


# Every parameter with every f at a generic phase and beyond several periods; the small phase and
# the sense −C/−A (a sign algebra on top, J = D J_w D) on the f = 1 body.
CASES = [
    (m, f, phase, sense)
    for m in SAM_PARAMETERS + LAM_PARAMETERS
    for f in F_VALUES
    for phase in PHASES
    for sense in (1.0, -1.0)
    if (phase != PHASES[0] and sense > 0) or f == 1.0
]


@pytest.mark.validation
@pytest.mark.parametrize("m, f, phase, sense", CASES)
def test_every_component_against_mpmath(m, f, phase, sense):
    elements, moments, kappa = elements_for(m, f, phase, sense)
    ic = inertia_constants(*moments)
    jac = andoyer_jacobian(elements, ic)
    ref = reference_jacobian(elements, moments, natural_units(elements, kappa)[1])
    errors = component_errors(jac, ref, elements, kappa)
    tolerance = TOLERANCE + CONDITIONING_ULPS * one_ulp_sensitivity(elements, moments, kappa, ref)
    assert errors.max() < tolerance, (errors.max(), np.unravel_index(errors.argmax(), errors.shape))


def turning_point_elements(f, offset):
    """LAM elements at the first turning point v = K(μ) (M_z = 0), shifted by ``offset`` in v."""
    elements, moments, kappa = elements_for(1.5, f, 0.5)
    elements[3] += offset / kappa
    return elements, moments, kappa


@pytest.mark.validation
@pytest.mark.parametrize("f", F_VALUES)
@pytest.mark.parametrize("offset", (0.0, 1e-9, -1e-5, 1e-3))
def test_lam_turning_points(f, offset):
    """Where pn(u, m|m) of the (u, m) form is singular, the (v, μ) form is not."""
    elements, moments, kappa = turning_point_elements(f, offset)
    ic = inertia_constants(*moments)
    jac = andoyer_jacobian(elements, ic)
    assert np.all(np.isfinite(jac))
    ref = reference_jacobian(elements, moments, natural_units(elements, kappa)[1])
    tolerance = TOLERANCE + CONDITIONING_ULPS * one_ulp_sensitivity(elements, moments, kappa, ref)
    assert component_errors(jac, ref, elements, kappa).max() < tolerance


# --------------------------------------------------------------------------------------------------
# Checks that need no reference
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("m, f, phase, sense", CASES)
def test_symplectic(m, f, phase, sense):
    """Jᵀ Ω J = Ω: the Jacobian of a canonical transformation is symplectic (ordering (S,Z,H; s,z,h))."""
    elements, moments, _ = elements_for(m, f, phase, sense)
    jac = andoyer_jacobian(elements, inertia_constants(*moments))
    residual = jac.T @ OMEGA @ jac - OMEGA
    scale = np.abs(jac).max(axis=0)
    assert np.abs(residual / np.outer(scale, scale)).max() < SYMPLECTIC_TOLERANCE


@pytest.mark.parametrize("m, f, phase, sense", CASES[::5])
def test_zero_components(m, f, phase, sense):
    elements, moments, _ = elements_for(m, f, phase, sense)
    jac = andoyer_jacobian(elements, inertia_constants(*moments))
    assert len(ZERO_COMPONENTS) == 23
    for row, col in ZERO_COMPONENTS:
        assert jac[row, col] == 0.0
    nonzero = {(i, j) for i in range(6) for j in range(6)} - set(ZERO_COMPONENTS)
    assert len(nonzero) == 13
    assert jac[1, 1] == jac[2, 2] == jac[4, 4] == jac[5, 5] == 1.0


def test_separatrix_and_uniform_are_nan():
    # A sphere (A = B = C) has no finite elements: every S, Z gives a permanent rotation.
    jac = andoyer_jacobian(np.array([1.0, 1.0, 0.5, 0.3, 0.0, 0.0]), inertia_constants(1.0, 1.0, 1.0))
    assert np.all(np.isnan(jac[[0, 3, 4]][:, [0, 1, 3]]))


def test_sign_of_s_is_the_b_flip_of_the_state():
    """S < 0 is the working frame turned by π about B: (L, l, g) → (−L, −l, g + π), checked on the
    attitude built by the project's own state machinery (state_from_elements with FLIP_B)."""
    for m in (0.3, 10.0):
        elements, moments, _ = elements_for(m, 1.0, 0.61)
        ic = inertia_constants(*moments)
        working_att, working_mom = state_from_elements(elements, 0, ic)
        flipped_att, flipped_mom = state_from_elements(elements, FLIP_B, ic)
        big_l, big_g, big_h, l, g, h = andoyer_from_attitude(working_att, working_mom)
        flipped = andoyer_from_attitude(flipped_att, flipped_mom)
        expected = (-big_l, big_g, big_h, -l, g + math.pi, h)
        for got, want in zip(flipped[:3], expected[:3]):
            assert abs(got - want) < 1e-13
        for got, want in zip(flipped[3:], expected[3:]):
            assert abs(math.remainder(got - want, 2 * math.pi)) < 1e-13


def test_reference_l_is_the_working_l():
    """The paper's l of eq. (7) equals the package's atan2 form of l (mod 2π): same backward map."""
    for m in (0.3, 10.0):
        elements, moments, _ = elements_for(m, 1.0, 0.61)
        ic = inertia_constants(*moments)
        att, mom = state_from_elements(elements, 0, ic)
        _, _, _, l, g, _ = andoyer_from_attitude(att, mom)
        with mp.workdps(DIGITS):
            ref = reference_andoyer([mp.mpf(x) for x in elements], moments, {})
        assert abs(math.remainder(l - float(ref[3]), 2 * math.pi)) < 1e-13
        assert abs(math.remainder(g - float(ref[4]), 2 * math.pi)) < 1e-12


@pytest.mark.validation
@pytest.mark.parametrize("m, f", [(0.3, 1.0), (0.9, 1e-6), (10.0, 1e6)])
def test_reference_pn_is_the_quadrature(m, f):
    """The reference's pn (Π of the amplitude, reciprocal modulus for m > 1) is ∫₀ᵘ du′/(1 + f sn²)."""
    with mp.workdps(30):
        m, f = mp.mpf(m), mp.mpf(f)
        u = mp.mpf("3.3")
        if m < 1:
            via_pi = secular_pi(secular_am(u, m), -f, m)
            sn = lambda t: mp.ellipfun("sn", t, m)  # noqa: E731
            period = 2 * mp.ellipk(m)
        else:
            mu = 1 / m
            v = mp.sqrt(m) * u
            via_pi = secular_pi(secular_am(v, mu), -f / m, mu) / mp.sqrt(m)
            sn = lambda t: mp.ellipfun("sn", mp.sqrt(m) * t, mu) / mp.sqrt(m)  # noqa: E731
            period = 2 * mp.ellipk(mu) / mp.sqrt(m)
        knots = [mp.mpf(0)] + [k * period / 2 for k in range(1, int(u / (period / 2)) + 1)] + [u]
        quad = mp.quad(lambda t: 1 / (1 + f * sn(t) ** 2), knots)
        assert abs(quad - via_pi) < mp.mpf("1e-25") * abs(quad)


# --------------------------------------------------------------------------------------------------
# Building blocks
# --------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("q", (1e-8, 0.5, 1.0 - 1e-9))
@pytest.mark.parametrize("x", (0.02, 1.3, 17.9))
def test_parameter_derivative_blocks(q, x):
    """∂(sn, cn, dn, am, pn)/∂q at fixed argument and the associate integrals vs mpmath."""
    f = 3.0
    mk = parameter_constants(q, 1.0 - q)
    sn, cn, dn, jm, jn, _ = associate_integrals(x, mk, f)
    derivs = jacobi_parameter_derivatives(sn, cn, dn, jm, q)
    dpn = pn_parameter_derivative(sn, dn, jm, jn, f, f / (q + f))
    with mp.workdps(DIGITS):
        xq, qq, fq = mp.mpf(x), mp.mpf(q), mp.mpf(f)
        step = mp.mpf("1e-20")
        funcs = (
            lambda p: mp.ellipfun("sn", xq, p),
            lambda p: mp.ellipfun("cn", xq, p),
            lambda p: mp.ellipfun("dn", xq, p),
            lambda p: secular_am(xq, p),
            lambda p: secular_pi(secular_am(xq, p), -fq, p),
        )
        expected = [float((fn(qq + step) - fn(qq - step)) / (2 * step)) for fn in funcs]
        jm_ref = (secular_pi(secular_am(xq, qq), qq, qq) - xq) / qq
    got = list(derivs) + [dpn]
    # scale: the derivatives grow like x/(1 − q) near q = 1 (period lengthening)
    scale = max(1.0, x / (1.0 - q) ** 0.5)
    for value, want in zip(got, expected):
        assert abs(value - want) <= 1e-13 * max(abs(want), scale)
    assert abs(jm - float(jm_ref)) <= 1e-14 * max(abs(float(jm_ref)), 1.0)


def test_canonical_gradient_is_the_chain_rule():
    elements, moments, _ = elements_for(0.3, 1.0, 0.61)
    jac = andoyer_jacobian(elements, inertia_constants(*moments))
    du = np.array([0.3, -1.2, 0.5, 2.0, -0.7, 0.1])
    assert np.allclose(canonical_gradient(du, jac), jac.T @ du, rtol=1e-15, atol=0.0)


def test_many_matches_single():
    elements = np.stack([elements_for(m, 1.0, 0.61)[0] for m in (0.3, 10.0)])
    moments = body(1.0)
    many = andoyer_jacobian_many(elements, *moments)
    for k in range(2):
        assert np.array_equal(many[k], andoyer_jacobian(elements[k], inertia_constants(*moments)))
