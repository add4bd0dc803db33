"""Where a rotating body's orbit comes from: :class:`Orbit` and its constructors, and its close approaches.

An orbit is DE421's (:meth:`Orbit.de421`), a user ephemeris (:meth:`Orbit.ephemeris`,
:meth:`Orbit.circular`), or a REBOUND run: one the user owns (:meth:`Orbit.rebound`,
:meth:`Orbit.from_rebound`) or one built here from published osculating elements
(:meth:`Orbit.from_elements`) or a state vector (:meth:`Orbit.from_state`) at an epoch. The built
runs have DE421's Sun, planets, Moon and Pluto and the force model of the shipped Apophis orbit
(:mod:`spinorbit.coupling.rebound.small_body`: EIH 1PN, Earth J2, optional A1/A2/A3).
:meth:`Orbit.approaches` and :meth:`Orbit.closest_approach` find where the body passes closest to
another (:mod:`spinorbit.coupling.approaches`). Elements and frames: :mod:`spinorbit.orbital_elements`.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u
from astropy.table import QTable
from astropy.time import Time

from spinorbit.core.errors import SpinorbitError
from spinorbit.quantities import require_quantity, value_in
from spinorbit.scene.errors import SceneError
from spinorbit.time import tdb_days, time_from_tdb_days

__all__ = ["APPROACH_MAX_DISTANCE", "NON_GRAVITATIONAL_TERMS", "ApproachError", "Orbit"]

#: The non-gravitational terms a built orbit takes (JPL's small-body model, g(r) = (1 au/r)²).
NON_GRAVITATIONAL_TERMS = ("A1", "A2", "A3")
#: G of REBOUND's ("AU", "day", "Msun") units = DE421's GM_Sun in au³/day², to this relative difference.
UNITS_G_TOLERANCE = 1e-6


class ApproachError(SpinorbitError, ValueError):
    """No close approach inside the span asked for, or a span an orbit cannot be asked about."""


#: The default cut-off of :meth:`Orbit.approaches`: JPL's Close-Approach Data lists one object's approaches
#: to 0.2 au (its documented per-object query, https://ssd-api.jpl.nasa.gov/doc/cad.html; the 0.05 au default
#: there is the all-NEO survey's, which would drop Toutatis's 2008 approach at 0.0502 au). A minimum farther
#: out is the body passing on the far side of its orbit, not an encounter.
APPROACH_MAX_DISTANCE = 0.2 * u.au


def _scalar_time(name, value):
    if not isinstance(value, Time) or not value.isscalar:
        raise SceneError(f"{name} expects a scalar astropy Time such as Time('2004-09-29', scale='tdb'); "
                         f"got {value!r}.")
    whole, rest = tdb_days(value)
    return float(whole + rest)


def _check_inside_de421(what, *days):
    from spinorbit.ephemeris import DE421_SPAN_JD_TDB, J2000_JD_TDB, EphemerisRangeError

    lo, hi = (jd - J2000_JD_TDB for jd in DE421_SPAN_JD_TDB)
    outside = [d for d in days if not lo <= d <= hi]
    if outside:
        raise EphemerisRangeError(
            f"{what} expects times inside DE421's span (1899-12-04 to 2200-02-01 TDB, JD "
            f"{DE421_SPAN_JD_TDB[0]}–{DE421_SPAN_JD_TDB[1]}); got JD {outside[0] + J2000_JD_TDB:.1f} TDB. "
            "Choose an epoch and span inside it."
        )


def _non_gravitational(terms, au_km):
    """``{"A1": Quantity, …}`` (acceleration at 1 au) → DE421 au/day² floats, or SceneError."""
    if terms is None:
        return None
    if not isinstance(terms, dict) or not set(terms) <= set(NON_GRAVITATIONAL_TERMS):
        raise SceneError(f"non_gravitational expects a dict with keys among {NON_GRAVITATIONAL_TERMS} "
                         f"such as {{'A2': -2.9e-14 * u.au / u.day**2}}; got {terms!r}.")
    out = {}
    for key, value in terms.items():
        if (not isinstance(value, u.Quantity) or value.unit.physical_type != "acceleration"
                or not value.isscalar or not math.isfinite(value.value)):
            raise SceneError(f"non_gravitational[{key!r}] expects a finite acceleration Quantity "
                             f"(au/d² at 1 au, as JPL publishes A1, A2, A3); got {value!r}.")
        out[key] = float(value.to_value(u.km / u.day**2)) / au_km
    return out


@dataclass(frozen=True)
class Orbit:
    """Where the rotating body's orbit (and its perturbers' positions) come from.

    Build with :meth:`de421`, :meth:`ephemeris`, :meth:`circular`, :meth:`rebound` /
    :meth:`from_rebound`, :meth:`from_elements` or :meth:`from_state`. ``description`` says in words
    where the orbit came from (the commands print it and the gallery examples quote it).
    """

    kind: str
    name: str
    function: object = None
    simulation: object = None
    description: str = ""
    #: Built here among DE421's planets: runs stay inside DE421's span (:meth:`check_span`).
    de421_planets: bool = False
    #: Of kind "kepler": the heliocentric ellipse as ICRF elements (a au, e, i, Ω, ω, M rad, epoch TDB day).
    kepler_elements: tuple | None = None

    @classmethod
    def de421(cls, name):
        """A body DE421 carries (e.g. ``"moon"``); perturbers are DE421 bodies."""
        from spinorbit.ephemeris import resolve_body

        return cls("de421", resolve_body(name))

    @classmethod
    def ephemeris(cls, function, name="body"):
        """A user ephemeris ``function(days) -> (positions (n, 3) au, velocities (n, 3) au/day)``,
        barycentric ICRF at TDB days since J2000; perturbers are DE421 bodies."""
        if not callable(function):
            raise SceneError(f"Orbit.ephemeris expects a callable days -> (positions, velocities); got "
                             f"{type(function).__name__}.")
        return cls("ephemeris", str(name), function=function)

    @classmethod
    def circular(cls, radius, name="circular"):
        """A synthetic user ephemeris: a circle of ``radius`` (length Quantity) about the barycentre in
        the ICRF xy plane, at the Keplerian rate of DE421's GM_Sun, starting on +x at J2000. For
        scenes whose geometry should be simple (tests, benchmarks, tutorials)."""
        from spinorbit.ephemeris import de421_constants

        require_quantity("radius", radius, u.au, "2.5 * u.au")
        if not isinstance(radius, u.Quantity) or radius.unit.physical_type != "length" or not radius.value > 0:
            raise SceneError(f"Orbit.circular expects a positive length Quantity such as 2.5 * u.au; got {radius!r}.")
        r = float(radius.to_value(u.au))
        n = math.sqrt(de421_constants().gm["sun"] / r**3)

        def orbit(days):
            days = np.atleast_1d(np.asarray(days, dtype=float))
            c, s, zero = np.cos(n * days), np.sin(n * days), np.zeros(days.shape)
            return r * np.stack([c, s, zero], axis=1), r * n * np.stack([-s, c, zero], axis=1)

        return cls("ephemeris", str(name), function=orbit)

    @classmethod
    def kepler(cls, a, e, inc, raan, argp, mean_anomaly, epoch, frame="ecliptic", name="body"):
        """A fixed heliocentric Kepler ellipse: the Sun alone, exact at any time (thermal scenes over 10⁶ yr).

        The elements and frames are those of :meth:`from_elements`, but nothing is integrated: the Sun
        moves on the two-body ellipse of DE421's GM_Sun relative to the body, with no planets and no
        limit of span. It is the orbit a mean YORP run averages over
        (:func:`spinorbit.core.averaging.thermal_mean.propagate_mean_thermal`), and the full route
        integrates under the same analytic Sun (:mod:`spinorbit.scene.thermal_planning`).

        Raises
        ------
        spinorbit.orbital_elements.OrbitElementsError
            Elements out of range (e ≥ 1, a ≤ 0, an angle outside its range) or an unknown frame.
        SceneError
            An epoch that is not a scalar Time.
        """
        from spinorbit.orbital_elements import check_elements, frame_to_icrf_matrix

        a_km, e, inc, raan, argp, mean_anomaly = check_elements(a, e, inc, raan, argp, mean_anomaly)
        epoch_day = _scalar_time("epoch", epoch)
        # The perifocal axes P, Q, W in ICRF, then the ICRF angles the core's Kepler source takes.
        cos_o, sin_o, cos_i, sin_i, cos_w, sin_w = (math.cos(raan), math.sin(raan), math.cos(inc), math.sin(inc),
                                                    math.cos(argp), math.sin(argp))
        p = np.array([cos_o * cos_w - sin_o * sin_w * cos_i, sin_o * cos_w + cos_o * sin_w * cos_i, sin_w * sin_i])
        w = np.array([sin_o * sin_i, -cos_o * sin_i, cos_i])
        to_icrf = frame_to_icrf_matrix(frame)
        p, w = to_icrf @ p, to_icrf @ w
        inc_icrf = math.acos(max(-1.0, min(1.0, float(w[2]))))
        if math.hypot(w[0], w[1]) > 1e-15:
            node = math.atan2(w[0], -w[1])
            n_vec = np.array([math.cos(node), math.sin(node), 0.0])
            argp_icrf = math.atan2(float(np.cross(n_vec, p) @ w), float(p @ n_vec))
        else:  # an orbit in the ICRF equator: the node is undefined, take Ω = 0
            node, argp_icrf = 0.0, math.atan2(p[1], p[0]) * (1.0 if w[2] > 0 else -1.0)
        au_km = float((1 * u.au).to_value(u.km))
        description = (f"heliocentric Kepler ellipse a = {a:.6g}, e = {e:.6g}, i = {math.degrees(inc):.6g} deg "
                       f"({frame}) at {epoch.tdb.iso} TDB, the Sun alone, no planets")
        return cls("kepler", str(name), description=description,
                   kepler_elements=(a_km / au_km, e, inc_icrf, node % (2 * math.pi), argp_icrf, mean_anomaly, epoch_day))

    def kepler_sun(self):
        """The core Kepler source of the Sun relative to the body (au, day; :func:`~spinorbit.core.model.perturbers.kepler_source`)."""
        from spinorbit.core.model.perturbers import kepler_source
        from spinorbit.ephemeris import de421_constants

        if self.kind != "kepler":
            raise SceneError(f"kepler_sun needs an Orbit.kepler; this orbit is of kind {self.kind!r}.")
        a, e, inc, node, argp, mean_anomaly, epoch_day = self.kepler_elements
        return kepler_source(de421_constants().gm["sun"], a, e, inc, node, argp, mean_anomaly, epoch=epoch_day,
                             sign=-1.0)

    def kepler_frame(self):
        """Inertial (ICRF) → orbit frame (P, Q, W) of an Orbit.kepler: W, the orbit normal, is its z."""
        _, _, inc, node, argp, _, _ = self.kepler_elements
        cos_o, sin_o, cos_i, sin_i, cos_w, sin_w = (math.cos(node), math.sin(node), math.cos(inc), math.sin(inc),
                                                    math.cos(argp), math.sin(argp))
        p = [cos_o * cos_w - sin_o * sin_w * cos_i, sin_o * cos_w + cos_o * sin_w * cos_i, sin_w * sin_i]
        q = [-cos_o * sin_w - sin_o * cos_w * cos_i, -sin_o * sin_w + cos_o * cos_w * cos_i, cos_w * sin_i]
        w = [sin_o * sin_i, -cos_o * sin_i, cos_i]
        return np.array([p, q, w])

    @classmethod
    def rebound(cls, simulation, particle):
        """A particle of a REBOUND simulation (("AU", "day", "Msun") units, t in TDB days since J2000,
        ICRF); perturbers are particles of the same simulation."""
        from spinorbit.coupling.rebound import body_index

        body_index(simulation, particle)  # MissingBodyError now, not after a survey
        return cls("rebound", str(particle), simulation=simulation)

    @classmethod
    def from_rebound(cls, simulation, particle):
        """A particle of a REBOUND simulation the user owns, checked for spinorbit's units.

        The simulation must be in ("AU", "day", "Msun") units (G = DE421's GM_Sun in au³/day²) with
        ``t`` in TDB days since J2000 and ICRF axes, as
        :func:`~spinorbit.coupling.rebound.simulation.simulation_from_de421` builds it; spinorbit
        reads it only through copies, so the user's simulation is never moved.
        """
        from spinorbit.ephemeris import de421_constants

        g = getattr(simulation, "G", None)
        gm_sun = de421_constants().gm["sun"]
        if not isinstance(g, float) or abs(g / gm_sun - 1.0) > UNITS_G_TOLERANCE:
            raise SceneError(f"Orbit.from_rebound expects a rebound.Simulation in ('AU', 'day', 'Msun') units "
                             f"(G = {gm_sun:.10g}); got G = {g!r}. Set sim.units = ('AU', 'day', 'Msun') "
                             "before adding particles.")
        orbit = cls.rebound(simulation, particle)
        return cls("rebound", orbit.name, simulation=simulation,
                   description=f"REBOUND simulation given by the user, particle {orbit.name!r}")

    @classmethod
    def from_elements(cls, a, e, inc, raan, argp, mean_anomaly, epoch, frame="ecliptic", name="body",
                      non_gravitational=None, extra_forces=True):
        """Heliocentric osculating elements at ``epoch``, integrated among DE421's planets in REBOUND.

        Parameters
        ----------
        a : Quantity (length)
            Semi-major axis (> 0: elliptic orbits only; an open orbit goes through :meth:`from_state`).
        e : float
            Eccentricity, 0 ≤ e < 1.
        inc, raan, argp, mean_anomaly : Quantity (angle)
            Inclination (0°–180°), longitude of the ascending node, argument of perihelion and mean
            anomaly at ``epoch`` (each within ±360°).
        epoch : astropy.time.Time
            The elements' epoch (scalar, inside DE421's 1899-12-04 … 2200-02-01).
        frame : {"ecliptic", "ecliptic-iau2006", "icrf"}
            What the angles are referred to: the ecliptic and equinox J2000 of astropy (IAU 2006,
            default), JPL's (IAU 1976 obliquity, no frame bias: the frame of SBDB and Horizons
            elements; 0.05″ from the former) or the ICRF equator (:mod:`spinorbit.orbital_elements`).
        name : str
            The particle's name in the simulation (the Scene's orbit name).
        non_gravitational : dict, optional
            ``{"A1": …, "A2": …, "A3": …}`` acceleration Quantities at 1 au (JPL's A1, A2, A3 in
            au/d²; A2 is the Yarkovsky drift).
        extra_forces : bool
            EIH 1PN and Earth J2 (default True), as the Apophis orbit.

        Returns
        -------
        Orbit
            Of kind "rebound": the simulation sits at ``epoch``; the Scene and the approaches integrate
            copies of it forwards or backwards.

        Raises
        ------
        spinorbit.orbital_elements.OrbitElementsError
            Elements out of range (e ≥ 1, a ≤ 0, an angle outside its range) or an unknown frame.
        spinorbit.ephemeris.EphemerisRangeError
            An epoch outside DE421.
        SceneError
            An epoch that is not a scalar Time, bad non-gravitational terms.
        """
        from spinorbit.ephemeris import de421_constants
        from spinorbit.orbital_elements import check_elements, elements_to_state, frame_to_icrf_matrix

        a_km, e, inc, raan, argp, mean_anomaly = check_elements(a, e, inc, raan, argp, mean_anomaly)
        frame_to_icrf_matrix(frame)  # the frame's error before anything is built
        constants = de421_constants()
        position, velocity = elements_to_state(a_km / constants.au_km, e, inc, raan, argp, mean_anomaly,
                                               constants.gm["sun"], frame)
        description = (f"osculating elements a = {a:.6g}, e = {e:.6g}, i = {math.degrees(inc):.6g} deg "
                       f"({frame}) at {epoch.tdb.iso if isinstance(epoch, Time) else epoch} TDB, DE421 planets")
        return cls._built(name, epoch, position, velocity, "sun", non_gravitational, extra_forces, description)

    @classmethod
    def from_sbpy(cls, orbit, row=0, frame="ecliptic", name=None, kepler=False, non_gravitational=None,
                  extra_forces=True):
        """The orbit of one row of an ``sbpy.data.Orbit`` (filled from JPL Horizons or the SBDB, or built with
        ``sbpy.data.Orbit.from_dict``): :meth:`from_elements` of its elements, or with ``kepler=True``
        :meth:`kepler` of them.

        Parameters
        ----------
        orbit : sbpy.data.Orbit
            Its ``a`` (or the perihelion distance ``q``), ``e``, ``i``, ``Omega``, ``w``, ``M`` (or the time of
            perihelion ``Tp``) and ``epoch``, by any of sbpy's alternative names, with the units the table carries
            (:func:`spinorbit.sbpy_tables.orbit_arguments`; a field without its unit is refused).
        row : int
            Which row of the table.
        frame : {"ecliptic", "ecliptic-iau2006", "icrf"}
            What the angles are referred to. The table does not say: sbpy's ``Orbit.from_horizons`` documents
            heliocentric elements on the ecliptic and mean equinox of J2000 (JPL's, IAU 1976 obliquity: the
            default "ecliptic"), as the SBDB gives them; "icrf" for a Horizons query made with ``refplane="earth"``.
        name : str, optional
            The orbit's name; by default the row's ``targetname``, else "body".
        kepler : bool
            False (default): integrated among DE421's planets (:meth:`from_elements`); True: the fixed Sun-alone
            ellipse (:meth:`kepler`, which takes no non-gravitational terms).
        non_gravitational, extra_forces
            As in :meth:`from_elements`.

        Raises
        ------
        spinorbit.sbpy_tables.SbpyInputError
            Not an sbpy Orbit, no such row, or a missing field (named, with the fields the row has).
        spinorbit.quantities.QuantityInputError
            A field without a unit, or of the wrong kind.
        """
        from spinorbit.sbpy_tables import orbit_arguments

        arguments = orbit_arguments(orbit, row)
        name = name or arguments.pop("name") or "body"
        arguments.pop("name", None)
        if kepler:
            if non_gravitational is not None:
                raise SceneError("Orbit.from_sbpy(kepler=True) is the Sun-alone ellipse and takes no non_gravitational "
                                 f"terms; got {non_gravitational!r}. Drop kepler=True to integrate them.")
            return cls.kepler(**arguments, frame=frame, name=name)
        return cls.from_elements(**arguments, frame=frame, name=name, non_gravitational=non_gravitational,
                                 extra_forces=extra_forces)

    @classmethod
    def from_state(cls, position, velocity, epoch, frame="icrf", centre="sun", name="body",
                   non_gravitational=None, extra_forces=True):
        """A state vector at ``epoch``, integrated among DE421's planets in REBOUND (any conic: open
        orbits too).

        Parameters
        ----------
        position, velocity : Quantity, shape (3,)
            Length and speed, in the axes of ``frame``, relative to ``centre``.
        epoch : astropy.time.Time
        frame : {"icrf", "ecliptic", "ecliptic-iau2006"}
        centre : {"sun", "barycenter"}
            Heliocentric (default) or barycentric.
        name, non_gravitational, extra_forces
            As :meth:`from_elements`.
        """
        from spinorbit.coupling.rebound import CENTRES
        from spinorbit.ephemeris import de421_constants
        from spinorbit.orbital_elements import frame_to_icrf_matrix

        turn = frame_to_icrf_matrix(frame)
        if centre not in CENTRES:
            raise SceneError(f"centre expects one of {CENTRES}; got {centre!r}.")
        au_km = de421_constants().au_km
        vectors = []
        for label, value, kind, unit in (("position", position, "length", u.km),
                                         ("velocity", velocity, "speed", u.km / u.day)):
            require_quantity(label, value, unit, "[1, 0, 0] * u.au" if kind == "length" else "[0, 30, 0] * u.km / u.s")
            if (not isinstance(value, u.Quantity) or value.unit.physical_type != kind or value.shape != (3,)
                    or not np.all(np.isfinite(value.value))):
                raise SceneError(f"{label} expects a finite {kind} Quantity of shape (3,) such as "
                                 f"[1, 0, 0] * u.{'au' if kind == 'length' else 'km / u.s'}; got {value!r}.")
            vectors.append(turn @ (value.to_value(unit) / au_km))
        if not np.any(vectors[0]):
            raise SceneError(f"position expects a non-zero vector (the body cannot sit on its centre); got {position!r}.")
        description = f"state vector ({frame}, {centre}-centred) at {epoch.tdb.iso if isinstance(epoch, Time) else epoch} TDB, DE421 planets"
        return cls._built(name, epoch, vectors[0], vectors[1], centre, non_gravitational, extra_forces, description)

    @classmethod
    def _built(cls, name, epoch, position_au, velocity_au_day, centre, non_gravitational, extra_forces, description):
        from spinorbit.coupling.rebound import small_body_simulation
        from spinorbit.ephemeris import de421_constants

        epoch_day = _scalar_time("epoch", epoch)
        _check_inside_de421("epoch", epoch_day)
        if not isinstance(name, str) or not name.strip():
            raise SceneError(f"name expects a non-empty string (the particle's name); got {name!r}.")
        terms = _non_gravitational(non_gravitational, de421_constants().au_km)
        if terms and not extra_forces:
            raise SceneError("non_gravitational needs extra_forces=True (the terms live in the same compiled force).")
        sim = small_body_simulation(name, epoch, position_au, velocity_au_day, centre=centre,
                                    extra_forces=bool(extra_forces), non_gravitational=terms)
        if terms:
            description += ", non-gravitational " + ", ".join(f"{k} = {v:.4g} au/d2" for k, v in terms.items())
        if extra_forces:
            description += ", EIH 1PN + Earth J2"
        return cls("rebound", name, simulation=sim, description=description, de421_planets=True)

    def __reduce__(self):
        """Pickle to the orbit's description, never REBOUND's raw simulation (issue 36).

        REBOUND pickles a simulation as its binary, which holds neither the compiled extra forces'
        function pointer nor (rebound 5.2.2) names that outlive the simulation saved: a pickled
        orbit would run without EIH and J2 and change the physics silently (REBOUND only warns).
        A REBOUND orbit goes as a :class:`~spinorbit.coupling.rebound.snapshot.SimulationSnapshot`
        (binary, names, the extra forces in effect) and is rebuilt with its forces reinstalled, so
        the copy integrates bit for bit like the original (``tests/test_orbit_pickling.py``). A
        simulation with forces spinorbit did not install cannot be carried: refused with SceneError.
        """
        fields = {f.name: getattr(self, f.name) for f in dataclasses.fields(self)}
        if self.simulation is not None:
            from spinorbit.coupling.rebound import ForceInstallError, SimulationSnapshot

            try:
                snapshot = SimulationSnapshot.of(self.simulation)
            except ForceInstallError as error:
                raise SceneError(f"the orbit of {self.name!r} cannot be pickled (sent to another process): {error}") \
                    from None
            fields["simulation"] = (snapshot, int(self.simulation.exact_finish_time))
        return (_orbit_from_description, (fields,))

    def check_span(self, *days):
        """EphemerisRangeError if an orbit built among DE421's planets is asked about times (TDB days
        since J2000) outside DE421's span: its planets start from DE421 and are compared with it."""
        if self.de421_planets:
            _check_inside_de421(f"the orbit of {self.name}", *(float(d) for d in days))

    # --------------------------------------------------------------------------------------------
    # Close approaches

    def _separation(self, target):
        from spinorbit.coupling import approaches, sampling
        from spinorbit.coupling.rebound import MissingBodyError
        from spinorbit.ephemeris import resolve_body

        if self.kind == "rebound":
            try:
                return approaches.rebound_separation(self.simulation, self.name, target)
            except MissingBodyError:
                function = sampling.rebound_orbit(self.simulation, self.name)
        elif self.kind == "de421":
            function = sampling.de421_orbit(self.name)
        else:
            function = self.function
        return approaches.ephemeris_separation(function, resolve_body(target))

    def relative_state(self, body, times):
        """Position and velocity of the orbit's body relative to ``body`` at ``times`` (ICRF axes).

        Parameters
        ----------
        body : str
            A particle of the REBOUND simulation (for a REBOUND orbit) or a DE421 body ("sun" for the
            heliocentric state, whose r × v is the orbit's pole).
        times : astropy.time.Time
            Scalar or 1-D, inside DE421's span.

        Returns
        -------
        position : Quantity, shape (n, 3), au
        velocity : Quantity, shape (n, 3), au/day
        """
        if not isinstance(times, Time):
            raise SceneError(f"times expects an astropy Time; got {type(times).__name__}.")
        whole, rest = tdb_days(times)
        days = np.atleast_1d(np.asarray(whole, dtype=float) + np.asarray(rest, dtype=float))
        _check_inside_de421("times", float(days.min()), float(days.max()))
        separation = self._separation(body)
        states = [separation(float(day)) for day in days]
        return (np.array([r for r, _ in states]) * u.au, np.array([v for _, v in states]) * u.au / u.day)

    def approaches(self, body, start, end, max_distance=APPROACH_MAX_DISTANCE):
        """The close approaches to ``body`` between ``start`` and ``end``: each local minimum of the distance
        within ``max_distance``.

        Parameters
        ----------
        body : str
            A particle of the REBOUND simulation (for a REBOUND orbit) or a DE421 body.
        start, end : astropy.time.Time
            Scalar, start before end, inside DE421's span.
        max_distance : Quantity (length) or None
            The cut-off, :data:`APPROACH_MAX_DISTANCE` (0.2 au, JPL's Close-Approach Data for one object)
            by default; None lists every local minimum, the far side of the orbit included.

        Returns
        -------
        astropy.table.QTable
            ``time`` (Time, TDB), ``distance`` (au) and ``distance_km`` (km), centre to centre, ``speed``
            (km/s, relative); one row per approach, in time order (empty if none is within the cut-off).
        """
        from spinorbit.coupling.approaches import approaches
        from spinorbit.ephemeris import de421_constants

        limit_au = math.inf if max_distance is None else value_in("max_distance", max_distance, u.au, "0.05 * u.au",
                                                                  shape=())
        if not limit_au > 0:
            raise ApproachError(f"max_distance expects a positive length such as 0.05 * u.au, or None for every "
                                f"minimum; got {max_distance!s}.")
        start_day, end_day = _scalar_time("start", start), _scalar_time("end", end)
        if not end_day > start_day:
            raise ApproachError(f"end expects a time after start; got start {start.tdb.iso}, end {end.tdb.iso}.")
        _check_inside_de421("the span", start_day, end_day)
        found = [m for m in approaches(self._separation(body), start_day, end_day) if m[1] <= limit_au]
        au_km = de421_constants().au_km
        table = QTable()
        table["time"] = time_from_tdb_days(np.array([m[0] for m in found]))
        table["distance"] = np.array([m[1] for m in found]) * u.au
        table["distance_km"] = np.array([m[1] for m in found]) * au_km * u.km  # DE421's au, as the orbit's states
        table["speed"] = (np.array([m[2] for m in found]) * au_km / 86400.0) * u.km / u.s
        return table

    def closest_approach(self, body, start, end):
        """The closest approach to ``body`` between ``start`` and ``end``: (Time, distance Quantity).

        The smallest local minimum of the distance inside the span, however far (:meth:`approaches` with
        ``max_distance=None``), found to 1e-9 d (0.1 ms; :mod:`spinorbit.coupling.approaches`); the
        distance in au.

        Raises
        ------
        ApproachError
            No local minimum inside the span (the distance only falls or only rises), or end ≤ start.
        spinorbit.ephemeris.EphemerisRangeError
            A span outside DE421.
        """
        table = self.approaches(body, start, end, max_distance=None)
        if len(table) == 0:
            raise ApproachError(f"no close approach of {self.name} to {body} between {start.tdb.iso} and "
                                f"{end.tdb.iso} TDB: the distance only falls or only rises there. Widen the span.")
        best = int(np.argmin(table["distance"].value))
        return table["time"][best], table["distance"][best]


def _orbit_from_description(fields):
    """The :class:`Orbit` of :meth:`Orbit.__reduce__`'s fields, its REBOUND simulation rebuilt from its snapshot."""
    if fields.get("simulation") is not None:
        snapshot, exact_finish_time = fields["simulation"]
        simulation = snapshot.build()  # the names set again, the extra forces reinstalled
        simulation.exact_finish_time = exact_finish_time
        fields = {**fields, "simulation": simulation}
    return Orbit(**fields)
