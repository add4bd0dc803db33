"""The Apophis encounter ensemble on Keplerian orbits: the one physics spinorbit and heyoka both integrate.

heyoka cannot call REBOUND, so for the ensemble comparison (``bench_ensemble.py``) both peers get
the encounter's torques from two Keplerian orbits fitted once to the REBOUND encounter orbit
(:func:`spinorbit.ensemble.apophis.encounter_orbit`) at the 2029 perigee:

- the Earth relative to Apophis on its geocentric hyperbola (μ = GM_Earth of DE421; the relative
  two-body equation is the same for r and −r, so the elements of −r_geo are the Earth's);
- the Sun relative to Apophis on Apophis's heliocentric ellipse (μ = GM_Sun), reversed the same way.

The Moon is left out (its torque needs its own orbit in heyoka's equations; both peers leave it out).
A member is the published Apophis state at a rotation phase with moment ratios I1/I3, I2/I3
(:func:`spinorbit.ensemble.apophis.apophis_member`'s parameters), from 5 days before the perigee to
``span_days / 2`` after it.

- spinorbit: the member is a Scene whose Earth and Sun are :class:`~spinorbit.scene.EphemerisPerturber`
  s evaluating the Kepler states (``KeplerStates``); the planner samples them onto its Hermite grid,
  once per worker process (the ensemble's sampling memo), and runs at the Scene's tolerance.
- heyoka: one ``taylor_adaptive`` with the moment ratios as runtime parameters (so one compiled
  integrator serves every member), the Sun's position from ``kepE`` of the time and the Earth's from
  the two-body ODE appended to the state (heyoka has no hyperbolic Kepler solver), the degree-2
  torque of both point masses in the formulation of ``peers.heyoka_equations`` (r_b = M(q)ᵀ r, no
  |q|² division, the constant factors folded into the parameters).
"""

from __future__ import annotations

import functools
import math

import numpy as np
from astropy import units as u

from spinorbit.core.model.perturbers import K_P, K_Q, kepler_source, kepler_state

#: Parameter slots of the heyoka integrator: Euler's three coefficients, then 3 torque factors per perturber.
EULER_PARS, EARTH_PARS, SUN_PARS = slice(0, 3), slice(3, 6), slice(6, 9)


def elements_from_state(state, mu):
    """(a, e, inc, node, argp, mean anomaly) of a relative state (6,) on a two-body orbit of G·M ``mu``.

    Any consistent units; angles in radians in the state's own axes; a < 0 and the hyperbolic mean
    anomaly for e > 1 (the conventions of :func:`spinorbit.core.model.perturbers.kepler_source`).
    """
    r, v = np.asarray(state[:3], float), np.asarray(state[3:], float)
    h = np.cross(r, v)
    e_vec = np.cross(v, h) / mu - r / np.linalg.norm(r)
    e = float(np.linalg.norm(e_vec))
    a = 1.0 / (2.0 / np.linalg.norm(r) - v @ v / mu)
    h_hat, e_hat, r_hat = h / np.linalg.norm(h), e_vec / e, r / np.linalg.norm(r)
    inc = math.acos(h_hat[2])
    node_vec = np.array([-h[1], h[0], 0.0])
    n_hat = node_vec / np.linalg.norm(node_vec)
    node = math.atan2(n_hat[1], n_hat[0])
    argp = math.atan2(np.cross(n_hat, e_hat) @ h_hat, n_hat @ e_hat)
    nu = math.atan2(np.cross(e_hat, r_hat) @ h_hat, e_hat @ r_hat)
    if e < 1.0:
        big_e = 2.0 * math.atan(math.sqrt((1.0 - e) / (1.0 + e)) * math.tan(nu / 2.0))
        mean = big_e - e * math.sin(big_e)
    else:
        big_h = 2.0 * math.atanh(math.sqrt((e - 1.0) / (e + 1.0)) * math.tan(nu / 2.0))
        mean = e * math.sinh(big_h) - big_h
    return a, e, inc, node, argp, mean


@functools.cache
def encounter_orbits():
    """'mu a e inc node argp M epoch' of the Earth and the Sun relative to Apophis (one string each, exact
    reprs), fitted to the REBOUND encounter orbit at the sample nearest the 2029 perigee."""
    from spinorbit.coupling.sampling import sample_from_rebound
    from spinorbit.data.asteroids import APOPHIS_2029, APOPHIS_STATE_EPOCH
    from spinorbit.ensemble.apophis import encounter_orbit
    from spinorbit.ephemeris import de421_constants

    orbit = encounter_orbit()
    samples = sample_from_rebound(orbit.simulation, orbit.name, APOPHIS_STATE_EPOCH, APOPHIS_2029.time_tdb + 2 * u.day,
                                  ["earth", "sun"], tolerance=1e-10)
    perigee = span_days(0.0)[1]
    k = int(np.argmin(np.abs(samples.days - perigee)))
    gm = de421_constants().gm
    out = {}
    for j, name in enumerate(samples.names):
        mu = gm[name]
        elements = elements_from_state(samples.states[k, j], mu)
        source = kepler_source(mu, *elements, epoch=float(samples.days[k]))
        fitted = kepler_state(float(samples.days[k]), source.params)
        assert np.allclose(fitted, samples.states[k, j], rtol=1e-10, atol=0.0), (name, fitted, samples.states[k, j])
        out[name] = " ".join(repr(float(x)) for x in (mu, *elements, samples.days[k]))
    return out["earth"], out["sun"]


