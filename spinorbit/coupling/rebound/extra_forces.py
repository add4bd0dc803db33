"""Compiled extra forces on REBOUND's orbits: Earth's J2, the EIH 1PN terms, a non-gravitational push.

:func:`install_extra_forces` puts a numba ``@cfunc`` into ``sim._additional_forces`` as a raw C
function pointer (not the public ``additional_forces`` property, which would wrap it in a Python
thunk and make it as slow as a Python callback). It adds Earth's J2 acting on every other body (with
the reaction on Earth) and the first post-Newtonian (Einstein–Infeld–Hoffmann) accelerations of all
bodies on each other; :func:`set_nongravitational` switches on the Marsden–Sekanina–Yeomans
acceleration of one body (e.g. Yarkovsky). The cfunc reads its parameters through ``sim.extras``;
every object C can reach (cfunc, pointer, parameter array) is kept alive on the simulation object
for its whole life. :func:`apply_extra_forces` is the compiled body, shared with the rigid-body
coupling's combined force (:mod:`spinorbit.coupling.rebound.rotation_hooks`).

Units: DE421's ("AU", "day", "Msun"); the parameter block holds au, au³/day², au/day and au/day².
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numba import carray, cfunc, types

from spinorbit.core.jit import jit
from spinorbit.coupling.rebound.memory_layout import (
    ADDITIONAL_FORCES_TYPE,
    PARTICLE_WORDS,
    SIM_EXTRAS_WORD,
    SIM_G_WORD,
    SIM_N_WORD,
    SIM_PARTICLES_WORD,
    SIM_WORDS,
    as_float64_pointer,
    word_as_float64,
)
# Short names for the particle word offsets, read in the index arithmetic of the kernels below.
from spinorbit.coupling.rebound.memory_layout import PARTICLE_AX as _AX
from spinorbit.coupling.rebound.memory_layout import PARTICLE_M as _M
from spinorbit.coupling.rebound.memory_layout import PARTICLE_VX as _VX
from spinorbit.coupling.rebound.memory_layout import PARTICLE_X as _X
from spinorbit.coupling.rebound.simulation import body_index
from spinorbit.ephemeris import de421_constants

__all__ = [
    "ForceInstallError",
    "ExtraForces",
    "EXTRA_SIZE",
    "extra_force_parameters",
    "hand_forces_to_rebound",
    "install_extra_forces",
    "reinstall_extra_forces",
    "set_nongravitational",
    "apply_extra_forces",
    "extra_forces_cfunc",
]


class ForceInstallError(RuntimeError):
    """Extra forces cannot be installed safely on this simulation."""


# The parameter block the cfunc reads through sim.extras: word offsets into a float64 array.
EXTRA_EARTH, EXTRA_USE_J2, EXTRA_USE_GR = 1, 2, 3  # word 0 unused; EXTRA_EARTH: Earth's particle index
EXTRA_EARTH_GM, EXTRA_EARTH_J2, EXTRA_EARTH_RADIUS = 4, 5, 6  # au³/day², 1, au
EXTRA_POLE = 7  # 7, 8, 9: unit vector of Earth's figure axis (ICRF)
EXTRA_C = 11  # word 10 unused; speed of light, au/day
# Marsden–Sekanina–Yeomans (1973) non-gravitational acceleration on one body (e.g. Yarkovsky):
# a = g(r) (A1 r̂ + A2 t̂ + A3 n̂), g(r) = (r0/r)², r heliocentric; 0 in EXTRA_NG_BODY means "off".
EXTRA_NG_BODY, EXTRA_NG_SUN = 12, 13  # particle indices
EXTRA_NG_A = 14  # 14, 15, 16: A1, A2, A3 in au/day²
EXTRA_NG_R0 = 17  # au
#: Length of the parameter block (float64 words).
EXTRA_SIZE = 18


@jit
def apply_extra_forces(words, p):
    """The body of :func:`extra_forces_cfunc`, callable from any cfunc that owns ``additional_forces``.

    ``words``: the simulation struct as 64-bit words; ``p``: the extra-force parameter block
    (``EXTRA_SIZE`` floats). Shared so that the rigid-body coupling's combined force
    (:mod:`spinorbit.coupling.rebound.rotation_hooks`) runs exactly the same EIH + J2 code.
    """
    n = np.int64(words[SIM_N_WORD])
    particles = carray(as_float64_pointer(words[SIM_PARTICLES_WORD]), n * PARTICLE_WORDS)
    earth = np.int64(p[EXTRA_EARTH]) * PARTICLE_WORDS
    correction = np.zeros((n, 3))  # 1PN accelerations × c², added after J2 (see below)

    if p[EXTRA_USE_GR] != 0.0:
        # Einstein–Infeld–Hoffmann 1PN accelerations (β = γ = 1; Moyer 2003, eq. 4-61), all pairs.
        # Uses the Newtonian accelerations REBOUND has just stored, so it runs before J2 is added.
        c2 = p[EXTRA_C] * p[EXTRA_C]
        g = word_as_float64(words[SIM_G_WORD])
        potential = np.zeros(n)  # Σ_k G m_k / r_ik
        for i in range(n):
            bi = i * PARTICLE_WORDS
            for k in range(i + 1, n):
                bk = k * PARTICLE_WORDS
                dx = particles[bi + _X] - particles[bk + _X]
                dy = particles[bi + _X + 1] - particles[bk + _X + 1]
                dz = particles[bi + _X + 2] - particles[bk + _X + 2]
                r = np.sqrt(dx * dx + dy * dy + dz * dz)
                potential[i] += g * particles[bk + _M] / r
                potential[k] += g * particles[bi + _M] / r
        for i in range(n):
            bi = i * PARTICLE_WORDS
            vix, viy, viz = particles[bi + _VX], particles[bi + _VX + 1], particles[bi + _VX + 2]
            vi2 = vix * vix + viy * viy + viz * viz
            for j in range(n):
                if j == i:
                    continue
                bj = j * PARTICLE_WORDS
                mu = g * particles[bj + _M]
                if mu == 0.0:
                    continue
                dx = particles[bj + _X] - particles[bi + _X]  # r_j − r_i
                dy = particles[bj + _X + 1] - particles[bi + _X + 1]
                dz = particles[bj + _X + 2] - particles[bi + _X + 2]
                r2 = dx * dx + dy * dy + dz * dz
                r = np.sqrt(r2)
                r3 = r2 * r
                vjx, vjy, vjz = particles[bj + _VX], particles[bj + _VX + 1], particles[bj + _VX + 2]
                ajx, ajy, ajz = particles[bj + _AX], particles[bj + _AX + 1], particles[bj + _AX + 2]
                vj2 = vjx * vjx + vjy * vjy + vjz * vjz
                vivj = vix * vjx + viy * vjy + viz * vjz
                rvj = -(dx * vjx + dy * vjy + dz * vjz) / r  # (r_i − r_j)·v_j / r_ij
                raj = dx * ajx + dy * ajy + dz * ajz  # (r_j − r_i)·a_j
                bracket = (
                    -4.0 * potential[i] - potential[j] + vi2 + 2.0 * vj2 - 4.0 * vivj
                    - 1.5 * rvj * rvj + 0.5 * raj
                )
                # (r_i − r_j)·(4 v_i − 3 v_j)
                rw = -(dx * (4.0 * vix - 3.0 * vjx) + dy * (4.0 * viy - 3.0 * vjy)
                       + dz * (4.0 * viz - 3.0 * vjz))
                correction[i, 0] += mu / r3 * (dx * bracket + rw * (vix - vjx)) + 3.5 * mu / r * ajx
                correction[i, 1] += mu / r3 * (dy * bracket + rw * (viy - vjy)) + 3.5 * mu / r * ajy
                correction[i, 2] += mu / r3 * (dz * bracket + rw * (viz - vjz)) + 3.5 * mu / r * ajz
    if p[EXTRA_USE_J2] != 0.0:
        # a = 3 J2 GM R² / (2 r⁵) · [(5 z²/r² − 1) r − 2 z k], z = r·k (r from Earth to the body).
        gm, kx, ky, kz = p[EXTRA_EARTH_GM], p[EXTRA_POLE], p[EXTRA_POLE + 1], p[EXTRA_POLE + 2]
        factor0 = 1.5 * p[EXTRA_EARTH_J2] * gm * p[EXTRA_EARTH_RADIUS] ** 2
        m_earth = particles[earth + _M]
        for i in range(n):
            b = i * PARTICLE_WORDS
            if b == earth:
                continue
            dx = particles[b + _X] - particles[earth + _X]
            dy = particles[b + _X + 1] - particles[earth + _X + 1]
            dz = particles[b + _X + 2] - particles[earth + _X + 2]
            r2 = dx * dx + dy * dy + dz * dz
            r = np.sqrt(r2)
            z = dx * kx + dy * ky + dz * kz
            factor = factor0 / (r2 * r2 * r)
            radial = 5.0 * z * z / r2 - 1.0
            ax = factor * (radial * dx - 2.0 * z * kx)
            ay = factor * (radial * dy - 2.0 * z * ky)
            az = factor * (radial * dz - 2.0 * z * kz)
            particles[b + _AX] += ax
            particles[b + _AX + 1] += ay
            particles[b + _AX + 2] += az
            # Reaction: Earth's figure is pulled back with the opposite force (momentum conserved).
            ratio = particles[b + _M] / m_earth
            particles[earth + _AX] -= ratio * ax
            particles[earth + _AX + 1] -= ratio * ay
            particles[earth + _AX + 2] -= ratio * az

    if p[EXTRA_NG_BODY] != 0.0:
        _add_nongravitational(particles, p)

    if p[EXTRA_USE_GR] != 0.0:
        for i in range(n):
            bi = i * PARTICLE_WORDS
            particles[bi + _AX] += correction[i, 0] / c2
            particles[bi + _AX + 1] += correction[i, 1] / c2
            particles[bi + _AX + 2] += correction[i, 2] / c2


@jit
def _add_nongravitational(particles, p):
    """Add g(r) (A1 r̂ + A2 t̂ + A3 n̂) to the body's acceleration (no reaction: photon recoil).

    r̂ from the Sun to the body, n̂ along r × v (heliocentric), t̂ = n̂ × r̂ (along the motion), as in
    JPL's small-body model (Marsden, Sekanina & Yeomans 1973, AJ 78, 211) with g(r) = (r0/r)².
    """
    b = np.int64(p[EXTRA_NG_BODY]) * PARTICLE_WORDS
    s = np.int64(p[EXTRA_NG_SUN]) * PARTICLE_WORDS
    x = particles[b + _X] - particles[s + _X]
    y = particles[b + _X + 1] - particles[s + _X + 1]
    z = particles[b + _X + 2] - particles[s + _X + 2]
    vx = particles[b + _VX] - particles[s + _VX]
    vy = particles[b + _VX + 1] - particles[s + _VX + 1]
    vz = particles[b + _VX + 2] - particles[s + _VX + 2]
    r = np.sqrt(x * x + y * y + z * z)
    nx, ny, nz = y * vz - z * vy, z * vx - x * vz, x * vy - y * vx
    h = np.sqrt(nx * nx + ny * ny + nz * nz)
    rx, ry, rz = x / r, y / r, z / r
    nx, ny, nz = nx / h, ny / h, nz / h
    tx, ty, tz = ny * rz - nz * ry, nz * rx - nx * rz, nx * ry - ny * rx
    g = (p[EXTRA_NG_R0] / r) ** 2
    a1, a2, a3 = p[EXTRA_NG_A], p[EXTRA_NG_A + 1], p[EXTRA_NG_A + 2]
    particles[b + _AX] += g * (a1 * rx + a2 * tx + a3 * nx)
    particles[b + _AX + 1] += g * (a1 * ry + a2 * ty + a3 * ny)
    particles[b + _AX + 2] += g * (a1 * rz + a2 * tz + a3 * nz)


@cfunc(types.void(types.CPointer(types.uint64)), cache=True)
def extra_forces_cfunc(simulation):
    """Earth J2 on all bodies (+ reaction on Earth) and the EIH 1PN accelerations, in place.

    ``simulation`` is REBOUND's ``struct reb_simulation*``, viewed as 64-bit words. Accelerations
    are *added* to ``ax, ay, az``, which REBOUND has filled with Newtonian gravity already.
    """
    words = carray(simulation, SIM_WORDS)
    p = carray(as_float64_pointer(words[SIM_EXTRAS_WORD]), EXTRA_SIZE)
    apply_extra_forces(words, p)


def hand_forces_to_rebound(sim, holder, parameters: np.ndarray, force_cfunc):
    """Make ``force_cfunc`` (reading ``parameters`` through ``sim.extras``) ``sim``'s additional forces.

    Keep-alive: rebound.Simulation has fixed ``__slots__`` and no weakrefs; its own slots ``_afp``
    (holder of the additional-forces function) and ``_extras_ref`` (holder of what ``extras`` points
    to) are the places REBOUND itself uses for exactly this, and die with the simulation. ``holder``
    (which must keep the returned pointer and the cfunc alive) goes into ``_afp``.

    Returns
    -------
    ctypes function pointer
        The raw pointer now in ``sim._additional_forces``.
    """
    pointer = ADDITIONAL_FORCES_TYPE(force_cfunc.address)
    sim._afp = holder
    sim._extras_ref = parameters
    sim.extras = parameters.ctypes.data
    sim._additional_forces = pointer
    return pointer


@dataclass
class ExtraForces:
    """What :func:`install_extra_forces` attached; kept on the simulation for its whole life.

    Attributes
    ----------
    parameters : ndarray
        The float64 array the cfunc reads through ``sim.extras`` (do not reallocate it).
    earth_j2, gr : bool
        Which forces are on.
    """

    parameters: np.ndarray
    earth_j2: bool
    gr: bool
    _function_pointer: object = None
    _cfunc: object = None

    @classmethod
    def from_parameters(cls, parameters) -> ExtraForces:
        """A description (not installed) of the forces a parameter block switches on; the block is copied.

        What :func:`reinstall_extra_forces` needs to put the same forces on another simulation, e.g.
        the block stored in a checkpoint (``CoupledRigidBody.checkpoint``).

        Raises
        ------
        ValueError
            ``parameters`` is not a block of ``EXTRA_SIZE`` finite floats.
        """
        block = np.array(parameters, dtype=float)
        if block.shape != (EXTRA_SIZE,) or not np.all(np.isfinite(block)):
            raise ValueError(f"parameters: expected the {EXTRA_SIZE} finite floats of an install_extra_forces "
                             f"block, got an array of shape {block.shape}.")
        return cls(block, bool(block[EXTRA_USE_J2]), bool(block[EXTRA_USE_GR]))


def install_extra_forces(sim, earth_j2: bool = True, gr: bool = True, earth_pole=(0.0, 0.0, 1.0)):
    """Install compiled extra forces (Earth J2, solar 1PN) as a raw C pointer in ``sim``.

    Parameters
    ----------
    sim : rebound.Simulation
        Must contain a particle named 'Earth' (for J2), in DE421 units
        ("AU", "day", "Msun"), e.g. from :func:`simulation_from_de421`.
    earth_j2 : bool, optional
        Add DE421's Earth J2 (J2E, radius AE) acting on every other body, reaction on Earth.
    gr : bool, optional
        Add the Einstein–Infeld–Hoffmann 1PN accelerations among all bodies (β = γ = 1, harmonic
        gauge, as DE421 integrates them).
    earth_pole : array_like, shape (3,), optional
        Earth's figure axis in ICRF (unit vector). Default: ICRF z, which is the J2000 mean pole
        to the frame bias (≈ 20 mas); precession moves the true pole ≈ 20″ a year.

    Returns
    -------
    ExtraForces
        The installed forces; also kept on ``sim`` (in REBOUND's own keep-alive slots ``_afp`` and
        ``_extras_ref``) so that the cfunc, its pointer and its parameters live as long as ``sim``.
        Setting ``sim.additional_forces`` afterwards replaces these forces.

    Raises
    ------
    ForceInstallError
        If ``sim.extras`` is already in use (REBOUNDx attached: add the forces as a REBOUNDx custom
        force instead) or extra forces are already installed.
    MissingBodyError
        If 'Earth' is missing when J2 is requested.
    """
    if isinstance(getattr(sim, "_afp", None), ExtraForces):
        raise ForceInstallError("extra forces are already installed on this simulation.")
    if sim.extras:
        raise ForceInstallError(
            "sim.extras is already set (is REBOUNDx attached?). REBOUNDx replaces additional_forces; "
            "add these forces through REBOUNDx instead of spinorbit's raw pointer."
        )
    parameters = extra_force_parameters(sim, earth_j2, gr, earth_pole)
    handle = ExtraForces(parameters, bool(earth_j2), bool(gr))
    handle._cfunc = extra_forces_cfunc
    handle._function_pointer = hand_forces_to_rebound(sim, handle, parameters, extra_forces_cfunc)
    if gr:
        sim.force_is_velocity_dependent = 1  # IAS15 must iterate the velocity-dependent EIH terms
    return handle


def extra_force_parameters(sim, earth_j2: bool, gr: bool, earth_pole=(0.0, 0.0, 1.0)) -> np.ndarray:
    """The parameter block (:data:`EXTRA_SIZE` floats) of J2 and EIH on ``sim``'s particles, not installed.

    What :func:`install_extra_forces` installs, and what the rigid-body coupling folds into its
    combined force. Parameters as in :func:`install_extra_forces`.

    Raises
    ------
    ValueError
        ``earth_pole`` is not a unit 3-vector.
    MissingBodyError
        'Earth' is missing when J2 is requested.
    """
    pole = np.asarray(earth_pole, dtype=float)
    if pole.shape != (3,) or not np.isclose(np.linalg.norm(pole), 1.0, atol=1e-9):
        raise ValueError(f"earth_pole must be a unit 3-vector in ICRF; got {earth_pole!r}.")
    constants = de421_constants()
    parameters = np.zeros(EXTRA_SIZE)
    parameters[EXTRA_EARTH] = body_index(sim, "earth") if earth_j2 else 0
    parameters[EXTRA_USE_J2] = float(earth_j2)
    parameters[EXTRA_USE_GR] = float(gr)
    parameters[EXTRA_EARTH_GM] = constants.gm["earth"]
    parameters[EXTRA_EARTH_J2] = constants.earth_j2
    parameters[EXTRA_EARTH_RADIUS] = constants.earth_radius_km / constants.au_km
    parameters[EXTRA_POLE:EXTRA_POLE + 3] = pole / np.linalg.norm(pole)
    parameters[EXTRA_C] = constants.c_km_s * 86400.0 / constants.au_km
    return parameters


def reinstall_extra_forces(sim, handle: ExtraForces) -> ExtraForces:
    """Install on ``sim`` the same forces, with the same parameters, as ``handle`` (from another sim).

    For rebuilt copies of a simulation (the raw pointer does not survive ``sim.copy()``, REBOUND's
    binary or a Simulationarchive): ``sim`` must hold the same particles in the same order, since
    the parameter block refers to particles by index (Earth for J2, the body and the Sun for the
    non-gravitational terms). ``handle`` may come from :func:`extra_forces_in_effect` or
    :meth:`ExtraForces.from_parameters`.
    """
    copy = install_extra_forces(sim, earth_j2=handle.earth_j2, gr=handle.gr,
                                earth_pole=handle.parameters[EXTRA_POLE:EXTRA_POLE + 3])
    copy.parameters[:] = handle.parameters  # in place: sim.extras points at this array
    return copy


def set_nongravitational(sim, body: str, a1: float, a2: float = 0.0, a3: float = 0.0, r0_au: float = 1.0):
    """Switch on the non-gravitational acceleration of one body in forces from :func:`install_extra_forces`.

    JPL's small-body model (Marsden, Sekanina & Yeomans 1973): a = g(r) (A1 r̂ + A2 t̂ + A3 n̂) with
    g(r) = (r0/r)², r the heliocentric distance, r̂ radial, n̂ along r × v, t̂ = n̂ × r̂. For asteroids
    A2 is the Yarkovsky drift (e.g. Apophis, JPL#218: A2 = −2.90e-14 au/d²).

    Parameters
    ----------
    sim : rebound.Simulation
        With forces from :func:`install_extra_forces`, a particle named 'Sun' and the body itself
        (add the body first, then call this), in DE421 units ("AU", "day", "Msun").
    body : str
        The body's name.
    a1, a2, a3 : float
        Radial, transverse and normal coefficients, au/day².
    r0_au : float, optional
        Normalising distance of g(r), au (JPL: 1 au for asteroids).

    Raises
    ------
    ForceInstallError
        If :func:`install_extra_forces` has not been called on ``sim``.
    MissingBodyError
        If the body or the Sun is missing.
    ValueError
        If a coefficient is not finite or ``r0_au`` is not positive.
    """
    handle = getattr(sim, "_afp", None)
    if not isinstance(handle, ExtraForces):
        raise ForceInstallError(
            "non-gravitational forces live in the block of install_extra_forces; call "
            "install_extra_forces(sim) first, then set_nongravitational(sim, ...)."
        )
    coefficients = np.array([a1, a2, a3, r0_au], dtype=float)
    if not np.all(np.isfinite(coefficients)) or r0_au <= 0.0:
        raise ValueError(
            f"A1, A2, A3 must be finite (au/day²) and r0_au > 0; got A=({a1!r}, {a2!r}, {a3!r}), "
            f"r0_au={r0_au!r}."
        )
    index, sun = body_index(sim, body), body_index(sim, "sun")
    if index == 0:
        raise ValueError(
            f"{body!r} is particle 0; the parameter block uses index 0 for 'off'. Add the Sun (or "
            "another body) first, as simulation_from_de421 does."
        )
    p = handle.parameters  # written in place: the cfunc reads this very array through sim.extras
    p[EXTRA_NG_SUN] = sun
    p[EXTRA_NG_A:EXTRA_NG_A + 3] = coefficients[:3]
    p[EXTRA_NG_R0] = r0_au
    p[EXTRA_NG_BODY] = index  # last: the force switches on only once its parameters are complete

