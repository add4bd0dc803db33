"""Asteroid data for the one-way examples: bodies, published spin states, and encounter geometries.

What is published and what is constructed
-----------------------------------------
**Spin states** (cited): (99942) Apophis, Pravec et al. 2014 (Icarus 233, 48): short-axis mode,
retrograde, P_ψ = 263 h, P_φ = 27.38 h, E/E0 = 1.024 ± 0.013, moment ratios A:B:C ≈ 0.61:0.965:1,
angular momentum towards ecliptic (λ, β) ≈ (250°, −75°), taken in the published tumbler form by
:meth:`spinorbit.RotationState.from_tumbling` (the rotation phase, unknown at 2029, is this package's choice). (4179) Toutatis, Takahashi, Busch & Scheeres
2013 (AJ 146, 95, Table 2): epoch 1992-11-09T17:49:47 UTC, moments (x, y, z) = 3.0836 : 3.235 : 1
(z the long axis), ZXZ Euler angles body → inertial (145.498°, 65.865°, 241.524°), body angular
velocity (14.51, 33.529, −98.709) deg/day.

**Apophis orbit (default)**: the JPL Horizons solution JPL#218 state at 2021-01-01 TDB
(:data:`APOPHIS_HORIZONS`), integrated to 2029 by :func:`published_orbit_simulation` /
:func:`apophis_encounter_simulation`; measured closest approach 38 054.9 km at 7.4209 km/s,
2029-04-13 21:46:13.7 TDB (docs/asteroids.md). The encounter geometry below remains the fallback
(``orbit="geometry"``) and is still used for Toutatis.

**Fallback orbits** (not an orbit solution): I cannot cite osculating elements *with* their epoch and mean
anomaly reliably from memory, and without the exact orbit solution no published element set pins a
close approach down to a few 10³ km anyway. So each asteroid is placed on a **documented encounter
geometry** that reproduces the published close-approach distance and speed:

- the geocentric hyperbola has the published perigee distance and perigee speed at the published
  time (:data:`APOPHIS_2029`, :data:`TOUTATIS_2004`);
- the *direction* of the incoming asymptote v∞ and of the impact parameter come from approximate
  heliocentric elements (a, e, i, Ω, ω; ecliptic J2000) of the asteroid, recalled from the JPL
  Small-Body Database and rounded — they are used only for directions: v∞ is the velocity of the
  point of that ellipse nearest Earth relative to Earth, and the impact-parameter direction is the
  part of the offset (ellipse point − Earth) perpendicular to v∞;
- the asteroid is then a massless particle in a REBOUND simulation of the Sun, planets, Moon and Pluto
  from DE421 (IAS15, ``exact_finish_time``) and is integrated backwards and forwards from the
  encounter.

The elements' |v∞| is printed by the examples next to the imposed one as a consistency check.

Attitude conventions: ``docs/conventions.md`` and :func:`toutatis_rotation_state` (how Takahashi
et al.'s "ZXZ body → inertial" angles are read).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u
from astropy.time import Time
from scipy.optimize import minimize_scalar

from spinorbit.body import RigidBody
from spinorbit.core.math import rotations as _rotations
from spinorbit.coupling.rebound import (
    DEFAULT_BODIES,
    body_index,
    install_extra_forces,
    integrate_interruptibly,
    simulation_from_de421,
    small_body_simulation,
)
from spinorbit.ephemeris import barycentric_state_au, de421_constants
from spinorbit.frames import icrf_to_ecliptic_matrix
from spinorbit.state import RotationState
from spinorbit.time import tdb_day_and_fraction, tdb_days, time_from_tdb_days

__all__ = [
    "HeliocentricDirections",
    "EncounterGeometry",
    "APOPHIS_ELEMENTS",
    "TOUTATIS_ELEMENTS",
    "APOPHIS_2029",
    "TOUTATIS_2004",
    "APOPHIS_BODY",
    "TOUTATIS_BODY",
    "TOUTATIS_EPOCH",
    "encounter_state",
    "encounter_simulation",
    "PublishedState",
    "APOPHIS_HORIZONS",
    "IAU_AU_KM",
    "published_orbit_simulation",
    "closest_approach",
    "apophis_encounter_simulation",
    "apophis_rotation_state",
    "APOPHIS_STATE_EPOCH",
    "APOPHIS_P_PSI",
    "APOPHIS_P_PHI",
    "APOPHIS_MOMENTUM_ECLIPTIC_DEG",
    "APOPHIS_MOMENT_RATIOS",
    "APOPHIS_PHI0",
    "APOPHIS_PSI0",
    "toutatis_rotation_state",
    "ecliptic_direction",
    "aligning_quaternion",
    "OsculatingElements",
    "TOUTATIS_ELEMENT_SETS",
    "TOUTATIS_APPROACHES",
    "toutatis_orbit",
]

DEG = math.pi / 180.0


@dataclass(frozen=True)
class HeliocentricDirections:
    """Approximate heliocentric ellipse (ecliptic J2000), used only for directions (module docstring).

    a in au, angles in degrees. No epoch or mean anomaly: the encounter fixes the timing.
    """

    a: float
    e: float
    inc: float
    node: float
    argp: float
    source: str


@dataclass(frozen=True)
class EncounterGeometry:
    """A published close approach: time, geocentric perigee distance and speed at perigee."""

    name: str
    time: Time
    distance_km: float
    speed_km_s: float
    elements: HeliocentricDirections
    source: str

    @property
    def time_tdb(self):
        """The encounter time on the TDB scale, converted through :mod:`spinorbit.time` (astropy's own
        ``.tdb`` warns "dubious year" for 2029 through an irrelevant UTC leg)."""
        return _tdb(self.time)


APOPHIS_ELEMENTS = HeliocentricDirections(
    0.9224, 0.1914, 3.339, 204.43, 126.39,
    "approximate pre-2029 JPL SBDB elements, recalled and rounded (the values of benchmarks/scenes.py)",
)
TOUTATIS_ELEMENTS = HeliocentricDirections(
    2.5336, 0.6294, 0.4469, 124.37, 278.7,
    "approximate JPL SBDB elements, recalled and rounded (the values of benchmarks/scenes.py)",
)

#: 2029-04-13 21:46 UTC. UTC after 2026 is not yet defined (future leap seconds are unknown, ERFA warns
#: "dubious year"); we assume none after 2017, so TT = UTC + 69.184 s.
APOPHIS_2029 = EncounterGeometry(
    "Apophis", Time("2029-04-13T21:47:09.184", scale="tt"), 38_000.0, 7.4, APOPHIS_ELEMENTS,
    "≈ 38 000 km from Earth's centre at ≈ 7.4 km/s on 2029-04-13 21:46 UTC ("
    "JPL Small-Body Database close-approach data give 38 012 km)",
)
#: 2004-09-29 ≈ 13:37 UTC at 0.01036 au (JPL Small-Body Database close-approach data). The perigee
#: speed is the one of the element-derived v∞ (computed, see :func:`encounter_state`), so ``speed_km_s``
#: is None here.
TOUTATIS_2004 = EncounterGeometry(
    "Toutatis", Time("2004-09-29T13:37:00", scale="utc"), 0.01036 * 149_597_870.7, None, TOUTATIS_ELEMENTS,
    "0.01036 au from Earth on 2004-09-29 (JPL Small-Body Database close-approach data); time of day ≈ 13:37 UTC (recalled, approximate)",
)

#: Apophis moment ratios A:B:C (Pravec et al. 2014), principal axes = user axes.
APOPHIS_BODY = RigidBody([0.61, 0.965, 1.0], name="Apophis")
#: Toutatis moments about the published body axes x, y, z (z the long axis; Takahashi et al. 2013).
TOUTATIS_BODY = RigidBody([3.0836, 3.235, 1.0], name="Toutatis")
#: Epoch of the Takahashi et al. (2013) Toutatis state (UTC as published).
TOUTATIS_EPOCH = Time("1992-11-09T17:49:47", scale="utc")


def ecliptic_direction(lon_deg, lat_deg):
    """ICRF unit vector of ecliptic-J2000 longitude and latitude (degrees)."""
    lon, lat = lon_deg * DEG, lat_deg * DEG
    ecl = np.array([math.cos(lat) * math.cos(lon), math.cos(lat) * math.sin(lon), math.sin(lat)])
    return icrf_to_ecliptic_matrix().T @ ecl


def _kepler_state_from_true_anomaly(el, nu, gm_sun):
    """Heliocentric ICRF position (au) and velocity (au/day) at true anomaly nu on ellipse ``el``."""
    p = el.a * (1 - el.e**2)
    r = p / (1 + el.e * math.cos(nu))
    pos = np.array([r * math.cos(nu), r * math.sin(nu), 0.0])
    vel = math.sqrt(gm_sun / p) * np.array([-math.sin(nu), el.e + math.cos(nu), 0.0])
    rot = (_rotations.rot3(-el.node * DEG) @ _rotations.rot1(-el.inc * DEG) @ _rotations.rot3(-el.argp * DEG))
    to_icrf = icrf_to_ecliptic_matrix().T
    return to_icrf @ rot @ pos, to_icrf @ rot @ vel


def encounter_state(geometry, return_details=False):
    """Geocentric ICRF state (au, au/day) of the asteroid at perigee of a documented encounter.

    Construction (module docstring): v̂∞ from the element ellipse point nearest Earth; impact-parameter
    direction b̂ = the part of (ellipse point − Earth) perpendicular to v̂∞; perigee speed v_p as
    published; when ``geometry.speed_km_s`` is None, v∞ is the ellipse's heliocentric velocity
    direction with the vis-viva speed of its semi-major axis at the perigee point, minus Earth's
    velocity (so the asteroid keeps the elements' orbital period); then, with
    e = 1 + r_p v∞²/μ and the turning angle δ (sin δ/2 = 1/e), the perigee velocity is
    v̂∞ rotated by δ/2 towards −b̂ (gravity bends the path towards Earth) and the perigee position
    r_p (sin δ/2 v̂∞ + cos δ/2 b̂), perpendicular to it.
    """
    constants = de421_constants()
    au_km = constants.au_km
    mu_earth, gm_sun = constants.gm["earth"], constants.gm["sun"]
    day, fraction = tdb_day_and_fraction(geometry.time)
    earth_r, earth_v = barycentric_state_au("earth", day, fraction)
    sun_r, sun_v = barycentric_state_au("sun", day, fraction)
    earth_helio, earth_helio_v = earth_r - sun_r, earth_v - sun_v
    el = geometry.elements

    def distance(nu):
        return np.linalg.norm(_kepler_state_from_true_anomaly(el, nu, gm_sun)[0] - earth_helio)

    coarse = np.linspace(-math.pi, math.pi, 721)
    nu0 = coarse[int(np.argmin([distance(x) for x in coarse]))]
    nu = minimize_scalar(distance, bracket=(nu0 - 0.01, nu0, nu0 + 0.01), tol=1e-12).x
    point, velocity = _kepler_state_from_true_anomaly(el, nu, gm_sun)
    v_inf_elements = float(np.linalg.norm(velocity - earth_helio_v))
    offset = point - earth_helio
    r_p = geometry.distance_km / au_km
    position = np.zeros(3)
    # Three passes: without a published speed, the vis-viva speed is taken at the asteroid's own
    # perigee position, which depends (weakly) on the v∞ direction it produces.
    for _ in range(3 if geometry.speed_km_s is None else 1):
        v_inf_vec = velocity - earth_helio_v
        if geometry.speed_km_s is None:
            # No published speed: keep the ellipse's heliocentric velocity direction but give it the
            # vis-viva speed of the elements' a at the asteroid's position, so that the semi-major axis
            # — hence the period and the near-commensurability with Earth that brings the asteroid
            # back every few years — is the elements' a (Earth's potential at perigee changes it by
            # < 1e-3 relative).
            r_here = float(np.linalg.norm(earth_helio + position))
            speed = math.sqrt(gm_sun * (2 / r_here - 1 / el.a))
            v_inf_vec = speed * velocity / np.linalg.norm(velocity) - earth_helio_v
        v_inf_hat = v_inf_vec / np.linalg.norm(v_inf_vec)
        b = offset - (offset @ v_inf_hat) * v_inf_hat
        if np.linalg.norm(b) < 1e-9:  # ellipse through Earth: any perpendicular; take ecliptic north's
            b = ecliptic_direction(0.0, 90.0) - (ecliptic_direction(0.0, 90.0) @ v_inf_hat) * v_inf_hat
        b_hat = b / np.linalg.norm(b)
        if geometry.speed_km_s is None:
            v_inf = float(np.linalg.norm(v_inf_vec))
            v_p = math.sqrt(v_inf**2 + 2 * mu_earth / r_p)
        else:
            v_p = geometry.speed_km_s * 86400.0 / au_km
            v_inf = math.sqrt(v_p**2 - 2 * mu_earth / r_p)
        ecc = 1 + r_p * v_inf**2 / mu_earth
        half_turn = math.asin(1 / ecc)
        velocity_hat = math.cos(half_turn) * v_inf_hat - math.sin(half_turn) * b_hat
        position_hat = math.sin(half_turn) * v_inf_hat + math.cos(half_turn) * b_hat
        position, perigee_velocity = r_p * position_hat, v_p * velocity_hat
    velocity = perigee_velocity
    if not return_details:
        return position, velocity
    kms = au_km / 86400.0
    return position, velocity, {
        "v_inf_elements_km_s": v_inf_elements * kms,
        "v_inf_km_s": v_inf * kms,
        "v_perigee_km_s": v_p * kms,
        "eccentricity": ecc,
        "ellipse_miss_distance_km": float(np.linalg.norm(offset)) * au_km,
        "v_inf_direction_icrf": v_inf_hat,
    }


def encounter_simulation(geometry, bodies=DEFAULT_BODIES, integrator="ias15"):
    """REBOUND simulation at the encounter time with the asteroid added as a massless particle.

    The Sun, planets, Moon and Pluto come from DE421 (:func:`~spinorbit.coupling.rebound.simulation.simulation_from_de421`);
    the asteroid (named ``geometry.name``) sits at Earth + :func:`encounter_state`.
    """
    sim = simulation_from_de421(_tdb(geometry.time), bodies=bodies, integrator=integrator)
    position, velocity = encounter_state(geometry)
    earth = sim.particles[body_index(sim, "earth")]
    sim.add(m=0.0, x=earth.x + position[0], y=earth.y + position[1], z=earth.z + position[2],
            vx=earth.vx + velocity[0], vy=earth.vy + velocity[1], vz=earth.vz + velocity[2], name=geometry.name)
    return sim


def _tdb(time):
    days, remainder = tdb_days(time)
    return time_from_tdb_days(days, remainder)


# ------------------------------------------------------------------------------------------------
# Published orbit solutions (heliocentric states from JPL Horizons).

#: IAU 2012 astronomical unit (km), the au of Horizons' output. DE421's au (its header ``AU``) is
#: 149 597 870.6996262 km, 2.5e-12 smaller in relative terms (docs/ephemeris.md).
IAU_AU_KM = 149_597_870.700


@dataclass(frozen=True)
class PublishedState:
    """A heliocentric ICRF state of a small body from an orbit solution, as published.

    ``position_au`` and ``velocity_au_day`` are in IAU 2012 au (:data:`IAU_AU_KM`) and TDB days, at
    ``epoch`` (TDB). ``elements`` keeps the osculating elements printed with them (ecliptic J2000,
    IAU76 obliquity; not used by the code, a record of what was published).
    """

    name: str
    epoch: Time
    position_au: tuple
    velocity_au_day: tuple
    elements: dict
    non_gravitational: dict
    source: str


#: (99942) Apophis, JPL Horizons, orbit solution JPL#218 (solution date 2023-Nov-06), retrieved in 2024
#: as Horizons output: "Equivalent ICRF heliocentric cartesian coordinates (au, au/d)" at
#: EPOCH = 2459215.5 = 2021-Jan-01.00 TDB. Horizons' model also has the non-gravitational terms A1, A2
#: (au/d², g(r) = (1 au/r)²) and Earth J2; :func:`published_orbit_simulation` includes both.
APOPHIS_HORIZONS = PublishedState(
    "Apophis",
    Time(2459215.5, format="jd", scale="tdb"),
    (-4.098530837957945e-01, 9.070198867765817e-01, 3.267919471926086e-01),
    (-1.507552412223498e-02, -3.713559924880165e-03, -1.761867984500986e-03),
    dict(EC=0.1915216892529348, QR=0.7458270479403062, TP=2459101.039422418, OM=204.0389271089114,
         W=126.6520518833791, IN=3.336751319526047, A=0.9225071817339578, MA=127.3225632500591),
    dict(A1=4.999999873689e-13, A2=-2.901092102547e-14),
    "JPL Horizons, (99942) Apophis, solution JPL#218 (2023-Nov-06), heliocentric ICRF state at "
    "2021-01-01.0 TDB (retrieved 2024)",
)


def published_orbit_simulation(state=APOPHIS_HORIZONS, time=None, bodies=DEFAULT_BODIES, integrator="ias15",
                               extra_forces=True, non_gravitational=True):
    """REBOUND simulation with a published heliocentric state, integrated to ``time``.

    The Sun, planets, Moon and Pluto come from DE421 at ``state.epoch``
    (:func:`~spinorbit.coupling.rebound.simulation.simulation_from_de421`); the body (named
    ``state.name``, massless) is placed at the simulation's Sun + the published heliocentric state,
    converted from IAU 2012 au to DE421's au (the simulation's unit). With ``extra_forces`` (default),
    :func:`~spinorbit.coupling.rebound.extra_forces.install_extra_forces` adds Earth's J2 and the EIH 1PN
    terms — Horizons' small-body model has both — and, with ``non_gravitational`` (default), the
    solution's own non-gravitational terms ``state.non_gravitational`` (A1, A2, A3 in au/d², g(r) =
    (1 au/r)², :func:`~spinorbit.coupling.rebound.extra_forces.set_nongravitational`). Left out are the
    asteroid perturbers. The run is IAS15 with ``exact_finish_time`` up to ``time`` (astropy Time;
    None: stay at the epoch).
    """
    if non_gravitational and not extra_forces:
        raise ValueError(
            "non_gravitational=True needs extra_forces=True (the terms live in the same compiled "
            "force); pass non_gravitational=False for a purely Newtonian run."
        )
    scale = IAU_AU_KM / de421_constants().au_km  # IAU 2012 au (Horizons) → DE421's au
    terms = None
    if non_gravitational and state.non_gravitational:
        terms = {k: v * scale for k, v in state.non_gravitational.items()}
    sim = small_body_simulation(state.name, state.epoch, np.asarray(state.position_au, float) * scale,
                                np.asarray(state.velocity_au_day, float) * scale, bodies=bodies,
                                integrator=integrator, extra_forces=extra_forces, non_gravitational=terms)
    if time is not None:
        day, fraction = tdb_day_and_fraction(time)
        integrate_interruptibly(sim, day + fraction)
    return sim


def closest_approach(sim, body, near, window_days=1.0, target="earth"):
    """Closest approach of ``body`` to ``target`` within ``near`` ± ``window_days`` (``sim`` is not moved).

    The smallest minimum of their distance found by :func:`spinorbit.coupling.approaches.approaches`
    on a copy of the simulation (the root of the range rate, to 1e-9 d); the same finder as
    :meth:`spinorbit.scene.Orbit.closest_approach`.

    Returns
    -------
    time : Time (TDB)
    distance_km : float
        Centre-to-centre, DE421 km.
    speed_km_s : float
        Relative speed at closest approach.
    """
    from spinorbit.coupling.approaches import approaches, rebound_separation

    au_km = de421_constants().au_km
    day, fraction = tdb_day_and_fraction(near)
    centre = day + fraction
    found = approaches(rebound_separation(sim, body, target), centre - window_days, centre + window_days)
    if not found:
        raise ValueError(f"no closest approach of {body} to {target} inside ±{window_days} d of {near.tdb.iso}.")
    when, distance, speed = min(found, key=lambda minimum: minimum[1])
    return time_from_tdb_days(when), distance * au_km, speed * au_km / 86400.0


def apophis_encounter_simulation(orbit="published", extra_forces=None):
    """Apophis for the 2029 encounter: a REBOUND simulation at :data:`APOPHIS_2029`'s time.

    ``orbit="published"`` (default): :data:`APOPHIS_HORIZONS` integrated from 2021-01-01 TDB with
    :func:`published_orbit_simulation` (Earth J2 + EIH + the solution's Yarkovsky terms on unless
    ``extra_forces=False``).
    ``orbit="geometry"``: the documented fallback encounter geometry, :func:`encounter_simulation`
    (no extra forces unless ``extra_forces=True``).
    """
    if orbit == "published":
        full = True if extra_forces is None else bool(extra_forces)
        return published_orbit_simulation(APOPHIS_HORIZONS, APOPHIS_2029.time_tdb,
                                          extra_forces=full, non_gravitational=full)
    if orbit == "geometry":
        sim = encounter_simulation(APOPHIS_2029)
        if extra_forces:
            install_extra_forces(sim)
        return sim
    raise ValueError(f"orbit must be 'published' or 'geometry', got {orbit!r}.")


# ------------------------------------------------------------------------------------------------
# Published osculating elements: orbits of their own (Orbit.from_elements).


@dataclass(frozen=True)
class OsculatingElements:
    """Heliocentric osculating elements at an epoch, as published (a in au, angles in degrees).

    ``frame`` is the frame name of :mod:`spinorbit.orbital_elements` the angles are referred to.
    """

    name: str
    epoch: Time
    a: float
    e: float
    inc: float
    raan: float
    argp: float
    mean_anomaly: float
    frame: str
    source: str

    def orbit(self, **options):
        """:meth:`spinorbit.scene.Orbit.from_elements` of these elements (``options``: non_gravitational,
        extra_forces)."""
        from spinorbit.scene import Orbit

        return Orbit.from_elements(self.a * u.au, self.e, self.inc * u.deg, self.raan * u.deg, self.argp * u.deg,
                                   self.mean_anomaly * u.deg, self.epoch, frame=self.frame, name=self.name, **options)


_TOUTATIS_SOURCE = ("JPL Small-Body Database osculating elements (ecliptic and equinox J2000) as quoted in public "
                    "encyclopedia infoboxes, 4-5 digits)")
#: (4179) Toutatis: the two published element sets of the project's reference data
#: (``../shared/data/toutatis_orbit.json``), keyed by the epoch's year. SBDB's ecliptic is JPL's
#: (IAU 1976 obliquity): ``frame="ecliptic"``. The 2008 set, the nearer to 1992–2012, is the default.
TOUTATIS_ELEMENT_SETS = {
    "2008": OsculatingElements("Toutatis", Time(2454797.5, format="jd", scale="tdb"), 2.5321, 0.6288, 0.4460,
                               124.30, 278.75, 5.1220, "ecliptic", _TOUTATIS_SOURCE + ", epoch 2008-11-27"),
    "2016": OsculatingElements("Toutatis", Time(2457400.5, format="jd", scale="tdb"), 2.5344, 0.62938, 0.44712,
                               124.37, 278.73, 281.88, "ecliptic", _TOUTATIS_SOURCE + ", epoch 2016-01-13"),
}
#: Toutatis' Earth approaches of the reference data: (date, distance au, published time of day or None,
#: how it is known). The checks of ``tests/test_orbits.py`` say what is measured against each.
TOUTATIS_APPROACHES = (
    ("1992-12-08", 0.024, None, "widely quoted; recalled, not read from a table"),
    ("2004-09-29", 0.0104, None, "public infobox text"),
    ("2008-11-09", 0.0502, "12:23 UTC", "public infobox text"),
    ("2012-12-12", 0.0463, "06:40 UTC", "'about 18 lunar distances', converted"),
)


def toutatis_orbit(orbit="elements", element_set="2008"):
    """Toutatis' orbit for a Scene: the published elements (default) or the 2004-flyby geometry.

    Parameters
    ----------
    orbit : {"elements", "geometry"}
        "elements": :data:`TOUTATIS_ELEMENT_SETS` ``[element_set]`` integrated among DE421's planets
        with EIH 1PN and Earth J2 (:meth:`spinorbit.scene.Orbit.from_elements`); it passes Earth in
        1992, 1996, 2000, 2004, 2008 and 2012 where the published approaches are (docs/asteroids.md).
        "geometry": the documented fallback, a hyperbola with the 2004 perigee imposed
        (:func:`encounter_simulation`); it misses the 1992 and 1996 approaches, so it is kept only to
        compare with the runs made on it before.
    element_set : {"2008", "2016"}
    """
    from spinorbit.scene import Orbit

    if orbit == "elements":
        if element_set not in TOUTATIS_ELEMENT_SETS:
            raise ValueError(f"element_set expects one of {tuple(TOUTATIS_ELEMENT_SETS)}; got {element_set!r}.")
        return TOUTATIS_ELEMENT_SETS[element_set].orbit()
    if orbit == "geometry":
        return Orbit("rebound", "Toutatis", simulation=encounter_simulation(TOUTATIS_2004),
                     description="documented 2004-flyby encounter geometry (0.01036 au imposed), DE421 planets")
    raise ValueError(f"orbit expects 'elements' or 'geometry'; got {orbit!r}.")


# ------------------------------------------------------------------------------------------------
# Spin states.


def aligning_quaternion(v_body, v_inertial):
    """Unit quaternion q (body → inertial) with M(q) v̂_body = v̂_inertial (the smallest rotation)."""
    a = np.asarray(v_body, float) / np.linalg.norm(v_body)
    b = np.asarray(v_inertial, float) / np.linalg.norm(v_inertial)
    q = np.concatenate([[1.0 + a @ b], np.cross(a, b)])
    return q / np.linalg.norm(q)


#: (99942) Apophis as Pravec et al. (2014, Icarus 233, 48) publish it, in the tumbler form of Kaasalainen (2001):
#: SAM, P_ψ = 263 ± 6 h, P_φ = 27.38 ± 0.07 h, angular momentum towards ecliptic (λ_L, β_L) = (250°, −75°),
#: moment ratios I1/I3 = 0.61, I2/I3 = 0.965 (3σ errors as published; E/E0 = 1.024 ± 0.013 follows from them,
#: the state gives 1.0236). Their Euler angles (φ0, ψ0) and epoch JD0 are not reproduced here: they were not in the
#: sources available when this module was written, and a 2012–13 phase could not be carried to 2029 anyway (P_ψ ± 6 h is
#: ± 0.5 turns after 16 years). :data:`APOPHIS_PHI0`, :data:`APOPHIS_PSI0` below are this package's choice.
APOPHIS_P_PSI = 263.0 * u.hour
APOPHIS_P_PHI = 27.38 * u.hour
APOPHIS_MOMENTUM_ECLIPTIC_DEG = (250.0, -75.0)
APOPHIS_MOMENT_RATIOS = (0.61, 0.965)

#: Where the Apophis state is placed: 5 days before the 2029 perigee (APOPHIS_2029, TDB). The published
#: periods and pole (2012-2013 photometry) do not fix the rotation phase 16 years later, so the state
#: at this epoch is the constructed one moved along its free motion by ``phase`` × P_psi.
APOPHIS_STATE_EPOCH = APOPHIS_2029.time_tdb - 5 * u.day
#: The rotation phase at :data:`APOPHIS_STATE_EPOCH` (not published; see above): ψ0 = 0 puts the body momentum in
#: the body's y–z plane, and φ0 is that of the state the examples and docs have used since they began (the
#: smallest rotation taking that body momentum to the published direction), so their numbers stay comparable.
#: θ0 follows from the periods and ψ0 (53.83°).
APOPHIS_PHI0 = 62.373763573 * u.deg
APOPHIS_PSI0 = 0.0 * u.deg


def apophis_rotation_state(phase=0.0, moment_ratios=APOPHIS_MOMENT_RATIOS):
    """Apophis (Pravec et al. 2014) at :data:`APOPHIS_STATE_EPOCH`, attitude relative to ICRF (its ``epoch``).

    ``RotationState.from_tumbling`` of the published P_ψ, P_φ, (λ_L, β_L) and moment ratios, with the phase
    (:data:`APOPHIS_PHI0`, :data:`APOPHIS_PSI0`) the published solution leaves unknown at 2029.

    Parameters
    ----------
    phase : float
        The rotation phase, in [0, 1): the state is moved along its own free motion by ``phase`` × P_ψ
        (its epoch stays). 0 (default) is the state itself, "phase as constructed" in the examples and docs.
    moment_ratios : (float, float)
        I1/I3, I2/I3 of the body (default: the published 0.61, 0.965); the ensemble varies them.
    """
    if not (isinstance(phase, (int, float)) and 0.0 <= phase < 1.0):
        raise ValueError(f"phase expects a fraction of the rotation period P_psi in [0, 1); got {phase!r}.")
    body = APOPHIS_BODY if tuple(moment_ratios) == APOPHIS_MOMENT_RATIOS else RigidBody(
        [*moment_ratios, 1.0], name="Apophis")
    state = RotationState.from_tumbling(body, APOPHIS_P_PSI, APOPHIS_P_PHI, *(a * u.deg for a in APOPHIS_MOMENTUM_ECLIPTIC_DEG),
                                        APOPHIS_PHI0, None, APOPHIS_PSI0, APOPHIS_STATE_EPOCH, mode="SAM")
    if phase == 0.0:
        return state
    quaternions, omegas = state.propagate_torque_free(phase * APOPHIS_P_PSI)
    return RotationState(body, quaternions[0], omegas[0], epoch=state.epoch)


#: Takahashi et al. (2013) Toutatis Euler angles (deg) and body angular velocity (deg/day, x, y, z).
TOUTATIS_EULER_DEG = (145.498, 65.865, 241.524)
TOUTATIS_OMEGA_DEG_DAY = (14.51, 33.529, -98.709)


def toutatis_rotation_state(frame="icrf"):
    """Toutatis at :data:`TOUTATIS_EPOCH` (Takahashi, Busch & Scheeres 2013, Table 2).

    Reading of "ZXZ Euler angles body → inertial (α, β, γ) = (145.498°, 65.865°, 241.524°)": the
    active rotation taking body axes to inertial axes is M = Rz(α) Rx(β) Rz(γ) (active elementary
    rotations). The project's attitude matrix is R = Mᵀ = R3(γ) R1(β) R3(α) with passive R1, R3, i.e.
    exactly the project's passive 3-1-3 angles (φ, θ, ψ) = (α, β, γ): ``from_euler313(body, α, β, γ)``.
    The inertial frame is taken as ecliptic J2000 (the frame of the radar spin solutions); the state is
    then rotated to ICRF for the torques. The spin (and so the periods 5.369 / 7.412 d) does not depend
    on this reading; the attitude — and through it the torques — does.

    Parameters
    ----------
    frame : {"icrf", "ecliptic"}
        Inertial frame of the returned attitude.
    """
    omega = np.array(TOUTATIS_OMEGA_DEG_DAY) * u.deg / u.day
    state = RotationState.from_euler313(TOUTATIS_BODY, *(a * u.deg for a in TOUTATIS_EULER_DEG), omega)
    if frame == "ecliptic":
        return state
    if frame != "icrf":
        raise ValueError(f"frame must be 'icrf' or 'ecliptic', got {frame!r}.")
    # v_body = R_ecl v_ecl = R_ecl E v_icrf with E the passive ICRF → ecliptic matrix.
    return RotationState.from_matrix(TOUTATIS_BODY, state.attitude_matrix @ icrf_to_ecliptic_matrix(), omega)
