"""Peer integrators on the same quaternion equations, for benchmarks and validation tests only.

Not runtime dependencies of spinorbit. Every method is a :class:`Method`: ``prepare(scene, tol)``
does the one-off work (heyoka's LLVM compilation, numba's first call) and returns a callable that
integrates the scene once and returns the states at ``scene.t_out``. The benchmark times only that
callable. Adding a method (e.g. the canonical-element equations or a splitting scheme) is adding one
entry to :data:`METHODS`.

- ``spinorbit-dop853``: :func:`spinorbit.core.integrate_quaternion` (the package's stable entry points
  are imported from :mod:`spinorbit.core`, so the benchmarks survive moves inside it).
- ``spinorbit DOP853, tabulated perturbers``: the same integrator with each Keplerian perturber
  replaced by cubic Hermite samples of its orbit, dense enough for 1e-15 relative position error
  (:func:`tabulated_model`): how an ephemeris-driven run looks, and it takes the Kepler solve (80 % of
  the cost in scene (a)) out of the loop. Tabulation time counts as preparation.
- ``spinorbit splitting <scheme>``: :func:`spinorbit.core.integrators.splitting.integrate_splitting`, a
  fixed-step symplectic splitting (exact torque-free drift + torque kicks). It has no tolerance: its
  sweep parameter is the number of steps per rotation of the scene (step = span / (rotations × n),
  ``prepare_splitting``), reported in the "tol" column of the tables.
- ``spinorbit canonical elements (DOP853)``:
  :func:`spinorbit.core.integrators.elements.integrate_elements`, the canonical-element equations
  (paper eq. 11) with the same DOP853 tableau; same state layout in and out.
- ``spinorbit Taylor (numba)``: :func:`spinorbit.core.integrators.taylor.integrate_taylor`, the adaptive
  Taylor method on the same equations (tolerance = its tol, heyoka's order and step rule).
- ``scipy DOP853, pure-Python RHS``: ``solve_ivp(method="DOP853")`` with the package's right-hand side
  transcribed to plain Python/numpy (:mod:`spinorbit.core.dynamics.python_reference`, held equal to the
  compiled one by ``tests/test_python_reference.py``), the baseline the ≥100× goal names; scene (a)
  only and two tolerances (≈1–3 s per run).
- ``scipy-DOP853``: ``scipy.integrate.solve_ivp(method="DOP853")`` with the Python RHS
  :func:`spinorbit.core.dynamics.equations.scipy_rhs` (which calls the same compiled RHS).
- ``heyoka``: heyoka's Taylor integrator on the same physics in the formulation cheapest for heyoka
  (:func:`heyoka_equations`: degree-2 torque of point masses, no |q|² normalisation, constants
  folded), in its compact mode or not, whichever is faster on the scene at that tolerance
  (:func:`fastest_heyoka_integrator`; recorded in the info as ``compact_mode``). q is not
  renormalised (heyoka has no step hook for it); the outputs are.
"""

from __future__ import annotations

import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from spinorbit.core.dynamics import python_reference
from spinorbit.core.dynamics.equations import scipy_rhs
from spinorbit.core import integrate_elements, integrate_quaternion, integrate_splitting, integrate_taylor
from spinorbit.core import make_model, sampled_source
from spinorbit.core.integrators.quaternion import default_atol
from spinorbit.core.model.perturbers import K_P, K_Q, kepler_state


@dataclass
class Method:
    name: str
    prepare: Callable  # (scene, tol) -> (run: () -> ys (n, 7), info: dict)
    tolerances: tuple
    color: str = "k"
    marker: str = "o"
    scenes: str = "abc"  # the scenes the method runs on


# --------------------------------------------------------------------------- spinorbit

