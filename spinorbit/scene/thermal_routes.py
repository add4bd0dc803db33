"""The route runners of a scene that feels sunlight: the full torques and the mean YORP run.

Both take the plan's :class:`~spinorbit.scene.thermal_planning.ThermalSetup` (one model array) and
return ``(table, error_parts, stats)`` like :mod:`spinorbit.scene.routes`:

- :func:`run_thermal_full`: :func:`~spinorbit.core.integrators.quaternion.integrate_quaternion` under
  the Sun's gravity and the recoil, checked a posteriori (:func:`~spinorbit.scene.tolerances.refine`);
  the schema's table plus the osculating elements S, Z, H, h in the orbit frame.
- :func:`run_thermal_mean`: :func:`~spinorbit.core.averaging.thermal_mean.propagate_mean_thermal`,
  checked against a run at half its step; the table has the mean S, Z, H, h and what follows from
  them alone (pole of L, obliquity, mode, E/E0, periods), no attitude or ω.
"""

from __future__ import annotations

import numpy as np
from astropy import units as u

from spinorbit.scene.routes import attitude_angles, result_table
from spinorbit.scene.tolerances import MAX_RTOL_RETRIES, refine
from spinorbit.state_table import OMEGA_COLUMNS, add_obliquity, from_principal

__all__ = ["run_thermal_full", "run_thermal_mean", "rows_of_elements", "elements_of_rows"]

QUATERNION_COLUMNS = ("q_w", "q_x", "q_y", "q_z")
ELEMENT_COLUMNS = ("S", "Z", "H", "h")


def rows_of_elements(elements, setup):
    """Core rows (q, ω) on the principal axes of signed elements (S, Z, H, s, z, h) in the orbit frame."""
    from spinorbit.core.elements.canonical import inertia_constants
    from spinorbit.core.elements.equations import attitude_and_momentum, inertial_quaternion

    ic = inertia_constants(*setup.moments)
    rows = np.empty((len(elements), 7))
    for i, el in enumerate(np.asarray(elements, dtype=float)):
        attitude, momentum = attitude_and_momentum(np.ascontiguousarray(el), ic)
        rows[i, :4] = inertial_quaternion(attitude, setup.frame)
        rows[i, 4:] = momentum / setup.moments
    return rows


def elements_of_rows(rows, setup):
    """Signed osculating elements (n, 6) of core rows in the orbit frame, or None where a row has none."""
    from spinorbit.core.errors import SpinorbitError
    from spinorbit.core.integrators.elements import elements_of_state

    try:
        return np.array([elements_of_state(np.ascontiguousarray(y), setup.model, setup.frame) for y in rows])
    except SpinorbitError:  # a permanent rotation or the separatrix: no finite elements
        return None


def _element_columns(table, scene, elements, kind):
    unit = scene.state.body.moment_unit / u.day
    for i, name in enumerate(ELEMENT_COLUMNS[:3]):
        table[name] = elements[:, i] * unit
    table["h"] = np.degrees(np.mod(elements[:, 5], 2 * np.pi)) * u.deg
    table.meta["elements"] = (f"{kind} canonical elements S, Z = |L|, H = L·W in the orbit frame (P, Q, W) of the "
                              "Kepler orbit, h the node of L from P (deg)")


def _normals(scene, n):
    return np.tile(scene.orbit.kepler_frame()[2], (n, 1))


