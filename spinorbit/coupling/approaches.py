"""Close approaches of one body to another along an orbit: every local minimum of their distance.

:func:`approaches` walks a span with steps of a tenth of the time scale r/|v| of the pair (r, v the
separation and relative velocity), so a minimum of width ≈ r_min/v is never stepped over, and
finds each minimum as the root of the range rate r·v with Brent's method (to 1e-9 d ≈ 0.1 ms).
The states come from a callable ``separation(day) -> (r, v)`` that may be asked for any time in any
order: :func:`rebound_separation` integrates a copy of a REBOUND simulation back and forth
(``exact_finish_time``), :func:`ephemeris_separation` reads a body's ephemeris against DE421.
Units: TDB days since J2000, DE421's au and au/day.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import brentq

from spinorbit.coupling.rebound import SimulationSnapshot, body_index, integrate_interruptibly
from spinorbit.coupling.sampling import de421_state

__all__ = ["MAX_STEP_DAYS", "MIN_STEP_DAYS", "approaches", "ephemeris_separation", "rebound_separation"]

#: Step of the walk: a tenth of r/|v|, between these (days). The lower end keeps a walk finite
#: through a collision course (r → 0); the upper end keeps slow far pairs from skipping a turn.
MIN_STEP_DAYS, MAX_STEP_DAYS = 1e-5, 5.0
STEP_SHARE = 0.1


def rebound_separation(sim, body, target):
    """``day -> (r, v)`` of ``body`` relative to ``target``, two particles of ``sim`` (not modified)."""
    i, j = body_index(sim, body), body_index(sim, target)
    run = SimulationSnapshot.of(sim).build()

    def separation(day):
        integrate_interruptibly(run, day)
        a, b = run.particles[i], run.particles[j]
        return (np.array([a.x - b.x, a.y - b.y, a.z - b.z]), np.array([a.vx - b.vx, a.vy - b.vy, a.vz - b.vz]))

    return separation


def ephemeris_separation(function, target):
    """``day -> (r, v)`` of a body on ``function(days) -> (positions, velocities)`` (barycentric ICRF)
    relative to the DE421 body ``target``."""

    def separation(day):
        position, velocity = (np.asarray(x, dtype=float).reshape(-1, 3)[0] for x in function(np.array([day])))
        target_position, target_velocity = de421_state(target, day)
        return position - target_position, velocity - target_velocity

    return separation


def approaches(separation, start_day, end_day):
    """Every local minimum of |r| inside (start_day, end_day): a list of (day, distance au, speed au/day).

    The minima are those where the range rate r·v/|r| goes from negative to positive; a distance
    that only falls (or only rises) over the span has none.
    """

    def range_rate(day):
        r, v = separation(day)
        return float(r @ v)

    found = []
    day = start_day
    r, v = separation(day)
    rate = float(r @ v)
    while day < end_day:
        scale = float(np.linalg.norm(r)) / max(float(np.linalg.norm(v)), 1e-300)
        step = min(max(STEP_SHARE * scale, MIN_STEP_DAYS), MAX_STEP_DAYS)
        following = min(day + step, end_day)
        r_next, v_next = separation(following)
        rate_next = float(r_next @ v_next)
        if rate < 0.0 <= rate_next:
            root = brentq(range_rate, day, following, xtol=1e-9, rtol=4 * np.finfo(float).eps)
            r_min, v_min = separation(root)
            found.append((root, float(np.linalg.norm(r_min)), float(np.linalg.norm(v_min))))
            r_next, v_next = separation(following)  # a REBOUND copy now sits at ``root``: back to the walk
        day, r, v, rate = following, r_next, v_next, rate_next
    return [m for m in found if start_day < m[0] < end_day and math.isfinite(m[1])]
