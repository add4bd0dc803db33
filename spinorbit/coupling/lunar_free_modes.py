"""The Moon's libration spectrum and the free-mode periods of each Moon model, measured.

What is measured: every model (:data:`spinorbit.coupling.moon.MOON_MODELS`) is run twice from
DE421's state at the same start, once as it is and once with a small kick to the mantle's angular
velocity. The forced librations are the same in both runs, so the difference kicked − reference is
the model's free response (linear at these amplitudes) and each free mode is fitted in the one
signal where it stands alone:

- **longitude** (≈ 1056 d): Δτ, fitted with a damped sinusoid plus a line;
- **latitude** (free precession of the pole about its Cassini position, ≈ 24.2 yr): Δρ + i·ΔIσ,
  averaged over a sidereal month (the wobble is monthly in that frame), fitted with a damped
  ellipse (both senses of rotation at one frequency) plus a line;
- **wobble** (≈ 74.6 yr): the kicked run's small rotation from the reference on the mantle's x and
  y axes, averaged over a sidereal month (the latitude mode is monthly in the mantle frame), fitted
  the same way.

The period is 2π over the fitted angular frequency, found by variable projection (the amplitudes
and line are linear least squares inside a one-parameter-pair search for ω and the damping rate),
starting from the highest peak of the signal's spectrum. Literature: Rambaux & Williams 2011
(CeMDA 109, 85; DE421) and Yang et al. 2017 (RAA 17, 127; DE430): :data:`LITERATURE_PERIODS_DAYS`.
"""

from __future__ import annotations

import time as _time
from dataclasses import dataclass

import numpy as np
from scipy.optimize import least_squares

from spinorbit.coupling.moon import (
    check_run,
    compare_interior_with_de421,
    compare_with_de421,
    moon_at_de421,
)
from spinorbit.time import time_from_tdb_days

__all__ = [
    "FREE_MODES",
    "LITERATURE_PERIODS_DAYS",
    "FreeModeFit",
    "FreeModes",
    "free_modes",
    "libration_spectrum",
]

FREE_MODES = ("longitude", "latitude", "wobble")
#: Published free-mode periods (days): Yang et al. 2017 (RAA 17, 127, abstract: 1056.16, 8806.9 and
#: 27262.99 d from DE430) and Rambaux & Williams 2011 (CeMDA 109, 85: 1056 d, 24.2 yr, 74.6 yr from
#: DE421, Julian years of 365.25 d).
LITERATURE_PERIODS_DAYS = {
    "Yang et al. 2017 (DE430)": {"longitude": 1056.16, "latitude": 8806.9, "wobble": 27262.99},
    "Rambaux & Williams 2011 (DE421)": {"longitude": 1056.0, "latitude": 24.2 * 365.25,
                                        "wobble": 74.6 * 365.25},
}
#: Sidereal month (days), the width of the average that separates the slow modes from the monthly ones.
SIDEREAL_MONTH_DAYS = 27.321662
#: Kick to the mantle's angular velocity, relative to its rate 0.23 rad/day: about x (tilts the spin:
#: wobble and latitude modes, ≈ 2″ and ≈ 0.1″) and about z (longitude mode, ≈ 8″). Small enough that
#: the response is linear (the forced librations are ~100″), large enough to stand far above the
#: runs' difference without a kick (zero: same code, same steps).
KICK_RELATIVE = {"x": 1e-5, "z": 1e-6}
ARCSEC_PER_RAD = 180.0 * 3600.0 / np.pi
#: Default run: 200 yr from JD 2415045.0 TDB (1900-01-25 12:00), every 2 days; two cycles and more of
#: the wobble, eight of the latitude mode, inside DE421 (1899-12-04 .. 2200-02-01).
DEFAULT_START_DAY = -36500.0
DEFAULT_SPAN_DAYS = 200 * 365.25
DEFAULT_STEP_DAYS = 2.0