def prepare_spinorbit(scene, tol, hit_output_times=False):
    atol = default_atol(np.asarray(scene.y0, float), tol)

    def run():
        return integrate_quaternion(scene.y0, scene.t0, scene.t_out, scene.model, rtol=tol, atol=atol,
                                    hit_output_times=hit_output_times)

    t = time.perf_counter()
    _, _stats = integrate_quaternion(scene.y0, scene.t0, scene.t_out[:1], scene.model, rtol=tol, atol=atol,
                                    return_stats=True)  # numba compile / cache load, excluded
    info = {"prepare_s": time.perf_counter() - t}
    return run, info


#: Relative position error allowed when a Kepler perturber is tabulated for Hermite interpolation:
#: at 1e-15 the torque changes by ~1e-15 relative, far below every accuracy in the benchmark.
TABULATION_RTOL = 1e-15


def tabulated_model(scene, rtol=TABULATION_RTOL):
    """The scene's model with every Kepler perturber replaced by cubic Hermite samples of its orbit.

    Spacing from the Hermite bound |δx| ≤ h⁴/384 · max|x⁗| with |x⁗| ≤ r ω_max⁴ (ω_max the largest
    angular rate on the orbit, at pericentre; the bound is rough, so a factor 2 of margin is kept):
    h = 0.5 (384 rtol)^(1/4) / ω_max.
    """
    t_lo = min(scene.t0, float(np.min(scene.t_out)))
    t_hi = max(scene.t0, float(np.max(scene.t_out)))
    sources = []
    for p in scene.perturbers:
        src = p.source()
        mu_o = p.mu_orbit or p.mu
        q_peri = abs(p.a) * abs(1 - p.e)
        v_peri = np.sqrt(mu_o * (2 / q_peri - 1 / p.a))
        omega_max = v_peri / q_peri
        h = 0.5 * (384 * rtol) ** 0.25 / omega_max
        n = int(np.ceil((t_hi - t_lo) / h)) + 1
        times = np.linspace(t_lo, t_hi, max(n, 2))
        states = np.array([kepler_state(t, src.params) for t in times])
        sources.append(sampled_source(p.mu, times, states[:, :3], states[:, 3:]))
    return make_model(scene.moments, sources)


def prepare_spinorbit_tabulated(scene, tol):
    import dataclasses

    t = time.perf_counter()
    model = tabulated_model(scene)
    tab = dataclasses.replace(scene)
    tab.model = model
    run, info = prepare_spinorbit(tab, tol)
    info["prepare_s"] = time.perf_counter() - t
    return run, info


# --------------------------------------------------------------------------- splitting

def prepare_splitting(scene, steps_per_rotation, scheme):
    """Fixed-step splitting with ``steps_per_rotation`` steps per rotation of the scene."""
    span = abs(float(scene.t_out[-1]) - scene.t0)
    step = span / (scene.rotations * steps_per_rotation)

    def run():
        return integrate_splitting(scene.y0, scene.t0, scene.t_out, scene.model, step, scheme)

    t = time.perf_counter()
    integrate_splitting(scene.y0, scene.t0, scene.t_out[:1], scene.model, span, scheme)  # compile / cache
    return run, {"prepare_s": time.perf_counter() - t}


def splitting_method(scheme, label, color, marker):
    return Method(f"spinorbit splitting {label}", lambda scene, n: prepare_splitting(scene, n, scheme),
                  SPLITTING_STEPS_PER_ROTATION, color, marker)


#: Sweep of the splitting methods: steps per rotation (a rotation = the scene's spin period), from
#: coarse to where rounding dominates.
SPLITTING_STEPS_PER_ROTATION = (4, 8, 16, 32, 64, 128, 256)


def _prepare_call(integrate, scene, **kwargs):
    """A run() calling ``integrate(y0, t0, t_out, model, **kwargs)``, after one short call that compiles
    or loads the numba cache (its time is the preparation)."""

    def run():
        return integrate(scene.y0, scene.t0, scene.t_out, scene.model, **kwargs)

    t = time.perf_counter()
    integrate(scene.y0, scene.t0, scene.t_out[:1], scene.model, **kwargs)  # compile / cache load
    return run, {"prepare_s": time.perf_counter() - t}


def prepare_spinorbit_elements(scene, tol):
    return _prepare_call(integrate_elements, scene, rtol=tol)


