"""
Apophis's lightcurve before and after its 2029 Earth encounter
==============================================================

What an observer on Earth would see of (99942) Apophis in the days around its 2029-04-13 flyby. The
tumbling state is Pravec et al. (2014)'s (:func:`spinorbit.data.asteroids.apophis_rotation_state`:
P_ψ = 263 h, P_φ = 27.38 h, its angular momentum towards ecliptic (250°, −75°), at the phase the
other Apophis examples use). The encounter's torques change the spin, so the state runs as a planned
:class:`~spinorbit.scene.Scene` under the Sun, the Earth and the Moon, with outputs at the times the
body emits the light that reaches Earth in two windows: two days ending 3 days before perigee, and
two days starting 3 days after it (:func:`spinorbit.photometry.viewing_geometry` gives those times).
Then :func:`spinorbit.photometry.lightcurve` turns the scene's attitudes into magnitudes.

The shape is the homogeneous triaxial ellipsoid with the published moment ratios
(I1/I3 = 0.61, I2/I3 = 0.965: semi-axes in the ratio 0.82 : 0.57 : 0.54) and an equal-volume
diameter of 340 m. The surface scatters by the Kaasalainen law (Lommel–Seeliger + 0.1 Lambert). H,
G1 and G2 are illustrative values, not a fit: H = 19.1 mag, G1 = 0.25, G2 = 0.45. The geometry is the
Earth's centre from DE421, with light time.

Runs offline in about half a minute.
"""

# %%
# The state, the orbit and the shape
# ----------------------------------

# sphinx_gallery_start_ignore
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # a checkout's spinorbit first, uninstalled
# sphinx_gallery_end_ignore
import matplotlib.pyplot as plt
import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit.data.asteroids import (
    APOPHIS_2029,
    APOPHIS_MOMENT_RATIOS,
    APOPHIS_STATE_EPOCH,
    apophis_encounter_simulation,
    apophis_rotation_state,
)
from spinorbit.photometry import HG1G2, Ellipsoid, lightcurve, viewing_geometry
from spinorbit.scene import Orbit, Scene

# sphinx_gallery_thumbnail_path = "gallery/plot_apophis_lightcurve.png"
state = apophis_rotation_state()
orbit = Orbit.from_rebound(apophis_encounter_simulation("published"), "Apophis")
perigee = APOPHIS_2029.time_tdb

# Homogeneous ellipsoid: A ∝ b² + c², B ∝ a² + c², C ∝ a² + b²; solve for a², b², c² with C = 1.
ratio_a, ratio_b = APOPHIS_MOMENT_RATIOS
total = (ratio_a + ratio_b + 1.0) / 2.0
squares = np.array([total - ratio_a, total - ratio_b, total - 1.0])
axes = np.sqrt(squares) * (0.170 / np.prod(np.sqrt(squares)) ** (1 / 3))  # equal-volume radius 170 m
shape = Ellipsoid(axes * u.km)
phase_function = HG1G2(19.1 * u.mag, 0.25, 0.45)
print(f"{state.mode}: P_psi = {state.periods[0].to(u.h):.1f}, P_phi = {state.periods[1].to(u.h):.2f}; "
      f"ellipsoid semi-axes {np.round(axes * 1000).astype(int)} m")

# %%
# The spin through the encounter, sampled where the light leaves the body
# -----------------------------------------------------------------------
windows = {"before": perigee - 5 * u.day + np.linspace(0.0, 2.0, 241) * u.day,
           "after": perigee + 3 * u.day + np.linspace(0.0, 2.0, 241) * u.day}
observed = Time(np.concatenate([windows["before"].tdb.jd, windows["after"].tdb.jd]), format="jd", scale="tdb")
body_times = viewing_geometry(observed, orbit).emission_times
result = Scene(state, APOPHIS_STATE_EPOCH, body_times, perturbers=("sun", "earth", "moon"), orbit=orbit,
               tolerance=1 * u.arcsec).run()
print(f"scene: route {result.plan.route}, kept {', '.join(result.plan.kept)}, error estimate "
      f"{result.error_estimate:.3f}")
table = lightcurve(result, shape, orbit, phase_function=phase_function, law="kaasalainen")
print(table.meta["shadowing"])
halves = {"before": table[: len(windows["before"])], "after": table[len(windows["before"]):]}
for label, part in halves.items():
    print(f"{label}: {part['time'][0].tdb.iso[:16]} to {part['time'][-1].tdb.iso[:16]} TDB, "
          f"V = {part['magnitude'].min().value:.2f} to {part['magnitude'].max().value:.2f} mag "
          f"(reduced: amplitude {np.ptp(part['reduced_magnitude'].value):.2f} mag), phase angle {part['phase_angle'].mean():.1f}, "
          f"Earth {part['delta'].mean().to(u.km):.3g}, light time {part['light_time'].mean():.1f}")
before_row, after_row = result.table[0], result.table[-1]
print(f"spin: P_psi {before_row['P_psi'].to(u.h):.1f} -> {after_row['P_psi'].to(u.h):.1f}, "
      f"P_phi {before_row['P_phi'].to(u.h):.2f} -> {after_row['P_phi'].to(u.h):.2f}")

# %%
# The two lightcurves
# -------------------
figure, panels = plt.subplots(2, 2, figsize=(10, 6.5), layout="constrained")
for column, (label, part) in enumerate(halves.items()):
    dates = part["time"].tdb.datetime64
    panels[0, column].plot(dates, part["magnitude"].to_value(u.mag), color="C0")
    panels[0, column].set_title(f"{label} perigee ({part['time'][0].tdb.iso[:10]} to {part['time'][-1].tdb.iso[5:10]})")
    panels[1, column].plot(dates, part["reduced_magnitude"].to_value(u.mag), color="C1", label="reduced magnitude")
    twin = panels[1, column].twinx()
    twin.plot(dates, part["phase_angle"].to_value(u.deg), color="0.5", lw=0.8, label="phase angle")
    twin.set_ylabel("phase angle [deg]")
    panels[1, column].set_xlabel("date (TDB)")
    for panel in panels[:, column]:
        panel.tick_params(axis="x", labelrotation=30)
panels[0, 0].set_ylabel("apparent V [mag]")
panels[1, 0].set_ylabel("reduced V [mag]")
for panel in panels.flat:
    panel.invert_yaxis()  # brighter up
panels[0, 1].set_ylabel("apparent V [mag]")
panels[1, 1].set_ylabel("reduced V [mag]")
figure.suptitle("(99942) Apophis seen from Earth's centre around the 2029 encounter (illustrative H, G1, G2)")
plt.show()
