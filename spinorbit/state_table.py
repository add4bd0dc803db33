"""The output-table columns of many rotation states at once, with :class:`~spinorbit.RotationState`'s definitions.

A run's table (:class:`spinorbit.scene.scene.SceneResult`, :func:`spinorbit.coupling.one_way.propagate_one_way`)
reports for every row what the row's RotationState would: its unit quaternion, angular velocity, spin
pole (RA, Dec; λ, β), the obliquity when the orbit normals are given and, with "periods", the mode,
E/E0, P_ψ, P_φ, sidereal period and wobble amplitude of its torque-free motion and its rotation class
(PA, SAM, LAM; :func:`classify_rows`) — as scalar columns of the one output schema
(``docs/conventions.md``, "Output tables").
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
from astropy.utils.masked import Masked

from spinorbit import pole as _pole
from spinorbit import spin_forms as _spin_forms
from spinorbit.core.free_motion import summary as _summary
from spinorbit.core.free_motion import wobble as _wobble
from spinorbit.core.math.rotations import attitude_to_quat_many, quat_to_attitude_many
from spinorbit.state import MODE_NAMES, QUATERNION_NORM_TOLERANCE, InvalidStateError, RotationState

__all__ = ["CLASS_COLUMNS", "MOTION_COLUMNS", "OMEGA_COLUMNS", "PERIOD_UNIT", "POLE_COLUMNS", "QUATERNION_COLUMNS", "add_obliquity",
           "classify_rows", "from_principal", "omega_array", "pole_directions", "quaternion_array", "schema_meta", "table_columns",
           "as_schema_time", "time_column", "unit_quaternions"]


def from_principal(body, rows):
    """User-axes quaternions and angular velocities (rad/day) of core rows (q, ω) in principal axes.

    What ``RotationState.from_matrix(body, Pᵀ R(q), Pᵀ ω)`` holds for each row (same quaternion
    representative: the largest component positive), for all rows at once.
    """
    p = body.to_principal
    rows = np.atleast_2d(np.asarray(rows, dtype=float))
    attitudes = np.matmul(p.T, quat_to_attitude_many(np.ascontiguousarray(rows[:, :4])))
    return attitude_to_quat_many(np.ascontiguousarray(attitudes)), rows[:, 4:] @ p


def unit_quaternions(quaternions):
    """Each row divided by its norm, refused like RotationState refuses one (not finite, or not unit)."""
    if not np.all(np.isfinite(quaternions)):
        raise InvalidStateError("quaternion components must be finite; the propagated rows contain NaN or inf.")
    norms = np.linalg.norm(quaternions, axis=1)
    worst = float(np.max(np.abs(norms - 1.0))) if norms.size else 0.0
    if worst > QUATERNION_NORM_TOLERANCE:
        raise InvalidStateError(f"attitude quaternions must have unit norm; a propagated row has |q| − 1 = {worst!r}.")
    return quaternions / norms[:, None]


#: Scalar attitude and spin columns (the schema has no (N, k) columns, so API, ECSV and CSV agree).
QUATERNION_COLUMNS = ("q_w", "q_x", "q_y", "q_z")
OMEGA_COLUMNS = ("omega_x", "omega_y", "omega_z")
POLE_COLUMNS = ("pole_ra", "pole_dec", "pole_lon", "pole_lat")


#: Names of the motion columns, in order (``docs/conventions.md``, "Output tables").
MOTION_COLUMNS = ("mode", "energy_ratio", "P_psi", "P_phi", "sidereal_period")
#: Names of the columns that say whether a row is a principal-axis rotator, after the motion columns: the wobble
#: amplitude (deg; docs/conventions.md, "Wobble and rotation class") and the class at the table's threshold.
CLASS_COLUMNS = ("wobble_amplitude", "rotation_class")
#: Unit of the period columns of every output table (the one output schema: hours).
PERIOD_UNIT = u.h


def _motion_columns(body, omegas):
    """mode, E/E0, P_ψ, P_φ, P_sid of every row's torque-free motion (the kernels of RotationState's properties)."""
    momenta = np.ascontiguousarray((body.moment_values * omegas) @ body.to_principal.T)  # P (I ω), row by row
    if not np.all(np.any(momenta != 0.0, axis=1)):
        raise InvalidStateError("the body is not rotating (zero spin): it has no rotation mode or elements.")
    n = momenta.shape[0]
    modes, ratios = np.empty(n, dtype=np.int64), np.empty(n)
    p_psi, p_phi, p_sidereal = np.empty(n), np.empty(n), np.empty(n)
    _summary.motion_summary_many(momenta, *body.principal_moments, modes, ratios, p_psi, p_phi, p_sidereal)
    amplitudes = np.empty(n)
    _wobble.wobble_amplitude_many(momenta, *body.principal_moments, amplitudes)
    return (_mode_names(modes), ratios, *((p * u.day).to(PERIOD_UNIT) for p in (p_psi, p_phi, p_sidereal)),
            np.degrees(amplitudes) * u.deg)


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
    periods = (p.to_value(PERIOD_UNIT) for p in (p_psi, p_phi, state.sidereal_period))
    return (np.full(n, state.mode), np.full(n, state.energy_ratio), *(np.full(n, p) * PERIOD_UNIT for p in periods),
            np.full(n, state.wobble_amplitude.to_value(u.deg)) * u.deg)


def pole_directions(body, quaternions, omegas):
    """Unit ICRF angular-momentum directions Rᵀ I ω / |…| of rows (N, 4) and (N, 3), user body axes."""
    inertial = np.einsum("nji,nj->ni", quat_to_attitude_many(np.ascontiguousarray(quaternions)), body.moment_values * omegas)
    norms = np.linalg.norm(inertial, axis=1, keepdims=True)
    if not np.all(norms > 0.0):
        raise InvalidStateError("the body is not rotating (zero spin) in some row: it has no spin pole, rotation mode "
                                "or elements.")
    return inertial / norms


def quaternion_array(table):
    """The (N, 4) scalar-first quaternions of a result table's ``q_w, q_x, q_y, q_z`` columns ((1, 4) of a row)."""
    return np.stack([np.atleast_1d(np.asarray(table[name], dtype=float)) for name in QUATERNION_COLUMNS], axis=1)


