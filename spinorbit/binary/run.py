"""The coupled propagation of a binary with units, and what a run shows about the secondary.

:func:`propagate` strips the units once, runs :func:`spinorbit.core.binary.propagate.propagate_binary`
(DOP853) and returns a :class:`BinaryRun`: the states, the conserved quantities' drifts, the
secondary's libration angle and canonical elements (:mod:`spinorbit.core.binary.libration`), the
mutual orbit period and the libration's free and forced components.

How the components are measured (:meth:`BinaryRun.libration_components`): the two strongest lines
of the periodogram of φ(t) (the second at least three resolutions from the first), each frequency
refined by maximising the periodogram near its peak, then both amplitudes fitted together by linear
least squares. The line nearer the mean motion n is the forced libration: it is driven at the
*anomalistic* frequency of the orbit, which differs from n by the apsidal precession (for the
Didymos case by ~4 %, measured), so it is found, not assumed at n. The other is the free
libration. The periodogram resolves two lines 2π/T apart, so the run must cover many libration
periods (the Didymos run: 100 orbits).

When the lines are reported (:data:`MIN_LINE_CYCLES`, :data:`MIN_LINE_SEPARATION`): each must
complete at least 10 cycles in the run, and the two must lie at least 4 resolutions 2π/T apart;
otherwise :class:`~spinorbit.core.binary.errors.UnresolvedPeriodError` says by how much the run
falls short. Each period is given with its resolution δP = P²/T, one bin of the periodogram. The
errors measured on lines that pass are far below it (Didymos, 27 orbits: 3e-4 of the period against a
resolution of 4 %), since the peak is refined between the bins.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from astropy import units as u

from spinorbit.binary.sun import HeliocentricOrbit
from spinorbit.binary.system import G_SI, BinaryState
from spinorbit.core.binary import equations as core
from spinorbit.core.binary.boundedness import ENERGY, first_unbound, hill_radius, orbit_energies
from spinorbit.core.binary.errors import UnboundPairError, UnresolvedPeriodError
from spinorbit.core.binary.libration import (
    COL_ENERGY_RATIO,
    COL_LIBRATION,
    COL_MODE,
    COL_P_PHI,
    COL_P_PSI,
    secondary_rotation_table,
)
from spinorbit.core.binary.propagate import propagate_binary
from spinorbit.core.free_motion.wobble import wobble_amplitude_many
from spinorbit.quantities import value_in

#: Fewest cycles a reported libration line completes in the run: below 10, one resolution 2π/T is more
#: than 10 % of its frequency, and the Hann window, which weights the middle half of the run, sees
#: fewer than five cycles.
MIN_LINE_CYCLES = 10
#: Fewest resolutions 2π/T between the free and forced lines. The Hann window's main lobe is ±2
#: resolutions wide and :func:`strongest_line` masks 3 around the first line, so a second line found
#: closer than 4 may be the first one's shoulder; lines that close also pull each other's peaks.
#: Measured on Didymos (orders 2 and 4, against 100 orbits): 3.1 resolutions apart the periods are
#: off by up to 1.4e-3, 3.9 by 6e-4, 4.2 by 3e-4, 4.7 by 1e-4; at 2.6 the forced one by 10 %.
MIN_LINE_SEPARATION = 4.0
#: Fewest revolutions of the longitude for a mutual period: over part of an eccentric orbit the
#: longitude's slope carries the equation of centre (up to 2e), over N whole ones ~e/N.
MIN_REVOLUTIONS = 1.0
#: Fewest revolutions for :meth:`BinaryRun.mutual_orbit`: its fit separates the line from the orbit's
#: harmonics, which takes a few of them. Measured on DART's orbit (e = 0.03): over 6 orbits the period
#: change is 0.5 s off the 80-orbit value, over 10 to 80 within 0.01 s.
MIN_ORBIT_REVOLUTIONS = 3.0

#: Names of the rotation modes of :func:`spinorbit.core.free_motion.summary.mode_code`.
MODE_NAMES = {1: "SAM", -1: "LAM", 0: "principal-axis", 2: "separatrix"}


@dataclass(frozen=True)
class LibrationComponents:
    """The secondary's libration split into its free and forced lines (periods and amplitudes).

    ``free_resolution`` and ``forced_resolution`` are each period's resolution P²/T over the run's
    span T (one bin of the periodogram; print a period as P ± that).
    """

    free_period: u.Quantity
    free_amplitude: u.Quantity
    forced_period: u.Quantity
    forced_amplitude: u.Quantity
    residual_rms: u.Quantity
    free_resolution: u.Quantity
    forced_resolution: u.Quantity


@dataclass(frozen=True)
class MutualOrbit:
    """The mutual orbit's mean motion as the observations measure it, from the separation vector alone.

    ``sidereal_period`` is 2π over the mean rate of the longitude (what mutual events time);
    ``anomalistic_period`` the period of the separation's oscillation; ``apsidal_rate`` their
    difference as the periapsis's mean motion; ``eccentricity`` the amplitude of the separation's line
    over its mean (r ≈ a(1 − e cos M)); ``mean_separation`` that mean. On a circular orbit (the
    separation constant to 1e-9 of itself) there is no periapsis: ``anomalistic_period`` and
    ``apsidal_rate`` are None and ``eccentricity`` is the measured (rounding-level) amplitude.
    These are Meyer et al. (2023, PSJ 4, 141)'s "observable elements": osculating Keplerian elements
    of a non-Keplerian orbit oscillate, the separation's lines do not.
    """

    sidereal_period: u.Quantity
    anomalistic_period: u.Quantity | None
    apsidal_rate: u.Quantity | None
    eccentricity: float
    mean_separation: u.Quantity


@dataclass(frozen=True)
class BinaryRun:
    """States of a binary run at its output times, with the secondary's rotation read off them."""

    initial: BinaryState
    times: u.Quantity
    states: np.ndarray
    stats: dict
    sun: object = None

    @property
    def model(self):
        """The core's model array of the pair (with the Sun's block on when the run had one)."""
        model = self.initial.system.model()
        return model if self.sun is None else core.with_sun(model, self.sun)

    def tide_power(self):
        """dE/dt at each output time (W): the Sun's tide working on the orbit and both spins (0 without the Sun)."""
        model = self.model
        t = self.times.to_value(u.s)
        return np.array([core.tide_power(ti, y, model) for ti, y in zip(t, self.states)]) * u.W

    def energy(self):
        """Total energy at each output time (J)."""
        model = self.model
        return np.array([core.binary_energy(y, model) for y in self.states]) * u.J

    def angular_momentum(self):
        """Total angular momentum (inertial axes) at each output time (kg m²/s)."""
        model = self.model
        return np.array([core.binary_angular_momentum(y, model) for y in self.states]) * u.kg * u.m ** 2 / u.s

    def energy_drift(self):
        """(|E − E₀|/|E₀|, |E − E₀|/|U₀|) at each output time: relative to the energy and to the mutual potential.

        The total energy of a fast-spinning primary is mostly its spin; the second ratio measures the
        drift on the scale of the orbit–figure coupling.
        """
        energy = self.energy().to_value(u.J)
        potential = core.mutual_state(self.states[0], self.model)[0]
        change = np.abs(energy - energy[0])
        return change / abs(energy[0]), change / abs(potential)

    def angular_momentum_drift(self):
        """|H − H₀| / |H₀| at each output time."""
        h = self.angular_momentum().value
        return np.linalg.norm(h - h[0], axis=1) / np.linalg.norm(h[0])

    def secondary_rotation(self):
        """Per output time: libration angle φ (rad), B's canonical elements, mode, E/E0, P_ψ, P_φ (s)."""
        return secondary_rotation_table(np.ascontiguousarray(self.states), self.model)

    def libration(self):
        """φ(t), B's long axis from the line to A in B's equator, modulo π (Quantity rad)."""
        return self.secondary_rotation()[:, COL_LIBRATION] * u.rad

    def secondary_wobble(self):
        """The wobble amplitude of B's rotation at each output time (Quantity deg): the largest angle its
        circulation axis (C in SAM, A in LAM) makes with its angular momentum over the torque-free motion
        through that instant (:mod:`spinorbit.core.free_motion.wobble`; ``docs/conventions.md``, "Wobble and
        rotation class"). 0 for a principal-axis rotation; the package calls a body tumbling above 1°."""
        model = self.model
        moments = np.array([model[core.M_INERTIA_B], model[core.M_INERTIA_B + 4], model[core.M_INERTIA_B + 8]])
        momenta = np.ascontiguousarray(self.states[:, core.OMEGA_B:core.OMEGA_B + 3] * moments)
        out = np.empty(len(momenta))
        wobble_amplitude_many(momenta, moments[0], moments[1], moments[2], out)
        return (out * u.rad).to(u.deg)

    def secondary_modes(self):
        """Mode names (SAM, LAM, principal-axis, separatrix) of B's rotation at each output time."""
        return [MODE_NAMES[int(code)] for code in self.secondary_rotation()[:, COL_MODE]]

    def tumbling_summary(self):
        """(fraction of output times in SAM or LAM, max E/E0 − 1, median P_ψ, median P_φ (s) over those times)."""
        table = self.secondary_rotation()
        tumbling = np.isin(table[:, COL_MODE], (1, -1)) & np.isfinite(table[:, COL_P_PSI])
        if not np.any(tumbling):
            return 0.0, float(np.max(table[:, COL_ENERGY_RATIO]) - 1.0), math.inf * u.s, math.inf * u.s
        return (float(np.mean(tumbling)), float(np.max(table[:, COL_ENERGY_RATIO]) - 1.0),
                float(np.median(table[tumbling, COL_P_PSI])) * u.s, float(np.median(table[tumbling, COL_P_PHI])) * u.s)

    def orbit_energy(self):
        """The mutual orbit's energy ½ ν |Ṙ|² − U at each output time (J; < 0 while the pair is bound)."""
        return orbit_energies(np.ascontiguousarray(self.states), self.model) * u.J

    def is_bound(self):
        """True if the pair is bound at every output time (:mod:`spinorbit.core.binary.boundedness`)."""
        return first_unbound(np.ascontiguousarray(self.states), self.model)[0] < 0

    def unbound_reason(self):
        """None while the pair stays bound; else one sentence: the first output time at which it is not, and why.

        Why is the energy (≥ 0, with the speed against the escape speed there) or the Hill radius
        (:mod:`spinorbit.core.binary.boundedness`).
        """
        model = self.model
        index, reason, value = first_unbound(np.ascontiguousarray(self.states), model)
        if index < 0:
            return None
        y = self.states[index]
        when = self.times[index].to(u.h)
        r = float(np.linalg.norm(y[core.POSITION:core.POSITION + 3]))
        speed = float(np.linalg.norm(y[core.VELOCITY:core.VELOCITY + 3]))
        if reason == ENERGY:
            reduced_mass = 1.0 / (1.0 / model[core.M_MASS_A] + 1.0 / model[core.M_MASS_B])
            potential = 0.5 * reduced_mass * speed ** 2 - value  # U = ½ ν v² − E_orb
            escape = math.sqrt(2.0 * potential / reduced_mass) if potential > 0 else 0.0
            why = (f"the mutual orbit's energy is {value:.4g} J ≥ 0 (relative speed {speed:.4g} m/s against the escape "
                   f"speed {escape:.4g} m/s at a separation of {r:.4g} m): B is escaping A")
        else:
            why = f"the separation {value:.4g} m exceeds the Hill radius {hill_radius(model):.4g} m: the Sun holds B, not A"
        return f"the pair is unbound at t = {when:.4g} (output time {index}): {why}"

    def require_bound(self, what):
        """Raise :class:`~spinorbit.core.binary.errors.UnboundPairError` for ``what`` unless the pair stays bound."""
        reason = self.unbound_reason()
        if reason is not None:
            raise UnboundPairError(f"{what}: {reason}. There is no mutual period or libration to report; lower the "
                                   "impulse or start from a bound orbit.")

    def orbital_longitude(self):
        """Unwrapped longitude of B about A in the inertial x-y plane (rad)."""
        return np.unwrap(np.arctan2(self.states[:, core.POSITION + 1], self.states[:, core.POSITION]))

    def mutual_period(self):
        """Mean sidereal period of the mutual orbit: 2π over the least-squares slope of the longitude (s).

        Raises
        ------
        UnboundPairError
            The pair is not bound at some output time (:meth:`require_bound`).
        UnresolvedPeriodError
            The longitude turns less than :data:`MIN_REVOLUTIONS` times over the run.
        """
        self.require_bound("mutual_period")
        t = self.times.to_value(u.s)
        longitude = self.orbital_longitude()
        slope = np.polyfit(t, longitude, 1)[0]
        turns = abs(longitude[-1] - longitude[0]) / (2.0 * math.pi)
        if not turns >= MIN_REVOLUTIONS:
            need = MIN_REVOLUTIONS * 2.0 * math.pi / abs(slope) if slope else None
            raise UnresolvedPeriodError(
                f"mutual_period: the run of {(t[-1] - t[0]) * u.s.to(u.h):.4g} h covers {turns:.3g} of a revolution; a "
                f"mean period needs at least {MIN_REVOLUTIONS:g} whole one (over part of an eccentric orbit the "
                "longitude's slope carries the equation of centre)"
                + (f": propagate over at least {need * u.s.to(u.h):.4g} h." if need else "."), need)
        return 2.0 * math.pi / abs(slope) * u.s

    def mutual_orbit(self):
        """The mean mutual orbit over the run (:class:`MutualOrbit`); needs equally spaced output times.

        The anomalistic frequency κ is the strongest line of the separation r(t) (:func:`strongest_line`),
        the secondary's free libration ω the strongest line of its libration angle more than three
        resolutions from κ. The longitude θ(t) is fitted by least squares with a line, the first two
        harmonics of κ and the line at ω; the slope is the mean motion. The harmonics take out the
        eccentric orbit's 2e sin M and (5/4)e² sin 2M, the ω line the orbit's answer to the libration's
        torque; a line alone is biased by them by ~e/N over N orbits (for DART's orbit 0.4 s of the
        period change over 12 orbits, 0.01 s with them). r(t) is fitted with a constant and the first
        harmonic of κ, whose amplitude over the constant is e. On two point masses the period equals
        vis-viva's to 1e-7 of the change (``tests/test_dart.py``).

        Raises
        ------
        UnboundPairError
            The pair is not bound at some output time (:meth:`require_bound`).
        UnresolvedPeriodError
            The longitude turns less than :data:`MIN_ORBIT_REVOLUTIONS` times over the run.
        """
        self.require_bound("mutual_orbit")
        t = self.times.to_value(u.s)
        if len(t) < 64 or not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=0):
            raise ValueError(f"mutual_orbit: expected ≥ 64 equally spaced output times, got {len(t)} times; "
                             "propagate on np.linspace(0, span, n) over a few orbits.")
        theta = self.orbital_longitude()
        turns = abs(theta[-1] - theta[0]) / (2.0 * math.pi)
        if not turns >= MIN_ORBIT_REVOLUTIONS:
            need = MIN_ORBIT_REVOLUTIONS * (t[-1] - t[0]) / turns if turns > 0 else None
            raise UnresolvedPeriodError(
                f"mutual_orbit: the run of {(t[-1] - t[0]) * u.s.to(u.h):.4g} h covers {turns:.3g} revolutions; the "
                f"mean orbit needs at least {MIN_ORBIT_REVOLUTIONS:g} to separate its line from the orbit's harmonics"
                + (f": propagate over at least {need * u.s.to(u.h):.4g} h." if need else "."), need)
        r = np.linalg.norm(self.states[:, core.POSITION:core.POSITION + 3], axis=1)
        mean_r = float(r.mean())
        if np.ptp(r) <= 1e-9 * mean_r:
            slope = np.polyfit(t - t[0], theta, 1)[0]
            return MutualOrbit(2.0 * math.pi / abs(slope) * u.s, None, None, float(0.5 * np.ptp(r) / mean_r),
                               mean_r * u.m)
        kappa = strongest_line(t, r - mean_r)
        phi = self.libration().to_value(u.rad)
        libration = strongest_line(t, phi - phi.mean(), kappa)
        s = t - t[0]
        harmonics = [f(k * kappa * s) for k in (1, 2) for f in (np.cos, np.sin)]
        design = np.stack([np.ones_like(s), s, *harmonics, np.cos(libration * s), np.sin(libration * s)], axis=1)
        slope = np.linalg.lstsq(design, theta, rcond=None)[0][1]
        radial = np.linalg.lstsq(np.stack([np.ones_like(s), *harmonics[:2]], axis=1), r, rcond=None)[0]
        rate = abs(slope)
        return MutualOrbit(2.0 * math.pi / rate * u.s, 2.0 * math.pi / kappa * u.s,
                           ((rate - kappa) * u.rad / u.s).to(u.deg / u.day), float(math.hypot(*radial[1:]) / radial[0]),
                           float(radial[0]) * u.m)

    def libration_components(self):
        """The free and forced lines of φ(t) (module docstring); needs equally spaced output times.

        Raises
        ------
        UnboundPairError
            The pair is not bound at some output time (:meth:`require_bound`): φ then measures no libration.
        UnresolvedPeriodError
            A line completes fewer than :data:`MIN_LINE_CYCLES` cycles in the run, or the two lie fewer
            than :data:`MIN_LINE_SEPARATION` resolutions apart (module docstring).
        """
        self.require_bound("libration_components")
        t = self.times.to_value(u.s)
        if len(t) < 64 or not np.allclose(np.diff(t), t[1] - t[0], rtol=1e-9, atol=0):
            raise ValueError(f"libration_components: expected ≥ 64 equally spaced output times, got {len(t)} "
                             "times; propagate on np.linspace(0, span, n).")
        phi = self.libration().to_value(u.rad)
        n = 2.0 * math.pi / self.mutual_period().to_value(u.s)
        first = strongest_line(t, phi - phi.mean(), None)
        second = strongest_line(t, phi - phi.mean(), first)
        forced, free = (first, second) if abs(first - n) <= abs(second - n) else (second, first)
        span = t[-1] - t[0]
        _require_resolved(span, free, forced)
        amplitudes, residual = _fit_lines(t, phi, (free, forced))
        free_period, forced_period = 2 * math.pi / free, 2 * math.pi / forced
        return LibrationComponents(free_period * u.s, amplitudes[0] * u.rad, forced_period * u.s,
                                   amplitudes[1] * u.rad, residual * u.rad, free_period ** 2 / span * u.s,
                                   forced_period ** 2 / span * u.s)


