"""The output-table columns of many rotation states at once, with :class:`~spinorbit.RotationState`'s definitions.

A run's table (:class:`spinorbit.scene.scene.SceneResult`, :func:`spinorbit.coupling.one_way.propagate_one_way`)
reports for every row what the row's RotationState would: its unit quaternion, angular velocity,
inertial momentum direction and, with "periods", the mode, E/E0, P_ψ and P_φ of its torque-free motion.
Building one RotationState per row cost ~0.1 ms a row (validation, Quantities, one compiled call per
property), far more than the exact flow behind it; here the columns come from array operations and
one compiled loop (:func:`spinorbit.core.free_motion.summary.motion_summary_many`, the kernels the
properties themselves call).

On a torque-free run mode, E/E0 and the periods are constants of the motion: ``motion=state`` takes
them once from the initial state instead of from every row. The rows' own values differ from those by
the rounding of the propagated momentum only (``tests/test_state_table.py``: a few ulps; 6e-11
relative for the periods 1e-7 from the separatrix, where 1 − m from b − d amplifies the rounding).
"""

from __future__ import annotations

import numpy as np
from astropy import units as u

from spinorbit.core.free_motion import summary as _summary
from spinorbit.core.math.rotations import attitude_to_quat_many, quat_to_attitude_many
from spinorbit.state import MODE_NAMES, QUATERNION_NORM_TOLERANCE, InvalidStateError, RotationState

__all__ = ["from_principal", "table_columns"]


def from_principal(body, rows):
    """User-axes quaternions and angular velocities (rad/day) of core rows (q, ω) in principal axes.

    What ``RotationState.from_matrix(body, Pᵀ R(q), Pᵀ ω)`` holds for each row (same quaternion
    representative: the largest component positive), for all rows at once.
    """
    p = body.to_principal
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    attitudes = np.matmul(p.T, quat_to_attitude_many(np.ascontiguousarray(rows[:, :4])))
    return attitude_to_quat_many(np.ascontiguousarray(attitudes)), rows[:, 4:] @ p


def _unit_quaternions(quaternions):
    """Each row divided by its norm, refused like RotationState refuses one (not finite, or not unit)."""
    if not np.all(np.isfinite(quaternions)):
        raise InvalidStateError("quaternion components must be finite; the propagated rows contain NaN or inf.")
    norms = np.linalg.norm(quaternions, axis=1)
    worst = float(np.max(np.abs(norms - 1.0))) if norms.size else 0.0
    if worst > QUATERNION_NORM_TOLERANCE:
        raise InvalidStateError(f"attitude quaternions must have unit norm; a propagated row has |q| − 1 = {worst!r}.")
    return quaternions / norms[:, None]


def _motion_columns(body, omegas):
    """mode, E/E0, P_ψ, P_φ of every row's torque-free motion (the kernels of RotationState's properties)."""
    momenta = np.ascontiguousarray((body.moment_values * omegas) @ body.to_principal.T)  # P (I ω), row by row
    if not np.all(np.any(momenta != 0.0, axis=1)):
        raise InvalidStateError("the body is not rotating (zero spin): it has no rotation mode or elements.")
    n = momenta.shape[0]
    modes, ratios, p_psi, p_phi = np.empty(n, dtype=np.int64), np.empty(n), np.empty(n), np.empty(n)
    _summary.motion_summary_many(momenta, *body.principal_moments, modes, ratios, p_psi, p_phi)
    return _mode_names(modes), ratios, p_psi * u.day, p_phi * u.day


def _mode_names(codes):
    """Mode names of codes, as the array a list of the names would make (a Python list of N strings
    costs astropy a scan of every element when it becomes a column)."""
    names = {code: MODE_NAMES[code] for code in np.unique(codes).tolist()}
    out = np.empty(codes.shape[0], dtype=f"<U{max((len(v) for v in names.values()), default=1)}")
    for code, name in names.items():
        out[codes == code] = name
    return out


def _constant_motion_columns(state, n):
    """The same columns for ``n`` rows of the torque-free motion of ``state``: its values, repeated."""
    p_psi, p_phi = state.periods
    return (np.full(n, state.mode), np.full(n, state.energy_ratio), np.full(n, p_psi.to_value(u.day)) * u.day,
            np.full(n, p_phi.to_value(u.day)) * u.day)


def table_columns(body, quaternions, omegas, omega=True, motion=None):
    """Columns of a rotation table, in order: quaternion, [omega], momentum_direction, [mode, energy_ratio, P_psi, P_phi].

    Parameters
    ----------
    body : RigidBody
    quaternions : ndarray, shape (N, 4)
        Scalar first, user body axes → inertial; unit to 1e-6 (each row is divided by its norm,
        as RotationState does).
    omegas : ndarray, shape (N, 3)
        Body angular velocity in user axes, rad/day.
    omega : bool
        Include the ``omega`` column (Quantity, rad/day).
    motion : None, "rows" or RotationState
        None: no motion columns; "rows": each row's own (osculating) mode, E/E0 and periods;
        a RotationState: those of its torque-free motion for every row (a torque-free run from it).

    Returns
    -------
    dict
        Column name → ndarray, list of str (``mode``) or Quantity (``omega`` rad/day, periods day).
    """
    quaternions = _unit_quaternions(np.atleast_2d(np.asarray(quaternions, dtype=float)))
    omegas = np.atleast_2d(np.asarray(omegas, dtype=float))
    columns = {"quaternion": quaternions}
    if omega:
        columns["omega"] = omegas * (u.rad / u.day)
    inertial = np.einsum("nji,nj->ni", quat_to_attitude_many(np.ascontiguousarray(quaternions)), body.moment_values * omegas)
    columns["momentum_direction"] = inertial / np.linalg.norm(inertial, axis=1, keepdims=True)  # Rᵀ I ω / |…|
    if motion is None:
        return columns
    if isinstance(motion, RotationState):
        values = _constant_motion_columns(motion, quaternions.shape[0])
    elif motion == "rows":
        values = _motion_columns(body, omegas)
    else:
        raise ValueError(f"motion expects None, 'rows' or a RotationState; got {motion!r}.")
    columns.update(zip(("mode", "energy_ratio", "P_psi", "P_phi"), values))
    return columns