def omega_array(table):
    """The (N, 3) body angular velocities (rad/day) of a result table's ``omega_x, omega_y, omega_z`` columns
    ((1, 3) of a row)."""
    return np.stack([np.atleast_1d(u.Quantity(table[name]).to_value(u.rad / u.day)) for name in OMEGA_COLUMNS], axis=1)


def table_columns(body, quaternions, omegas, omega=True, motion=None, orbit_normals=None):
    """Columns of a rotation table, in the order of the output schema (``docs/conventions.md``, "Output tables").

    ``q_w, q_x, q_y, q_z``, [``omega_x, omega_y, omega_z``], ``pole_ra, pole_dec, pole_lon, pole_lat``,
    [``obliquity``], [``mode, energy_ratio, P_psi, P_phi, sidereal_period, wobble_amplitude``]; the table's
    maker adds ``rotation_class`` and masks P_ψ, P_φ of the PA rows (:func:`classify_rows`).

    Parameters
    ----------
    body : RigidBody
    quaternions : ndarray, shape (N, 4)
        Scalar first, user body axes → inertial; unit to 1e-6 (each row is divided by its norm,
        as RotationState does).
    omegas : ndarray, shape (N, 3)
        Body angular velocity in user axes, rad/day.
    omega : bool
        Include the ``omega_*`` columns (Quantity, rad/day).
    motion : None, "rows" or RotationState
        None: no motion columns; "rows": each row's own (osculating) mode, E/E0, periods and wobble amplitude;
        a RotationState: those of its torque-free motion for every row (a torque-free run from it).
    orbit_normals : None or ndarray, shape (N, 3) or (3,)
        ICRF normals of the body's current heliocentric orbit plane: adds ``obliquity`` (deg).

    Returns
    -------
    dict
        Column name → ndarray, str array (``mode``) or Quantity (``omega_*`` rad/day, pole,
        obliquity and wobble amplitude deg, periods h).
    """
    quaternions = unit_quaternions(np.atleast_2d(np.asarray(quaternions, dtype=float)))
    omegas = np.atleast_2d(np.asarray(omegas, dtype=float))
    columns = dict(zip(QUATERNION_COLUMNS, quaternions.T.copy()))
    if omega:
        columns.update(zip(OMEGA_COLUMNS, omegas.T.copy() * (u.rad / u.day)))
    directions = pole_directions(body, quaternions, omegas)
    columns.update(zip(POLE_COLUMNS, (angle * u.deg for angle in _pole.pole_angles_deg(directions))))
    if orbit_normals is not None:
        columns["obliquity"] = _pole.obliquity_deg(directions, orbit_normals) * u.deg
    if motion is None:
        return columns
    if isinstance(motion, RotationState):
        values = _constant_motion_columns(motion, quaternions.shape[0])
    elif motion == "rows":
        values = _motion_columns(body, omegas)
    else:
        raise ValueError(f"motion expects None, 'rows' or a RotationState; got {motion!r}.")
    columns.update(zip((*MOTION_COLUMNS, CLASS_COLUMNS[0]), values))
    return columns


