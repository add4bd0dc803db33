"""Torque-free members in one vectorised call: set-up, exact free flow and outcome columns on arrays.

A member with no perturbers and no orbit needs no integration (``docs/ensembles.md``). Its
outcome comes from the exact free flow (paper eq. 12, :mod:`spinorbit.core.free_motion.members`:
one compiled loop over all members, each with its own moments and its own times), and its columns
are array operations on the flow's output:

- ``mode``, ``energy_ratio``, ``P_psi``, ``P_phi``, ``sidereal_period`` (h): constants of the motion,
  from the initial momentum (the kernels :class:`~spinorbit.RotationState`'s properties call);
- ``pole_ra``, ``pole_dec``, ``pole_lon``, ``pole_lat`` (deg) at each outcome time, from the flow's
  attitude and body momentum there (the inertial momentum M(q) m, as a Scene's end pole), and
  ``pole_shift`` (deg) against the initial pole (zero to rounding: the momentum is fixed);
- the initial values (the same constants), and ``error_estimate`` 0, ``tolerance_met``, ``route``.

:func:`free_outcome_columns` is that one computation on arrays; :func:`free_members_table` is the
front for a caller that has the members as arrays (no Scene, no Python per member: millions of
members per second, ``benchmarks/bench_ensemble.py``); and the ensemble's per-member route
(:func:`torque_free_rows`, members built as Scenes) stacks its
members' states and calls the same function. No number of a member depends on the other members
of its call, so all routes give the same bits (``tests/test_ensemble_free.py``).
"""

from __future__ import annotations

import numpy as np
from astropy import units as u
from astropy.table import QTable

from spinorbit.core.free_motion.members import free_members
from spinorbit.core.math.rotations import attitude_to_quat
from spinorbit.ensemble.errors import EnsembleError
from spinorbit.ensemble.outcomes import OUTCOME_UNITS, TIMED_COLUMNS, time_rows
from spinorbit.pole import angle_between_deg, pole_angles_deg
from spinorbit.quantities import value_in
from spinorbit.state import MAX_FLOW_PHASE, MODE_NAMES
from spinorbit.state_table import QUATERNION_COLUMNS

__all__ = ["FREE_TIMED_COLUMNS", "free_members_table", "free_outcome_columns", "free_table_columns",
           "principal_members", "torque_free_rows"]

#: The time-dependent outcome columns of a member without orbit (no obliquity), in the table's order.
FREE_TIMED_COLUMNS = tuple(name for name in TIMED_COLUMNS if name != "obliquity")
HOURS_PER_DAY = u.day.to(u.h)


def _inertial_momenta(quaternions, momenta):
    """M(q) m row by row ((…, 4), (…, 3) → (…, 3)): body momentum to inertial, q body → inertial.

    Written out component by component (no BLAS product), so a row's bits do not depend on how many
    rows are computed with it.
    """
    w, x, y, z = (quaternions[..., k] for k in range(4))
    mx, my, mz = (momenta[..., k] for k in range(3))
    return np.stack([(1.0 - 2.0 * (y * y + z * z)) * mx + 2.0 * (x * y - w * z) * my + 2.0 * (x * z + w * y) * mz,
                     2.0 * (x * y + w * z) * mx + (1.0 - 2.0 * (x * x + z * z)) * my + 2.0 * (y * z - w * x) * mz,
                     2.0 * (x * z - w * y) * mx + 2.0 * (y * z + w * x) * my + (1.0 - 2.0 * (x * x + y * y)) * mz],
                    axis=-1)


