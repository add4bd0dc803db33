"""
Didymos and Dimorphos as two rigid figures, before and after a DART-like impact
================================================================================

The binary asteroid (65803) Didymos – Dimorphos in the full two-body problem: the relative orbit,
both attitudes and both spins integrated together, with the mutual potential of the two figures
expanded in inertia integrals to order 4 (Hou, Scheeres & Xin 2017; :mod:`spinorbit.core.binary`).
The set-up is the example case of the GUBAS code (``../shared/data/didymos_gubas_case.json``;
:mod:`spinorbit.data.didymos` says which number is derived and why): Dimorphos a
103.16 × 79.35 × 66.13 m ellipsoid, synchronous, 1.20 km from a spherical Didymos.

Dimorphos librates: its long axis swings about the line to Didymos with a **free** period set by its
shape (≈ n √(3(B − A)/C), with the corrections of ``docs/binary.md``) and a **forced** one, the
orbit's anomalistic period. Then a DART-like impact: Δv = β m v / M against the orbital motion with
DART's mass and speed and β = 3.61 (Cheng et al. 2023). Tilted 20° out of the orbit plane (an
illustrative choice, not DART's geometry), the impulse also excites out-of-plane motion, and
Dimorphos's rotation, read in Fukushima's canonical elements, leaves the principal axis: it tumbles.

Runs offline in about ten seconds (plus the one-off compilation).
"""

# gallery-arguments: --orbits 100
# sphinx_gallery_thumbnail_path = "gallery/plot_didymos_dart.png"

# %%
# The system and the nominal run
# ------------------------------

# sphinx_gallery_start_ignore
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # a checkout's spinorbit first, uninstalled
# sphinx_gallery_end_ignore
import argparse
import math

import matplotlib.pyplot as plt
import numpy as np
from astropy import units as u

from spinorbit.binary import momentum_impulse, propagate
from spinorbit.data.didymos import DART_BETA, DART_MASS, DART_SPEED, RELATIVE_SPEED, SEPARATION, didymos_state

parser = argparse.ArgumentParser()
parser.add_argument("--orbits", type=int, default=100)
orbits = parser.parse_known_args()[0].orbits

state = didymos_state(order=4)
period = (2 * math.pi * SEPARATION / RELATIVE_SPEED).to(u.s)
times = np.linspace(0.0, orbits, orbits * 40 + 1) * period
nominal = propagate(state, times, rtol=1e-12)


def report(label, run):
    parts = run.libration_components()
    tumbling, excess, p_psi, p_phi = run.tumbling_summary()
    print(f"{label}:")
    print(f"  mutual orbit period   {run.mutual_period().to_value(u.h):.4f} h")
    print(f"  free libration        {parts.free_period.to_value(u.h):.3f} h, {parts.free_amplitude.to_value(u.deg):.3f} deg")
    print(f"  forced libration      {parts.forced_period.to_value(u.h):.3f} h, {parts.forced_amplitude.to_value(u.deg):.3f} deg")
    print(f"  Dimorphos rotation    max E/E0 - 1 = {excess:.3g}"
          + (f", tumbling: P_psi = {p_psi.to_value(u.h):.2f} h, P_phi = {p_phi.to_value(u.h):.2f} h" if tumbling else
             ", principal-axis"))
    print(f"  max drift             |dE/E| = {run.energy_drift()[0].max():.1e}, |dH/H| = "
          f"{run.angular_momentum_drift().max():.1e}")


report("nominal", nominal)

# %%
# The impact
# ----------
# DART's momentum, enhanced by β, against Dimorphos's orbital velocity, 20° out of the orbit plane.

elevation = math.radians(20.0)
backwards = -state.velocity.value / np.linalg.norm(state.velocity.value)
direction = backwards * math.cos(elevation) + np.array([0.0, 0.0, math.sin(elevation)])
delta_v = momentum_impulse(DART_MASS, direction * DART_SPEED, DART_BETA, state.system.secondary.mass)
print(f"impact: |dv| = {np.linalg.norm(delta_v.to_value(u.mm / u.s)):.3f} mm/s")
after = propagate(state.with_velocity_change(delta_v), times, rtol=1e-12)
report("after the impact", after)

# %%
# Libration and tumbling
# ----------------------

hours = times.to_value(u.h)
figure, (top, middle, bottom) = plt.subplots(3, 1, figsize=(8, 8), sharex=True)
top.plot(hours, nominal.libration().to_value(u.deg), lw=0.8, label="nominal")
top.plot(hours, after.libration().to_value(u.deg), lw=0.6, label="after the impact")
top.set_ylabel("libration (deg)")
top.legend(loc="upper right", fontsize=8)
from spinorbit.core.binary.libration import COL_ENERGY_RATIO  # noqa: E402

middle.plot(hours, nominal.secondary_rotation()[:, COL_ENERGY_RATIO] - 1, lw=0.8, label="nominal")
middle.plot(hours, after.secondary_rotation()[:, COL_ENERGY_RATIO] - 1, lw=0.6, label="after the impact")
middle.set_ylabel("E/E0 - 1 of Dimorphos")
middle.legend(loc="upper right", fontsize=8)
bottom.semilogy(hours[1:], np.maximum.accumulate(after.energy_drift()[0][1:]) + 1e-17, label="max |dE/E|")
bottom.semilogy(hours[1:], np.maximum.accumulate(after.angular_momentum_drift()[1:]) + 1e-17, label="max |dH/H|")
bottom.set_ylabel("drift after the impact")
bottom.set_xlabel("time (h)")
bottom.legend(loc="lower right", fontsize=8)
figure.tight_layout()
plt.show()
