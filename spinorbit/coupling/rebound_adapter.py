"""REBOUND behind one adapter: offline DE421 simulations, compiled extra forces, perturber reads.

This module owns every raw pointer the package hands to REBOUND (``docs/ephemeris.md``):

- :func:`simulation_from_de421` builds a ``rebound.Simulation`` from DE421 at an astropy ``Time``,
  offline: units ("AU", "day", "Msun") so that G = k² = DE421's GM_Sun; masses GM/G; ``sim.t`` in
  TDB days since J2000; barycentric ICRF, moved to the centre of mass; ``exact_finish_time = 1``
  (REBOUND has no dense output, so every output time must be hit exactly).
- :func:`install_extra_forces` puts a numba ``@cfunc`` into ``sim._additional_forces`` as a raw C
  function pointer (not the public ``additional_forces`` property, which would wrap it in a Python
  thunk and make it as slow as a Python callback). It adds Earth's J2 acting on every other body
  (with the reaction on Earth) and the first post-Newtonian (Einstein–Infeld–Hoffmann) accelerations
  of all bodies on each other.
  The cfunc reads its parameters through ``sim.extras``; every object C can reach (cfunc, pointer,
  parameter array) is kept alive on the simulation object for its whole life.
- :func:`perturber_positions` reads positions relative to a named body straight out of REBOUND's
  particle array into numpy (body-centric, au, at ``sim.t`` in TDB days since J2000): the input the
  rotation integrators consume for their torques.

Units: "AU" here is DE421's astronomical unit (``spinorbit.ephemeris`` explains the 2.5e-12
difference from IAU 2012's), days are TDB days.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np
import rebound
from numba import carray, cfunc, types
from numba.extending import intrinsic

from ..core._jit import jit
from ..ephemeris import barycentric_state_au, de421_constants
from ..time import tdb_day_and_fraction

__all__ = [
    "DEFAULT_BODIES",
    "MissingBodyError",
    "ForceInstallError",
    "ExtraForces",
    "simulation_from_de421",
    "install_extra_forces",
    "body_index",
    "perturber_positions",
]

#: Bodies of :func:`simulation_from_de421` by default: Sun, the planets (system barycentres as DE421
#: has them; Earth and Moon separately) and Pluto's system barycentre. REBOUND names are these,
#: capitalised.
DEFAULT_BODIES = (
    "sun",
    "mercury",
    "venus",
    "earth",
    "moon",
    "mars",
    "jupiter",
    "saturn",
    "uranus",
    "neptune",
    "pluto",
)


class MissingBodyError(LookupError):
    """A body the caller named is not in the REBOUND simulation."""


class ForceInstallError(RuntimeError):
    """Extra forces cannot be installed safely on this simulation."""


# --------------------------------------------------------------------------------------------
# Raw layout of REBOUND's structs, read from rebound's own ctypes declarations (not hard-coded),
# so that a REBOUND version with another layout changes these numbers instead of corrupting memory.
_WORD = 8
_SIM_N_WORD = rebound.Simulation.N.offset // _WORD
_SIM_PARTICLES_WORD = rebound.Simulation._particles.offset // _WORD
_SIM_EXTRAS_WORD = rebound.Simulation.extras.offset // _WORD
_SIM_G_WORD = rebound.Simulation.G.offset // _WORD
_SIM_WORDS = max(_SIM_N_WORD, _SIM_PARTICLES_WORD, _SIM_EXTRAS_WORD, _SIM_G_WORD) + 1
_PARTICLE_WORDS = ctypes.sizeof(rebound.Particle) // _WORD
_X, _VX, _AX, _M = (getattr(rebound.Particle, f).offset // _WORD for f in ("x", "vx", "ax", "m"))
for _offset in (rebound.Simulation.N.offset, rebound.Simulation._particles.offset,
                rebound.Simulation.extras.offset, ctypes.sizeof(rebound.Particle)):
    assert _offset % _WORD == 0, "REBOUND struct layout is not 8-byte aligned as assumed"
assert ctypes.sizeof(dict(rebound.Simulation._fields_)["N"]) == _WORD, "sim.N is not a 64-bit word"

# Parameter array read by the cfunc through sim.extras (indices into a float64 array).
_P_EARTH, _P_USE_J2, _P_USE_GR = 1, 2, 3  # word 0 unused
_P_EARTH_GM, _P_EARTH_J2, _P_EARTH_RADIUS = 4, 5, 6
_P_POLE = 7  # 7, 8, 9: unit vector of Earth's figure axis (ICRF)
_P_C = 11  # word 10 unused
_N_PARAMETERS = 12


@intrinsic
def _as_float64_pointer(typingctx, address):
    """Reinterpret an integer address as ``double*`` (numba cannot cast int → pointer natively)."""
    if not isinstance(address, types.Integer):
        return None
    signature = types.CPointer(types.float64)(address)

    def codegen(context, builder, sig, args):
        return builder.inttoptr(args[0], context.get_value_type(types.CPointer(types.float64)))

    return signature, codegen


@intrinsic
def _word_as_float64(typingctx, word):
    """Reinterpret the bits of a 64-bit word as a double (sim.G is read from the word view)."""
    if not isinstance(word, types.Integer):
        return None
    signature = types.float64(word)

    def codegen(context, builder, sig, args):
        return builder.bitcast(args[0], context.get_value_type(types.float64))

    return signature, codegen


@jit
def _apply_extra_forces(words, p):
    """The body of :func:`_extra_forces_cfunc`, callable from any cfunc that owns ``additional_forces``.

    ``words``: the simulation struct as 64-bit words; ``p``: the extra-force parameter block
    (``_N_PARAMETERS`` floats). Shared so that the rigid-body coupling's combined force
    (``rotation_coupling``) runs exactly the same EIH + J2 code.
    """
    n = np.int64(words[_SIM_N_WORD])
    particles = carray(_as_float64_pointer(words[_SIM_PARTICLES_WORD]), n * _PARTICLE_WORDS)
    earth = np.int64(p[_P_EARTH]) * _PARTICLE_WORDS
    correction = np.zeros((n, 3))  # 1PN accelerations × c², added after J2 (see below)

    if p[_P_USE_GR] != 0.0:
        # Einstein–Infeld–Hoffmann 1PN accelerations (β = γ = 1; Moyer 2003, eq. 4-61), all pairs.
        # Uses the Newtonian accelerations REBOUND has just stored, so it runs before J2 is added.
        c2 = p[_P_C] * p[_P_C]
        g = _word_as_float64(words[_SIM_G_WORD])
        potential = np.zeros(n)  # Σ_k G m_k / r_ik
        for i in range(n):
            bi = i * _PARTICLE_WORDS
            for k in range(i + 1, n):
                bk = k * _PARTICLE_WORDS
                dx = particles[bi + _X] - particles[bk + _X]
                dy = particles[bi + _X + 1] - particles[bk + _X + 1]
                dz = particles[bi + _X + 2] - particles[bk + _X + 2]
                r = np.sqrt(dx * dx + dy * dy + dz * dz)
                potential[i] += g * particles[bk + _M] / r
                potential[k] += g * particles[bi + _M] / r
        for i in range(n):
            bi = i * _PARTICLE_WORDS
            vix, viy, viz = particles[bi + _VX], particles[bi + _VX + 1], particles[bi + _VX + 2]
            vi2 = vix * vix + viy * viy + viz * viz
            for j in range(n):
                if j == i:
                    continue
                bj = j * _PARTICLE_WORDS
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
    if p[_P_USE_J2] != 0.0:
        # a = 3 J2 GM R² / (2 r⁵) · [(5 z²/r² − 1) r − 2 z k], z = r·k (r from Earth to the body).
        gm, kx, ky, kz = p[_P_EARTH_GM], p[_P_POLE], p[_P_POLE + 1], p[_P_POLE + 2]
        factor0 = 1.5 * p[_P_EARTH_J2] * gm * p[_P_EARTH_RADIUS] ** 2
        m_earth = particles[earth + _M]
        for i in range(n):
            b = i * _PARTICLE_WORDS
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

    if p[_P_USE_GR] != 0.0:
        for i in range(n):
            bi = i * _PARTICLE_WORDS
            particles[bi + _AX] += correction[i, 0] / c2
            particles[bi + _AX + 1] += correction[i, 1] / c2
            particles[bi + _AX + 2] += correction[i, 2] / c2


@cfunc(types.void(types.CPointer(types.uint64)), cache=True)
def _extra_forces_cfunc(simulation):
    """Earth J2 on all bodies (+ reaction on Earth) and the EIH 1PN accelerations, in place.

    ``simulation`` is REBOUND's ``struct reb_simulation*``, viewed as 64-bit words. Accelerations
    are *added* to ``ax, ay, az``, which REBOUND has filled with Newtonian gravity already.
    """
    words = carray(simulation, _SIM_WORDS)
    p = carray(_as_float64_pointer(words[_SIM_EXTRAS_WORD]), _N_PARAMETERS)
    _apply_extra_forces(words, p)


# The ctypes type of the struct field itself: assigning an instance of it stores the raw address.
_ADDITIONAL_FORCES_TYPE = dict(rebound.Simulation._fields_)["_additional_forces"]


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


def _rebound_name(body: str) -> str:
    return body.strip().capitalize()


def simulation_from_de421(time, bodies=DEFAULT_BODIES, integrator: str = "ias15"):
    """A REBOUND simulation with DE421 states at ``time``, built offline.

    Parameters
    ----------
    time : astropy.time.Time
        Scalar epoch, any scale convertible to TDB, within DE421's span.
    bodies : sequence of str, optional
        Names from :data:`spinorbit.ephemeris.KNOWN_BODIES`; default :data:`DEFAULT_BODIES`.
        Particles are named by the capitalised names ('Sun', 'Earth', 'Moon', ...).
    integrator : str, optional
        REBOUND integrator name (default 'ias15'). Use 'bs' when a user ODE must be coupled
        (see the REBOUND coupling note in the project's shared notes).

    Returns
    -------
    rebound.Simulation
        Units ("AU", "day", "Msun"); masses GM/G with DE421 GMs (au³/day²); ``t`` = TDB days since
        J2000 (as one float; its rounding is ≤ 0.31 µs in 1900–2100); barycentric ICRF positions
        (au_DE421) and velocities (au/day), moved to the centre of mass of the chosen bodies;
        ``exact_finish_time = 1``.

    Raises
    ------
    TypeError
        If ``time`` is not a scalar astropy ``Time``.
    spinorbit.ephemeris.UnknownBodyError, spinorbit.ephemeris.EphemerisRangeError
    """
    day, fraction = tdb_day_and_fraction(time)
    if np.ndim(day) != 0:
        raise TypeError(
            f"time must be a scalar Time (one epoch); got an array of shape {np.shape(day)}."
        )
    constants = de421_constants()
    sim = rebound.Simulation()
    sim.units = ("AU", "day", "Msun")
    sim.integrator = integrator
    sim.t = day + fraction
    for body in bodies:
        position, velocity = barycentric_state_au(body, day, fraction)
        name = body.strip().lower()
        sim.add(
            m=constants.gm[name] / sim.G,
            x=position[0], y=position[1], z=position[2],
            vx=velocity[0], vy=velocity[1], vz=velocity[2],
            name=_rebound_name(name),
        )
    sim.move_to_com()
    sim.exact_finish_time = 1
    return sim


def body_index(sim, body: str) -> int:
    """Index of the particle named ``body`` (case-insensitive) in ``sim``.

    Raises
    ------
    MissingBodyError
        If no particle has that name; the message lists the names present.
    """
    wanted = _rebound_name(body)
    names = [particle.name for particle in sim.particles]
    for index, name in enumerate(names):
        if name is not None and name.capitalize() == wanted:
            return index
    raise MissingBodyError(
        f"the simulation has no particle named {body!r}; it has {names}. Add it (with name=...) or "
        "build the simulation with spinorbit.coupling.rebound_adapter.simulation_from_de421."
    )


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
    pole = np.asarray(earth_pole, dtype=float)
    if pole.shape != (3,) or not np.isclose(np.linalg.norm(pole), 1.0, atol=1e-9):
        raise ValueError(f"earth_pole must be a unit 3-vector in ICRF; got {earth_pole!r}.")
    constants = de421_constants()
    parameters = np.zeros(_N_PARAMETERS)
    parameters[_P_EARTH] = body_index(sim, "earth") if earth_j2 else 0
    parameters[_P_USE_J2] = float(earth_j2)
    parameters[_P_USE_GR] = float(gr)
    parameters[_P_EARTH_GM] = constants.gm["earth"]
    parameters[_P_EARTH_J2] = constants.earth_j2
    parameters[_P_EARTH_RADIUS] = constants.earth_radius_km / constants.au_km
    parameters[_P_POLE:_P_POLE + 3] = pole / np.linalg.norm(pole)
    parameters[_P_C] = constants.c_km_s * 86400.0 / constants.au_km
    pointer = _ADDITIONAL_FORCES_TYPE(_extra_forces_cfunc.address)
    handle = ExtraForces(parameters, bool(earth_j2), bool(gr), pointer, _extra_forces_cfunc)
    # Keep-alive: rebound.Simulation has fixed __slots__ and no weakrefs; its own slots '_afp'
    # (holder of the additional-forces function) and '_extras_ref' (holder of what extras points
    # to) are the places REBOUND itself uses for exactly this, and die with the simulation.
    sim._afp = handle
    sim._extras_ref = parameters
    sim.extras = parameters.ctypes.data
    sim._additional_forces = pointer
    if gr:
        sim.force_is_velocity_dependent = 1  # IAS15 must iterate the velocity-dependent EIH terms
    return handle


def perturber_positions(sim, body: str, perturbers=None):
    """Positions of perturbers relative to ``body``, read from the running simulation.

    Parameters
    ----------
    sim : rebound.Simulation
        A simulation in ("AU", "day", "Msun") units with named particles.
    body : str
        The body whose rotation is being integrated (e.g. 'Moon').
    perturbers : sequence of str, optional
        Names to read; default every other named particle, in simulation order.

    Returns
    -------
    positions : ndarray, shape (k, 3), unit: au_DE421
        r_perturber − r_body in ICRF axes, at ``sim.t`` (TDB days since J2000).
    gm : ndarray, shape (k,), unit: au³/day²
        G·m of each perturber.
    names : tuple of str
        The perturbers' names, in the order of the rows.

    Raises
    ------
    MissingBodyError
        If ``body`` or a named perturber is not in the simulation.
    """
    centre = body_index(sim, body)
    if perturbers is None:
        indices = [i for i, p in enumerate(sim.particles) if i != centre and p.name is not None]
    else:
        indices = [body_index(sim, name) for name in perturbers]
    n = sim.N
    # A numpy view on REBOUND's particle array (no copy, no per-particle Python objects).
    raw = (ctypes.c_double * (n * _PARTICLE_WORDS)).from_address(ctypes.addressof(sim._particles.contents))
    table = np.frombuffer(raw, dtype=np.float64).reshape(n, _PARTICLE_WORDS)
    index = np.asarray(indices, dtype=np.intp)
    positions = table[index, _X:_X + 3] - table[centre, _X:_X + 3]
    gm = table[index, _M] * sim.G
    names = tuple(sim.particles[i].name for i in indices)
    return positions, gm, names