def free_outcome_columns(quaternions, momenta, moments, elapsed_days, attitudes=False):
    """Outcome columns of N torque-free members, each at its own K times.

    Parameters
    ----------
    quaternions : (N, 4) ndarray
        Principal-axis attitudes at each member's epoch (scalar first, body → inertial, unit).
    momenta : (N, 3) ndarray
        Body angular momenta on the principal axes (moment unit · rad/day), non-zero.
    moments : (N, 3) ndarray
        Principal moments A ≤ B ≤ C (any one unit per member; only ratios and the momenta matter).
    elapsed_days : (N, K) ndarray
        Outcome times of each member, days since its epoch.
    attitudes : bool
        False: the pole at every time is the initial one (the inertial momentum is a constant of the
        free motion) and ``pole_shift`` is 0. True: the exact flow (paper eq. 12) to each time gives
        the attitudes (``q_w`` … ``q_z``) and the pole from the propagated momentum, as a Scene's
        run does (it differs from the initial pole by the flow's rounding, ~1e-14°).

    Returns
    -------
    dict
        ``mode`` (N,) str; ``energy_ratio``, ``P_psi``, ``P_phi``, ``sidereal_period`` (N,) (h);
        ``pole_ra``, ``pole_dec``, ``pole_lon``, ``pole_lat``, ``pole_shift`` (N, K) deg; with
        ``attitudes`` also ``q_w``, ``q_x``, ``q_y``, ``q_z`` (N, K).
    """
    n, k = elapsed_days.shape
    modes, ratios, p_psi, p_phi, p_sidereal, q_out, m_out = free_members(
        quaternions, momenta, moments, elapsed_days if attitudes else None)
    start = _inertial_momenta(quaternions, momenta)
    poles = _inertial_momenta(q_out, m_out).reshape(n * k, 3) if attitudes else start
    angles = pole_angles_deg(poles)
    if attitudes:
        shift = angle_between_deg(poles, np.repeat(start, k, axis=0), "the pole", "the start pole").reshape(n, k)
        ra, dec, lon, lat = (angle.reshape(n, k) for angle in angles)
    else:
        shift = np.zeros((n, k))
        ra, dec, lon, lat = (np.repeat(angle[:, None], k, axis=1) for angle in angles)
    codes = sorted(MODE_NAMES)
    names = np.array([MODE_NAMES[code] for code in codes])[np.searchsorted(codes, modes)]
    columns = {"mode": names, "energy_ratio": ratios, "P_psi": p_psi * HOURS_PER_DAY,
               "P_phi": p_phi * HOURS_PER_DAY, "sidereal_period": p_sidereal * HOURS_PER_DAY,
               "pole_ra": ra, "pole_dec": dec, "pole_lon": lon, "pole_lat": lat, "pole_shift": shift}
    if attitudes:
        columns.update(zip(QUATERNION_COLUMNS, (q_out[:, :, c] for c in range(4))))
    return columns


