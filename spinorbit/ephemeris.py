"""Offline JPL DE421: barycentric states, the Moon's orientation, and the DE421 constants.

Data source (primary): the ``de421`` PyPI package, read with ``jplephem.ephem.Ephemeris``. It is
the only offline source here that has all three things the project needs from one file set: the
positions, the lunar **libration angles** (the orientation of the Moon's principal-axis mantle
frame, which ``de421.bsp`` does not carry), and the **DE421 header constants** (GMs, lunar gravity
field, moment ratios, tides, core). One source keeps positions, orientation and constants mutually
consistent. It also spans JD 2414992.5–2524624.5 TDB (1899-12-04 to 2200-02-01), longer than
skyfield-data's ``de421.bsp`` (to 2053-10-09). The test suite cross-checks positions against the
``.bsp`` through skyfield (``docs/ephemeris.md`` gives the measured agreement).

Frames and units
----------------
- ICRF axes, Solar-System barycentre origin (Earth, Moon and the planets' system barycentres as
  DE421 defines them; Mercury and Venus have no moons, so barycentre = planet).
- TDB. Plain-float functions (suffix ``_au``) take TDB days since J2000 in two-float form
  (``day``, ``fraction``; see :mod:`spinorbit.time`) and return **DE421 astronomical units**:
  1 au_DE421 = :attr:`DE421Constants.au_km` = 149 597 870.6996262 km, the unit in which DE421's
  GMs are given (GM_Sun = k², Gauss's constant squared, as REBOUND's ("AU", "day", "Msun") units
  assume). The Quantity functions return astropy's IAU 2012 ``u.AU`` (149 597 870.700 km); the
  two differ by 2.5e-12 relative (0.37 m at 1 au, 11 m at Neptune), and each function converts
  from DE421's kilometres so that both are physically right.
- Moon orientation: DE421 3-1-3 passive Euler angles (φ, θ, ψ), ICRF → mantle principal axes,
  R = R3(ψ) R1(θ) R3(φ), rates in rad/day. Quaternion scalar first, body → inertial (conventions).
"""

from __future__ import annotations

import dataclasses
import functools
import math
import types

import astropy.units as u
import numpy as np

from spinorbit.core.errors import SpinorbitError
from spinorbit.core.jit import jit
from spinorbit.core.math.rotations import attitude_to_quat_many, euler313_rates_to_omega, euler313_to_attitude
from spinorbit.time import J2000_JD_TDB, tdb_day_and_fraction

__all__ = [
    "KNOWN_BODIES",
    "DE421_SPAN_JD_TDB",
    "UnknownBodyError",
    "EphemerisRangeError",
    "DE421Constants",
    "de421_constants",
    "barycentric_state",
    "barycentric_state_au",
    "earth_from_moon_au",
    "barycentric_state_km",
    "moon_libration_angles",
    "moon_libration_angles_raw",
    "moon_orientation",
    "moon_orientation_raw",
]

#: Bodies this module knows, lower case. Planet names other than Earth mean the planet's *system*
#: barycentre, as DE421 integrates them (Mars with Phobos and Deimos, Jupiter with its moons, ...).
KNOWN_BODIES = (
    "sun",
    "mercury",
    "venus",
    "earth",
    "moon",
    "earth-moon barycenter",
    "mars",
    "jupiter",
    "saturn",
    "uranus",
    "neptune",
    "pluto",
)

_ALIASES = {"emb": "earth-moon barycenter", "earth-moon barycentre": "earth-moon barycenter"}

# Series stored in the de421 package under these names: (series, kind). Earth and Moon are built
# from the Earth–Moon barycentre series and the geocentric Moon series with DE421's EMRAT.
_SERIES = {
    "sun": "sun",
    "mercury": "mercury",
    "venus": "venus",
    "earth-moon barycenter": "earthmoon",
    "mars": "mars",
    "jupiter": "jupiter",
    "saturn": "saturn",
    "uranus": "uranus",
    "neptune": "neptune",
    "pluto": "pluto",
}


class UnknownBodyError(SpinorbitError, ValueError):
    """A body name DE421 (as exposed here) does not have."""


class EphemerisRangeError(SpinorbitError, ValueError):
    """A time outside the span covered by the DE421 data."""


