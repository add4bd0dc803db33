"""A run's output table: one RotationState per row (the former build) against all rows at once.

For a torque-free run of 2000 outputs (an axisymmetric body, whose flow is the closed-form regular
precession, and a triaxial SAM body): the wall time of the exact flow itself, of the table built from
one :class:`~spinorbit.RotationState` per row (quaternion, omega, momentum direction, mode, E/E0,
P_ψ, P_φ read from each row's properties, as ``Scene`` and ``propagate_one_way`` did), of the same
columns from :func:`spinorbit.state_table.table_columns` with each row's own motion (``"rows"``, what
the one-way route does) and with the motion's constants taken once (the torque-free route), and of
the whole ``Scene.run``. Best of ``--repeat``, all alternated in one process: read the ratios.

Usage::

    python benchmarks/bench_state_table.py            # writes the 'state_table' section of docs/performance.md
    python benchmarks/bench_state_table.py --no-write # print only
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from astropy import units as u
from astropy.table import QTable
from astropy.time import Time

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from _report import interleaved_timings, machine_line, repeat_main

from spinorbit import RigidBody, RotationState
from spinorbit.scene import Scene
from spinorbit.state_table import table_columns

EPOCH = Time("2020-01-01", scale="tdb")
OUTPUTS = 2000


def cases():
    """(name, state): the 'closed form' scene of bench_scene_skips.py and the same spin on a triaxial body."""
    spin = [5, 3, 40] * u.deg / u.hour
    return [("axisymmetric (1, 1, 2), regular precession", RotationState.from_euler313(
                RigidBody([1.0, 1.0, 2.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg, spin)),
            ("triaxial SAM (0.61, 0.965, 1), elliptic flow", RotationState.from_euler313(
                RigidBody([0.61, 0.965, 1.0]), 10 * u.deg, 40 * u.deg, 70 * u.deg, spin))]


def per_row_table(body, quaternions, omegas):
    """The former build: one RotationState per row and its properties."""
    states = [RotationState(body, q, w * u.rad / u.day) for q, w in zip(quaternions, omegas)]
    table = QTable()
    for i, name in enumerate(("q_w", "q_x", "q_y", "q_z")):
        table[name] = np.array([s.quaternion[i] for s in states])
    for i, name in enumerate(("omega_x", "omega_y", "omega_z")):
        table[name] = np.array([s.angular_velocity[i].to_value(u.rad / u.day) for s in states]) * (u.rad / u.day)
    icrf, ecliptic = [s.pole_icrf for s in states], [s.pole_ecliptic for s in states]
    table["pole_ra"], table["pole_dec"] = ([p[i].to_value(u.deg) for p in icrf] * u.deg for i in (0, 1))
    table["pole_lon"], table["pole_lat"] = ([p[i].to_value(u.deg) for p in ecliptic] * u.deg for i in (0, 1))
    table["mode"] = [s.mode for s in states]
    table["energy_ratio"] = [s.energy_ratio for s in states]
    pairs = [s.periods for s in states]
    table["P_psi"] = [p[0].to_value(u.h) for p in pairs] * u.h
    table["P_phi"] = [p[1].to_value(u.h) for p in pairs] * u.h
    table["sidereal_period"] = [s.sidereal_period.to_value(u.h) for s in states] * u.h
    return table


def columns_table(body, quaternions, omegas, motion):
    table = QTable()
    for name, column in table_columns(body, quaternions, omegas, motion=motion).items():
        table[name] = column
    return table


def measure(repeat):
    rows = []
    offsets = np.linspace(0.01, 100.0, OUTPUTS)
    for name, state in cases():
        body = state.body
        scene = Scene(state, EPOCH, EPOCH + offsets * u.day, tolerance=1e-12 * u.rad)
        quaternions, omegas = state.propagate_torque_free(offsets * u.day)
        omegas = omegas.to_value(u.rad / u.day)
        work = {
            "flow": lambda: state.propagate_torque_free(offsets * u.day),
            "per row": lambda: per_row_table(body, quaternions, omegas),
            "columns, rows": lambda: columns_table(body, quaternions, omegas, "rows"),
            "columns, constants": lambda: columns_table(body, quaternions, omegas, state),
            "scene": lambda: scene.run(scene.plan()),
        }
        timings, _ = interleaved_timings(work.values(), repeat, warm_up=True)  # warm-up: numba compilation
        best = dict(zip(work, timings))
        old, new = per_row_table(body, quaternions, omegas), columns_table(body, quaternions, omegas, state)
        spread = max(float(np.max(np.abs(new[k].value / old[k].value - 1))) for k in ("energy_ratio", "P_psi", "P_phi", "sidereal_period"))
        rows.append({"case": name, **best, "spread": spread})
        print(f"{name}: " + "  ".join(f"{k} {v.text(fmt='.3f')} ms" for k, v in best.items()) + f"  max rel {spread:.1e}")
    return rows


def _ms(timing, fmt):
    return f"{timing.median * 1e3:{fmt}} ({timing.min * 1e3:{fmt}}–{timing.max * 1e3:{fmt}})"


def markdown(rows, repeat):
    lines = ["## A run's output table (`benchmarks/bench_state_table.py`)", "", machine_line(), "",
             (f"Torque-free run of {OUTPUTS} outputs over 100 d. Wall time (ms, median (min–max) of {repeat}, all "
              "alternated in one process) of the exact flow, of the table from one `RotationState` per row (the former build), of "
              "the same columns from `state_table.table_columns` with each row's own mode/E/E0/periods (`rows`: the "
              "one-way route) and with them taken once as constants of the motion (the torque-free route), and of "
              "the whole `Scene.run` (planning included). Max rel = largest relative difference of E/E0, P_psi, P_phi, "
              "the sidereal period between the constants and the per-row values (the columns include the spin pole since issue 15)."), "",
             "| body | flow | per row | columns, rows | columns, constants | per row / constants | Scene.run | max rel |",
             "|---|---:|---:|---:|---:|---:|---:|---:|"]
    for r in rows:
        lines.append(f"| {r['case']} | {_ms(r['flow'], '.3f')} | {_ms(r['per row'], '.1f')} | "
                     f"{_ms(r['columns, rows'], '.2f')} | {_ms(r['columns, constants'], '.2f')} | "
                     f"{r['per row'].median / r['columns, constants'].median:.0f} | {_ms(r['scene'], '.2f')} "
                     f"| {r['spread']:.1e} |")
    return "\n".join(lines)


def main(argv=None):
    repeat_main("state_table", __doc__.splitlines()[0], measure, markdown, repeat=5, argv=argv)


if __name__ == "__main__":
    main()
