"""The mean effect of sunlight's recoil on a rotation: generalised YORP over the (s, z) torus and the orbit.

YORP is a torque without a force function, so unlike gravity it moves the momenta of the canonical
elements in the mean: the size Z of the spin's angular momentum L, its projection H on the reference z axis
(with the orbit normal as z, cos ε = H/Z is the obliquity) and S, which sets the tumbling state
(d = a S²/Z²; Vokrouhlický, Breiter, Nesvorný & Bottke 2007, Icarus 191, 636, "Generalized YORP
evolution"; Breiter, Vokrouhlický & Nesvorný 2011, MNRAS 413, 2251).

The mean rates are eq. (11)'s right-hand side with the recoil torque alone
(:func:`spinorbit.core.elements.equations.elements_rhs_into` on a copy of the model whose perturbers
carry μ = 0, so only the thermal block's torque is left), averaged

- over the torus of the exact free motion: a trapezoidal n_s × n_z grid of (s, z), s over one period
  of s and z over 2π, as in :func:`spinorbit.core.averaging.mean_equations.torus_mean_rhs`. The
  momenta's rates are generalised forces, periodic on the torus, so the grid average converges
  geometrically;
- and over the Sun's Keplerian orbit: n_orbit equally spaced times over one orbital period (the
  representation of :mod:`spinorbit.core.model.thermal` has finite degree, so the integrand is smooth
  in time and the trapezoidal rule converges geometrically too).

The grid point (s, z) fixes the attitude for all orbit times and (S, Z) the free motion for all grid
points, and the rates are linear in the body torque at a fixed attitude
(:func:`spinorbit.core.elements.equations.elements_rhs_of_torque`): so the backward map runs once per
(s, z), the torque is averaged over the orbit there, and one gradient follows (the same sums as the
point-by-point average in another order; tests/test_thermal_mean.py holds them to rounding).

The slow state is (S, Z, H, h). Gravity's mean torque (degree 2, orbit-averaged closed form of
:func:`spinorbit.core.averaging.mean_equations.degree2_mean_rhs`) is added for dh/dt: it precesses L
about the orbit normal without changing (S, Z, H). The fast phases s and z are not propagated (their
thermal drifts do not enter the slow rates at first order).
"""

import math

import numpy as np

from spinorbit.core.averaging.dissipation import damping_rate_of_s
from spinorbit.core.averaging.mean_equations import degree2_mean_rhs, mean_constants, torus_frequencies
from spinorbit.core.averaging.recoil_orbit_mean import (check_exact_average, orbit_mean_facet_sum_xyz,
                                                        orbit_mean_scale, orbit_normal)
from spinorbit.core.dynamics.equations import MODEL_PERTURBERS, body_frame_xyz, force_function_and_torque_xyz
from spinorbit.core.elements.canonical import (MO_MODE, MO_PARAM_C, MODE_UNIFORM, elliptic_constants, inertia_constants,
                                               motion_from_elements, state_from_elements_motion)
from spinorbit.core.errors import SpinorbitError
from spinorbit.core.elements.equations import elements_rhs_of_torque, inertial_quaternion, working_elements
from spinorbit.core.integrators.dop853 import dop853_scratch, dop853_step, landing_step
from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import BODY_A, BODY_B, BODY_C, FIG_THERMAL
from spinorbit.core.model.perturbers import K_MEAN_MOTION, PERTURBER_ROW
from spinorbit.core.model.thermal import TH_SUN_ROW

__all__ = ["recoil_only_model", "orbital_period", "mean_thermal_rates", "exact_mean_thermal_rates",
           "propagate_mean_thermal", "THERMAL_POINTS_S", "THERMAL_POINTS_Z", "THERMAL_POINTS_ORBIT",
           "EXACT_POINTS_S", "EXACT_POINTS_Z", "AVERAGES", "SeparatrixReachedError"]

#: Closest approach to the separatrix (1 − m) a mean step may start from: there the period of s
#: grows without bound and the torus average stops being a time average (the averaged propagator's
#: own threshold, :data:`spinorbit.core.averaging.propagate.MIN_SEPARATRIX_DISTANCE`).
MIN_SEPARATRIX_DISTANCE = 1e-3