def _require_resolved(span, free, forced):
    """Raise UnresolvedPeriodError unless both lines (angular frequencies) are resolved by a run of ``span``."""
    resolution = 2.0 * math.pi / span
    cycles = [f / resolution for f in (free, forced)]
    separation = abs(free - forced) / resolution
    if min(cycles) >= MIN_LINE_CYCLES and separation >= MIN_LINE_SEPARATION:
        return
    need = max(MIN_LINE_CYCLES * 2.0 * math.pi / min(free, forced),
               MIN_LINE_SEPARATION * 2.0 * math.pi / abs(free - forced) if free != forced else math.inf)
    hours = u.s.to(u.h)
    raise UnresolvedPeriodError(
        f"the libration's lines are not resolved by this run of {span * hours:.4g} h: the strongest two, at "
        f"{2 * math.pi / free * hours:.4g} h (free) and {2 * math.pi / forced * hours:.4g} h (forced), complete "
        f"{cycles[0]:.3g} and {cycles[1]:.3g} cycles and lie {separation:.3g} frequency resolutions (2π/T) apart; "
        f"each needs ≥ {MIN_LINE_CYCLES} cycles and the two ≥ {MIN_LINE_SEPARATION:g} resolutions, so the run "
        f"must span at least {need * hours:.4g} h (more if these lines are not the true ones).", need)