def run_thermal_full(scene, plan, report):
    """The full integration under the Sun's gravity and the recoil, checked a posteriori; ``report(fraction)``."""
    from spinorbit.core.integrators.quaternion import integrate_quaternion
    from spinorbit.scene.thermal import warn_if_yorp_vanishes

    warn_if_yorp_vanishes(scene.thermal)
    setup = plan.thermal["setup"]
    t_out = scene.output_days

    def run_and_check(rtol, check_rtol):
        ys, stats = integrate_quaternion(setup.y0, setup.t0, t_out, setup.model, rtol=rtol, return_stats=True)
        check = integrate_quaternion(setup.y0, setup.t0, t_out, setup.model, rtol=check_rtol)
        return (ys, stats), float(np.max(attitude_angles(ys[:, :4], check[:, :4])))

    def attempted(attempt):
        report((attempt + 1) / (MAX_RTOL_RETRIES + 1))

    (ys, stats), integration, rtol = refine("quaternion", plan.rtol, plan.integration_share_rad, run_and_check,
                                            attempted)
    ys[:, :4] /= np.linalg.norm(ys[:, :4], axis=1, keepdims=True)
    table = result_table(scene, *from_principal(scene.state.body, ys))
    add_obliquity(table, _normals(scene, len(table)))
    elements = elements_of_rows(ys, setup)
    if elements is not None:
        _element_columns(table, scene, elements, "osculating")
    else:
        table.meta["elements"] = "not given: a row is a permanent rotation or on the separatrix (no finite elements)"
    if "omega" not in scene.quantities:
        table.remove_columns(list(OMEGA_COLUMNS))
    table.meta["rtol"] = rtol
    stats = {k: stats[k] for k in ("accepted", "rejected", "rhs_calls") if k in stats}
    stats.update(integrator="quaternion", rtol=rtol)
    return table, {"dropped": 0.0, "integration": integration, "sampling": 0.0}, stats


def run_thermal_mean(scene, plan, report):
    """The mean YORP run (and its check at half the step): mean elements, pole, obliquity, periods."""
    from spinorbit.core.averaging.thermal_mean import SeparatrixReachedError, propagate_mean_thermal
    from spinorbit.scene.thermal import warn_if_yorp_vanishes
    from spinorbit.scene.thermal_planning import SeparatrixCrossingError, mean_difference
    from spinorbit.time import time_from_tdb_days

    warn_if_yorp_vanishes(scene.thermal)
    setup, info = plan.thermal["setup"], plan.thermal["mean"]
    t_out = scene.output_days

    def mean(step):
        return propagate_mean_thermal(setup.el0, setup.t0, t_out, setup.model, setup.frame, step,
                                      damping_constant=setup.damping)

    try:
        elements, steps = mean(info["step"])
    except SeparatrixReachedError as error:
        when = time_from_tdb_days(error.time)
        partial = _mean_table(scene, setup, error.elements, t_out[:len(error.times)]) if len(error.times) else None
        raise SeparatrixCrossingError(
            f"the mean YORP run reached the separatrix (1 − m below its threshold) near {when.tdb.iso} TDB, where "
            f"the torus average is undefined; the {len(error.times)} outputs before it are in the error's .table. "
            "A hand-over to the full integrator is not implemented: end the span before that time, or run "
            "thermal_route='full' across it (from a state you know there).", when, partial) from None
    report(0.6)
    check, _ = mean(0.5 * info["step"])  # half the step: twice it would land on the same outputs
    integration = mean_difference(elements, check)
    table = _mean_table(scene, setup, elements, t_out)
    table.meta["mean_step_days"] = info["step"]
    parts = {"dropped": 0.0, "short_period": info["short_period"], "averaging": info["averaging"],
             "integration": integration}
    return table, parts, {"integrator": "mean-dop853", "steps": int(steps), "step_days": info["step"]}


def _mean_table(scene, setup, elements, days):
    """The mean route's table: time, mean (S, Z, H, h), and the pole, obliquity and motion they define."""
    from spinorbit.scene.routes import result_table as _result_table

    rows = rows_of_elements(elements, setup)
    # The frozen phases s, z make some attitude: the pole of L, mode, E/E0 and periods do not depend on it.
    view = _Days(scene, days)
    table = _result_table(view, *from_principal(scene.state.body, rows))
    table.remove_columns([c for c in (*QUATERNION_COLUMNS, *OMEGA_COLUMNS) if c in table.colnames])
    add_obliquity(table, _normals(scene, len(table)))
    _element_columns(table, scene, np.asarray(elements), "mean")
    table.meta["estimated"] = ("mean (orbit- and torus-averaged) S, Z, H, h and what they alone define: the pole "
                               "of L, the obliquity, mode, E/E0 and the periods; not the attitude or ω (the rotation "
                               "phase is not followed)")
    return table


class _Days:
    """A scene seen with other output days (the rows a partial mean run reached)."""

    def __init__(self, scene, days):
        self.state, self.quantities, self.output_days = scene.state, scene.quantities, np.asarray(days)