@functools.lru_cache(maxsize=1)
def _ephemeris():
    """The jplephem reader over the ``de421`` package's files (loaded once, lazily)."""
    import de421
    from jplephem.ephem import Ephemeris

    return Ephemeris(de421)


def _span():
    ephemeris = _ephemeris()
    return float(ephemeris.jalpha), float(ephemeris.jomega)


#: First and last Julian dates (TDB) covered by the ``de421`` package's series.
DE421_SPAN_JD_TDB = (2414992.5, 2524624.5)


def resolve_body(body) -> str:
    if not isinstance(body, str):
        raise TypeError(f"body must be a name (str); got {type(body).__name__} ({body!r}).")
    name = body.strip().lower()
    name = _ALIASES.get(name, name)
    if name not in KNOWN_BODIES:
        raise UnknownBodyError(
            f"unknown body {body!r}; DE421 here knows {', '.join(KNOWN_BODIES)} "
            "(planet names other than Earth are the planet-system barycentres)."
        )
    return name


def _check_span(day, fraction):
    """Raise :class:`EphemerisRangeError` if any J2000-relative TDB time lies outside DE421."""
    start, end = DE421_SPAN_JD_TDB
    jd = J2000_JD_TDB + (np.asarray(day) + np.asarray(fraction))
    if np.any(~np.isfinite(jd)) or np.any(jd < start) or np.any(jd > end):
        bad = jd[(jd < start) | (jd > end) | ~np.isfinite(jd)] if jd.ndim else jd
        raise EphemerisRangeError(
            f"time(s) JD {np.ravel(bad)[:3]} TDB outside DE421's span JD {start}–{end} TDB "
            "(1899-12-04 to 2200-02-01); choose times inside it."
        )


@jit
def _numpy_pairwise_sum(values, count):
    """``values[:count].sum()`` in numpy's order (its ``pairwise_sum`` below 128 terms): term by term
    under eight terms, else eight running partial sums, combined as a tree, then the leftover terms."""
    if count < 8:
        total = 0.0
        for i in range(count):
            total += values[i]
        return total
    r0, r1, r2, r3 = values[0], values[1], values[2], values[3]
    r4, r5, r6, r7 = values[4], values[5], values[6], values[7]
    i = 8
    while i < count - count % 8:
        r0 += values[i]
        r1 += values[i + 1]
        r2 += values[i + 2]
        r3 += values[i + 3]
        r4 += values[i + 4]
        r5 += values[i + 5]
        r6 += values[i + 6]
        r7 += values[i + 7]
        i += 8
    total = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < count:
        total += values[i]
        i += 1
    return total


@jit
def chebyshev_sums(coefficients, chebyshev, twice_t, days_per_set):
    """Position and rate of Chebyshev series, as jplephem's ``position/velocity_from_bundle``.

    Parameters
    ----------
    coefficients : ndarray, shape (axes, n, k)
        Each time's segment coefficients.
    chebyshev : ndarray, shape (k, n)
        T_0 … T_{k−1} at each time's scaled argument t.
    twice_t : ndarray, shape (n,)
        2t.
    days_per_set : float
        Segment length (days): the rate is per day.

    Returns
    -------
    position, rate : ndarray, shape (axes, n)
        k ≤ 128 (DE421's series have at most 13 coefficients).
    """
    axes, n, k = coefficients.shape
    position = np.empty((axes, n))
    rate = np.empty((axes, n))
    derivative = np.empty(k)
    terms = np.empty(k)
    for j in range(n):
        # dT_0 = 0, dT_1 = 1, dT_i = 2t dT_{i−1} − dT_{i−2} + 2 T_{i−1}, then times 2 / segment length.
        derivative[0] = 0.0
        if k > 1:
            derivative[1] = 1.0
        if k > 2:
            derivative[2] = twice_t[j] + twice_t[j]
        for i in range(3, k):
            derivative[i] = twice_t[j] * derivative[i - 1] - derivative[i - 2] + chebyshev[i - 1, j] + chebyshev[i - 1, j]
        for i in range(k):
            derivative[i] = derivative[i] * 2.0
            derivative[i] = derivative[i] / days_per_set
        for a in range(axes):
            for i in range(k):
                terms[i] = chebyshev[i, j] * coefficients[a, j, i]
            position[a, j] = _numpy_pairwise_sum(terms, k)
            for i in range(k):
                terms[i] = derivative[i] * coefficients[a, j, i]
            rate[a, j] = _numpy_pairwise_sum(terms, k)
    return position, rate