class SeparatrixReachedError(SpinorbitError, ValueError):
    """YORP drove the mean motion to the separatrix (a change of rotation mode), where the mean run stops.

    Attributes ``times`` and ``elements`` hold the outputs computed before it (possibly none), and
    ``time`` the time of the last step's start.
    """

    def __init__(self, message, times, elements, time):
        super().__init__(message)
        self.times, self.elements, self.time = times, elements, time

#: Default grid: points per period of s, per 2π of z, per orbit. tests/test_thermal_mean.py holds the
#: rates of 16 × 8 × 16 to those of 32 × 16 × 32 within 1e-3; coarser grids alias the torque's
#: harmonics (12 × 6 × 12 was off by tens of percent of a 10⁶-yr change).
THERMAL_POINTS_S, THERMAL_POINTS_Z, THERMAL_POINTS_ORBIT = 16, 8, 16
#: Default torus grid of the exact orbit average (:func:`exact_mean_thermal_rates`): points per period of
#: s and per 2π of z. The facet sum's orbit mean is a smooth function of the attitude with all the
#: facets' detail, so z needs more points than the degree-8 representation did; docs/thermal.md
#: measures the rates' convergence on this grid against finer ones and the brute-force reference.
EXACT_POINTS_S, EXACT_POINTS_Z = 16, 64
#: The averages of :func:`propagate_mean_thermal`: the facet sum with the orbit average exact, or the
#: representation on the torus × orbit grid (the only one for a shadowed fit).
AVERAGES = ("exact", "representation")

# The slow state's layout (the six elements' positions; s and z stay fixed).
EL_S, EL_Z, EL_H, EL_SMALL_S, EL_SMALL_Z, EL_SMALL_H = range(6)


def recoil_only_model(model):
    """A copy of ``model`` whose perturbers have μ = 0: its torque is the thermal block's alone."""
    if not model[FIG_THERMAL] > 0.0:
        raise ValueError("model: expected a model with a thermal block (make_model(..., thermal=...)); it has none, "
                         "so there is no recoil to average.")
    out = np.array(model, dtype=float)
    for k in range(int(out[MODEL_PERTURBERS])):
        out[MODEL_PERTURBERS + 1 + k * PERTURBER_ROW + 1] = 0.0
    return out


def orbital_period(model):
    """2π/n of the Sun's Kepler row (time unit), the span of the orbit average."""
    row = int(model[int(model[FIG_THERMAL]) + TH_SUN_ROW])
    if int(model[row]) != 0:
        raise ValueError("model: the orbit average needs the Sun on a Kepler orbit (kepler_source); got a sampled or "
                         "fixed source.")
    return 2.0 * math.pi / model[row + 2 + K_MEAN_MOTION]


@jit
def mean_thermal_rates(t, elements, recoil_model, frame, ic, n_s, n_z, n_orbit, period_orbit, out):
    """d(S, Z, H, h)/dt of the recoil alone, averaged over the torus and the orbit, into out[0:4].

    Parameters
    ----------
    t : float
        Start of the orbit average (any time: the average covers one period).
    elements : (6,) ndarray
        Signed mean elements (S, Z, H, s, z, h) in ``frame``.
    recoil_model : ndarray
        :func:`recoil_only_model`.
    frame, ic
        As for :func:`spinorbit.core.elements.equations.elements_rhs_into`.
    n_s, n_z, n_orbit : int
        Grid points in s (one period), z (2π) and time (one orbit).
    period_orbit : float
        The orbital period (:func:`orbital_period`).
    """
    period, _, _ = torus_frequencies(elements[0], elements[1], ic)
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    point = elements.copy()
    buf = np.empty(6)
    # (S, Z) are the same at every grid point: the free motion's constants once per call. At each (s, z)
    # the attitude is the same at every orbit time, and the rates are linear in the body torque
    # (elements_rhs_of_torque), so the torque is averaged over the orbit before the one gradient.
    work, _ = working_elements(point)
    mo = motion_from_elements(work[EL_S], work[EL_Z], ic)
    mk, pk = elliptic_constants(mo)
    acc_s = acc_z = acc_big_h = acc_h = 0.0
    for j in range(n_s):
        point[EL_SMALL_S] = sign * period * j / n_s if math.isfinite(period) else 0.0
        for k in range(n_z):
            point[EL_SMALL_Z] = 2.0 * math.pi * k / n_z
            work, flip = working_elements(point)
            attitude, momentum = state_from_elements_motion(work, flip, mo, mk, pk)
            q = inertial_quaternion(attitude, frame)
            tx = ty = tz = 0.0
            for i in range(n_orbit):
                _, nx, ny, nz = force_function_and_torque_xyz(t + period_orbit * i / n_orbit, q[0], q[1], q[2], q[3],
                                                              recoil_model)
                tx += nx
                ty += ny
                tz += nz
            elements_rhs_of_torque(point, ic, mo, mk, attitude, momentum, tx / n_orbit, ty / n_orbit, tz / n_orbit, buf)
            acc_s += buf[EL_S]
            acc_z += buf[EL_Z]
            acc_big_h += buf[EL_H]
            acc_h += buf[EL_SMALL_H]
    count = n_s * n_z
    out[0] = acc_s / count
    out[1] = acc_z / count
    out[2] = acc_big_h / count
    out[3] = acc_h / count


