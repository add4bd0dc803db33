"""
A principal-axis rotator's obliquity and period over 10 years, on an orbit from elements
========================================================================================

Most asteroids spin about their axis of largest moment. Here such a body — moments 0.7 : 0.9 : 1, an
8-hour spin about C, its pole at ecliptic (λ, β) = (40°, 55°) — moves on an orbit given by
heliocentric osculating elements (illustrative round values of an inner main-belt orbit, not a
catalogued asteroid), integrated in REBOUND among DE421's planets
(:meth:`spinorbit.scene.Orbit.from_elements`). The Sun's degree-2 torque makes the spin axis
precess about the orbit's pole; over 10 years that turns the pole by a measurable angle while the
obliquity (the angle between spin axis and orbit pole) and the sidereal period stay nearly fixed.

The obliquity (to the osculating heliocentric orbit plane), the pole in ecliptic J2000 and the
sidereal period are columns of the result table (docs/conventions.md, "Output tables") and
properties of :class:`~spinorbit.RotationState`.

Runs offline in well under a minute.
"""

# %%
# The body, its spin state and its orbit
# --------------------------------------

# sphinx_gallery_start_ignore
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # a checkout's spinorbit first, uninstalled
# sphinx_gallery_end_ignore
import matplotlib.pyplot as plt
import numpy as np
from astropy import units as u
from astropy.time import Time

from spinorbit import RigidBody, RotationState
from spinorbit.data.asteroids import aligning_quaternion, ecliptic_direction
from spinorbit.scene import Orbit, Scene

epoch = Time("2020-01-01T00:00:00", scale="tdb")
orbit = Orbit.from_elements(2.4 * u.au, 0.12, 7.0 * u.deg, 60.0 * u.deg, 150.0 * u.deg, 20.0 * u.deg, epoch,
                            frame="ecliptic", name="rotator")
body = RigidBody([0.7, 0.9, 1.0], name="rotator")
period = 8.0 * u.h
pole = ecliptic_direction(40.0, 55.0)  # ICRF unit vector of the spin pole
# The body's C axis (0, 0, 1) on the pole, spinning about it: permanent rotation about C.
state = RotationState(body, aligning_quaternion([0.0, 0.0, 1.0], pole), [0.0, 0.0, 2 * np.pi / period.to_value(u.day)] * u.rad / u.day)
print(orbit.description)

# %%
# Ten years under the Sun's and Jupiter's torques
# -----------------------------------------------
times = epoch + np.linspace(5.0, 3652.5, 300) * u.day
scene = Scene(state, epoch, times, perturbers=("sun", "jupiter"), orbit=orbit, tolerance=20 * u.arcsec)
result = scene.run()
table = result.table
print(f"route {result.plan.route}, integrator {result.plan.integrator}, kept {', '.join(result.plan.kept)}; "
      f"dropped {', '.join(result.plan.dropped) or 'none'}; error estimate {result.error_estimate:.2f}")

# %%
# Obliquity, pole and sidereal period from the table
# --------------------------------------------------
# the table has them (docs/conventions.md, "Output tables"): the obliquity to the osculating
# heliocentric orbit plane, the pole in ecliptic J2000 and the sidereal period
obliquity = table["obliquity"].to_value(u.deg)
longitude, latitude = table["pole_lon"].to_value(u.deg), table["pole_lat"].to_value(u.deg)
sidereal = table["sidereal_period"].to(u.h)
print(f"obliquity {obliquity[0]:.4f}° → {obliquity[-1]:.4f}°; pole (λ, β) ({longitude[0]:.3f}°, {latitude[0]:.3f}°) → "
      f"({longitude[-1]:.3f}°, {latitude[-1]:.3f}°); sidereal period {sidereal[0]:.6f} → {sidereal[-1]:.6f}")

dates = table["time"].tdb.datetime64
figure, axes = plt.subplots(3, 1, figsize=(8, 8), sharex=True, layout="constrained")
axes[0].plot(dates, obliquity)
axes[0].set_ylabel("obliquity [deg]")
axes[1].plot(dates, longitude, label="λ")
axes[1].set_ylabel("pole longitude λ [deg]")
axes[2].plot(dates, (sidereal - period).to_value(u.ms), color="C2")
axes[2].set_ylabel("sidereal period − 8 h [ms]")
axes[2].set_xlabel("date (TDB)")
axes[0].set_title("A principal-axis rotator on an orbit from elements: Sun + Jupiter torques")
plt.show()