def _periodogram(t, x, frequency):
    """|Σ w x e^{−iωt}| with the Hann window w: its sidelobes fall as 1/f³, so a second line a few
    resolutions away shifts the peak by ~1e-6 of its frequency instead of ~1e-4 (measured on the
    libration test of tests/test_binary_propagation.py)."""
    window = np.sin(np.pi * np.arange(len(t)) / (len(t) - 1)) ** 2
    return abs(np.sum(window * x * np.exp(-1j * frequency * t)))


def strongest_line(t, x, avoided=None):
    """Angular frequency (rad per unit of t) of the highest peak of the Hann-windowed periodogram of x(t),
    more than 3 resolutions from ``avoided`` (None: anywhere), refined by maximising the periodogram.
    ``t`` equally spaced."""
    from scipy.optimize import minimize_scalar

    span = t[-1] - t[0]
    resolution = 2.0 * math.pi / span
    n = len(t)
    # The coarse grid k · resolution / 4 (k ≥ 4, below Nyquist) is the FFT of the windowed samples padded
    # to 4 (n − 1) points: the same sums as _periodogram's (equally spaced times; a start t₀ ≠ 0 only turns
    # their phase), in n log n instead of n² operations.
    window = np.sin(np.pi * np.arange(n) / (n - 1)) ** 2
    spectrum = np.abs(np.fft.rfft(window * x, 4 * (n - 1)))
    bins = np.arange(4, 2 * (n - 1))
    grid = bins * (resolution / 4.0)
    power = spectrum[bins]
    if avoided is not None:
        power[np.abs(grid - avoided) < 3.0 * resolution] = 0.0
    peak = grid[int(np.argmax(power))]
    best = minimize_scalar(lambda f: -_periodogram(t, x, f), bounds=(peak - resolution / 2, peak + resolution / 2),
                           method="bounded", options={"xatol": resolution * 1e-6})
    return float(best.x)