@jit
def exact_mean_thermal_rates(elements, model, frame, ic, n_s, n_z, out):
    """d(S, Z, H, h)/dt of the recoil alone: the facet sum averaged exactly over the orbit, then over the torus.

    At each (s, z) of a trapezoidal n_s × n_z grid the attitude is frozen and the recoil averaged over the
    Sun's Kepler orbit in closed form (:mod:`spinorbit.core.averaging.recoil_orbit_mean`: one pass over
    the facets with the orbit normal in the body frame); the rates are linear in the torque at a fixed
    attitude, so that mean goes through eq. (11) once (:func:`elements_rhs_of_torque`). Unlike
    :func:`mean_thermal_rates` there is no representation and no orbit grid.

    Parameters
    ----------
    elements : (6,) ndarray
        Signed mean elements (S, Z, H, s, z, h) in ``frame``.
    model : ndarray
        A model with an unshadowed thermal block carrying its facets, the Sun on a Kepler orbit
        (:func:`spinorbit.core.averaging.recoil_orbit_mean.check_exact_average`).
    frame, ic
        As for :func:`spinorbit.core.elements.equations.elements_rhs_into`.
    n_s, n_z : int
        Grid points in s (one period) and z (2π).
    """
    base = int(model[FIG_THERMAL])
    w, semi_major_axis, root = orbit_normal(model, int(model[base + TH_SUN_ROW]))
    scale = orbit_mean_scale(model, base, semi_major_axis, root)
    period, _, _ = torus_frequencies(elements[0], elements[1], ic)
    sign = 1.0 if elements[0] >= 0.0 else -1.0
    point = elements.copy()
    buf = np.empty(6)
    work, _ = working_elements(point)
    mo = motion_from_elements(work[EL_S], work[EL_Z], ic)
    mk, pk = elliptic_constants(mo)
    acc_s = acc_z = acc_big_h = acc_h = 0.0
    for j in range(n_s):
        point[EL_SMALL_S] = sign * period * j / n_s if math.isfinite(period) else 0.0
        for k in range(n_z):
            point[EL_SMALL_Z] = 2.0 * math.pi * k / n_z
            work, flip = working_elements(point)
            attitude, momentum = state_from_elements_motion(work, flip, mo, mk, pk)
            q = inertial_quaternion(attitude, frame)
            wx, wy, wz = body_frame_xyz(q[0], q[1], q[2], q[3], w[0], w[1], w[2])
            tx, ty, tz = orbit_mean_facet_sum_xyz(wx, wy, wz, model, base)
            elements_rhs_of_torque(point, ic, mo, mk, attitude, momentum, scale * tx, scale * ty, scale * tz, buf)
            acc_s += buf[EL_S]
            acc_z += buf[EL_Z]
            acc_big_h += buf[EL_H]
            acc_h += buf[EL_SMALL_H]
    count = n_s * n_z
    out[0] = acc_s / count
    out[1] = acc_z / count
    out[2] = acc_big_h / count
    out[3] = acc_h / count


