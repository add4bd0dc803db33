"""The three benchmark scenes: what is integrated, from which initial state, over which span.

A scene is a plain record: the spinorbit model array, the initial state, the output times, and
the same physics described for the peers (moments and Kepler perturbers), so every method integrates
the identical problem. Units: days, AU, moments normalised to C = 1 (only moment ratios and μ
matter for the rotation), unless a scene says otherwise.

(a) Apophis-like SAM tumbler under the solar torque over one heliocentric orbit.
(b) Toutatis-like LAM tumbler through a hyperbolic Earth flyby at 0.01 AU, plus the Sun.
(c) Hairer–Lubich–Wanner body under a weak point-mass torque over 10⁴ rotations.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import quad, solve_ivp
from scipy.optimize import brentq
from scipy.special import ellipk

from spinorbit.data.asteroids import aligning_quaternion as _quat_aligning  # one implementation, in the library
from spinorbit.core import kepler_source, make_model
from spinorbit.core.dynamics import python_reference
from spinorbit.core.math.rotations import matrix_to_quat

GM_SUN = 2.9591220828559115e-4  # AU³/day² (IAU nominal, k²)
GM_EARTH = GM_SUN / 332946.0487  # AU³/day²
KM_S_TO_AU_DAY = 86400.0 / 1.495978707e8
DEG = math.pi / 180.0


@dataclass
class KeplerPerturber:
    """A perturber on a Keplerian orbit relative to the body (the peers rebuild it from this)."""

    mu: float
    a: float
    e: float
    inc: float
    node: float
    argp: float
    mean_anomaly: float
    epoch: float = 0.0
    sign: float = 1.0
    mu_orbit: float | None = None

    def source(self):
        return kepler_source(self.mu, self.a, self.e, self.inc, self.node, self.argp, self.mean_anomaly,
                             self.epoch, self.mu_orbit, self.sign)


@dataclass
class Scene:
    name: str
    title: str
    moments: tuple
    perturbers: list
    y0: np.ndarray
    t0: float
    t_out: np.ndarray
    notes: str = ""
    rotations: float = 0.0
    model: np.ndarray = field(init=False)

    def __post_init__(self):
        self.model = make_model(self.moments, [p.source() for p in self.perturbers])


def sam_periods(moments, G, d):
    """(P_ψ, P_φ) of the free SAM rigid body: P_ψ = 4K(m)/(G√((a−d)(b−c))) (period of the body-frame
    angular momentum, the Andoyer l), P_φ = 2π/⟨ġ⟩ with ġ = G(2T − cL²)/(G² − L²) averaged over one
    P_ψ by quadrature along a direct integration of the torque-free equations of motion (the package's,
    :mod:`spinorbit.core.dynamics.python_reference`; rtol 1e-12)."""
    A, B, C = moments
    a, b, c = 1 / A, 1 / B, 1 / C
    m = (a - b) * (d - c) / ((a - d) * (b - c))
    p_psi = 4 * ellipk(m) / (G * math.sqrt((a - d) * (b - c)))
    L = G * math.sqrt((b - d) / (b - c))
    Lb = np.array([0.0, math.sqrt(G * G - L * L), L])
    y0 = np.concatenate([[1.0, 0.0, 0.0, 0.0], Lb / np.array(moments)])
    sol = solve_ivp(python_reference.make_rhs(make_model(moments)), (0, p_psi), y0, method="DOP853", rtol=1e-12,
                    atol=1e-14 * np.concatenate([np.ones(4), np.full(3, G / C)]), dense_output=True)
    two_t = d * G * G

    def g_dot(t):
        lz = C * sol.sol(t)[6]
        return G * (two_t - c * lz * lz) / (G * G - lz * lz)

    mean, _ = quad(g_dot, 0, p_psi, limit=200, epsabs=0, epsrel=1e-12)
    return p_psi, 2 * math.pi / (mean / p_psi)


def apophis_spin(moments=(0.61, 0.965, 1.0), p_psi=263.0 / 24, p_phi=27.38 / 24):
    """(G, d, L) of the SAM state with the requested periods (days): d from the period ratio (which
    depends on d only), then G from P_ψ (all rates scale with G at fixed d)."""
    A, B, C = moments
    b, c = 1 / B, 1 / C
    ratio = p_psi / p_phi

    def f(d):
        pp, pf = sam_periods(moments, 1.0, d)
        return pp / pf - ratio

    d = brentq(f, c * (1 + 1e-6), b * (1 - 1e-6), xtol=1e-15, rtol=1e-14)
    pp, _ = sam_periods(moments, 1.0, d)
    G = pp / p_psi
    return G, d


def scene_apophis(n_out=11):
    moments = (0.61, 0.965, 1.0)
    G, d = apophis_spin(moments)
    A, B, C = moments
    b, c = 1 / B, 1 / C
    L = G * math.sqrt((b - d) / (b - c))
    L_body = np.array([0.0, math.sqrt(G * G - L * L), L])
    # Retrograde: angular momentum towards ecliptic (λ, β) = (250°, −75°) (Pravec et al. 2014).
    lam, beta = 250 * DEG, -75 * DEG
    L_dir = np.array([math.cos(beta) * math.cos(lam), math.cos(beta) * math.sin(lam), math.sin(beta)])
    q0 = _quat_aligning(L_body, L_dir)
    y0 = np.concatenate([q0, L_body / np.array(moments)])
    a, e = 0.9224, 0.1914
    sun = KeplerPerturber(GM_SUN, a, e, 3.339 * DEG, 204.43 * DEG, 126.39 * DEG, 0.0, sign=-1.0)
    period = 2 * math.pi / math.sqrt(GM_SUN / a**3)
    notes = (f"A:B:C = 0.61:0.965:1; |L| = {G:.6f} (C·rad/day), d = 2T/G² = {d:.6f}, so E/E0 = dC = "
             f"{d:.4f} (published 1.024 ± 0.013); P_ψ = 263 h, P_φ = 27.38 h from the free-body formulas "
             "(P_ψ exact with K(m), P_φ by quadrature); angular momentum towards ecliptic (250°, −75°), "
             f"retrograde. Sun on the orbit a = {a} AU, e = {e}, i = 3.339°, one period = {period:.2f} d.")
    return Scene("a", "Apophis-like SAM, solar torque, one orbit", moments, [sun], y0, 0.0,
                 np.linspace(0, period, n_out)[1:], notes, rotations=period / (27.38 / 24))


def scene_toutatis(n_out=11, half_span=60.0):
    # Published body axes (x, y, z) with z the long axis: moments 3.0836 : 3.235 : 1. Principal-axis
    # convention A ≤ B ≤ C on x', y', z': x' = z, y' = x, z' = y (a cyclic, proper permutation).
    moments_pub = np.array([3.0836, 3.235, 1.0])
    perm = np.array([[0, 0, 1], [1, 0, 0], [0, 1, 0]])  # v_new = perm @ v_pub
    moments = tuple(perm @ moments_pub / 3.235)
    omega_pub = np.array([14.51, 33.529, -98.709]) * DEG  # rad/day
    omega = perm @ omega_pub
    # ZXZ Euler angles body → inertial (145.498°, 65.865°, 241.524°), read as the active rotation
    # M_pub = Rz(φ) Rx(θ) Rz(ψ) in the ecliptic frame (an interpretation; the scene is "Toutatis-like").
    def rz(t):
        return np.array([[math.cos(t), -math.sin(t), 0], [math.sin(t), math.cos(t), 0], [0, 0, 1]])

    def rx(t):
        return np.array([[1, 0, 0], [0, math.cos(t), -math.sin(t)], [0, math.sin(t), math.cos(t)]])

    m_pub = rz(145.498 * DEG) @ rx(65.865 * DEG) @ rz(241.524 * DEG)
    m_new = m_pub @ perm.T  # body' → body_pub → inertial
    q0 = matrix_to_quat(np.ascontiguousarray(m_new))
    y0 = np.concatenate([q0, omega])
    v_inf = 8.4 * KM_S_TO_AU_DAY
    a_hyp = -GM_EARTH / v_inf**2
    q_peri = 0.01
    e_hyp = 1 - q_peri / a_hyp
    earth = KeplerPerturber(GM_EARTH, a_hyp, e_hyp, 30 * DEG, 40 * DEG, 70 * DEG, 0.0, epoch=0.0, sign=1.0)
    sun = KeplerPerturber(GM_SUN, 2.5336, 0.6294, 0.4469 * DEG, 124.37 * DEG, 278.7 * DEG, 0.05,
                          epoch=0.0, sign=-1.0)
    t0 = -half_span
    notes = (f"Moments (x', y', z') = (1, 3.0836, 3.235)/3.235 with x' the published long axis; "
             f"ω = {np.round(omega / DEG, 3).tolist()} deg/day in x', y', z'. Earth on a hyperbola relative "
             f"to the body: perigee 0.01 AU at t = 0, v∞ = 8.4 km/s (e = {e_hyp:.1f}), i = 30°, Ω = 40°, "
             f"ω = 70° (ecliptic). Sun: a = 2.5336 AU, e = 0.6294, M = 0.05 rad at t = 0 (near perihelion). "
             f"Span t = ±{half_span:g} d.")
    return Scene("b", "Toutatis-like LAM, Earth flyby at 0.01 AU + Sun", moments, [earth, sun], y0, t0,
                 np.linspace(t0, half_span, n_out)[1:], notes, rotations=2 * half_span / 5.4)


#: Torque strength of scene (c): 3μ/(R³|ω|²) — the gravity-gradient rate relative to the spin rate².
HLW_TORQUE_RATIO = 1e-4


def scene_hlw(n_out=11, rotations=1e4):
    # HLW: I = (2, 1, 2/3) on (x, y, z); principal convention A ≤ B ≤ C: x' = z, y' = −y, z' = x
    # (an odd permutation with one sign flip, so the frame stays right-handed).
    moments = (2 / 3, 1.0, 2.0)
    L_body = np.array([math.sin(1.1), 0.0, math.cos(1.1)])  # HLW's (cos 1.1, 0, sin 1.1) in x', y', z'
    omega = L_body / np.array(moments)
    y0 = np.concatenate([[1.0, 0, 0, 0], omega])
    w2 = float(omega @ omega)
    radius = 1.0
    mu = HLW_TORQUE_RATIO * w2 * radius**3 / 3
    pert = KeplerPerturber(mu, radius, 0.0, 0.4, 0.3, 0.0, 0.0)
    rot_period = 2 * math.pi / math.sqrt(w2)
    t_end = rotations * rot_period
    notes = (f"HLW body I = (2, 1, 2/3), L = (cos 1.1, 0, sin 1.1) mapped to A ≤ B ≤ C; |ω| = {math.sqrt(w2):.4f}, "
             f"one 'rotation' = 2π/|ω| = {rot_period:.3f} time units, span {rotations:g} rotations = {t_end:.0f}. "
             f"Perturber on a circular orbit of radius 1 inclined 0.4 rad with μ = {mu:.3e} so that "
             f"3μ/(R³|ω|²) = {HLW_TORQUE_RATIO:g}.")
    return Scene("c", "HLW body, weak point-mass torque, 10⁴ rotations", moments, [pert], y0, 0.0,
                 np.linspace(0, t_end, n_out)[1:], notes, rotations=rotations)


def all_scenes(quick=False):
    if quick:
        return [scene_apophis(), scene_toutatis(half_span=30.0), scene_hlw(rotations=1e3)]
    return [scene_apophis(), scene_toutatis(), scene_hlw()]
