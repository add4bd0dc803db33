"""Force function, gradient and torque: one definition, checked against independent evaluations."""

import math

import mpmath as mp
import numpy as np
import pytest
from scipy.optimize import brentq

from spinorbit.core.dynamics.equations import (
    force_function,
    make_model,
    rhs,
    total_energy,
    total_torque,
)
from spinorbit.core.model.gravity_field import (
    degree2_torque_closed_form,
    figure_force_function_and_gradient,
    figure_torque,
    make_body,
    normalize_stokes,
    pack_stokes,
    stokes_force_function_and_gradient,
    unnormalize_stokes,
)
from spinorbit.core.model.perturbers import (
    fixed_source,
    hermite_state,
    kepler_source,
    kepler_state,
    pack_perturbers,
    perturber_state,
    sampled_source,
    sampled_source_from_callable,
    solve_kepler_elliptic,
    solve_kepler_hyperbolic,
)
from spinorbit.core.math.rotations import quat_normalize

# Central differences with step h have truncation error ~h²·U''' and rounding ~ε·U/h; h = 1e-5 of
# the length scale balances them at ~1e-10 relative.
FD_STEP = 1e-5
FD_RTOL = 1e-8
#: Agreement of two double-precision evaluations of the same closed form: a few ulps of the terms.
ROUNDING_RTOL = 1e-13

RNG = np.random.default_rng(20261122)


def random_stokes(degree_max=4, scale=1e-2):
    c = np.zeros((5, 5))
    s = np.zeros((5, 5))
    for n in range(3, degree_max + 1):
        for m in range(n + 1):
            c[n, m] = scale * RNG.normal()
            s[n, m] = 0.0 if m == 0 else scale * RNG.normal()
    return c, s


def moon_like_body():
    c, s = random_stokes()
    return make_body((0.39, 0.3902, 0.3905), mass=1.3, reference_radius=0.9, stokes_c=c, stokes_s=s)


def test_gradient_matches_finite_differences_of_u():
    body = moon_like_body()
    mu = 2.5
    for _ in range(5):
        r = RNG.normal(size=3) * 3.0
        _, grad = figure_force_function_and_gradient(r, mu, body)
        fd = np.empty(3)
        for k in range(3):
            e = np.zeros(3)
            e[k] = FD_STEP * np.linalg.norm(r)
            up = figure_force_function_and_gradient(r + e, mu, body)[0]
            dn = figure_force_function_and_gradient(r - e, mu, body)[0]
            fd[k] = (up - dn) / (2 * e[k])
        np.testing.assert_allclose(grad, fd, rtol=FD_RTOL, atol=FD_RTOL * np.abs(grad).max())


def test_torque_is_derivative_of_u_under_body_rotation():
    """δU = N·δθ for an infinitesimal active body rotation δθ (r_body → r − δθ × r)."""
    body = moon_like_body()
    mu = 1.7
    r = np.array([2.1, -1.3, 0.8])
    torque = figure_torque(r, mu, body)
    h = FD_STEP
    for k in range(3):
        axis = np.zeros(3)
        axis[k] = 1.0

        def u_rotated(angle):
            # Rotating the body by +angle about axis rotates r (body frame) by −angle.
            ca, sa = math.cos(-angle), math.sin(-angle)
            rot = ca * r + sa * np.cross(axis, r) + (1 - ca) * np.dot(axis, r) * axis
            return figure_force_function_and_gradient(rot, mu, body)[0]

        derivative = (u_rotated(h) - u_rotated(-h)) / (2 * h)
        assert derivative == pytest.approx(torque[k], rel=FD_RTOL, abs=FD_RTOL * np.abs(torque).max())


def test_degree2_torque_equals_closed_form():
    body = make_body((0.61, 0.965, 1.0))
    for _ in range(10):
        r = RNG.normal(size=3) * 5
        np.testing.assert_allclose(
            figure_torque(r, 3.0, body),
            degree2_torque_closed_form(r, 3.0, 0.61, 0.965, 1.0),
            rtol=ROUNDING_RTOL,
            atol=1e-15 * np.abs(degree2_torque_closed_form(r, 3.0, 0.61, 0.965, 1.0)).max(),
        )


def _legendre_geodesy(n, m, x):
    """Unnormalised associated Legendre P_nm(x) without Condon–Shortley phase, by differentiation."""
    return (1 - x**2) ** (mp.mpf(m) / 2) * mp.diff(lambda t: mp.legendre(n, t), x, m)