@jit
def _slow_rhs(t, y, params, dy):
    """d(S, Z, H, s, z, h)/dt of the slow system; s and z held (their rates zero)."""
    model, recoil_model, frame, n_s, n_z, n_orbit, period_orbit, with_gravity, damping_constant, exact, scratch = params
    ic = inertia_constants(model[BODY_A], model[BODY_B], model[BODY_C])
    if recoil_model[FIG_THERMAL] > 0.0 and exact:
        exact_mean_thermal_rates(y, recoil_model, frame, ic, n_s, n_z, scratch)
    elif recoil_model[FIG_THERMAL] > 0.0:
        mean_thermal_rates(t, y, recoil_model, frame, ic, n_s, n_z, n_orbit, period_orbit, scratch)
    else:
        for i in range(4):
            scratch[i] = 0.0
    scratch[0] += damping_rate_of_s(y[EL_S], y[EL_Z], ic, damping_constant)
    gravity_h = 0.0
    if with_gravity:
        moments = np.array([model[BODY_A], model[BODY_B], model[BODY_C]])
        mc = mean_constants(y[EL_S], y[EL_Z], ic, moments)
        grav = np.empty(6)
        degree2_mean_rhs(t, y, mc, model, frame, True, grav)
        gravity_h = grav[EL_SMALL_H]
    dy[EL_S] = scratch[0]
    dy[EL_Z] = scratch[1]
    dy[EL_H] = scratch[2]
    dy[EL_SMALL_S] = 0.0
    dy[EL_SMALL_Z] = 0.0
    dy[EL_SMALL_H] = scratch[3] + gravity_h


@jit
def _slow_kernel(el0, t0, t_out, step, model, recoil_model, frame, n_s, n_z, n_orbit, period_orbit, with_gravity,
                 damping_constant, exact, out):
    y = el0.copy()
    t = t0
    k, tmp, y_new = dop853_scratch(6)
    scratch = np.empty(4)
    params = (model, recoil_model, frame, n_s, n_z, n_orbit, period_orbit, with_gravity, damping_constant, exact,
              scratch)
    steps = 0
    ic = inertia_constants(model[BODY_A], model[BODY_B], model[BODY_C])
    for i in range(t_out.shape[0]):
        target = t_out[i]
        direction = 1.0 if target > t else -1.0
        while t != target:
            if recoil_model[FIG_THERMAL] > 0.0:  # the torus average needs a torus; damping alone does not
                mo = motion_from_elements(abs(y[EL_S]), y[EL_Z], ic)
                if mo[MO_MODE] == MODE_UNIFORM or not mo[MO_PARAM_C] >= MIN_SEPARATRIX_DISTANCE:
                    return i, t, steps
            remaining = abs(target - t)
            h = landing_step(step, remaining)
            dop853_step(_slow_rhs, params, t, y, direction * h, k, tmp, y_new)
            if recoil_model[FIG_THERMAL] > 0.0:
                # A step may jump across the separatrix band (SAM ↔ LAM) without starting inside it:
                # its rates came from one side's torus, so it is not taken.
                before = motion_from_elements(abs(y[EL_S]), y[EL_Z], ic)[MO_MODE]
                after = motion_from_elements(abs(y_new[EL_S]), y_new[EL_Z], ic)[MO_MODE]
                if after != before:
                    return i, t, steps
            t = target if h == remaining else t + direction * h
            for c in range(6):
                y[c] = y_new[c]
            steps += 1
        for c in range(6):
            out[i, c] = y[c]
    return t_out.shape[0], t, steps