# --------------------------------------------------------------------------- Taylor

def prepare_spinorbit_taylor(scene, tol):
    return _prepare_call(integrate_taylor, scene, tol=tol)


# --------------------------------------------------------------------------- scipy

def prepare_scipy_python(scene, tol):
    """scipy DOP853 with the pure-Python transcription of the package's RHS (the ≥100× baseline)."""
    return prepare_scipy(scene, tol, fun=python_reference.make_rhs(scene.model))


def prepare_scipy(scene, tol, fun=None):
    fun = scipy_rhs(scene.model) if fun is None else fun
    atol = default_atol(np.asarray(scene.y0, float), tol)
    fun(scene.t0, scene.y0)  # compile

    def run():
        sol = solve_ivp(fun, (scene.t0, scene.t_out[-1]), scene.y0, method="DOP853", rtol=tol, atol=atol,
                        t_eval=scene.t_out)
        if not sol.success:
            raise RuntimeError(sol.message)
        y = sol.y.T.copy()
        y[:, :4] /= np.linalg.norm(y[:, :4], axis=1)[:, None]
        return y

    return run, {"prepare_s": 0.0}


# --------------------------------------------------------------------------- heyoka

def heyoka_equations(moments, perturbers, t0):
    """The scene's equations of motion as heyoka expressions: the one place they are written for heyoka.

    The physics of :func:`spinorbit.core.dynamics.equations.rhs` with degree-2 point-mass torques, in
    the formulation cheapest for heyoka's Taylor decomposition:

    - r_b = M(q)ᵀ r (no division by |q|²: heyoka does not leave the unit sphere at stages, only by
      its tolerance over the run, and the division costs it extra series in every step);
    - the torque of a point mass μ, N = (3μ/R⁵) r_b × (I r_b), as (3μ/R⁵)((C − B) y z, (A − C) z x,
      (B − A) x y) with the constant factors folded, and Euler's equations divided through by the
      moments, ω̇x = (B − C)/A ωy ωz + Nx/A (cyclic);
    - an elliptic perturber's position from ``hy.kepE`` of the time; a hyperbolic one (heyoka has no
      hyperbolic Kepler solver) from the two-body ODE of its relative position, appended to the
      system and started from the exact Kepler state at t0.

    Parameters
    ----------
    moments : (A, B, C)
        Principal moments (the scene's units).
    perturbers : sequence of ``scenes.KeplerPerturber``
    t0 : float
        Start time (the hyperbolic perturbers' initial states are taken there).

    Returns
    -------
    eqs : list of (variable, expression)
        State (q0, q1, q2, q3, ωx, ωy, ωz) first, then 6 variables per hyperbolic perturber.
    extra_state : list of float
        Initial values of the appended variables.
    """
    import heyoka as hy

    q0, q1, q2, q3, wx, wy, wz = hy.make_vars("q0", "q1", "q2", "q3", "wx", "wy", "wz")
    A, B, C = (float(m) for m in moments)
    torque_over_moment = [hy.expression(0.0)] * 3  # N/A, N/B, N/C
    extra_eqs, extra_state = [], []
    for k, p in enumerate(perturbers):
        params = p.source().params
        if p.e < 1.0:
            n = float(np.sqrt((p.mu_orbit or p.mu) / p.a**3))
            E = hy.kepE(p.e, p.mean_anomaly + n * (hy.time - p.epoch))
            px = p.a * (hy.cos(E) - p.e)
            py = p.a * float(np.sqrt(1 - p.e**2)) * hy.sin(E)
            P, Q = params[K_P:K_P + 3], params[K_Q:K_Q + 3]
            rx, ry, rz = (float(P[i]) * px + float(Q[i]) * py for i in range(3))
        else:
            x, y, z, vx, vy, vz = hy.make_vars(*(f"{s}{k}" for s in ("x", "y", "z", "vx", "vy", "vz")))
            mu_o = p.mu_orbit or p.mu
            inv_r3 = (x * x + y * y + z * z) ** -1.5
            extra_eqs += [(x, vx), (y, vy), (z, vz), (vx, -mu_o * x * inv_r3), (vy, -mu_o * y * inv_r3),
                          (vz, -mu_o * z * inv_r3)]
            extra_state += list(kepler_state(t0, params))
            rx, ry, rz = x, y, z
        # r_body = M(q)ᵀ r
        bx = (q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3) * rx + 2 * (q1 * q2 + q0 * q3) * ry + 2 * (q1 * q3 - q0 * q2) * rz
        by = 2 * (q1 * q2 - q0 * q3) * rx + (q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3) * ry + 2 * (q2 * q3 + q0 * q1) * rz
        bz = 2 * (q1 * q3 + q0 * q2) * rx + 2 * (q2 * q3 - q0 * q1) * ry + (q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3) * rz
        inv_r5 = (bx * bx + by * by + bz * bz) ** -2.5
        coefficients = (3.0 * p.mu * (C - B) / A, 3.0 * p.mu * (A - C) / B, 3.0 * p.mu * (B - A) / C)
        products = (by * bz, bz * bx, bx * by)
        torque_over_moment = [acc + c * prod * inv_r5 for acc, c, prod in zip(torque_over_moment, coefficients, products)]
    nx, ny, nz = torque_over_moment
    eqs = [
        (q0, 0.5 * (-q1 * wx - q2 * wy - q3 * wz)),
        (q1, 0.5 * (q0 * wx + q2 * wz - q3 * wy)),
        (q2, 0.5 * (q0 * wy - q1 * wz + q3 * wx)),
        (q3, 0.5 * (q0 * wz + q1 * wy - q2 * wx)),
        (wx, (B - C) / A * (wy * wz) + nx),
        (wy, (C - A) / B * (wz * wx) + ny),
        (wz, (A - B) / C * (wx * wy) + nz),
    ] + extra_eqs
    return eqs, extra_state


