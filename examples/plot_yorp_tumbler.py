"""
A tumbler's spin over a million years under YORP and damping, planned by the Scene
===================================================================================

A 200 m asteroid — a Gaussian random sphere (σ = 0.15, seed 5) of density 2000 kg/m³ — tumbles with
a 6-hour spin on an orbit of a = 1 au, e = 0.1. Sunlight's recoil (Rubincam's zero-conductivity
model, docs/thermal.md) changes the size Z of its angular momentum, its obliquity ε (cos ε = H/Z
with the orbit normal as reference z) and its tumbling state (S/Z). A :class:`~spinorbit.scene.Scene`
with ``thermal=`` plans the run: over 10⁶ years it takes the mean YORP route (the recoil averaged
over the torus of the exact free motion, and over the orbit in closed form from the facets themselves)
and says why, with its error estimate.
Nutation damping (Burns & Safronov's time scale) pulls the tumbler back toward rotation about its
axis of largest moment; μQ = 10⁹ Pa and K₃² = 0.01 are illustrative values for a weak rubble pile.
Each 10⁶-year run costs some tens of CPU seconds, its check at half the step included (docs/thermal.md,
"Cost at matched accuracy"; the wall time printed below also carries the load of the machine it ran
on); the full integration would take hours (the plan says how many).

The attitude and spin of the :class:`~spinorbit.RotationState` are in the Scene's inertial frame
(ICRS, equatorial), while :meth:`~spinorbit.scene.Orbit.kepler` takes ecliptic elements, so this
orbit's plane is the ecliptic, tilted by 23.44° from the frame's equator: the spin starts at an
obliquity of 21.0°. Before this example ran through the Scene, the same quaternion was given in the
orbit frame itself (obliquity 31.0°), which is why its history then was different (Z/Z₀ 1.076 and
ε → 74.5° after 10⁶ yr, against 1.278 and 66.7° now). The inputs differ on purpose, not the theory:
the Scene's mean route is the core's ``propagate_mean_thermal`` on the Scene's starting elements
(tests/test_scene_thermal.py), and the old orbit-frame model started at the Scene's elements gives
the Scene's numbers. Until the mean route averaged the facets exactly it averaged the degree-8
harmonics, whose truncation gave 1.291 and 66.8° here (docs/thermal.md measures that truncation).
"""

# %%
# The shape, its body and its thermal model
# -----------------------------------------

# sphinx_gallery_thumbnail_path = "gallery/plot_yorp_tumbler.png"
# sphinx_gallery_start_ignore
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # a checkout's spinorbit first, uninstalled
# sphinx_gallery_end_ignore
import math

import matplotlib.pyplot as plt
import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit import RotationState
from spinorbit.scene import Orbit, Scene, ThermalModel
from spinorbit.shape import gaussian_random_sphere, rigid_body_from_shape

density = 2000 * u.kg / u.m**3
shape = gaussian_random_sphere(0.2 * u.km, 0.15, seed=5, subdivisions=3)
body = rigid_body_from_shape(shape, density=density)  # on the shape's principal axes
models = {"YORP": ThermalModel.from_shape(shape, density),
          "YORP + damping": ThermalModel.from_shape(shape, density, mu_q=1e9 * u.Pa)}
moments = np.array(body.principal_moments)
print(f"{len(shape)} facets, A : B : C = " + " : ".join(f"{m / moments[2]:.3f}" for m in moments))

# %%
# A tumbling start on a Kepler orbit, a million years asked
# ---------------------------------------------------------
epoch = Time("2020-01-01", scale="tdb")
orbit = Orbit.kepler(1 * u.au, 0.1, 0 * u.deg, 0 * u.deg, 0 * u.deg, 0 * u.deg, epoch)
omega = 2 * math.pi / 0.25  # rad/day: a 6-h rotation
q = np.array([0.9, 0.2, -0.3, 0.25])
state = RotationState(body, q / np.linalg.norm(q), np.array([0.3, 0.1, 1.0]) * omega * u.rad / u.day)
years = np.linspace(0.0, 1e6, 101)[1:]
# The state is in ICRS, the orbit's normal W on the ecliptic: the starting obliquity is their angle.
start_obliquity = math.degrees(math.acos(np.dot(state.angular_momentum_direction, orbit.kepler_frame()[2])))
print(f"obliquity at the start {start_obliquity:.1f}° (the orbit plane is the ecliptic, the state in ICRS)")
print(f"damping time at the start {models['YORP + damping'].damping_time(omega * u.rad / u.day):.3g}")
tables = {}
for label, thermal in models.items():
    # The estimate (0.06 × a relative change of ~1.7) sits at the 0.1 rad ceiling: the mean route is forced.
    scene = Scene(state, epoch, epoch + years * u.yr, orbit=orbit, thermal=thermal, tolerance=0.1 * u.rad,
                  thermal_route="mean")
    plan = scene.plan()
    if label == "YORP":
        print(plan)  # why the mean route, with the costs of both
    result = scene.run()
    tables[label] = table = result.table
    z0 = state.angular_momentum.to_value(u.kg * u.m**2 * u.rad / u.day)
    print(f"{label}: route {plan.route}, {result.stats['steps']} mean steps, {result.wall_seconds:.1f} s; "
          f"Z/Z0 {table['Z'][-1].value / np.linalg.norm(z0):.3f}, obliquity → {table['obliquity'][-1]:.1f}, "
          f"S/Z → {(table['S'][-1] / table['Z'][-1]).value:.4f}, mode {table['mode'][-1]}; error estimate "
          f"{result.error_estimate.to(u.deg):.3f} ({', '.join(f'{k} {v.to(u.deg):.2g}' for k, v in result.error_parts.items() if v.value)})")

# %%
# The mean evolution
# ------------------
figure, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True, layout="constrained")
z0 = np.linalg.norm(state.angular_momentum.to_value(u.kg * u.m**2 * u.rad / u.day))
for label, table in tables.items():
    kyr = (table["time"] - epoch).to_value(u.yr) / 1e3
    axes[0].plot(kyr, table["Z"].value / z0, label=label)
    axes[1].plot(kyr, table["obliquity"].to_value(u.deg), label=label)
    axes[2].plot(kyr, (table["S"] / table["Z"]).value, label=label)
    axes[3].plot(kyr, table["P_psi"].to_value(u.h), label=label)
axes[0].set_ylabel("Z / Z₀  (|L|)")
axes[1].set_ylabel("obliquity ε [deg]")
axes[2].set_ylabel("S / Z  (tumbling state)")
axes[3].set_ylabel("P_ψ [h]")
axes[3].set_xlabel(f"time since {epoch.tdb.iso[:10]} TDB [kyr]")
axes[0].legend()
axes[0].set_title("Mean YORP of a 200 m tumbler at 1 au, planned by the Scene (torus + orbit average)")
plt.show()