@dataclass(frozen=True)
class FreeModeFit:
    """One free mode fitted in a kicked-minus-reference signal.

    Attributes
    ----------
    period_days : float
        2π/|ω| (days, TDB).
    damping_days : float
        e-folding time of the amplitude (days; ``inf`` for no measurable damping, negative if it grew).
    amplitude_arcsec : float
        Amplitude at the start of the signal (arcsec); for the latitude mode and the wobble the
        semi-major axis of the ellipse the two components trace.
    minor_amplitude_arcsec : float
        The ellipse's semi-minor axis (arcsec; 0 for the longitude mode, a line).
    residual_arcsec : float
        RMS of the fit's residual (arcsec), what the damped sinusoid and line leave.
    """

    period_days: float
    damping_days: float
    amplitude_arcsec: float
    minor_amplitude_arcsec: float
    residual_arcsec: float


@dataclass(frozen=True)
class FreeModes:
    """The free modes of one model: ``modes[name]`` (a :class:`FreeModeFit`) and ``signals[name]``
    (TDB days, the kicked − reference signal fitted, arcsec; complex for latitude and wobble) for each
    mode asked for."""

    model: str
    start_day: float
    span_days: float
    step_days: float
    modes: dict
    signals: dict
    wall_seconds: float

    def relative_to(self, reference: str = "Yang et al. 2017 (DE430)") -> dict:
        """(measured − published)/published for each mode, against one of :data:`LITERATURE_PERIODS_DAYS`."""
        published = LITERATURE_PERIODS_DAYS[reference]
        return {name: fit.period_days / published[name] - 1.0 for name, fit in self.modes.items()}


def libration_spectrum(days, values, detrend: int = 1):
    """Amplitude spectrum of a sampled libration series (Hann window, amplitude-corrected).

    Parameters
    ----------
    days : array_like, shape (n,)
        Equally spaced TDB days.
    values : array_like, shape (n,)
        The series (e.g. τ in arcsec); a polynomial of degree ``detrend`` is removed first.

    Returns
    -------
    periods_days, amplitudes : ndarray
        Periods (days, longest first, the zero frequency left out) and the amplitude of a sinusoid
        at each (the series' unit). A line's amplitude is exact at a bin centre and within 15 % between.
    """
    days = np.asarray(days, dtype=float)
    values = np.asarray(values, dtype=float)
    step = np.diff(days)
    if days.size < 8 or not np.allclose(step, step[0], rtol=1e-6, atol=1e-9):
        raise ValueError(f"days: expected at least 8 equally spaced times, got {days.size} "
                         f"(spacings {step.min() if step.size else 0:g} .. {step.max() if step.size else 0:g} d).")
    centred = days - days.mean()
    values = values - np.polyval(np.polyfit(centred, values, detrend), centred)
    window = np.hanning(days.size)
    spectrum = np.fft.rfft(values * window)
    amplitudes = 2.0 * np.abs(spectrum) / window.sum()
    frequencies = np.fft.rfftfreq(days.size, step[0])
    return 1.0 / frequencies[1:], amplitudes[1:]


def _monthly_mean(days, values):
    """Boxcar average over one sidereal month (valid part only), with its times."""
    width = max(1, int(round(SIDEREAL_MONTH_DAYS / (days[1] - days[0]))))
    kernel = np.ones(width) / width
    return np.convolve(days, kernel, mode="valid"), np.convolve(values, kernel, mode="valid")