def heyoka_system(scene, fp_type=float):
    """heyoka (lhs, rhs) pairs and the initial state of the scene (:func:`heyoka_equations`)."""
    eqs, extra_state = heyoka_equations(scene.moments, scene.perturbers, scene.t0)
    return eqs, np.array(list(np.asarray(scene.y0, float)) + extra_state, dtype=fp_type)


#: Steps over which the two heyoka modes are timed against each other: the cost per step is what the
#: mode changes (same order, same steps), and 200 steps of the scenes take milliseconds.
MODE_TRIAL_STEPS = 200
MODE_TRIAL_REPEATS = 5
_COMPACT_MODE_CHOICE = {}


def fastest_heyoka_integrator(eqs, state, t0, t_end, tol):
    """(integrator at t0, compact_mode, {mode: median trial CPU}): heyoka in its faster mode here.

    Both modes are built and timed interleaved over MODE_TRIAL_STEPS steps from t0 towards t_end
    (the cost per step is what the mode changes); cached per (equations, state, t0, t_end, tol), and a
    copy of the faster integrator is returned, so each is compiled once.
    """
    import copy

    import heyoka as hy

    key = (str(eqs), np.asarray(state, float).tobytes(), t0, t_end, tol)
    if key not in _COMPACT_MODE_CHOICE:
        trials = {mode: hy.taylor_adaptive(eqs, state, tol=tol, compact_mode=mode, time=t0) for mode in (False, True)}
        cpu = {mode: [] for mode in trials}
        for _ in range(MODE_TRIAL_REPEATS):
            for mode, ta in trials.items():
                ta.state[:] = state
                ta.time = t0
                t = time.process_time()
                ta.propagate_until(float(t_end), max_steps=MODE_TRIAL_STEPS)
                cpu[mode].append(time.process_time() - t)
        medians = {mode: float(np.median(v)) for mode, v in cpu.items()}
        faster = min(medians, key=medians.get)
        _COMPACT_MODE_CHOICE[key] = (trials[faster], faster, medians)
    ta, faster, medians = _COMPACT_MODE_CHOICE[key]
    ta = copy.deepcopy(ta)
    ta.state[:] = state
    ta.time = t0
    return ta, faster, medians