def _evaluate(series: str, day, fraction):
    """Chebyshev evaluation of one series: (position, rate), each shape (..., n_axes)."""
    ephemeris = _ephemeris()
    day = np.asarray(day, dtype=float)
    fraction = np.asarray(fraction, dtype=float)
    shape = np.broadcast(day, fraction).shape
    # jplephem subtracts its start date from the first argument before adding the second: passing
    # J2000 + whole days and the fraction separately keeps the two-float precision.
    jd1 = np.ravel(J2000_JD_TDB + np.broadcast_to(day, shape))
    jd2 = np.ravel(np.broadcast_to(fraction, shape))
    # jplephem's bundle (segment, Chebyshev T_k), then both sums in one compiled pass: the same
    # arithmetic as its position/velocity_from_bundle, bit for bit (tests/test_de421_sampling_exact.py),
    # without the (axes, n, k) temporaries that dominated the "de421" Moon model's sampling.
    coefficients, days_per_set, chebyshev, twice_t = ephemeris.compute_bundle(series, jd1, jd2)
    position, rate = chebyshev_sums(np.ascontiguousarray(coefficients), np.ascontiguousarray(chebyshev),
                                    np.ascontiguousarray(twice_t), float(days_per_set))
    n_axes = position.shape[0]
    return (
        np.moveaxis(position, 0, -1).reshape(shape + (n_axes,)),
        np.moveaxis(rate, 0, -1).reshape(shape + (n_axes,)),
    )


def barycentric_state_km(body: str, day, fraction=0.0):
    """Barycentric ICRF position (km) and velocity (km/day) of ``body`` from plain TDB floats.

    Parameters
    ----------
    body : str
        One of :data:`KNOWN_BODIES` (case-insensitive; 'EMB' is accepted).
    day, fraction : float or array_like
        TDB days since J2000 in two-float form (sum is the time), unit: day.

    Returns
    -------
    position : ndarray, shape (..., 3), unit: km
    velocity : ndarray, shape (..., 3), unit: km/day

    Raises
    ------
    UnknownBodyError, EphemerisRangeError
    """
    name = resolve_body(body)
    _check_span(day, fraction)
    if name in _SERIES:
        return _evaluate(_SERIES[name], day, fraction)
    emb_r, emb_v = _evaluate("earthmoon", day, fraction)
    moon_r, moon_v = _evaluate("moon", day, fraction)  # geocentric Moon
    emrat = _ephemeris().EMRAT
    share = 1.0 / (1.0 + emrat) if name == "earth" else -emrat / (1.0 + emrat)
    # Earth = EMB − Moon_geo·M_moon/(M_earth+M_moon); Moon = EMB + Moon_geo·M_earth/(M_earth+M_moon).
    return emb_r - share * moon_r, emb_v - share * moon_v


def earth_from_moon_au(day, fraction=0.0):
    """Position and velocity of the Earth relative to the Moon (ICRF, au_DE421 and au/day).

    Minus DE421's geocentric Moon series, evaluated directly: one Chebyshev series instead of the
    four that the difference of two barycentric states needs, and no cancellation.
    """
    _check_span(day, fraction)
    position, velocity = _evaluate("moon", day, fraction)
    au_km = _ephemeris().AU
    return -position / au_km, -velocity / au_km


def barycentric_state_au(body: str, day, fraction=0.0):
    """As :func:`barycentric_state_km`, in DE421 au and au/day (the units of DE421's GMs).

    Returns
    -------
    position : ndarray, shape (..., 3), unit: au_DE421 (:attr:`DE421Constants.au_km` km)
    velocity : ndarray, shape (..., 3), unit: au_DE421/day
    """
    position, velocity = barycentric_state_km(body, day, fraction)
    au_km = _ephemeris().AU
    return position / au_km, velocity / au_km