def principal_members(moments, quaternions, omegas_rad_day):
    """Checked (quaternions, momenta, moments) of members given along principal axes A ≤ B ≤ C.

    Parameters
    ----------
    moments : (N, 3) or (3,) array_like
        Principal moments along the body axes, in increasing order in every row (A ≤ B ≤ C).
    quaternions : (N, 4) array_like
        Attitudes, scalar first, body → inertial, unit to 1e-6 (each row is divided by its norm).
    omegas_rad_day : (N, 3) array_like
        Body angular velocities in rad/day, plain floats (:func:`free_members_table` takes the Quantity).
    """
    q = np.atleast_2d(np.asarray(quaternions, dtype=float))
    n = q.shape[0]
    if q.shape != (n, 4):
        raise EnsembleError(f"quaternions expects shape (N, 4), scalar first; got {q.shape}.")
    omega = np.atleast_2d(np.asarray(omegas_rad_day, dtype=float))
    inertia = np.asarray(moments, dtype=float)
    inertia = np.broadcast_to(inertia, (n, 3)) if inertia.shape == (3,) else inertia
    for name, array in (("angular_velocities", omega), ("moments", inertia)):
        if array.shape != (n, 3):
            raise EnsembleError(f"{name} expects shape ({n}, 3), one row per member; got {array.shape}.")
        if not np.all(np.isfinite(array)):
            raise EnsembleError(f"{name} expects finite values; row {int(np.argmin(np.isfinite(array).all(1)))} "
                                "holds NaN or inf.")
    if not np.all(np.isfinite(q)):
        raise EnsembleError("quaternions expects finite values; some row holds NaN or inf.")
    if not np.all((inertia[:, 0] > 0.0) & (inertia[:, 0] <= inertia[:, 1]) & (inertia[:, 1] <= inertia[:, 2])):
        bad = int(np.argmin((inertia[:, 0] > 0.0) & (inertia[:, 0] <= inertia[:, 1]) & (inertia[:, 1] <= inertia[:, 2])))
        raise EnsembleError(f"moments expects 0 < A ≤ B ≤ C along the body axes in every row; row {bad} is "
                            f"{inertia[bad].tolist()}. Order the axes so, or build the members as Scenes.")
    norms = np.sqrt(q[:, 0] * q[:, 0] + q[:, 1] * q[:, 1] + q[:, 2] * q[:, 2] + q[:, 3] * q[:, 3])
    if not np.all(np.abs(norms - 1.0) <= 1e-6):
        raise EnsembleError(f"quaternions expects unit rows (to 1e-6); row {int(np.argmax(np.abs(norms - 1.0)))} has "
                            f"norm {float(norms[np.argmax(np.abs(norms - 1.0))])!r}.")
    momenta = inertia * omega
    if not np.all(np.any(momenta != 0.0, axis=1)):
        raise EnsembleError(f"angular_velocities: row {int(np.argmin(np.any(momenta != 0.0, axis=1)))} is zero; a body "
                            "at rest has no rotation mode or pole. Give every member a non-zero spin.")
    return q / norms[:, None], momenta, np.ascontiguousarray(inertia)


def free_members_table(moments, quaternions, angular_velocities, elapsed, parameters=None, attitudes=False):
    """The outcome table of N torque-free members given as arrays, in one vectorised call.

    The same columns, units and bits as :meth:`Ensemble.run` gives for those members built as Scenes
    (``tests/test_ensemble_free.py``), with no Scene and no Python per member.

    Parameters
    ----------
    moments : (N, 3) or (3,) array_like
        Principal moments along the body axes, A ≤ B ≤ C in each row.
    quaternions : (N, 4) array_like
        Attitudes at each member's epoch (scalar first, body → inertial).
    angular_velocities : (N, 3) Quantity
        Body angular velocities, an angle per time (``omegas * u.rad / u.day``; bare numbers are refused).
    elapsed : Quantity, shape (), (K,) or (N, K)
        Outcome times since each member's epoch (a time, ``30 * u.day``); several times suffix the
        time-dependent columns ``_t0``, ``_t1``, … as ``Ensemble(at=...)`` does.
    parameters : QTable, optional
        Columns to put first (one row per member), as an Ensemble's parameter table.
    attitudes : bool
        Also propagate every member by the exact free flow to its outcome times: adds the attitude
        columns ``q_w`` … ``q_z`` and takes the pole from the propagated state
        (:func:`free_outcome_columns`).

    Returns
    -------
    QTable
        One row per member.
    """
    omegas = value_in("angular_velocities", angular_velocities, u.rad / u.day, "omegas * u.rad / u.day", finite=False)
    q, momenta, inertia = principal_members(moments, quaternions, omegas)
    n = q.shape[0]
    days = np.asarray(value_in("elapsed", elapsed, u.day, "30 * u.day", finite=False), dtype=float)
    timed = np.ndim(days) > 0
    days = np.broadcast_to(np.atleast_1d(days), (n, np.atleast_1d(days).shape[-1])) if np.ndim(days) < 2 else days
    if days.shape[0] != n or not np.all(np.isfinite(days)):
        raise EnsembleError(f"elapsed expects finite times of shape (), (K,) or ({n}, K); got {np.shape(days)}.")
    if attitudes:  # the flow's domain, as RotationState.propagate_torque_free checks it
        phase = np.sqrt(np.sum(momenta * momenta, axis=1)) / inertia[:, 0] * np.max(np.abs(days), axis=1)
        if not np.all(phase <= MAX_FLOW_PHASE):
            bad = int(np.argmax(phase))
            raise EnsembleError(f"elapsed: member {bad}'s fastest angle turns by {phase[bad]:.3g} rad > "
                                f"{MAX_FLOW_PHASE:g} rad by its last time, beyond the free flow's domain (one ulp of the "
                                "time moves the attitude by more than 0.1 rad there); shorten the times.")
    columns = free_outcome_columns(q, momenta, inertia, np.ascontiguousarray(days), attitudes)
    table = QTable() if parameters is None else parameters.copy()
    if len(table) not in (0, n):
        raise EnsembleError(f"parameters expects {n} rows, one per member; got {len(table)}.")
    for name, values, unit in free_table_columns(columns, days.shape[1], timed):
        table[name] = values * unit if unit is not None else values
    return table