def make_heyoka_integrator(scene, tol, fp_type=float, compact_mode=None):
    """heyoka's integrator of the scene (at its start) and its initial state; ``compact_mode=None``:
    the faster mode on this scene (:func:`fastest_heyoka_integrator`, double precision)."""
    import heyoka as hy

    eqs, state = heyoka_system(scene, fp_type)
    if compact_mode is None and fp_type is float:
        return fastest_heyoka_integrator(eqs, state, scene.t0, scene.t_out[-1], tol)[0], state
    kwargs = {"tol": fp_type(tol), "compact_mode": bool(compact_mode), "time": fp_type(scene.t0)}
    if fp_type is not float:
        kwargs["fp_type"] = fp_type
    return hy.taylor_adaptive(eqs, state, **kwargs), state


def prepare_heyoka(scene, tol):
    t = time.perf_counter()
    eqs, state = heyoka_system(scene)
    ta, compact_mode, trial_cpu = fastest_heyoka_integrator(eqs, state, scene.t0, scene.t_out[-1], tol)
    compile_s = time.perf_counter() - t
    # heyoka's grid must start at the current time: prepend t0 and drop that row.
    grid = np.concatenate([[scene.t0], np.asarray(scene.t_out, float)])

    def run():
        ta.state[:] = state
        ta.time = scene.t0
        out = ta.propagate_grid(grid)
        res = out[-1][1:, :7].copy()
        res[:, :4] /= np.linalg.norm(res[:, :4], axis=1)[:, None]
        return res

    return run, {"prepare_s": compile_s, "compact_mode": compact_mode, "mode_trial_cpu": trial_cpu}


def reference_solution(scene):
    """heyoka in extended precision (x86 80-bit long double, ε ≈ 1.1e-19) at tol = ε: the reference.

    Returns states (n, 7) as float64 and the wall-clock seconds it took.
    """
    t = time.perf_counter()
    ta, _ = make_heyoka_integrator(scene, float(np.finfo(np.longdouble).eps), fp_type=np.longdouble,
                                   compact_mode=True)
    grid = np.concatenate([[scene.t0], np.asarray(scene.t_out, float)]).astype(np.longdouble)
    out = ta.propagate_grid(grid)
    res = np.asarray(out[-1][1:, :7], dtype=np.longdouble)
    res[:, :4] /= np.sqrt((res[:, :4] ** 2).sum(axis=1))[:, None]
    return res.astype(float), time.perf_counter() - t


METHODS = [
    Method("spinorbit DOP853 (numba)", prepare_spinorbit, (1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14),
           "tab:blue", "o"),
    Method("spinorbit DOP853, tabulated perturbers", prepare_spinorbit_tabulated,
           (1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14), "tab:cyan", "D"),
    Method("spinorbit canonical elements (DOP853)", prepare_spinorbit_elements,
           (1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13), "tab:brown", "v"),
    Method("spinorbit Taylor (numba)", prepare_spinorbit_taylor, (1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15),
           "k", "d"),
    Method("heyoka Taylor", prepare_heyoka, (1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15), "tab:red", "s"),
    Method("scipy DOP853 (Python RHS)", prepare_scipy, (1e-8, 1e-10, 1e-12, 1e-13), "tab:gray", "^"),
    Method("scipy DOP853, pure-Python RHS", prepare_scipy_python, (1e-12, 1e-13), "0.5", "x", scenes="a"),
    splitting_method("strang", "Strang", "tab:olive", "<"),
    splitting_method("saba2", "SABA2", "tab:green", "P"),
    splitting_method("saba3", "SABA3", "tab:purple", "X"),
    splitting_method("saba4", "SABA4", "tab:pink", "p"),
    splitting_method("yoshida4", "Yoshida4", "tab:brown", "*"),
    splitting_method("yoshida6", "Yoshida6", "tab:orange", "h"),
]