def barycentric_state(body: str, time):
    """Barycentric ICRF position and velocity of ``body`` at an astropy ``Time``.

    Parameters
    ----------
    body : str
        One of :data:`KNOWN_BODIES` (case-insensitive).
    time : astropy.time.Time
        Scalar or array, any scale convertible to TDB.

    Returns
    -------
    position : Quantity, shape time.shape + (3,), unit: AU (IAU 2012)
    velocity : Quantity, shape time.shape + (3,), unit: AU/day (TDB day)

    Raises
    ------
    UnknownBodyError
        If ``body`` is not known (the message lists the known names).
    EphemerisRangeError
        If a time lies outside JD 2414992.5–2524624.5 TDB.
    TypeError
        If ``time`` is not an astropy ``Time``.
    """
    name = resolve_body(body)  # before the time conversion, so a bad name fails first
    day, fraction = tdb_day_and_fraction(time)
    position, velocity = barycentric_state_km(name, day, fraction)
    return (position * u.km).to(u.AU), (velocity * (u.km / u.day)).to(u.AU / u.day)


def moon_libration_angles_raw(day, fraction=0.0):
    """DE421 lunar libration angles (φ, θ, ψ) and rates from plain TDB floats.

    Returns
    -------
    angles : ndarray, shape (..., 3), unit: rad
        Passive 3-1-3 angles ICRF → mantle principal axes. ψ is *not* wrapped (it grows by 2π per
        sidereal month); wrap it yourself if you need it in (−π, π].
    rates : ndarray, shape (..., 3), unit: rad/day
    """
    _check_span(day, fraction)
    return _evaluate("librations", day, fraction)


def moon_libration_angles(time):
    """DE421 lunar libration angles (φ, θ, ψ) and their rates at an astropy ``Time``.

    Returns
    -------
    angles : Quantity, shape time.shape + (3,), unit: rad
    rates : Quantity, shape time.shape + (3,), unit: rad/day
    """
    angles, rates = moon_libration_angles_raw(*tdb_day_and_fraction(time))
    return angles << u.rad, rates << (u.rad / u.day)


@jit
def _mantle_attitudes(angles, rates, psi):
    """Attitude matrices and body angular velocities of 3-1-3 angles (φ, θ, reduced ψ) and rates, per row."""
    n = angles.shape[0]
    attitudes = np.empty((n, 3, 3))
    omega = np.empty((n, 3))
    # Element by element: a whole-row assignment makes numba 0.68 compile its shape-mismatch message
    # (string formatting), which tripled this kernel's compile time on a cold cache.
    for i in range(n):
        attitude = euler313_to_attitude(angles[i, 0], angles[i, 1], psi[i])
        rate = euler313_rates_to_omega(angles[i, 0], angles[i, 1], psi[i], rates[i, 0], rates[i, 1], rates[i, 2])
        for j in range(3):
            omega[i, j] = rate[j]
            for k in range(3):
                attitudes[i, j, k] = attitude[j, k]
    return attitudes, omega


def moon_orientation_raw(day, fraction=0.0):
    """Quaternion and body angular velocity of the Moon's mantle frame from plain TDB floats.

    Returns
    -------
    quaternion : ndarray, shape (..., 4)
        Scalar first (w, x, y, z), body → inertial (ICRF): v_ICRF = M(q) v_body, attitude
        R = M(q)ᵀ = R3(ψ) R1(θ) R3(φ) (``docs/conventions.md``). Sign: largest component positive.
    omega_body : ndarray, shape (..., 3), unit: rad/day
        Angular velocity of the mantle frame in mantle (body) components,
        (φ̇ sinθ sinψ + θ̇ cosψ, φ̇ sinθ cosψ − θ̇ sinψ, φ̇ cosθ + ψ̇).
    """
    angles, rates = moon_libration_angles_raw(day, fraction)
    shape = angles.shape[:-1]
    flat_angles = np.ascontiguousarray(angles.reshape(-1, 3))
    # ψ grows without bound; reduce it first so the kernels' sin/cos see a small argument.
    psi = np.array([math.remainder(value, 2.0 * math.pi) for value in flat_angles[:, 2].tolist()])
    attitudes, omega = _mantle_attitudes(flat_angles, np.ascontiguousarray(rates.reshape(-1, 3)), psi)
    quaternion = attitude_to_quat_many(attitudes)
    return quaternion.reshape(shape + (4,)), omega.reshape(shape + (3,))