def kepler_params(text):
    """(mu, kepler_source params) of one 'mu a e inc node argp M epoch' string."""
    mu, a, e, inc, node, argp, mean, epoch = (float(x) for x in text.split())
    return mu, kepler_source(mu, a, e, inc, node, argp, mean, epoch=epoch).params


class KeplerStates:
    """``days -> (positions, velocities)`` (au, au/day) of one Kepler orbit: an EphemerisPerturber's function."""

    def __init__(self, text):
        self.params = kepler_params(text)[1]

    def __call__(self, days):
        states = np.array([kepler_state(float(t), self.params) for t in np.atleast_1d(days)])
        return states[:, :3], states[:, 3:]


@functools.cache
def _perturbers(earth, sun):
    """The two EphemerisPerturbers, one object per process and orbit (so the members share one sampling)."""
    from spinorbit.scene import EphemerisPerturber

    return tuple(EphemerisPerturber(name, kepler_params(text)[0] * u.au**3 / u.day**2, KeplerStates(text),
                                    relative=True) for name, text in (("earth", earth), ("sun", sun)))


@functools.cache
def _published_state(i1_i3, i2_i3):
    from spinorbit.data.asteroids import apophis_rotation_state

    return apophis_rotation_state(moment_ratios=(i1_i3, i2_i3))


def member_state(phase_psi, phase_momentum, i1_i3, i2_i3):
    """The member's RotationState at 5 days before the perigee (as :func:`apophis_member` builds it)."""
    from spinorbit.ensemble.samplers import state_at_phase

    return state_at_phase(_published_state(i1_i3, i2_i3), phase_psi, phase_momentum)


def span_days(span=4.0):
    """(t0, t_end) in TDB days since J2000: 5 days before the perigee to ``span / 2`` after it."""
    from spinorbit.data.asteroids import APOPHIS_2029, APOPHIS_STATE_EPOCH
    from spinorbit.time import tdb_days

    # the days a Scene of these times runs over (the same conversion, to the last bit)
    return (float(np.ravel(tdb_days(APOPHIS_STATE_EPOCH)[0])[0]),
            float(np.ravel(tdb_days(APOPHIS_2029.time_tdb + 0.5 * span * u.day)[0])[0]))


#: The member's initial state as parameter columns: principal-axis quaternion and angular velocity (rad/day).
STATE_COLUMNS = ("q_w", "q_x", "q_y", "q_z", "omega_x", "omega_y", "omega_z")


def state_rows(drawn):
    """Member parameter rows (dicts) of drawn Apophis parameters: the initial state, built once here.

    Both engines start from these numbers, so neither is timed building them (the published state's
    root find takes ~6 ms per body).
    """
    rows = []
    for i in range(len(drawn)):
        state = member_state(*(float(drawn[k][i]) for k in ("phase_psi", "phase_momentum", "i1_i3", "i2_i3")))
        values = state.core_state()  # principal axes are the body axes here (A ≤ B ≤ C given in order)
        rows.append({**dict(zip(STATE_COLUMNS, (float(v) for v in values))),
                     "i1_i3": float(drawn["i1_i3"][i]), "i2_i3": float(drawn["i2_i3"][i])})
    return rows


#: The members' spin unit, composed once (astropy's unit division costs ~0.1 ms per member).
RAD_PER_DAY = u.rad / u.day


def kepler_member(q_w, q_x, q_y, q_z, omega_x, omega_y, omega_z, i1_i3, i2_i3, earth, sun, span=4.0,
                  tolerance_arcsec=1.0):
    """One member's Scene: the state given, the Earth and the Sun on their Kepler orbits (:func:`encounter_orbits`)."""
    from spinorbit.body import RigidBody
    from spinorbit.data.asteroids import APOPHIS_STATE_EPOCH
    from spinorbit.scene import Scene
    from spinorbit.state import RotationState

    state = RotationState(RigidBody([i1_i3, i2_i3, 1.0], name="Apophis"), [q_w, q_x, q_y, q_z],
                          [omega_x, omega_y, omega_z] * RAD_PER_DAY)
    return Scene(state, APOPHIS_STATE_EPOCH, end_time(span), perturbers=_perturbers(earth, sun),
                 tolerance=tolerance_arcsec * u.arcsec)


@functools.cache
def end_time(span=4.0):
    """The members' last output time, ``span / 2`` after the perigee: one Time per process and span (its
    arithmetic costs more than the rest of a member's Scene), the same value each member computed."""
    from spinorbit.data.asteroids import APOPHIS_2029

    return APOPHIS_2029.time_tdb + 0.5 * span * u.day