def _fit_lines(t, x, frequencies):
    """Amplitudes of the lines at ``frequencies`` and the rms residual (linear least squares with a constant)."""
    columns = [np.ones_like(t)]
    for f in frequencies:
        columns += [np.cos(f * t), np.sin(f * t)]
    design = np.stack(columns, axis=1)
    coefficients, *_ = np.linalg.lstsq(design, x, rcond=None)
    residual = x - design @ coefficients
    amplitudes = [math.hypot(coefficients[1 + 2 * k], coefficients[2 + 2 * k]) for k in range(len(frequencies))]
    return amplitudes, float(np.sqrt(np.mean(residual ** 2)))


def propagate(state, times, rtol=1e-12, max_steps=100_000_000, sun=None):
    """Propagate a :class:`~spinorbit.binary.system.BinaryState` to ``times`` after it (Quantity, time).

    Parameters
    ----------
    state : BinaryState
    times : Quantity (n,), time
        Output times from the state's instant, strictly monotone, not 0 first unless more follow.
    rtol : float
        DOP853's relative tolerance (1e-15 … 1); 1e-12 keeps E and H to ~1e-13 over 10⁴ orbits
        (docs/binary.md).
    sun : HeliocentricOrbit, optional
        The barycentre's heliocentric orbit: adds the Sun's degree-2 tide on the orbit and its
        gravity-gradient torque on both bodies (:mod:`spinorbit.binary.sun`). Energy and angular
        momentum are then no longer conserved (:meth:`BinaryRun.tide_power` is the energy's rate).

    Raises
    ------
    ContactError, UnsupportedOrderError, IntegrationError
        From :func:`spinorbit.core.binary.propagate.propagate_binary`.
    """
    t = np.atleast_1d(value_in("times", times, u.s, "np.linspace(0, 10, 1001) * u.day"))
    y0 = state.core_state()
    model = state.system.model()
    source = None
    if sun is not None:
        if not isinstance(sun, HeliocentricOrbit):
            raise TypeError(f"sun: expected a spinorbit.binary.HeliocentricOrbit (the barycentre's heliocentric "
                            f"elements) or None, got {type(sun).__name__}.")
        source = sun.source(model[core.M_MASS_A] + model[core.M_MASS_B], G_SI)
    first = 1 if t[0] == 0.0 else 0
    ys, stats = propagate_binary(y0, 0.0, t[first:], model, rtol=rtol, max_steps=max_steps, return_stats=True,
                                 sun=source)
    if first:
        ys = np.vstack([y0[None, :], ys])
    return BinaryRun(state, t * u.s, ys, stats, source)