def moon_orientation(time):
    """Attitude quaternion and body angular velocity of the Moon (DE421 mantle frame).

    Parameters
    ----------
    time : astropy.time.Time
        Scalar or array, any scale convertible to TDB.

    Returns
    -------
    quaternion : ndarray, shape time.shape + (4,)
        Scalar first, body → ICRF (see :func:`moon_orientation_raw`).
    omega_body : Quantity, shape time.shape + (3,), unit: rad/day
        Mantle angular velocity in mantle principal-axis components.
    """
    quaternion, omega = moon_orientation_raw(*tdb_day_and_fraction(time))
    return quaternion, omega << (u.rad / u.day)


@dataclasses.dataclass(frozen=True)
class DE421Constants:
    """Constants of the DE421 integration, read from the ``de421`` package's header.

    Every value below is read from the package's ``constants.npy`` (the JPL header), except the
    moment-of-inertia ratios, which are derived from header values (see
    :attr:`moon_moments_over_mr2`). Units follow the header: lengths in km, GMs in
    au_DE421³/day², times in days, angles in rad.

    Attributes
    ----------
    header : mappingproxy
        All 229 header values by their JPL names (e.g. ``header['MA0001']``), read-only.
    au_km : float
        au_DE421 in km (header AU). Positions in 'AU' of this module's ``_au`` functions use it.
    c_km_s : float
        Speed of light, km/s (CLIGHT).
    emrat : float
        Earth/Moon mass ratio (EMRAT).
    gm : mappingproxy
        GM by body name (KNOWN_BODIES names; 'earth-moon barycenter' = Earth + Moon), au³/day².
        Planets other than Earth: the whole system (GM1…GM9); Sun: GMS; Earth and Moon split GMB
        with EMRAT.
    earth_radius_km, earth_j2, earth_j3, earth_j4 : float
        Equatorial radius of Earth's gravity field (AE, km) and zonal harmonics J2E, J3E, J4E.
    moon_radius_km : float
        Reference radius of the lunar gravity field (AM, km).
    moon_j2, moon_j3, moon_j4, moon_c22 : float
        Unnormalised lunar harmonics J2M, J3M, J4M, C22M (whole Moon).
    moon_degree3, moon_degree4 : mappingproxy
        Unnormalised tesseral/sectoral harmonics: C31M, S31M, C32M, S32M, C33M, S33M and
        C41M … S44M, by those names.
    moon_beta, moon_gamma : float
        LBET = (C − A)/B and LGAM = (B − A)/C.
    moon_k2, moon_tidal_delay_days : float
        Lunar Love number K2M and tidal time delay TAUM (days).
    moon_core_over_total_moment : float
        IFAC (0.0007). Read here as the fluid core's share of the polar moment, C_f/C, the role
        this name plays in the DE4xx lunar model (Folkner et al. 2009); the header itself carries
        only the name and value.
    moon_core_oblateness : float
        COBLAT, read as the flattening of the core–mantle boundary (same caveat as IFAC).
    moon_core_friction_per_day : float
        KVC, core–mantle friction coefficient k_v/C, 1/day (same caveat as IFAC).
    moon_epoch_jd_tdb : float
        JDEPOC, the epoch of the initial conditions (JD TDB).
    moon_angles_at_epoch : tuple
        (PHI, THT, PSI), mantle Euler angles at JDEPOC, rad.
    moon_omega_at_epoch : tuple
        (OMEGAX, OMEGAY, OMEGAZ), mantle angular velocity at JDEPOC in mantle components, rad/day.
    core_omega_at_epoch : tuple
        (OMGCX, OMGCY, OMGCZ), core angular velocity at JDEPOC (rad/day), as in the header.
    """

    header: types.MappingProxyType
    au_km: float
    c_km_s: float
    emrat: float
    gm: types.MappingProxyType
    earth_radius_km: float
    earth_j2: float
    earth_j3: float
    earth_j4: float
    moon_radius_km: float
    moon_j2: float
    moon_j3: float
    moon_j4: float
    moon_c22: float
    moon_degree3: types.MappingProxyType
    moon_degree4: types.MappingProxyType
    moon_beta: float
    moon_gamma: float
    moon_k2: float
    moon_tidal_delay_days: float
    moon_core_over_total_moment: float
    moon_core_oblateness: float
    moon_core_friction_per_day: float
    moon_epoch_jd_tdb: float
    moon_angles_at_epoch: tuple
    moon_omega_at_epoch: tuple
    core_omega_at_epoch: tuple

    @property
    def moon_c_over_mr2(self) -> float:
        """C/MR² of the whole Moon implied by DE421's constants (R = AM = 1738 km).

        The header carries no C/MR², but it is fixed by the gravity field and the moment ratios:
        C22 = (B − A)/(4MR²) and γ = (B − A)/C give C/MR² = 4 C22 / γ. Independently,
        J2 = (C − (A + B)/2)/MR² with β and γ gives C/MR² = J2 / ((β − γ)/(1 + β) + γ/2). The two
        agree to 1e-16 relative for DE421 (tested), so this is the value DE421 itself used:
        0.3932677 (not a separately published figure).
        """
        return 4.0 * self.moon_c22 / self.moon_gamma

    @property
    def moon_moments_over_mr2(self) -> tuple[float, float, float]:
        """Principal moments (A, B, C)/MR² of the whole Moon, A < B < C.

        From β = (C − A)/B, γ = (B − A)/C and C/MR² (:attr:`moon_c_over_mr2`):
        B = C (1 + γ)/(1 + β), A = B − γ C. Differences are formed from β and γ, not from the
        rounded moments.
        """
        c = self.moon_c_over_mr2
        b = c * (1.0 + self.moon_gamma) / (1.0 + self.moon_beta)
        a = b - self.moon_gamma * c
        return a, b, c