# ------------------------------------------------------------------------------------------ heyoka

def heyoka_parameters(moments, earth_mu, sun_mu):
    """The 9 runtime parameters of a member with principal moments (A, B, C)."""
    a, b, c = (float(m) for m in moments)
    euler = [(b - c) / a, (c - a) / b, (a - b) / c]
    torque = [3.0 * (c - b) / a, 3.0 * (a - c) / b, 3.0 * (b - a) / c]
    return np.array(euler + [earth_mu * f for f in torque] + [sun_mu * f for f in torque])


def heyoka_system(earth, sun):
    """(equations, extra initial state at the Earth's epoch-free t0 given later) of the encounter for heyoka."""
    import heyoka as hy

    q0, q1, q2, q3, wx, wy, wz = hy.make_vars("q0", "q1", "q2", "q3", "wx", "wy", "wz")
    x, y, z, vx, vy, vz = hy.make_vars("x", "y", "z", "vx", "vy", "vz")
    earth_mu = kepler_params(earth)[0]
    mu, a, e, inc, node, argp, mean, epoch = (float(s) for s in sun.split())
    sun_params = kepler_params(sun)[1]
    n = math.sqrt(mu / a**3)
    big_e = hy.kepE(e, mean + n * (hy.time - epoch))
    px, py = a * (hy.cos(big_e) - e), a * math.sqrt(1 - e**2) * hy.sin(big_e)
    sun_r = [float(sun_params[K_P + i]) * px + float(sun_params[K_Q + i]) * py for i in range(3)]
    inv_r3 = (x * x + y * y + z * z) ** -1.5
    extra = [(x, vx), (y, vy), (z, vz), (vx, -earth_mu * x * inv_r3), (vy, -earth_mu * y * inv_r3),
             (vz, -earth_mu * z * inv_r3)]
    torque = [hy.expression(0.0)] * 3
    for pars, (rx, ry, rz) in ((EARTH_PARS, (x, y, z)), (SUN_PARS, sun_r)):
        bx = (q0 * q0 + q1 * q1 - q2 * q2 - q3 * q3) * rx + 2 * (q1 * q2 + q0 * q3) * ry + 2 * (q1 * q3 - q0 * q2) * rz
        by = 2 * (q1 * q2 - q0 * q3) * rx + (q0 * q0 - q1 * q1 + q2 * q2 - q3 * q3) * ry + 2 * (q2 * q3 + q0 * q1) * rz
        bz = 2 * (q1 * q3 + q0 * q2) * rx + 2 * (q2 * q3 - q0 * q1) * ry + (q0 * q0 - q1 * q1 - q2 * q2 + q3 * q3) * rz
        inv_r5 = (bx * bx + by * by + bz * bz) ** -2.5
        products = (by * bz, bz * bx, bx * by)
        torque = [acc + hy.par[pars.start + i] * products[i] * inv_r5 for i, acc in enumerate(torque)]
    e0, e1, e2 = (hy.par[i] for i in range(3))
    return [(q0, 0.5 * (-q1 * wx - q2 * wy - q3 * wz)), (q1, 0.5 * (q0 * wx + q2 * wz - q3 * wy)),
            (q2, 0.5 * (q0 * wy - q1 * wz + q3 * wx)), (q3, 0.5 * (q0 * wz + q1 * wy - q2 * wx)),
            (wx, e0 * (wy * wz) + torque[0]), (wy, e1 * (wz * wx) + torque[1]),
            (wz, e2 * (wx * wy) + torque[2])] + extra


def heyoka_members(rows, earth, sun):
    """(initial states (N, 13), parameters (N, 9), t0) of member rows (:func:`state_rows`) for heyoka."""
    earth_mu, earth_params = kepler_params(earth)
    sun_mu = kepler_params(sun)[0]
    t0, _ = span_days()
    earth_state = kepler_state(t0, earth_params)
    states = np.array([[row[c] for c in STATE_COLUMNS] + list(earth_state) for row in rows])
    pars = np.array([heyoka_parameters((row["i1_i3"], row["i2_i3"], 1.0), earth_mu, sun_mu) for row in rows])
    return states, pars, t0


class MemberSetter:
    """heyoka's ensemble generator: member i's initial state, parameters and time (picklable for processes)."""

    def __init__(self, states, pars, t0):
        self.states, self.pars, self.t0 = states, pars, t0

    def __call__(self, ta, i):
        ta.state[:] = self.states[i]
        ta.pars[:] = self.pars[i]
        ta.time = self.t0
        return ta


def heyoka_integrator(earth, sun, tol, compact_mode=False, fp_type=float):
    """A taylor_adaptive of the encounter at tolerance ``tol`` (state and parameters set per member)."""
    import heyoka as hy

    kwargs = {"tol": fp_type(tol), "compact_mode": compact_mode, "pars": np.zeros(9, dtype=fp_type)}
    if fp_type is not float:
        kwargs["fp_type"] = fp_type
    return hy.taylor_adaptive(heyoka_system(earth, sun), np.zeros(13, dtype=fp_type), **kwargs)