def test_degree3_and_4_match_mpmath_legendre_sum():
    mp.mp.dps = 30
    c, s = random_stokes()
    mu, mass, radius = 1.3, 2.0, 0.8
    for _ in range(3):
        r = RNG.normal(size=3) * 2
        u, _ = stokes_force_function_and_gradient(r, mu, pack_stokes(c, s, mass, radius), 3, 4)
        big_r = mp.sqrt(sum(mp.mpf(float(v)) ** 2 for v in r))
        sin_phi = mp.mpf(float(r[2])) / big_r
        lam = mp.atan2(float(r[1]), float(r[0]))
        total = mp.mpf(0)
        for n in (3, 4):
            for m in range(n + 1):
                total += (radius / big_r) ** n * _legendre_geodesy(n, m, sin_phi) * (
                    c[n, m] * mp.cos(m * lam) + s[n, m] * mp.sin(m * lam)
                )
        expected = float(mu * mass / big_r * total)
        assert u == pytest.approx(expected, rel=1e-12, abs=1e-14 * abs(mu * mass / float(big_r)))


def test_expansion_matches_direct_summation_of_a_point_mass_body():
    """A cloud of point masses: its exact Stokes coefficients through degree 4 reproduce the exact
    mutual force function up to the degree-5 remainder, which shrinks as (R_ref/R)⁵."""
    masses = RNG.uniform(0.5, 1.5, 12)
    points = RNG.normal(size=(12, 3)) * 0.5
    points -= (masses[:, None] * points).sum(0) / masses.sum()  # centre of mass at the origin
    total_mass = masses.sum()
    radius = 1.0
    c = np.zeros((5, 5))
    s = np.zeros((5, 5))
    for n in range(5):
        for m in range(n + 1):
            norm = (2 - (m == 0)) * math.factorial(n - m) / math.factorial(n + m)
            for mass_i, p in zip(masses, points):
                rho = np.linalg.norm(p)
                sin_phi = p[2] / rho
                lam = math.atan2(p[1], p[0])
                pnm = float(_legendre_geodesy(n, m, mp.mpf(sin_phi)))
                c[n, m] += norm * mass_i / total_mass * (rho / radius) ** n * pnm * math.cos(m * lam)
                s[n, m] += norm * mass_i / total_mass * (rho / radius) ** n * pnm * math.sin(m * lam)
    errors = []
    for distance in (8.0, 16.0):
        r = np.array([0.6, -0.48, 0.64]) * distance
        exact = sum(mi / np.linalg.norm(r - p) for mi, p in zip(masses, points))
        u, _ = stokes_force_function_and_gradient(r, 1.0, pack_stokes(c, s, total_mass, radius), 0, 4)
        errors.append(abs(u - exact) / exact)
    assert errors[0] < 1e-5
    # Remainder of degree 5 (relative to the monopole, ∝ R⁻⁵): doubling R divides it by ~32.
    assert 16 < errors[0] / errors[1] < 64


def test_normalised_and_unnormalised_inputs_agree():
    c_bar, s_bar = random_stokes(scale=1e-3)
    c, s = unnormalize_stokes(c_bar, s_bar)
    np.testing.assert_allclose(normalize_stokes(c, s)[0], c_bar, rtol=ROUNDING_RTOL)
    # C̄_20 = C_20/√5 and C̄_22 = C_22 · √(12/5)·… : spot-check one known factor, N_22 = √(5/12).
    assert unnormalize_stokes(np.eye(3), np.zeros((3, 3)))[0][2, 2] == pytest.approx(math.sqrt(5 / 12))
    moments = (0.39, 0.3902, 0.3905)
    from_bar = make_body(moments, 1.0, 1.0, c_bar, s_bar, normalized=True)
    from_raw = make_body(moments, 1.0, 1.0, c, s)
    r = np.array([3.0, 1.0, -2.0])
    np.testing.assert_allclose(
        figure_torque(r, 1.0, from_bar), figure_torque(r, 1.0, from_raw), rtol=ROUNDING_RTOL
    )


@pytest.mark.parametrize("e", [0.0, 0.1, 0.5, 0.9, 0.99, 0.999999])
def test_kepler_elliptic_matches_brentq(e):
    for mean in np.linspace(-7.0, 7.0, 29):
        big_e = solve_kepler_elliptic(mean, e)
        assert big_e - e * math.sin(big_e) == pytest.approx(mean, abs=1e-14 * max(1.0, abs(mean)))
        # Root of the reduced equation by an independent bracketing solver.
        turns = math.floor((mean + math.pi) / (2 * math.pi))
        m = mean - turns * 2 * math.pi
        ref = brentq(lambda x: x - e * math.sin(x) - m, m - e - 1e-9, m + e + 1e-9, xtol=1e-15)
        assert big_e - turns * 2 * math.pi == pytest.approx(ref, abs=1e-12)


@pytest.mark.parametrize("e", [1.000001, 1.1, 2.0, 30.0, 265.0])
def test_kepler_hyperbolic_matches_mpmath(e):
    mp.mp.dps = 40
    for mean in (-500.0, -3.0, -1e-6, 1e-3, 2.0, 40.0, 1e4):
        h = solve_kepler_hyperbolic(mean, e)
        ref = mp.findroot(lambda x: e * mp.sinh(x) - x - mean, mp.asinh(mean / e) if e > 2 else mp.mpf(h))
        assert h == pytest.approx(float(ref), rel=1e-13, abs=1e-15)