def free_table_columns(columns, times, timed):
    """(name, values, unit or None) of the outcome table's columns from :func:`free_outcome_columns`, in the
    ensemble table's order (the timed columns per time, then the initial and run columns)."""
    n = columns["energy_ratio"].shape[0]
    out = []
    names = ((*QUATERNION_COLUMNS, *FREE_TIMED_COLUMNS) if "q_w" in columns else FREE_TIMED_COLUMNS)
    for k in range(times):
        for name in names:
            values = columns[name]
            values = values[:, k] if values.ndim == 2 else values
            out.append((f"{name}_t{k}" if timed else name, values, OUTCOME_UNITS.get(name)))
    for name, source in (("P_psi_initial", "P_psi"), ("P_phi_initial", "P_phi"),
                         ("sidereal_period_initial", "sidereal_period"), ("energy_ratio_initial", "energy_ratio")):
        out.append((name, columns[source], OUTCOME_UNITS.get(name)))
    out += [("error_estimate", np.zeros(n), OUTCOME_UNITS["error_estimate"]), ("tolerance_met", np.ones(n, dtype=bool),
            None), ("route", np.full(n, "torque-free"), None)]
    return out


def _identity_frame(body):
    """The body's axes are its principal axes in the order A ≤ B ≤ C (no conversion needed)."""
    return (np.array_equal(body.to_principal, np.eye(3))
            and np.array_equal(body.moment_values, np.asarray(body.principal_moments, dtype=float)))


def torque_free_rows(scenes, at=None):
    """Outcome rows (dicts of plain values) of torque-free single-body Scenes without orbits, in their order.

    The per-member route of the ensemble: each Scene's state is read (per-member Python), then all
    members go through :func:`free_outcome_columns` in one call. A body whose axes are not its
    principal axes in increasing order is turned to them first (its attitude matrix and momentum).
    """
    n = len(scenes)
    quaternions, omegas, moments = np.empty((n, 4)), np.empty((n, 3)), np.empty((n, 3))
    elapsed = []
    for i, scene in enumerate(scenes):
        state, body = scene.state, scene.state.body
        moments[i] = body.principal_moments
        if _identity_frame(body):
            # angular_velocity is in rad/day by construction: .value skips a unit conversion per member
            quaternions[i], omegas[i] = state.quaternion, state.angular_velocity.value
        else:
            attitude, momentum = state.principal_attitude_and_momentum()
            quaternions[i], omegas[i] = attitude_to_quat(np.ascontiguousarray(attitude)), momentum / moments[i]
        days = np.atleast_1d(np.asarray(scene.output_days, dtype=float))
        elapsed.append(days[time_rows(scene, at)] - float(scene.epoch_day))
    q, momenta, inertia = principal_members(moments, quaternions, omegas)
    columns = free_outcome_columns(q, momenta, inertia, np.ascontiguousarray(elapsed))
    table = free_table_columns(columns, len(elapsed[0]), at is not None)
    return [{name: (str(values[i]) if name in ("mode", "route") or name.startswith("mode_t") else
                    bool(values[i]) if name == "tolerance_met" else float(values[i]))
             for name, values, _ in table} for i in range(n)]
