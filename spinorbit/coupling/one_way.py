"""One-way spin–orbit coupling: orbits drive the rotation, the rotation does not act back.

The rotating body's translational motion and its perturbers' positions come from outside (DE421 for
the planets, a user ephemeris or a REBOUND run for the body). They are sampled once, onto an
adaptive time grid, into cubic-Hermite :func:`spinorbit.core.model.perturbers.sampled_source` s; the
rotation is then integrated entirely in numba by
:func:`spinorbit.core.integrators.quaternion.integrate_quaternion` (or the Taylor method,
:func:`spinorbit.core.integrators.taylor.integrate_taylor`, or the canonical elements). Neglecting the back-reaction is
exact to the ratio of the rotational to the orbital angular momentum of the body (≈ 1e-13 for a
300 m asteroid at 1 au), far below everything else here.

The sampling and its error estimate: :mod:`spinorbit.coupling.sampling`.

Frames, units, time
-------------------
ICRF axes; positions in au_DE421, velocities in au/day, GM in au³/day² (DE421's, REBOUND's
("AU", "day", "Msun") units); time in TDB days since J2000 (``docs/conventions.md``). A
:class:`spinorbit.RotationState` used here must give its attitude relative to **ICRF** (convert an
ecliptic attitude with :func:`spinorbit.frames.icrf_to_ecliptic_matrix` first).
"""

from __future__ import annotations

import numpy as np
from astropy.table import QTable

from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.integrators.quaternion import integrate_quaternion
from spinorbit.state import RotationState
from spinorbit.spin_forms import PA_MAX_WOBBLE
from spinorbit.state_table import (classify_rows, from_principal, schema_meta, table_columns, time_column,
                                   unit_quaternions)
from spinorbit.time import tdb_days

__all__ = ["DEFAULT_RTOL", "INTEGRATORS", "closest_approaches", "heliocentric_normals", "integrate_one_way",
           "one_way_days", "one_way_quaternions", "one_way_table", "propagate_one_way"]


#: Default relative tolerance of the rotation integrator (local error per DOP853 step).
DEFAULT_RTOL = 1e-10
#: Rotation integrators :func:`propagate_one_way` can run.
INTEGRATORS = ("quaternion", "elements", "taylor")


def heliocentric_normals(samples, days):
    """Unit normals (N, 3) of the body's osculating heliocentric orbit plane at ``days``, from sampled Sun states.

    ``samples`` must hold "sun" (relative to the body: the body's heliocentric state is its negative,
    and r × v is the same for both). The normal r × v is formed at the sample knots and interpolated
    linearly between them, then normalised: good to 1e-5 deg even for the Moon's monthly-wobbling
    heliocentric plane (``tests/test_pole.py``, against DE421's states at the output times: 4.4e-6 deg
    at 1e-10 sample tolerance), far below what an obliquity is quoted to. None without "sun".
    """
    if "sun" not in samples.names:  # also scene.sampling.NoSamples, which has no perturbers
        return None
    days = np.atleast_1d(np.asarray(days, dtype=float))
    slack = 1e-9 * max(1.0, abs(float(samples.days[-1])))  # TDB days from Times: rounding at the ends
    if days.min() < samples.days[0] - slack or days.max() > samples.days[-1] + slack:
        raise ValueError(f"orbit normals asked for TDB days [{days.min():.6f}, {days.max():.6f}] since J2000 but the Sun "
                         f"is sampled on [{samples.days[0]:.6f}, {samples.days[-1]:.6f}]; sample the whole span.")
    sun = samples.states[:, samples.names.index("sun")]
    knots = np.cross(sun[:, :3], sun[:, 3:])
    knots /= np.linalg.norm(knots, axis=1, keepdims=True)
    normals = np.stack([np.interp(days, samples.days, knots[:, k]) for k in range(3)], axis=1)
    return normals / np.linalg.norm(normals, axis=1, keepdims=True)


def closest_approaches(samples):
    """{name: (TDB day, distance au)} of each sampled perturber's closest approach on the sample grid.

    The grid is adaptive (denser where the relative motion bends), so its minimum is the encounter to
    within a knot spacing: good for marking it on a plot, not for an encounter's exact time.
    """
    distances = np.linalg.norm(samples.states[:, :, :3], axis=2)
    nearest = np.argmin(distances, axis=0)
    return {name: (float(samples.days[j]), float(distances[j, i])) for i, (name, j) in enumerate(zip(samples.names,
                                                                                                       nearest))}


