"""
Apophis through its 2029 Earth encounter at a stated rotation phase
===================================================================

(99942) Apophis tumbles in short-axis mode (Pravec et al. 2014: P_ψ = 263 h, P_φ = 27.38 h,
angular momentum towards ecliptic (250°, −75°)). On 2029-04-13 it passes 38 000 km from Earth's
centre, and Earth's torque changes its spin. The published solution fixes the periods and the pole
but not the rotation phase sixteen years later, and the outcome depends on it, so the phase is a
parameter here: the state at its epoch, 2029-04-08 21:47 TDB (5 days before perigee), is the
constructed one moved along its free motion by ``PHASE`` × P_ψ
(:func:`spinorbit.data.asteroids.apophis_rotation_state`).

The orbit is JPL#218's Horizons state of 2021 integrated to 2029 in REBOUND among DE421's planets
with EIH 1PN, Earth J2 and the solution's Yarkovsky terms; its closest approach is an outcome
(:meth:`spinorbit.scene.Orbit.closest_approach`). The spin runs as a planned
:class:`~spinorbit.scene.Scene` under the Sun's, Earth's and Moon's torques over ±5 days.

Runs offline in about ten seconds.
"""

# %%
# The stated phase and the orbit
# ------------------------------

# sphinx_gallery_start_ignore
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))  # a checkout's spinorbit first, uninstalled
# sphinx_gallery_end_ignore
import matplotlib.pyplot as plt
import numpy as np
from astropy import units as u

from spinorbit.data.asteroids import (
    APOPHIS_2029,
    APOPHIS_STATE_EPOCH,
    apophis_encounter_simulation,
    apophis_rotation_state,
)
from spinorbit.scene import Orbit, Scene

#: The rotation phase at the state's epoch, as a fraction of P_psi (0: the state as constructed).
PHASE = 0.25

state = apophis_rotation_state(PHASE)
print(f"phase {PHASE} of P_psi at {APOPHIS_STATE_EPOCH.iso[:16]} TDB: {state.mode}, "
      f"P_psi = {state.periods[0].to(u.h):.2f}, P_phi = {state.periods[1].to(u.h):.2f}")
orbit = Orbit.from_rebound(apophis_encounter_simulation("published"), "Apophis")
perigee = APOPHIS_2029.time_tdb
when, distance = orbit.closest_approach("earth", perigee - 1 * u.day, perigee + 1 * u.day)
print(f"closest approach {when.iso[:19]} TDB at {distance:.1f} from Earth's centre")

# %%
# The spin through the encounter
# ------------------------------
times = perigee + np.linspace(-5.0, 5.0, 400) * u.day
result = Scene(state, APOPHIS_STATE_EPOCH, times, perturbers=("sun", "earth", "moon"), orbit=orbit,
               tolerance=1 * u.arcsec).run()
table = result.table
print(f"route {result.plan.route}, kept {', '.join(result.plan.kept)}, "
      f"error estimate {result.error_estimate:.3f} (tolerance met: {result.tolerance_met})")
for label, row in (("5 d before", table[0]), ("5 d after", table[-1])):
    print(f"{label}: {row['mode']}, P_psi = {row['P_psi'].to(u.h):.2f}, P_phi = {row['P_phi'].to(u.h):.3f}, "
          f"E/E0 = {row['energy_ratio']:.5f}")

# %%
# Periods, energy and Earth distance
# ----------------------------------
position, _ = orbit.relative_state("earth", times)
earth_km = np.linalg.norm(position.to_value(u.km), axis=1)
dates = table["time"].tdb.datetime64
figure, axes = plt.subplots(4, 1, figsize=(8, 9), sharex=True, layout="constrained")
axes[0].plot(dates, table["P_psi"].to_value(u.h))
axes[0].set_ylabel("P_ψ [h]")
axes[1].plot(dates, table["P_phi"].to_value(u.h), color="C1")
axes[1].set_ylabel("P_φ [h]")
axes[2].plot(dates, table["energy_ratio"], color="C2")
axes[2].set_ylabel("E/E0")
axes[3].semilogy(dates, earth_km, color="0.4")
axes[3].set_ylabel("Earth distance [km]")
axes[3].set_xlabel("date (TDB)")
for axis in axes:
    axis.axvline(when.tdb.datetime64, color="r", lw=0.8, alpha=0.6)
axes[0].set_title(f"(99942) Apophis through the 2029 encounter, phase {PHASE} of P_ψ")
plt.show()