def classify_rows(table, threshold=_spin_forms.PA_MAX_WOBBLE):
    """Add ``rotation_class`` to a table with motion columns, mask P_ψ, P_φ of its PA rows, note the threshold.

    A row whose ``wobble_amplitude`` is at most ``threshold`` (an angle in [0°, 90°); default
    :data:`spinorbit.spin_forms.PA_MAX_WOBBLE`, 1°) is "PA": a principal-axis rotator, reported by its
    ``sidereal_period``; its P_ψ, P_φ (the split of one rotation into a wobble of that size and a spin) are
    masked, so the ECSV and CSV leave them empty. The other rows are "SAM", "LAM" or "separatrix" with their
    P_ψ, P_φ. When any row is PA the period columns become MaskedQuantity (the values stay underneath,
    ``column.unmasked``), else they stay Quantity, as astropy's readers do. ``table.meta["pa_threshold"]``
    records the threshold. Applying it again with another threshold re-classifies (the table is changed in
    place; one without motion columns is left as it is).
    """
    if CLASS_COLUMNS[0] not in table.colnames:
        return table
    limit = _spin_forms.wobble_threshold_deg(threshold, "pa_threshold")
    classes = _spin_forms.rotation_classes(u.Quantity(table[CLASS_COLUMNS[0]]).to_value(u.deg),
                                           np.asarray(table["mode"]).astype(str), limit * u.deg)
    principal = classes == "PA"
    for name in ("P_psi", "P_phi"):
        values = getattr(table[name], "unmasked", table[name])
        table[name] = Masked(values, mask=principal) if principal.any() else values
    if CLASS_COLUMNS[1] in table.colnames:
        table[CLASS_COLUMNS[1]] = classes
    else:
        table.add_column(classes, name=CLASS_COLUMNS[1], index=table.colnames.index(CLASS_COLUMNS[0]) + 1)
    table.meta["pa_threshold"] = f"{limit:g} deg"
    table.meta.setdefault("columns", {}).update({name: COLUMN_DESCRIPTIONS[name] for name in CLASS_COLUMNS})
    return table


def time_column(days):
    """The schema's ``time`` column of core times (TDB days since J2000): a TDB Time as ISO dates to the
    nanosecond (ECSV and CSV write the formatted strings, so the precision is what they keep)."""
    from spinorbit.time import time_from_tdb_days

    return as_schema_time(time_from_tdb_days(days))


def as_schema_time(times):
    """``times`` shown as the schema shows them: ISO (isot), TDB, nine decimals of the second."""
    times = times.tdb
    times.format = "isot"
    times.precision = 9
    return times


def schema_meta(epoch, model):
    """The ``table.meta`` every result table carries: ``epoch`` (ISO, TDB), ``frame``, ``model``, version, columns."""
    from spinorbit import __version__

    return {"epoch": epoch.tdb.isot, "frame": "ICRF", "model": model, "spinorbit_version": __version__,
            "columns": dict(COLUMN_DESCRIPTIONS)}


#: One line per column of the output schema (table.meta["columns"]; docs/conventions.md, "Output tables").
COLUMN_DESCRIPTIONS = {
    "time": "TDB",
    "q_w": "attitude quaternion, scalar first, user body axes -> ICRF",
    "omega_x": "body angular velocity along the user body axes (omega_y, omega_z likewise)",
    "pole_ra": "right ascension of the angular momentum, ICRF (pole_dec: declination)",
    "pole_lon": "ecliptic J2000 longitude of the angular momentum (pole_lat: latitude; IAU 2006 obliquity)",
    "obliquity": "angle between the angular momentum and the osculating heliocentric orbit normal",
    "mode": "SAM, LAM, separatrix or permanent rotation of the osculating torque-free motion",
    "energy_ratio": "E/E0 = 2TC/G^2",
    "P_psi": "rotation period of the tumbling (Pravec et al. 2005); inf for permanent rotation; masked for PA rows",
    "P_phi": "precession period (Pravec et al. 2005); 2 pi/|omega| for permanent rotation; masked for PA rows",
    "sidereal_period": "2 pi/|omega| for principal-axis rotation; 1/(1/P_phi -+ 1/P_psi) for SAM/LAM tumblers",
    "wobble_amplitude": "largest angle between the circulation axis (C in SAM, A in LAM) and the angular momentum "
                        "over the free motion",
    "rotation_class": "PA if wobble_amplitude <= meta['pa_threshold'], else SAM, LAM or separatrix",
}


def add_obliquity(table, normals):
    """Add the ``obliquity`` column (deg) of a table's ``pole_ra, pole_dec`` against orbit normals (N, 3), ICRF."""
    directions = _pole.directions_from_ra_dec_deg(*(u.Quantity(table[name]).to_value(u.deg)
                                                    for name in ("pole_ra", "pole_dec")))
    table["obliquity"] = _pole.obliquity_deg(directions, normals) * u.deg