def _fit(days, signal):
    """Damped ellipse (complex signal) or sinusoid (real) + line, by variable projection; a :class:`FreeModeFit`.

    A complex signal gets both senses of rotation at the one frequency, e^{±iωt}: the wobble traces an
    ellipse (axis ratio ≈ 2.5), which one circular term would leave in the residual.
    """
    t = days - days[0]
    scale = np.max(np.abs(signal))
    z = signal / scale
    is_complex = np.iscomplexobj(signal)
    # Start: the highest spectral peak of the detrended signal (both senses for a complex signal).
    detrended = z - np.polyval(np.polyfit(t, z, 1), t)
    padded = 8 * t.size
    spectrum = np.abs(np.fft.fft(detrended * np.hanning(t.size), padded))
    frequencies = np.fft.fftfreq(padded, t[1] - t[0])
    if not is_complex:
        spectrum[frequencies < 0] = 0.0
    spectrum[0] = 0.0
    omega0 = 2.0 * np.pi * frequencies[np.argmax(spectrum)]

    def basis(parameters):
        omega, rate = parameters
        wave = np.exp((1j * omega - rate) * t)
        columns = [np.ones_like(t), t]
        columns += [wave, np.conj(wave)] if is_complex else [wave.real, wave.imag]
        return np.array(columns, dtype=complex if is_complex else float).T

    def residual(parameters):
        design = basis(parameters)
        coefficients = np.linalg.lstsq(design, z, rcond=None)[0]
        r = design @ coefficients - z
        return np.concatenate([r.real, r.imag]) if is_complex else r

    solution = least_squares(residual, [omega0, 0.0], x_scale=[abs(omega0), abs(omega0) * 1e-2 + 1e-12],
                             xtol=1e-14, ftol=1e-14, gtol=1e-14)
    omega, rate = solution.x
    coefficients = np.linalg.lstsq(basis(solution.x), z, rcond=None)[0]
    if is_complex:
        major = abs(coefficients[2]) + abs(coefficients[3])
        minor = abs(abs(coefficients[2]) - abs(coefficients[3]))
    else:
        major, minor = float(np.hypot(coefficients[2], coefficients[3])), 0.0
    rms = float(np.sqrt(np.mean(residual(solution.x) ** 2)) * scale)
    return FreeModeFit(period_days=float(2.0 * np.pi / abs(omega)),
                       damping_days=float(1.0 / rate) if rate != 0.0 else float("inf"),
                       amplitude_arcsec=float(major * scale), minor_amplitude_arcsec=float(minor * scale),
                       residual_arcsec=rms)


def _run(model, start_day, span_days, step_days, spin_offset):
    if model == "de421":
        return compare_interior_with_de421(span_days, step_days, start_day=start_day, spin_offset=spin_offset)
    moon = moon_at_de421(epoch=time_from_tdb_days(start_day), model=model, spin_offset=spin_offset)
    return compare_with_de421(moon, span_days, step_days)


def free_modes(model: str = "rigid", start_day: float = DEFAULT_START_DAY, span_days: float = DEFAULT_SPAN_DAYS,
               step_days: float = DEFAULT_STEP_DAYS, modes=FREE_MODES) -> FreeModes:
    """Measure the free-mode periods of one Moon model (module docstring: what is measured).

    Parameters
    ----------
    model : {"de421", "rigid", "core-corrected"}
        The model (:func:`spinorbit.coupling.moon.compare_model_with_de421`).
    start_day, span_days, step_days : float
        Start (TDB days since J2000; default 1900-01-25 12:00), span and output spacing (days). Both runs
        must lie inside DE421 (:func:`spinorbit.coupling.moon.check_run`). A mode's period is
        resolved to ≈ 0.1 % once the span holds a few of its cycles: the wobble needs ≥ 150 yr,
        the latitude mode ≥ 80 yr, the longitude mode ≥ 15 yr.
    modes : sequence of str
        Which of :data:`FREE_MODES` to fit.

    Returns
    -------
    FreeModes
    """
    check_run(model, float(start_day), float(span_days), float(step_days))
    unknown = sorted(set(modes) - set(FREE_MODES))
    if unknown:
        raise ValueError(f"modes: expected names from {FREE_MODES}, got {unknown}.")
    begin = _time.perf_counter()
    reference = _run(model, start_day, span_days, step_days, None)
    rate = float(np.abs(np.gradient(reference.angles_de421[:, 2], reference.times)).mean())
    kick = rate * np.array([KICK_RELATIVE["x"], 0.0, KICK_RELATIVE["z"]])
    kicked = _run(model, start_day, span_days, step_days, kick)
    wall = _time.perf_counter() - begin
    days = reference.times
    delta = kicked.librations_model - reference.librations_model  # (Δτ, Δρ, ΔIσ), arcsec
    body = kicked.body_difference_arcsec - reference.body_difference_arcsec
    signals = {"longitude": (days, delta[:, 0]),
               "latitude": _monthly_mean(days, delta[:, 1] + 1j * delta[:, 2]),
               "wobble": _monthly_mean(days, body[:, 0] + 1j * body[:, 1])}
    signals = {name: signals[name] for name in FREE_MODES if name in modes}
    fits = {name: _fit(*signal) for name, signal in signals.items()}
    return FreeModes(model=model, start_day=float(start_day), span_days=float(span_days),
                     step_days=float(step_days), modes=fits, signals=signals, wall_seconds=wall)