def test_kepler_velocity_is_derivative_of_position():
    for src in (kepler_source(1.0, 2.0, 0.6, 0.3, 1.0, 2.0, 0.5), kepler_source(1.0, -0.5, 3.0, 0.2, 0.1, 0.4, -1.0)):
        p = src.params
        h = 1e-5
        fd = (kepler_state(0.3 + h, p)[:3] - kepler_state(0.3 - h, p)[:3]) / (2 * h)
        np.testing.assert_allclose(kepler_state(0.3, p)[3:], fd, rtol=1e-8)


def test_hermite_interpolation_error_on_a_circular_orbit():
    """Error ≤ h⁴/384·max|x⁗| = a (2π/n)⁴/384 on a circular orbit of radius a, n samples per orbit."""
    a, period = 1.0, 2 * math.pi
    orbit = kepler_source(1.0, a, 0.0, 0.0, 0.0, 0.0, 0.0)
    bounds = []
    for n_samples in (32, 64):
        times = np.linspace(0.0, period, n_samples + 1)
        states = np.array([kepler_state(t, orbit.params) for t in times])
        src = sampled_source(1.0, times, states[:, :3], states[:, 3:])
        block = pack_perturbers([src])
        fine = np.linspace(0.0, period, 2001)
        err = max(
            np.linalg.norm(perturber_state(t, block, 1)[:3] - kepler_state(t, orbit.params)[:3])
            for t in fine
        )
        bound = a * (period / n_samples) ** 4 / 384
        assert err <= bound
        bounds.append(err)
    assert 12 < bounds[0] / bounds[1] < 20  # fourth order: ×16 per halving of the spacing


def test_sampled_callable_reproduces_the_callable():
    orbit = kepler_source(1.0, 1.0, 0.1, 0.2, 0.3, 0.4, 0.5)
    times = np.linspace(0.0, 10.0, 401)
    src = sampled_source_from_callable(1.0, lambda t: kepler_state(t, orbit.params)[:3], times)
    t = 3.3337
    np.testing.assert_allclose(hermite_state(t, src.times, src.xv)[:3], kepler_state(t, orbit.params)[:3], atol=1e-8)


def _random_state():
    y = np.empty(7)
    y[:4] = quat_normalize(RNG.normal(size=4))
    y[4:] = RNG.normal(size=3)
    return y


def test_energy_balance_with_perturbers_at_rest():
    """d/dt (T − U) = 0 along the flow, evaluated by the chain rule with the RHS."""
    c, s = random_stokes()
    model = make_model(
        (0.7, 0.9, 1.2), [fixed_source(2.0, [3.0, -1.0, 2.0]), fixed_source(0.7, [-2.0, 2.5, 0.5])],
        mass=1.0, reference_radius=0.8, stokes_c=c, stokes_s=s,
    )
    for _ in range(5):
        y = _random_state()
        dy = rhs(0.0, y, model)
        h = 1e-6
        de_dt = (total_energy(0.0, y + h * dy, model) - total_energy(0.0, y - h * dy, model)) / (2 * h)
        scale = abs(total_energy(0.0, y, model)) + abs(force_function(0.0, y[:4], model))
        assert abs(de_dt) < 1e-8 * scale


def test_rhs_torque_enters_euler_equations():
    model = make_model((0.61, 0.965, 1.0), [fixed_source(1e3, [2.0, 1.0, 0.5])])
    y = np.array([1.0, 0, 0, 0, 0.0, 0.0, 0.0])
    n = total_torque(0.0, y[:4], model)
    np.testing.assert_allclose(rhs(0.0, y, model)[4:], n / np.array([0.61, 0.965, 1.0]), rtol=ROUNDING_RTOL)


@pytest.mark.parametrize(
    "moments, match",
    [((0.0, 1.0, 2.0), "positive"), ((2.0, 1.0, 1.5), "A ≤ B ≤ C"),
     ((np.nan, 1.0, 1.0), "finite")],
)
def test_bad_moments_raise(moments, match):
    with pytest.raises(ValueError, match=match):
        make_model(moments)


def test_bad_sources_raise():
    with pytest.raises(ValueError, match="parabolic"):
        kepler_source(1.0, 1.0, 1.0, 0, 0, 0, 0)
    with pytest.raises(ValueError, match="a < 0"):
        kepler_source(1.0, 1.0, 2.0, 0, 0, 0, 0)
    with pytest.raises(ValueError, match="increasing"):
        sampled_source(1.0, [0.0, 0.0], np.zeros((2, 3)), np.zeros((2, 3)))
    with pytest.raises(ValueError, match="mu"):
        fixed_source(-1.0, [1.0, 0.0, 0.0])
