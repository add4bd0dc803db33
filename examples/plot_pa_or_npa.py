"""
Principal-axis rotator or tumbler: the wobble amplitude and the rotation class
==============================================================================

Every spin state off a principal axis by any amount is, mathematically, a tumbler: ten years of the
Sun's torque on an 8-hour rotation about the axis of largest moment leave a wobble of a few hundredths
of an arcsecond, and with it a finite P_ψ, P_φ split of what is one rotation. Observers call a body
non-principal-axis (NPA) only when the wobble shows in its lightcurve (Pravec et al. 2005). spinorbit
measures each state's **wobble amplitude** — the largest angle between the axis the motion circulates
about and the angular momentum, over the free motion — and calls the state principal-axis ("PA") when it
is at most a threshold (default 1°, docs/design.md "PA or NPA"), else "SAM" or "LAM".

This example runs the case of issue 35 (moments 1 : 1.2 : 1.5, 8 h about C, an orbit from elements, 10
years of solar torque), prints its rows as an observer would report them, re-classifies the table at
other thresholds, compares a real tumbler (Apophis, Pravec et al. 2014), and plots what does change in
a PA run: the pole's drift, the obliquity, the sidereal period and the wobble itself.

Runs offline in about a minute (the orbit is integrated in REBOUND among DE421's planets).
"""

# %%
# The body, its spin and its orbit
# --------------------------------

# sphinx_gallery_start_ignore
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # a checkout's spinorbit first, uninstalled
# sphinx_gallery_end_ignore
# sphinx_gallery_thumbnail_path = "gallery/plot_pa_or_npa.png"
import matplotlib.pyplot as plt
import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.data.asteroids import apophis_rotation_state
from spinorbit.frames import icrf_to_ecliptic_matrix
from spinorbit.scene import Orbit, Scene
from spinorbit.state_table import classify_rows

epoch = Time("2020-01-01T00:00:00", scale="tdb")
orbit = Orbit.from_elements(1.5 * u.au, 0.2, 10 * u.deg, 80 * u.deg, 30 * u.deg, 10 * u.deg, epoch, frame="ecliptic",
                            name="example")
body = RigidBody([1.0, 1.2, 1.5], name="example")
# attitude: passive 3-1-3 angles (10°, 40°, 70°) from the ecliptic; spin 1080 deg/day (8 h) about C
ecliptic = RotationState.from_euler313(body, 10 * u.deg, 40 * u.deg, 70 * u.deg, [0, 0, 1080] * u.deg / u.day)
state = RotationState.from_matrix(body, ecliptic.attitude_matrix @ icrf_to_ecliptic_matrix(),
                                  ecliptic.angular_velocity, epoch=epoch)
print(f"start: mode {state.mode}, wobble amplitude {state.wobble_amplitude:.3g}, class {state.rotation_class()}, "
      f"P = {state.sidereal_period.to(u.h):.4f}")

# %%
# Ten years of solar torque
# -------------------------
times = epoch + np.linspace(0.0, 3652.5, 400) * u.day
result = Scene(state, times=times, perturbers=("sun",), orbit=orbit).run()
table = result.table
print(f"route {result.plan.route}, integrator {result.plan.integrator}; error estimate {result.error_estimate:.3f}")


def report(row):
    """A row as an observer reports it: one period for PA, P_ψ and P_φ for a tumbler."""
    if row["rotation_class"] == "PA":
        return f"PA, P = {row['sidereal_period'].to_value(u.h):.4f} h"
    return (f"{row['rotation_class']}, P_psi = {row['P_psi'].unmasked.to_value(u.h):.2f} h, "
            f"P_phi = {row['P_phi'].unmasked.to_value(u.h):.2f} h")


for label, row in (("first", table[0]), ("last", table[-1])):
    print(f"{label:5s} {row['time'].iso[:10]}  {report(row)}  (wobble {row['wobble_amplitude'].to(u.arcsec):.4f}, "
          f"mode {row['mode']})")
classes = sorted(set(table["rotation_class"].tolist()))
print(f"classes over the run: {classes}; largest wobble {table['wobble_amplitude'].max().to(u.arcsec):.4f}")

# %%
# The same rows at other thresholds
# ---------------------------------
# The amplitude is always in the table and the periods stay under the mask, so a reader can
# re-classify: at 0° every row off the axis by rounding is a SAM, with the small-wobble limits of its
# periods (P_ψ ≈ 22.6 h here), which is the split the threshold exists to hide.
for threshold in (1 * u.deg, 0.01 * u.arcsec, 0 * u.deg):
    classify_rows(table, threshold)
    counts = {name: int(np.sum(table["rotation_class"] == name)) for name in sorted(set(table["rotation_class"].tolist()))}
    print(f"threshold {threshold:g}: {counts}; last row {report(table[-1])}")
classify_rows(table)  # back to the default

# %%
# A real tumbler for comparison
# -----------------------------
apophis = apophis_rotation_state()
print(f"Apophis (Pravec et al. 2014): mode {apophis.mode}, wobble amplitude {apophis.wobble_amplitude:.2f}, "
      f"class {apophis.rotation_class()}, P_psi = {apophis.periods[0].to(u.h):.1f}, "
      f"P_phi = {apophis.periods[1].to(u.h):.2f}")

# %%
# What changes in a principal-axis run
# ------------------------------------
# The pole drifts (the Sun's torque precesses it about the orbit normal), the obliquity and the sidereal
# period oscillate with the orbit, and the wobble stays a few hundredths of an arcsecond, 10⁵ times below the
# 1° threshold: the run is PA in every row. The pole drift is the pole's offset from its start on the
# ecliptic sky (east: Δλ cos β, north: Δβ). The period and the wobble are osculating values: they carry
# short-period terms of the rotation and the orbit, which rows 9 days apart sample (and alias), so read
# their envelopes, not their wiggles.
lon, lat = np.radians(table["pole_lon"].to_value(u.deg)), np.radians(table["pole_lat"].to_value(u.deg))
east = np.degrees(np.arcsin(np.cos(lat) * np.sin(lon - lon[0]))) * 3600
north = np.degrees(np.arcsin(np.clip(np.sin(lat) * np.cos(lat[0]) - np.cos(lat) * np.sin(lat[0]) * np.cos(lon - lon[0]),
                                     -1, 1))) * 3600
obliquity = table["obliquity"].to(u.arcsec)
period = table["sidereal_period"]
dates = table["time"].tdb.datetime64
figure, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True, layout="constrained")
axes[0].plot(dates, east, label="east, Δλ cos β")
axes[0].plot(dates, north, label="north, Δβ")
axes[0].set_ylabel("pole drift [arcsec]")
axes[0].legend(fontsize="small")
axes[1].plot(dates, (obliquity - obliquity[0]).value, color="C4")
axes[1].set_ylabel(f"obliquity − {obliquity[0].to(u.deg):.4f}\n[arcsec]")
axes[2].plot(dates, (period - period[0]).to_value(u.ms), color="C5")
axes[2].set_ylabel(f"P − {period[0].to(u.h):.6f}\n[ms]")
axes[3].plot(dates, table["wobble_amplitude"].to_value(u.arcsec), color="C2")
axes[3].set_ylabel("wobble amplitude\n[arcsec]")
axes[3].set_xlabel("date (TDB)")
axes[0].set_title("8 h rotator, 10 yr of solar torque: PA in every row (threshold 1°)")
plt.show()
