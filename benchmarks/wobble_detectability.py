"""How large a wobble a lightcurve shows: the default PA threshold's reason, measured (docs/design.md, "PA or NPA").

A uniform triaxial ellipsoid, semi-axes 1.5 : 1.2 : 1 (a typical elongation: about 0.22 mag of lightcurve
amplitude seen from 60° off the pole), spins in SAM with an 8 h sidereal period and wobble amplitudes
θ_max from 0.1° to 10° (the state taken where its C axis is θ_max from L, so θ_max is exact). Its
brightness (Lommel–Seeliger, closed form; :func:`spinorbit.photometry.brightness`) is computed along the
exact free motion for 10 days (4000 points, 30 rotations, several precession cycles) with the Sun and
the observer fixed in space, 20° apart, at aspect angles 30°, 60° and 90° from L. The best
*single-period* lightcurve — a Fourier series of order 8 in one frequency, the period fitted on a grid of
±0.2 % about the sidereal one — is subtracted: what is left is what a principal-axis model cannot
explain, i.e. the tumbling signature an observer would have to detect to call the body NPA (Pravec et
al. 2005, Icarus 173, 108). The table gives its rms and peak (mmag) against the photometric error of good
dense lightcurves, ~10 mmag.

Usage: ``PYTHONPATH=$PWD python benchmarks/wobble_detectability.py [--no-write | --quick]`` (~1 min; --quick a few s).
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

import numpy as np
from astropy import units as u

sys.path.insert(0, str(Path(__file__).resolve().parent))
from _report import machine_line, write_section  # noqa: E402

from spinorbit import RigidBody, RotationState  # noqa: E402
from spinorbit.core.math.rotations import quat_to_attitude_many  # noqa: E402
from spinorbit.photometry import brightness  # noqa: E402
from spinorbit.photometry.brightness import Ellipsoid  # noqa: E402

SEMI_AXES = np.array([1.5, 1.2, 1.0])
#: A uniform ellipsoid's principal moments per unit mass × 5: (b² + c², a² + c², a² + b²).
MOMENTS = [SEMI_AXES[1] ** 2 + SEMI_AXES[2] ** 2, SEMI_AXES[0] ** 2 + SEMI_AXES[2] ** 2,
           SEMI_AXES[0] ** 2 + SEMI_AXES[1] ** 2]
PERIOD_H = 8.0
WOBBLES_DEG = (0.1, 0.3, 1.0, 3.0, 10.0)
ASPECTS_DEG = (30.0, 60.0, 90.0)
PHASE_ANGLE_DEG = 20.0
SPAN_DAYS, POINTS = 10.0, 4000
FOURIER_ORDER = 8
PERIOD_GRID = np.linspace(-2e-3, 2e-3, 41)  # relative offsets of the fitted period from the sidereal one


def tumbler(wobble_deg):
    """A SAM state of MOMENTS whose wobble amplitude is ``wobble_deg``, |ω| = 2π / 8 h: M ∝ (0, sin θ, cos θ)."""
    theta = math.radians(wobble_deg)
    omega = np.array([0.0, math.sin(theta), math.cos(theta)]) / MOMENTS
    omega *= 2 * math.pi / (PERIOD_H / 24.0) / np.linalg.norm(omega)
    return RotationState(RigidBody(MOMENTS), [1.0, 0.0, 0.0, 0.0], omega * u.rad / u.day)


def magnitudes(state, aspect_deg, times_days):
    """−2.5 log10 L along the free motion, Sun and observer fixed in space at ``aspect_deg`` from L."""
    pole = state.angular_momentum_direction
    across = np.cross(pole, [1.0, 0.0, 0.0])
    across /= np.linalg.norm(across)
    aspect, phase = math.radians(aspect_deg), math.radians(PHASE_ANGLE_DEG)
    observer = math.cos(aspect) * pole + math.sin(aspect) * across
    sun = math.cos(aspect + phase) * pole + math.sin(aspect + phase) * across
    quaternions, _ = state.propagate_torque_free(times_days * u.day)
    to_body = quat_to_attitude_many(np.ascontiguousarray(quaternions))  # inertial → body
    light = brightness(Ellipsoid(SEMI_AXES * u.km), to_body @ sun, to_body @ observer).to_value(u.km**2)
    return -2.5 * np.log10(light)


def single_period_residual(times_days, mags, sidereal_days):
    """(rms, peak) of the residual of the best single-period Fourier fit (period on PERIOD_GRID), mag."""
    best = None
    for offset in PERIOD_GRID:
        rate = 2 * math.pi / (sidereal_days * (1 + offset))
        design = np.column_stack([np.ones_like(times_days)] + [f(k * rate * times_days) for k in
                                                                range(1, FOURIER_ORDER + 1) for f in (np.cos, np.sin)])
        coefficients, *_ = np.linalg.lstsq(design, mags, rcond=None)
        residual = mags - design @ coefficients
        rms = float(np.sqrt(np.mean(residual ** 2)))
        if best is None or rms < best[0]:
            best = (rms, float(np.max(np.abs(residual))))
    return best


def measure(wobbles=WOBBLES_DEG, aspects=ASPECTS_DEG, points=POINTS):
    times = np.linspace(0.0, SPAN_DAYS, points)
    rows = []
    for wobble in wobbles:
        state = tumbler(wobble)
        sidereal = state.sidereal_period.to_value(u.day)
        cells = []
        for aspect in aspects:
            mags = magnitudes(state, aspect, times)
            rms, peak = single_period_residual(times, mags, sidereal)
            cells.append((float(np.ptp(mags)), rms, peak))
        rows.append((wobble, state.wobble_amplitude.to_value(u.deg), state.mode, cells))
    return rows


def markdown(rows, aspects=ASPECTS_DEG, points=POINTS):
    head = " | ".join(f"aspect {a:g}°: range, rms, peak" for a in aspects)
    lines = [machine_line(), "`PYTHONPATH=$PWD python benchmarks/wobble_detectability.py`: what a single-period "
             "(principal-axis) lightcurve leaves unexplained (rms and peak of the residual), with the lightcurve's "
             "range, in mmag, for an ellipsoid 1.5 : 1.2 : 1 in SAM (8 h, phase angle "
             f"{PHASE_ANGLE_DEG:g}°, {SPAN_DAYS:g} d, {points} points; aspect: the observer's angle from L).", "",
             f"| wobble amplitude | {head} |", "|---|" + "---|" * len(aspects)]
    for wobble, measured, mode, cells in rows:
        text = " | ".join(f"{amp * 1e3:.0f}, {rms * 1e3:.2f}, {peak * 1e3:.2f}" for amp, rms, peak in cells)
        lines.append(f"| {wobble:g}° ({mode}; `wobble_amplitude` {measured:.6g}°) | {text} |")
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--no-write", action="store_true", help="print only, do not touch docs/design.md")
    parser.add_argument("--quick", action="store_true", help="one wobble, one aspect, 800 points; print only")
    args = parser.parse_args(argv)
    if args.quick:
        text = markdown(measure((1.0,), (60.0,), 800), (60.0,), 800)
    else:
        text = markdown(measure())
    print(text)
    if not (args.no_write or args.quick):
        print(f"wrote {write_section('wobble_detectability', text, page='design.md')}")


if __name__ == "__main__":
    main()