@functools.lru_cache(maxsize=1)
def de421_constants() -> DE421Constants:
    """The DE421 header constants as a :class:`DE421Constants` (read once from the package)."""
    ephemeris = _ephemeris()
    raw = np.load(ephemeris.path("constants.npy"))
    header = {name.decode("ascii"): float(value) for name, value in raw}
    emrat = header["EMRAT"]
    gm_emb = header["GMB"]
    gm = {
        "sun": header["GMS"],
        "mercury": header["GM1"],
        "venus": header["GM2"],
        "earth-moon barycenter": gm_emb,
        "earth": gm_emb * emrat / (1.0 + emrat),
        "moon": gm_emb / (1.0 + emrat),
        "mars": header["GM4"],
        "jupiter": header["GM5"],
        "saturn": header["GM6"],
        "uranus": header["GM7"],
        "neptune": header["GM8"],
        "pluto": header["GM9"],
    }
    degree3 = ("C31M", "S31M", "C32M", "S32M", "C33M", "S33M")
    degree4 = tuple(f"{cs}4{m}M" for m in range(1, 5) for cs in "CS")
    frozen = types.MappingProxyType
    return DE421Constants(
        header=frozen(header),
        au_km=header["AU"],
        c_km_s=header["CLIGHT"],
        emrat=emrat,
        gm=frozen(gm),
        earth_radius_km=header["AE"],
        earth_j2=header["J2E"],
        earth_j3=header["J3E"],
        earth_j4=header["J4E"],
        moon_radius_km=header["AM"],
        moon_j2=header["J2M"],
        moon_j3=header["J3M"],
        moon_j4=header["J4M"],
        moon_c22=header["C22M"],
        moon_degree3=frozen({name: header[name] for name in degree3}),
        moon_degree4=frozen({name: header[name] for name in degree4}),
        moon_beta=header["LBET"],
        moon_gamma=header["LGAM"],
        moon_k2=header["K2M"],
        moon_tidal_delay_days=header["TAUM"],
        moon_core_over_total_moment=header["IFAC"],
        moon_core_oblateness=header["COBLAT"],
        moon_core_friction_per_day=header["KVC"],
        moon_epoch_jd_tdb=header["JDEPOC"],
        moon_angles_at_epoch=(header["PHI"], header["THT"], header["PSI"]),
        moon_omega_at_epoch=(header["OMEGAX"], header["OMEGAY"], header["OMEGAZ"]),
        core_omega_at_epoch=(header["OMGCX"], header["OMGCY"], header["OMGCZ"]),
    )
