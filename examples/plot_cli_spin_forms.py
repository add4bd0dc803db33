"""
Spin states typed as they are published: a pole and a period, a tumbler's periods and angles
============================================================================================

Light-curve inversions publish a principal-axis rotator as DAMIT does — ecliptic pole (λ, β),
sidereal period P, epoch and rotation angle φ0 — and a tumbler as Pravec et al. (2005) do — the
periods P_ψ and P_φ, the direction of the angular momentum (λ_L, β_L) and the z-x-z Euler angles
(φ0, θ0, ψ0) of the body in the momentum's frame. ``spinorbit torque-free`` and ``spinorbit
asteroid`` take both forms as options (``--pole``/``--period``/``--phase`` and
``--tumbling``/``--momentum``/``--euler-zxz``/``--mode``), each value followed by its unit, and the
scene file takes the same keys in ``[spin]`` (docs/cli.md, "Spin forms")::

    [spin]
    epoch = "2020-01-01T00:00:00"
    pole = ["40 deg", "55 deg"]
    period = "8 h"
    phase = "0 deg"

Here two such commands run, and the first row of each table is read back into the published form
with the API's inverses (:meth:`~spinorbit.RotationState.pole`,
:meth:`~spinorbit.RotationState.tumbling_parameters`): what was typed comes back. The plot shows
the ecliptic latitude of two body axes against the date: the rotator's spin axis stays on its
pole while its long axis turns every 8 hours; Apophis's axes nod and turn with its two periods.

Runs offline in a few seconds.
"""

# %%
# A principal-axis rotator, as DAMIT gives it
# -------------------------------------------

# sphinx_gallery_start_ignore
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # a checkout's spinorbit first, uninstalled
# sphinx_gallery_end_ignore
import shlex

import matplotlib.pyplot as plt
import numpy as np
from astropy import units as u
from astropy.table import Table

from spinorbit import RigidBody, RotationState, cli
from spinorbit.frames import icrf_to_ecliptic_matrix


def run(command):
    """Run one ``spinorbit`` command line as typed, and return its table."""
    print(f"$ {command}")
    assert cli.main(shlex.split(command)[1:]) == 0
    return Table.read(shlex.split(command)[-1])


def states(table, body):
    """The RotationState of each row (attitude: body axes → ICRF; omega in body axes, rad/day)."""
    q = np.column_stack([table[f"q_{c}"] for c in "wxyz"])
    omega = np.column_stack([table[f"omega_{c}"] for c in "xyz"])
    return [RotationState(body, q_row, omega_row * u.rad / u.day) for q_row, omega_row in zip(q, omega)]


def axis_latitude(row_states, axis):
    """Ecliptic latitude (deg) of a body axis (0: x, 1: y, 2: z) in each state."""
    ecliptic = icrf_to_ecliptic_matrix()
    vectors = np.array([ecliptic @ state.attitude_matrix[axis] for state in row_states])  # row i: axis i in ICRF
    return np.degrees(np.arcsin(np.clip(vectors[:, 2], -1.0, 1.0)))


rotator = RigidBody([0.7, 0.9, 1.0])
pa_table = run("spinorbit torque-free --moments 0.7 0.9 1 --pole 40 55 deg --period 8 h --phase 0 deg "
               "--epoch 2020-01-01 --span 2 d --n-times 193 --output rotator.ecsv")
pa_states = states(pa_table, rotator)
back = pa_states[0].pole()
print(f"read back: pole ({back.pole_lon.to_value(u.deg):.12f}, {back.pole_lat.to_value(u.deg):.12f}) deg, "
      f"P = {back.period.to_value(u.h):.12f} h, phase {(back.phase.to_value(u.deg) + 180) % 360 - 180:.12f} deg")

# %%
# A tumbler, as Pravec et al. (2014) give (99942) Apophis
# -------------------------------------------------------
# The published periods, momentum direction and moment ratios; the rotation phase in 2029 is not
# published, and φ0, ψ0 are those of :func:`spinorbit.data.asteroids.apophis_rotation_state` (θ0 then
# follows from the periods, the moments and ψ0: Kaasalainen 2001).

apophis = RigidBody([0.61, 0.965, 1.0])
tumbler_table = run("spinorbit torque-free --moments 0.61 0.965 1 --tumbling 263 27.38 h --momentum 250 -75 deg "
                    "--euler-zxz 62.373763573 53.83136931156045 0 deg --mode SAM --epoch 2029-04-08T21:47:09.186 "
                    "--span 30 d --n-times 721 --output apophis.ecsv")
tumbler_states = states(tumbler_table, apophis)
published = tumbler_states[0].tumbling_parameters()
print(f"read back: P_psi = {published.p_psi.to_value(u.h):.10f} h, P_phi = {published.p_phi.to_value(u.h):.10f} h, "
      f"L at ({published.momentum_lon.to_value(u.deg):.10f}, {published.momentum_lat.to_value(u.deg):.10f}) deg, "
      f"theta0 = {published.theta0.to_value(u.deg):.10f} deg, mode {published.mode}")

# %%
# The body axes against the date
# ------------------------------
figure, (top, bottom) = plt.subplots(2, 1, figsize=(9, 6.5), layout="constrained")
for axis, label in ((2, "C axis (largest moment)"), (0, "A axis (smallest moment)")):
    top.plot(pa_table["time"].datetime64, axis_latitude(pa_states, axis), label=label)
    bottom.plot(tumbler_table["time"].datetime64, axis_latitude(tumbler_states, axis), label=label)
top.set_title("principal-axis rotator: --pole 40 55 deg --period 8 h")
bottom.set_title("(99942) Apophis: --tumbling 263 27.38 h --momentum 250 -75 deg")
for panel in (top, bottom):
    panel.set_ylabel("ecliptic latitude [deg]")
    panel.legend(loc="best", fontsize="small")
    panel.tick_params(axis="x", labelrotation=20)
top.set_xlabel("date and hour, January 2020 (TDB)")
bottom.set_xlabel("date (TDB)")
plt.show()
# sphinx_gallery_thumbnail_path = "gallery/plot_cli_spin_forms.png"