def propagate_mean_thermal(el0, t0, t_out, model, frame, step, n_s=None, n_z=None, n_orbit=THERMAL_POINTS_ORBIT,
                           with_gravity=True, damping_constant=0.0, average="exact"):
    """Mean (S, Z, H, h) under sunlight's recoil, nutation damping and gravity's mean precession.

    Parameters
    ----------
    el0 : array_like (6,)
        Initial mean elements (S, Z, H, s, z, h) in ``frame`` (s and z are carried unchanged).
    t0 : float
    t_out : array_like (n,)
        Output times, monotone away from t0.
    model : ndarray
        :func:`spinorbit.core.dynamics.equations.make_model` with a thermal block, the Sun on an
        elliptic Kepler orbit.
    frame : (3, 3) ndarray
        Inertial → reference rotation (the orbit frame makes H/Z the cosine of the obliquity).
    step : float
        Fixed DOP853 step (time unit): the slow rates change on the YORP time scale, so a step of a
        few percent of it is enough.
    n_s, n_z : int, optional
        Torus grid: :data:`EXACT_POINTS_S` × :data:`EXACT_POINTS_Z` for the exact average,
        :data:`THERMAL_POINTS_S` × :data:`THERMAL_POINTS_Z` for the representation's.
    n_orbit : int
        Orbit points of the representation's average (the exact average has none).
    with_gravity : bool
        Add the gravitational mean precession dh/dt (degree 2, orbit-averaged).
    damping_constant : float
        k = μQ/(ρ K₃² R²) (time⁻²) of the nutation damping, τ_D = k/ω³
        (:mod:`spinorbit.core.averaging.dissipation`); 0: no damping. With damping the model need
        not have a thermal block.
    average : {"exact", "representation"}
        "exact": the facet sum with the orbit average in closed form (:func:`exact_mean_thermal_rates`),
        its error a few 1e-4 of the rates (docs/thermal.md); "representation": the block's harmonics on
        the torus × orbit grid (:func:`mean_thermal_rates`), the only average of a shadowed fit, whose
        truncation moves the mean torque by up to tens of per cent at degree 8.

    Returns
    -------
    elements : ndarray (n, 6)
    steps : int

    Raises
    ------
    SeparatrixReachedError
        The motion reached the separatrix (1 − m below MIN_SEPARATRIX_DISTANCE) before the last output,
        or a step would jump across it (its end in the other rotation mode).
    ValueError
        A model without a thermal block or without the Sun on a Kepler orbit, bad elements or step, an
        unknown average, or average="exact" on a block without facets or with shadows.
    """
    el0 = np.array(el0, dtype=float)
    t_out = np.atleast_1d(np.asarray(t_out, dtype=float))
    if el0.shape != (6,) or not np.all(np.isfinite(el0)):
        raise ValueError(f"el0: expected six finite mean elements (S, Z, H, s, z, h); got {el0!r}.")
    if not (math.isfinite(step) and step > 0.0):
        raise ValueError(f"step: expected a finite positive step (time unit); got {step!r}.")
    if average not in AVERAGES:
        raise ValueError(f"average: expected one of {AVERAGES}; got {average!r}.")
    exact = average == "exact"
    n_s = (EXACT_POINTS_S if exact else THERMAL_POINTS_S) if n_s is None else n_s
    n_z = (EXACT_POINTS_Z if exact else THERMAL_POINTS_Z) if n_z is None else n_z
    if not (min(n_s, n_z, n_orbit) >= 1):
        raise ValueError(f"n_s, n_z, n_orbit: expected positive grid sizes; got {n_s}, {n_z}, {n_orbit}.")
    if not (math.isfinite(damping_constant) and damping_constant >= 0.0):
        raise ValueError(f"damping_constant: expected k = μQ/(ρ K₃² R²) ≥ 0 (time⁻²); got {damping_constant!r}.")
    model = np.ascontiguousarray(model, dtype=float)
    if model[FIG_THERMAL] > 0.0 or damping_constant == 0.0:
        recoil = recoil_only_model(model)  # refuses a model with neither recoil nor damping
        period_orbit = orbital_period(model)
        if exact:
            check_exact_average(model, int(model[FIG_THERMAL]))
    else:
        recoil, period_orbit = model, 1.0  # damping alone: no orbit average needed
    out = np.empty((t_out.size, 6))
    written, t_stop, steps = _slow_kernel(el0, float(t0), t_out, float(step), model, recoil, np.ascontiguousarray(frame, dtype=float),
                         int(n_s), int(n_z), int(n_orbit), float(period_orbit), bool(with_gravity),
                         float(damping_constant), exact, out)
    if written < t_out.size:
        raise SeparatrixReachedError(
            f"propagate_mean_thermal: at t = {t_stop!r} the mean motion is within 1 − m < {MIN_SEPARATRIX_DISTANCE:g} "
            "of the separatrix (or a permanent rotation), or the next step would cross it, where the torus "
            "average is undefined; the "
            f"{written} outputs before it are in the error's .times and .elements. Continue across it with a "
            "full integrator (integrate_quaternion) and restart the mean run on the other side.",
            t_out[:written].copy(), out[:written].copy(), float(t_stop))
    return out, steps
