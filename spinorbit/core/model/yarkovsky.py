"""The Yarkovsky drift of a spherical body's orbit: the linear heat-conduction theory (diurnal and seasonal).

Sources of the formulas (transcribed, with their symbols):

- Vokrouhlický (1998), A&A 335, 1093, "Diurnal Yarkovsky effect as a source of mobility of meter-sized
  asteroidal fragments. I. Linear theory"; Vokrouhlický (1999), A&A 344, 362, "A complete linear model
  for the Yarkovsky thermal force on spherical asteroid fragments": the temperature of a homogeneous
  sphere, linearised about the mean temperature, as a function of the radius over the penetration depth.
- Bottke, Vokrouhlický, Rubincam & Nesvorný (2006), Annu. Rev. Earth Planet. Sci. 34, 157, eqs. (3)–(4):
  the circular-orbit drifts
  (da/dt)_diurnal = −(8/9)(αΦ/n) W(R_ω, Θ_ω) cos γ and (da/dt)_seasonal = (4/9)(αΦ/n) W(R_n, Θ_n) sin² γ,
  with W(R, Θ) = −κ₁(R) Θ / (1 + 2κ₂(R) Θ + κ₃(R) Θ²).
- Fenucci, Novaković, Vokrouhlický & Weryk (2021), A&A 647, A61, eq. (A.7), and its published code
  (github.com/Fenu24/D-NEAs, ``src/yarko_force.f90``): the closed forms of κ₁, κ₂, κ₃ in x = √2 R′
  used here, and the acceleration field of Vokrouhlický et al. (2017), AJ 153, 270, that
  :func:`yarkovsky_acceleration` evaluates along an eccentric orbit.

Symbols (SI): α = 1 − A the absorptivity, ε the emissivity, E* the solar flux at the body,
Φ = πR²E*/(mc) the radiation acceleration of the cross-section, εσT*⁴ = αE* (the subsolar
temperature), Θ = Γ√ν/(εσT*³) the thermal parameter at frequency ν (ω the spin rate for the diurnal
part, n the mean motion for the seasonal), Γ = √(Kρc) the thermal inertia, l = √(K/(ρcν)) the
penetration depth and R′ = R/l. W < 0 for every Θ > 0, so a prograde rotator (γ < 90°) drifts out
and the seasonal drift is always inward.

The linearisation is about an isothermal mean temperature, so the theory holds where the temperature
swings are small compared with it: large Θ. As Θ → 0 (no conduction) W → 0 and the drift vanishes,
the same as Rubincam's zero-conductivity model in :mod:`spinorbit.core.model.thermal`, whose recoil
has no lag. The comparison with a finite-difference solution of the full (non-linear) 1-D heat
equation, and where the linear theory stops holding, is in docs/thermal.md.
"""

import math
from typing import NamedTuple

import numpy as np

from spinorbit.core.model.thermal import SOLAR_IRRADIANCE_1AU, SPEED_OF_LIGHT, facet_force_torque

__all__ = [
    "STEFAN_BOLTZMANN", "GM_SUN", "ASTRONOMICAL_UNIT", "kappa_functions", "thermal_response",
    "thermal_parameter", "penetration_depth", "circular_drift", "yarkovsky_acceleration", "orbit_mean_drift",
    "zero_conductivity_drift",
]

#: Stefan–Boltzmann constant, W m⁻² K⁻⁴ (CODATA 2018, exact in the 2019 SI).
STEFAN_BOLTZMANN = 5.670374419e-8
#: The Sun's GM, m³/s² (IAU 2015 Resolution B3, nominal; the asteroid's own mass is left out).
GM_SUN = 1.3271244e20
#: The astronomical unit, m (IAU 2012 Resolution B2, exact).
ASTRONOMICAL_UNIT = 149597870700.0


#: Below this x = √2 R′ the four terms of the κ functions are summed from their Taylor series (40 terms): in
#: closed form they cancel to O(x⁴) and lose ~4 digits per decade of x (3e-5 at R′ = 0.01, measured).
SERIES_BELOW = 2.0
SERIES_TERMS = 40