def propagate_one_way(state, epoch, times, samples, rtol=DEFAULT_RTOL, periods=True, integrator="quaternion",
                      extra_sources=(), orbit_normals=None, pa_threshold=PA_MAX_WOBBLE):
    """Integrate the rotation of ``state`` under the sampled perturbers' torques.

    Parameters
    ----------
    state : spinorbit.RotationState
        Initial attitude (relative to **ICRF**) and body angular velocity. Only the moment *ratios*
        matter for the torque (degree 2; the body's mass is not used).
    epoch : astropy.time.Time
        Time of ``state``.
    times : astropy.time.Time
        Output times, strictly monotone away from ``epoch``, all inside ``samples.span``.
    samples : spinorbit.coupling.sampling.SampledPerturbers
        From :func:`~spinorbit.coupling.sampling.sample_from_ephemeris` or
        :func:`~spinorbit.coupling.sampling.sample_from_rebound`.
    rtol : float
        Local tolerance of the integrator: DOP853's rtol ("quaternion", "elements") or the Taylor
        method's ``tol`` ("taylor"; both are local errors per step, relative per component group).
    periods : bool
        Also compute the instantaneous (osculating, torque-free) P_ψ, P_φ, mode, E/E0, wobble amplitude
        and rotation class of every output state.
    integrator : {"quaternion", "elements", "taylor"}
        :func:`~spinorbit.core.integrators.quaternion.integrate_quaternion` (default; non-singular),
        :func:`~spinorbit.core.integrators.elements.integrate_elements` (canonical elements, paper
        eq. 11; raises near the separatrix, spin about C and the reference pole) or
        :func:`~spinorbit.core.integrators.taylor.integrate_taylor` (adaptive Taylor method on the same
        equations; it ends a step at every sample time, where the Hermite interpolant is not smooth,
        so it pays at least one step per sample inside the span).
    extra_sources : sequence
        More :mod:`spinorbit.core.model.perturbers` sources (e.g. ``fixed_source``) added to the sampled ones.
    orbit_normals : ndarray (N, 3), optional
        ICRF normals of the body's heliocentric orbit plane at ``times`` for the ``obliquity`` column;
        by default :func:`heliocentric_normals` of ``samples`` when they hold the Sun (else no column).
    pa_threshold : Quantity
        Wobble amplitude (angle) up to which a row is a principal-axis rotator, "PA", with P_ψ, P_φ masked
        (:func:`spinorbit.state_table.classify_rows`; default 1°, ``docs/design.md``, "PA or NPA").

    Returns
    -------
    astropy.table.QTable
        The one output schema (``docs/conventions.md``, "Output tables";
        :func:`spinorbit.state_table.table_columns`): ``time`` (Time, TDB), ``q_w, q_x, q_y, q_z``
        (scalar first, user body axes → ICRF), ``omega_x, omega_y, omega_z`` (rad/day, user body axes),
        ``pole_ra, pole_dec, pole_lon, pole_lat`` (deg), ``obliquity`` (deg, with orbit normals); with
        ``periods``: ``mode``, ``energy_ratio`` (E/E0), ``P_psi``, ``P_phi``, ``sidereal_period`` (h),
        ``wobble_amplitude`` (deg), ``rotation_class``.
        ``table.meta`` names ``epoch``, ``frame``, ``model`` and ``spinorbit_version``, and holds the
        integrator statistics and the sampling error estimate: DOP853's
        ``accepted``, ``rejected``, ``rhs_calls``; the Taylor method's ``steps``, ``order`` and
        ``mean_orbit_order``, with ``accepted`` = ``steps`` and ``rejected`` = 0 (it chooses each step
        after computing the series and never rejects one) and no ``rhs_calls`` (it evaluates no
        right-hand side: the series come from the recurrences).
    """
    if not isinstance(state, RotationState):
        raise TypeError(f"state must be a spinorbit.RotationState, got {type(state).__name__}.")
    t0, t_out = one_way_days(epoch, times)
    ys, stats = integrate_one_way(state, t0, t_out, samples, rtol, integrator, extra_sources)
    return one_way_table(state.body, epoch, t_out, ys, stats, samples, rtol, integrator, periods, orbit_normals,
                         pa_threshold)


