"""A member's outcome row: its spin state at the end (or at named times) from its SceneResult.

The columns are the output schema's (``docs/conventions.md``, "Output tables"): ``mode``,
``energy_ratio``, ``P_psi``, ``P_phi``, ``sidereal_period`` (h), ``pole_ra``, ``pole_dec``,
``pole_lon``, ``pole_lat`` (deg) and ``obliquity`` (deg, when the run has an orbit), plus
``pole_shift`` (deg: the angle between the angular momentum at that time and at the state's epoch)
and the initial ``P_psi_initial``, ``P_phi_initial``, ``sidereal_period_initial``, ``energy_ratio_initial`` (the member's state at
its epoch), then the run's ``error_estimate`` (arcsec), ``tolerance_met`` and ``route``.
With named times every time-dependent column is suffixed ``_t0``, ``_t1``, …

A row is a dict of plain floats, strings and booleans (units in :data:`OUTCOME_UNITS`), so that a
chunk's rows cross process boundaries and checkpoints as numbers, bit for bit.

Torque-free members (no perturbers, no orbit) need no integration: their rows come from the exact
free flow in one vectorised call (:mod:`spinorbit.ensemble.free`), in place of the Scene's run.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u

from spinorbit.ensemble.errors import EnsembleError
from spinorbit.pole import angle_between_deg, directions_from_ra_dec_deg
from spinorbit.state_table import MOTION_COLUMNS, POLE_COLUMNS
from spinorbit.time import tdb_days

__all__ = ["OUTCOME_UNITS", "TIMED_COLUMNS", "days_of", "outcome_row", "time_rows"]

#: Columns that depend on the time of the outcome, in order.
TIMED_COLUMNS = (*MOTION_COLUMNS, *POLE_COLUMNS, "obliquity", "pole_shift")
INITIAL_COLUMNS = ("P_psi_initial", "P_phi_initial", "sidereal_period_initial", "energy_ratio_initial")
RUN_COLUMNS = ("error_estimate", "tolerance_met", "route")
#: Unit of every numeric outcome column (a suffixed column has its base column's unit).
OUTCOME_UNITS = {"P_psi": u.h, "P_phi": u.h, "sidereal_period": u.h, "pole_ra": u.deg, "pole_dec": u.deg,
                 "pole_lon": u.deg, "pole_lat": u.deg, "obliquity": u.deg, "pole_shift": u.deg, "P_psi_initial": u.h,
                 "P_phi_initial": u.h, "sidereal_period_initial": u.h, "error_estimate": u.arcsec}
#: Output times within this many days of a named time are that time (float TDB days resolve ~1e-12 d).
TIME_MATCH_DAYS = 1e-9


def _suffix(name, k, timed):
    return f"{name}_t{k}" if timed else name


def time_rows(scene, at):
    """Row indices of the scene's table at the named times (TDB days), or [last row] when ``at`` is None."""
    days = np.atleast_1d(np.asarray(scene.output_days, dtype=float))
    if at is None:
        return [days.size - 1]
    rows = []
    for day in at:
        k = int(np.argmin(np.abs(days - day)))
        if abs(days[k] - day) > TIME_MATCH_DAYS:
            raise EnsembleError(f"at: the time {day!r} (TDB days since J2000) is not among the member's output times "
                                f"({days[0]!r} … {days[-1]!r}, {days.size} times); name times the scene outputs.")
        rows.append(k)
    return rows


def _initial(state):
    p_psi, p_phi = state.periods
    return {"P_psi_initial": float(p_psi.to_value(u.h)), "P_phi_initial": float(p_phi.to_value(u.h)),
            "sidereal_period_initial": float(state.sidereal_period.to_value(u.h)),
            "energy_ratio_initial": float(state.energy_ratio)}


def outcome_row(scene, result, at=None):
    """The outcome columns (dict of plain values) of one single-body member's SceneResult."""
    table = result.table
    timed = at is not None
    start_pole = scene.state.angular_momentum_direction
    row = {}
    columns = [(name, table[name]) for name in TIMED_COLUMNS[:-1] if name in table.colnames]
    for k, index in enumerate(time_rows(scene, at)):
        # element by element from the columns (an astropy Row per time costs more than the values)
        for name, column in columns:
            value = column[index]
            row[_suffix(name, k, timed)] = (str(value) if name == "mode" else
                                            float(u.Quantity(value).to_value(OUTCOME_UNITS[name]))
                                            if name in OUTCOME_UNITS else float(value))
        pole = directions_from_ra_dec_deg(row[_suffix("pole_ra", k, timed)], row[_suffix("pole_dec", k, timed)])
        row[_suffix("pole_shift", k, timed)] = float(angle_between_deg(pole, start_pole, "the pole", "the start pole")[0])
    row.update(_initial(scene.state))
    row.update(error_estimate=float(result.error_estimate.to_value(u.arcsec)), tolerance_met=bool(result.tolerance_met),
               route=str(result.plan.route))
    return row


def days_of(times):
    """TDB days since J2000 of a Time (scalar or array) as a 1-D float array."""
    return np.atleast_1d(tdb_days(times)[0])
