"""The pure-Python transcription of the dynamics equals the compiled right-hand side.

``spinorbit.core.dynamics.python_reference`` is what the benchmarks' pure-Python baselines integrate;
it must be the package's physics, feature by feature, not a look-alike.
"""

import math

import numpy as np
import pytest

from spinorbit.core.dynamics import python_reference
from spinorbit.core.dynamics.equations import make_model, rhs
from spinorbit.core.model.perturbers import fixed_source, kepler_source, kepler_state, sampled_source

#: The transcription evaluates the same formulas in the same order in IEEE double, so the only
#: differences come from libm's sin/cos/sinh/cosh (≤ 1 ulp each, in the Kepler solve) carried into
#: the torque with a condition number of order one: a few ulps of each component's largest term
#: (on x86-64 Linux with glibc the two agree bit for bit).
TRANSCRIPTION_RTOL = 1e-15
STATES = 200

RNG = np.random.default_rng(20260613)
MOMENTS = (0.61, 0.965, 1.0)


def _stokes():
    c, s = np.zeros((5, 5)), np.zeros((5, 5))
    for n in (3, 4):
        for m in range(n + 1):
            c[n, m] = 1e-2 * RNG.normal()
            s[n, m] = 0.0 if m == 0 else 1e-2 * RNG.normal()
    return c, s


def _sampled(mu, times):
    params = kepler_source(mu, 1.3, 0.2, 0.3, 0.4, 0.5, 0.6).params
    states = np.array([kepler_state(t, params) for t in times])
    return sampled_source(mu, times, states[:, :3], states[:, 3:])


def _models():
    stokes_c, stokes_s = _stokes()
    elliptic = kepler_source(3e-4, 0.92, 0.19, 0.06, 3.5, 2.2, 0.0, sign=-1.0)
    eccentric = kepler_source(1e-3, 2.0, 0.97, 1.1, 0.2, 4.0, 0.01)
    hyperbolic = kepler_source(9e-10, -8e-5, 126.0, 0.5, 0.7, 1.2, -3.0)
    fixed = fixed_source(2e-3, [0.3, -1.1, 0.7])
    sampled = _sampled(5e-4, np.linspace(0.0, 30.0, 401))
    return {
        "torque-free": (make_model(MOMENTS), (0.0, 30.0)),
        "Kepler elliptic": (make_model(MOMENTS, [elliptic]), (0.0, 400.0)),
        "Kepler e = 0.97": (make_model(MOMENTS, [eccentric]), (-50.0, 50.0)),
        "Kepler hyperbolic": (make_model(MOMENTS, [hyperbolic]), (-60.0, 60.0)),
        "fixed": (make_model(MOMENTS, [fixed]), (0.0, 1.0)),
        "sampled": (make_model(MOMENTS, [sampled]), (0.0, 30.0)),
        "degree 4 Stokes, all kinds": (make_model(MOMENTS, [elliptic, hyperbolic, fixed, sampled], mass=1.0,
                                                  reference_radius=0.3, stokes_c=stokes_c, stokes_s=stokes_s),
                                       (0.0, 30.0)),
        "degree 3 Stokes": (make_model(MOMENTS, [fixed], mass=2.0, reference_radius=0.2, stokes_c=stokes_c[:4, :4],
                                       stokes_s=stokes_s[:4, :4]), (0.0, 1.0)),
    }


MODELS = _models()


@pytest.mark.parametrize("name", list(MODELS))
def test_transcription_equals_compiled_rhs(name):
    model, (t_lo, t_hi) = MODELS[name]
    fun = python_reference.make_rhs(model)
    worst = 0.0
    for _ in range(STATES):
        q = RNG.normal(size=4) * RNG.uniform(0.8, 1.2)  # off the unit sphere, as at the RK stages
        y = np.concatenate([q, RNG.normal(size=3) * 10.0 ** RNG.uniform(-1, 1)])
        t = RNG.uniform(t_lo, t_hi)
        expected = rhs(t, y, model)
        got = fun(t, y)
        # Scale per block: the kinematics by |q||ω|, Euler's equations by their largest term.
        scale = np.empty(7)
        scale[:4] = np.linalg.norm(y[:4]) * np.linalg.norm(y[4:])
        torque_free = rhs(t, y, make_model(MOMENTS)) if name != "torque-free" else expected
        scale[4:] = np.maximum(np.abs(torque_free[4:]), np.abs(expected[4:] - torque_free[4:])) + np.abs(y[4:]) ** 2
        worst = max(worst, float(np.max(np.abs(got - expected) / scale)))
    assert worst <= TRANSCRIPTION_RTOL, f"{name}: largest relative difference {worst:.1e}"


def test_outside_the_samples_is_nan_in_both():
    model, _ = MODELS["sampled"]
    y = np.array([1.0, 0.0, 0.0, 0.0, 0.1, 0.2, 0.3])
    assert np.all(np.isnan(rhs(31.0, y, model)[4:])) and np.all(np.isnan(python_reference.rhs(31.0, y, model)[4:]))


def test_lunar_state_is_refused():
    model, _ = MODELS["torque-free"]
    with pytest.raises(ValueError, match="rigid body"):
        python_reference.rhs(0.0, np.zeros(10), model)


def test_the_solvers_match_kepler_equation():
    for e in (0.0, 0.3, 0.97, 0.999999):
        for m in (-7.0, -1e-9, 0.0, 0.4, 3.1, 20.0):
            s, c = python_reference.elliptic_anomaly_sincos(m, e)
            anomaly = math.atan2(s, c)
            residual = anomaly - e * s - (m - 2 * math.pi * math.floor((m + math.pi) / (2 * math.pi)))
            assert abs(math.remainder(residual, 2 * math.pi)) < 1e-14 and abs(s * s + c * c - 1) < 1e-15
    for e in (1.000001, 1.5, 126.0):
        for m in (-40.0, -1e-9, 1e-3, 2.0, 300.0):
            sh, ch = python_reference.hyperbolic_anomaly_sinhcosh(m, e)
            assert abs(e * sh - math.asinh(sh) - m) <= 1e-14 * max(1.0, abs(m)) and abs(ch * ch - sh * sh - 1) < 1e-12 * ch * ch