def _taylor_coefficients(terms):
    """Exact Taylor coefficients in x of A, B, U, V (each divided by eˣ), from e⁻ˣ, cos x and sin x."""
    from fractions import Fraction

    def series(sign_pattern):
        return [Fraction(sign_pattern(k), math.factorial(k)) for k in range(terms)]

    decay = series(lambda k: (-1) ** k)
    cosine = series(lambda k: 0 if k % 2 else (-1) ** (k // 2))
    sine = series(lambda k: (-1) ** (k // 2) if k % 2 else 0)

    def times_linear(coefficients, constant, slope):  # (constant + slope·x) · series
        return [constant * coefficients[k] + (slope * coefficients[k - 1] if k else 0) for k in range(terms)]

    def times_quadratic(coefficients, c0, c1, c2):
        return [c0 * coefficients[k] + (c1 * coefficients[k - 1] if k >= 1 else 0)
                + (c2 * coefficients[k - 2] if k >= 2 else 0) for k in range(terms)]

    def add(*parts):
        return [sum(values) for values in zip(*parts)]

    def neg(part):
        return [-value for value in part]

    a = add(neg(times_linear(decay, 2, 1)), neg(times_linear(cosine, -2, 1)), times_linear(sine, 0, 1))
    b = add(neg(times_linear(decay, 0, 1)), neg(times_linear(cosine, 0, 1)), neg(times_linear(sine, -2, 1)))
    u = add(times_linear(decay, 6, 3), times_linear(cosine, -6, 3), times_quadratic(sine, 0, -3, 1))
    v = add(times_quadratic(decay, 0, 3, 1), neg(times_quadratic(cosine, 0, -3, 1)), times_linear(sine, -6, 3))
    return tuple(np.array([float(value) for value in part]) for part in (a, b, u, v))


_SERIES = _taylor_coefficients(SERIES_TERMS)


def kappa_functions(radius_over_depth):
    """κ₁, κ₂, κ₃ of R′ = R/l (Vokrouhlický 1999; Fenucci et al. 2021 eq. A.7), each → 1/2 as R′ → ∞.

    The published forms carry terms in eˣ, x = √2 R′; every term is divided here by eˣ, which leaves
    the three ratios unchanged and keeps them finite for any R′. Below x = 2 the terms are summed
    from their exact Taylor series instead, where the closed forms cancel (the sphere is then nearly
    isothermal and κ₁ → 0).
    """
    x = math.sqrt(2.0) * float(radius_over_depth)
    if not x > 0.0 or not math.isfinite(x):
        raise ValueError(f"radius_over_depth: expected a finite R/l > 0; got {radius_over_depth!r}.")
    if x < SERIES_BELOW:
        powers = x ** np.arange(SERIES_TERMS)
        a, b, u, v = (float(coefficients[::-1] @ powers[::-1]) for coefficients in _SERIES)
    else:
        decay = math.exp(-x)
        cos_x, sin_x = math.cos(x), math.sin(x)
        a = -(x + 2.0) * decay - ((x - 2.0) * cos_x - x * sin_x)
        b = -x * decay - (x * cos_x + (x - 2.0) * sin_x)
        u = 3.0 * (x + 2.0) * decay + (3.0 * (x - 2.0) * cos_x + x * (x - 3.0) * sin_x)
        v = x * (x + 3.0) * decay - (x * (x - 3.0) * cos_x - 3.0 * (x - 2.0) * sin_x)
    denominator = x * (a * a + b * b)
    kappa1 = (a * v - b * u) / denominator
    kappa2 = (a * (a + u) + b * (b + v)) / denominator
    kappa3 = ((a + u) ** 2 + (b + v) ** 2) / (denominator * x)
    return kappa1, kappa2, kappa3


def thermal_response(radius_over_depth, theta):
    """(W, W₂): the lagging and the in-phase parts of the linear response at one frequency.

    W = −κ₁Θ/(1 + 2κ₂Θ + κ₃Θ²) (Bottke et al. 2006) is the part of the recoil 90° behind the
    insolation, which moves the semi-major axis; W₂ = (1 + κ₂Θ)/(1 + 2κ₂Θ + κ₃Θ²) is in phase
    (Vokrouhlický et al. 2017's γ₂).
    """
    if not theta >= 0.0 or not math.isfinite(theta):
        raise ValueError(f"theta: expected a finite thermal parameter Θ ≥ 0; got {theta!r}.")
    kappa1, kappa2, kappa3 = kappa_functions(radius_over_depth)
    denominator = 1.0 + 2.0 * kappa2 * theta + kappa3 * theta * theta
    return -kappa1 * theta / denominator, (1.0 + kappa2 * theta) / denominator


def subsolar_temperature(distance, absorptivity, emissivity):
    """T* in K from εσT*⁴ = αE*, E* = Φ₀ (1 au / d)², d in m."""
    flux = SOLAR_IRRADIANCE_1AU * (ASTRONOMICAL_UNIT / distance) ** 2
    return (absorptivity * flux / (emissivity * STEFAN_BOLTZMANN)) ** 0.25


def thermal_parameter(thermal_inertia, frequency, emissivity, temperature):
    """Θ = Γ√ν/(εσT*³): Γ in J m⁻² K⁻¹ s⁻½, ν in rad/s, T* in K."""
    return thermal_inertia * math.sqrt(frequency) / (emissivity * STEFAN_BOLTZMANN * temperature**3)


def penetration_depth(conductivity, density, heat_capacity, frequency):
    """l = √(K/(ρcν)) in m: the depth where the temperature wave of frequency ν falls by e."""
    return math.sqrt(conductivity / (density * heat_capacity * frequency))


def _response_at(radius, density, conductivity, heat_capacity, frequency, temperature, emissivity):
    inertia = math.sqrt(conductivity * density * heat_capacity)
    depth = penetration_depth(conductivity, density, heat_capacity, frequency)
    return thermal_response(radius / depth, thermal_parameter(inertia, frequency, emissivity, temperature))


def _radiation_acceleration(radius, density, distance):
    """Φ = πR²E*/(mc) in m/s², m = (4π/3)ρR³."""
    flux = SOLAR_IRRADIANCE_1AU * (ASTRONOMICAL_UNIT / distance) ** 2
    return math.pi * radius**2 * flux / (4.0 / 3.0 * math.pi * density * radius**3 * SPEED_OF_LIGHT)


def circular_drift(radius, density, conductivity, heat_capacity, absorptivity, emissivity, spin_rate,
                   obliquity, semi_major_axis):
    """(da/dt diurnal, da/dt seasonal) in m/s on a circular orbit (Bottke et al. 2006, eqs. 3–4).

    SI throughout: radius m, density kg/m³, conductivity W m⁻¹ K⁻¹, heat capacity J kg⁻¹ K⁻¹,
    spin rate rad/s, obliquity rad, semi-major axis m.
    """
    mean_motion = math.sqrt(GM_SUN / semi_major_axis**3)
    temperature = subsolar_temperature(semi_major_axis, absorptivity, emissivity)
    phi = _radiation_acceleration(radius, density, semi_major_axis)
    diurnal_w, _ = _response_at(radius, density, conductivity, heat_capacity, spin_rate, temperature, emissivity)
    seasonal_w, _ = _response_at(radius, density, conductivity, heat_capacity, mean_motion, temperature, emissivity)
    diurnal = -8.0 / 9.0 * absorptivity * phi / mean_motion * diurnal_w * math.cos(obliquity)
    seasonal = 4.0 / 9.0 * absorptivity * phi / mean_motion * seasonal_w * math.sin(obliquity) ** 2
    return diurnal, seasonal


def yarkovsky_acceleration(position, velocity, spin_axis, radius, density, conductivity, heat_capacity,
                           absorptivity, emissivity, spin_rate, mean_motion):
    """The linear theory's recoil acceleration (m/s², split (diurnal, seasonal)) at one heliocentric position.

    Vokrouhlický et al. (2017), AJ 153, 270, as written in Fenucci et al.'s code: with n̂ the unit vector from the Sun,
    ŝ the spin axis, e₂ = n̂ × ŝ, e₃ = ŝ × e₂ and N̂ the orbit normal,
    a = (4/9)αΦ(r) [γ₁ e₂ + γ₂ e₃  (diurnal)  +  (γ̄₂ n̂·ŝ + γ̄₁ (N̂ × n̂)·ŝ) ŝ  (seasonal)],
    (γ₁, γ₂) the response at the spin rate and (γ̄₁, γ̄₂) at the mean motion, both with T*(r) at the
    current distance (the theory's quasi-static reading of an eccentric orbit).
    """
    position = np.asarray(position, dtype=float)
    distance = float(np.linalg.norm(position))
    radial = position / distance
    normal = np.cross(position, velocity)
    normal /= np.linalg.norm(normal)
    axis = np.asarray(spin_axis, dtype=float)
    e2 = np.cross(radial, axis)
    e3 = np.cross(axis, e2)
    temperature = subsolar_temperature(distance, absorptivity, emissivity)
    scale = 4.0 / 9.0 * absorptivity * _radiation_acceleration(radius, density, distance)
    gamma1, gamma2 = _response_at(radius, density, conductivity, heat_capacity, spin_rate, temperature, emissivity)
    gamma1_bar, gamma2_bar = _response_at(radius, density, conductivity, heat_capacity, mean_motion, temperature,
                                          emissivity)
    diurnal = scale * (gamma1 * e2 + gamma2 * e3)
    seasonal = scale * (gamma2_bar * (radial @ axis) + gamma1_bar * (np.cross(normal, radial) @ axis)) * axis
    return diurnal, seasonal


def _check_eccentricity(eccentricity):
    if not 0.0 <= eccentricity < 1.0:
        raise ValueError(f"eccentricity: expected 0 ≤ e < 1 (a bound orbit); got {eccentricity!r}.")


def orbit_mean_drift(semi_major_axis, eccentricity, obliquity, spin_longitude, radius, density, conductivity,
                     heat_capacity, absorptivity, emissivity, spin_rate, samples=256):
    """(⟨da/dt⟩ diurnal, seasonal) in m/s over one Kepler orbit, from :func:`yarkovsky_acceleration`.

    Gauss's equation da/dt = 2/(n√(1 − e²)) [e sin f a_R + (p/r) a_T] averaged over the mean anomaly
    with the trapezoidal rule in the eccentric anomaly E (dM = (1 − e cos E) dE; periodic and smooth,
    so the rule converges geometrically). The orbit lies in the x–y plane with its perihelion on x;
    the spin axis is at ``obliquity`` from the orbit normal, its projection ``spin_longitude`` (rad)
    from the perihelion. For e = 0 the result is :func:`circular_drift` (a test checks it).
    """
    _check_eccentricity(eccentricity)
    mean_motion = math.sqrt(GM_SUN / semi_major_axis**3)
    axis = np.array([math.sin(obliquity) * math.cos(spin_longitude), math.sin(obliquity) * math.sin(spin_longitude),
                     math.cos(obliquity)])
    totals = np.zeros(2)
    for anomaly in 2.0 * math.pi * np.arange(samples) / samples:
        point = _orbit_point(semi_major_axis, eccentricity, anomaly, mean_motion)
        parts = yarkovsky_acceleration(point.position, point.velocity, axis, radius, density, conductivity, heat_capacity,
                                       absorptivity, emissivity, spin_rate, mean_motion)
        for index, acceleration in enumerate(parts):
            totals[index] += _weighted_rate(acceleration, point, semi_major_axis, eccentricity, anomaly, mean_motion)
    diurnal, seasonal = totals / samples
    return float(diurnal), float(seasonal)


class _OrbitPoint(NamedTuple):
    position: np.ndarray
    velocity: np.ndarray
    distance: float
    radial: np.ndarray
    along: np.ndarray  # in the plane, 90° ahead of r̂ (prograde)
    sin_true: float


def _orbit_point(semi_major_axis, eccentricity, eccentric_anomaly, mean_motion):
    """Position, velocity, distance, unit radial and along-track vectors, sin f at eccentric anomaly E."""
    root = math.sqrt(1.0 - eccentricity**2)
    cos_e, sin_e = math.cos(eccentric_anomaly), math.sin(eccentric_anomaly)
    distance = semi_major_axis * (1.0 - eccentricity * cos_e)
    position = semi_major_axis * np.array([cos_e - eccentricity, root * sin_e, 0.0])
    velocity = semi_major_axis**2 * mean_motion / distance * np.array([-sin_e, root * cos_e, 0.0])
    radial = position / distance
    along = np.array([-radial[1], radial[0], 0.0])
    return _OrbitPoint(position=position, velocity=velocity, distance=distance, radial=radial, along=along,
                       sin_true=root * sin_e * semi_major_axis / distance)


def _weighted_rate(acceleration, point, semi_major_axis, eccentricity, eccentric_anomaly, mean_motion):
    """Gauss's da/dt = 2/(n√(1 − e²)) [e sin f a_R + (p/r) a_T] times dM/dE = 1 − e cos E."""
    semi_latus = semi_major_axis * (1.0 - eccentricity**2)
    rate = 2.0 / (mean_motion * math.sqrt(1.0 - eccentricity**2)) * (
        eccentricity * point.sin_true * (acceleration @ point.radial)
        + semi_latus / point.distance * (acceleration @ point.along))
    return rate * (1.0 - eccentricity * math.cos(eccentric_anomaly))


def zero_conductivity_drift(normals, areas, mass, pressure, semi_major_axis, eccentricity, obliquity, spin_longitude,
                            spin_phases=64, samples=64):
    """⟨da/dt⟩ in m/s of Rubincam's zero-conductivity recoil (:mod:`spinorbit.core.model.thermal`) on an orbit.

    The shape spins about its body z axis (the axis at ``obliquity`` from the orbit normal, its
    projection ``spin_longitude`` from the perihelion), fast against the orbit: the force
    −P(r) Σ A max(0, n·ŝ) n (facets in m², mass kg, P the recoil pressure at 1 au in Pa) is averaged
    over ``spin_phases`` rotation phases, then Gauss's equation over ``samples`` eccentric anomalies.
    The recoil has no lag, so the spin-mean force lies in the plane of ŝ and the spin axis: with
    obliquity 0 it has no along-track part, and on a sphere it is radial and ∝ 1/r², a conservative
    force, so ⟨da/dt⟩ = 0 on any orbit. The diurnal drift needs conduction (the linear theory above).
    """
    _check_eccentricity(eccentricity)
    mean_motion = math.sqrt(GM_SUN / semi_major_axis**3)
    sin_o, cos_o = math.sin(obliquity), math.cos(obliquity)
    sin_l, cos_l = math.sin(spin_longitude), math.cos(spin_longitude)
    # Spin-axis frame → orbit frame: tilt the axis by the obliquity towards the spin longitude.
    tilt = np.array([[cos_o, 0.0, sin_o], [0.0, 1.0, 0.0], [-sin_o, 0.0, cos_o]])
    turn = np.array([[cos_l, -sin_l, 0.0], [sin_l, cos_l, 0.0], [0.0, 0.0, 1.0]])
    to_orbit = turn @ tilt
    centroids = np.zeros_like(normals)  # the torque is not needed
    total = 0.0
    for anomaly in 2.0 * math.pi * np.arange(samples) / samples:
        point = _orbit_point(semi_major_axis, eccentricity, anomaly, mean_motion)
        sun_spin_frame = to_orbit.T @ (-point.radial)
        mean_force = np.zeros(3)
        for phase in 2.0 * math.pi * np.arange(spin_phases) / spin_phases:
            spin = np.array([[math.cos(phase), -math.sin(phase), 0.0], [math.sin(phase), math.cos(phase), 0.0],
                             [0.0, 0.0, 1.0]])  # body → spin-axis frame at this phase
            force_over_pressure, _ = facet_force_torque(normals, areas, centroids, spin.T @ sun_spin_frame)
            mean_force += to_orbit @ (spin @ force_over_pressure)
        acceleration = -pressure * (ASTRONOMICAL_UNIT / point.distance) ** 2 * mean_force / (spin_phases * mass)
        total += _weighted_rate(acceleration, point, semi_major_axis, eccentricity, anomaly, mean_motion)
    return total / samples