def one_way_days(epoch, times):
    """(t0, t_out): ``epoch`` and ``times`` as TDB days since J2000, the floats :func:`propagate_one_way` integrates
    between (a caller that runs several integrations over the same times converts them once)."""
    d0, r0 = tdb_days(epoch)
    t0 = float(d0 + r0)
    days, rem = tdb_days(times)
    return t0, np.atleast_1d(np.asarray(days, dtype=float) + np.asarray(rem, dtype=float))


def integrate_one_way(state, t0, t_out, samples, rtol=DEFAULT_RTOL, integrator="quaternion", extra_sources=()):
    """The core rows (N, 7), principal axes, and the integrator's statistics of :func:`propagate_one_way`.

    ``t0``, ``t_out`` as :func:`one_way_days` gives them; the other arguments as :func:`propagate_one_way`'s
    (the same checks of the span and the integrator). No table is built: a check run that only needs the
    attitudes takes this, and :func:`one_way_table` turns a run's rows into the schema's table.
    """
    lo, hi = samples.span
    if min(t0, t_out.min()) < lo or max(t0, t_out.max()) > hi:
        raise ValueError(
            f"the run spans TDB days [{min(t0, t_out.min()):.4f}, {max(t0, t_out.max()):.4f}] since J2000 but the "
            f"perturbers are sampled on [{lo:.4f}, {hi:.4f}]; sample a longer span."
        )
    if integrator not in INTEGRATORS:
        raise ValueError(f"integrator: expected one of {INTEGRATORS}, got {integrator!r}.")
    model = make_model(state.body.principal_moments, [*samples.sources(), *extra_sources])
    if integrator == "elements":
        from spinorbit.core.integrators.elements import integrate_elements

        ys, stats = integrate_elements(state.core_state(), t0, t_out, model, rtol=rtol, return_stats=True)
        stats.pop("frame")
    elif integrator == "taylor":
        from spinorbit.core.integrators.taylor import integrate_taylor

        # The figure here is degree 2 (principal moments only), so integrate_taylor never falls back.
        ys, stats = integrate_taylor(state.core_state(), t0, t_out, model, tol=rtol, return_stats=True)
        stats.update(accepted=stats["steps"], rejected=0)
    else:
        ys, stats = integrate_quaternion(state.core_state(), t0, t_out, model, rtol=rtol, return_stats=True)
    return ys, stats


def one_way_quaternions(body, ys):
    """The (N, 4) attitudes of core rows ``ys`` as :func:`one_way_table` puts them in its ``q_*`` columns
    (user body axes, each row divided by its norm; refused when not finite or not unit)."""
    quaternions, _ = from_principal(body, ys)
    return unit_quaternions(np.atleast_2d(np.asarray(quaternions, dtype=float)))


def one_way_table(body, epoch, t_out, ys, stats, samples, rtol, integrator, periods=True, orbit_normals=None,
                  pa_threshold=PA_MAX_WOBBLE):
    """:func:`propagate_one_way`'s table of the core rows ``ys`` at ``t_out`` (from :func:`integrate_one_way`)."""
    if orbit_normals is None:
        orbit_normals = heliocentric_normals(samples, t_out)
    quaternions, omegas = from_principal(body, ys)  # all rows at once, no RotationState per row
    columns = {"time": time_column(t_out)}
    columns.update(table_columns(body, quaternions, omegas, motion="rows" if periods else None,
                                 orbit_normals=orbit_normals))
    table = QTable(columns)  # all columns in one go: astropy's per-column insertion costs ~30 µs a column
    table.meta.update(schema_meta(epoch, f"one-way rotation under sampled torques ({integrator})"))
    classify_rows(table, pa_threshold)
    table.meta.update(stats)
    table.meta["rtol"] = rtol
    table.meta["integrator"] = integrator
    table.meta["sample_tolerance"] = samples.tolerance
    table.meta["sample_midpoint_error"] = dict(zip(samples.names, samples.midpoint_error.tolist()))
    table.meta["samples"] = int(samples.days.size)
    return table
