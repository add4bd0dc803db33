"""REBOUND behind one adapter: offline DE421 simulations, compiled extra forces, perturber reads.

This module owns every raw pointer the package hands to REBOUND (``docs/ephemeris.md``,
``docs/coupling.md``):

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
- :func:`attach_rotation_hooks` integrates a rigid body's rotation (q, ω) with the orbits: a BS user
  ODE whose ``derivatives`` and a combined ``additional_forces`` (EIH + J2 + the figure's
  back-reaction) are raw cfuncs sharing one parameter block; :func:`attach_rotation_ias15` is the
  measured alternative (rotation in two pseudo-particles under IAS15).
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

from spinorbit.core.jit import jit
from spinorbit.ephemeris import barycentric_state_au, de421_constants
from spinorbit.time import tdb_day_and_fraction

__all__ = [
    "DEFAULT_BODIES",
    "MissingBodyError",
    "ForceInstallError",
    "ExtraForces",
    "simulation_from_de421",
    "install_extra_forces",
    "set_nongravitational",
    "reinstall_extra_forces",
    "extra_forces_in_effect",
    "body_index",
    "perturber_positions",
    "RotationCallbackError",
    "RotationHooks",
    "attach_rotation_hooks",
    "PseudoParticleHooks",
    "attach_rotation_ias15",
    "MAX_PERTURBERS",
    "ROTATION_STATE_SIZE",
    "integrate_interruptibly",
    "simulation_from_binary",
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
# Marsden–Sekanina–Yeomans (1973) non-gravitational acceleration on one body (e.g. Yarkovsky):
# a = g(r) (A1 r̂ + A2 t̂ + A3 n̂), g(r) = (r0/r)², r heliocentric; 0 in _P_NG_BODY means "off".
_P_NG_BODY, _P_NG_SUN = 12, 13
_P_NG_A = 14  # 14, 15, 16: A1, A2, A3 in au/day²
_P_NG_R0 = 17
_N_PARAMETERS = 18


def _address_as_pointer(pointee):
    """An intrinsic that reinterprets an integer address as ``pointee*``.

    numba cannot cast int → pointer natively; one factory serves every pointee type the adapter needs.
    """

    @intrinsic
    def cast(typingctx, address):
        if not isinstance(address, types.Integer):
            return None
        pointer = types.CPointer(pointee)

        def codegen(context, builder, sig, args):
            return builder.inttoptr(args[0], context.get_value_type(pointer))

        return pointer(address), codegen

    return cast


#: ``double*`` from an address (particle arrays, the parameter block).
_as_float64_pointer = _address_as_pointer(types.float64)


def _reinterpret_bits(source_kind, target):
    """An intrinsic that reinterprets the 64 bits of a ``source_kind`` value as ``target`` (a bitcast)."""

    @intrinsic
    def cast(typingctx, value):
        if not isinstance(value, source_kind):
            return None

        def codegen(context, builder, sig, args):
            return builder.bitcast(args[0], context.get_value_type(target))

        return target(value), codegen

    return cast


#: The bits of a 64-bit word as a double (sim.G is read from the word view).
_word_as_float64 = _reinterpret_bits(types.Integer, types.float64)


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

    if p[_P_NG_BODY] != 0.0:
        _add_nongravitational(particles, p)

    if p[_P_USE_GR] != 0.0:
        for i in range(n):
            bi = i * _PARTICLE_WORDS
            particles[bi + _AX] += correction[i, 0] / c2
            particles[bi + _AX + 1] += correction[i, 1] / c2
            particles[bi + _AX + 2] += correction[i, 2] / c2


@jit
def _add_nongravitational(particles, p):
    """Add g(r) (A1 r̂ + A2 t̂ + A3 n̂) to the body's acceleration (no reaction: photon recoil).

    r̂ from the Sun to the body, n̂ along r × v (heliocentric), t̂ = n̂ × r̂ (along the motion), as in
    JPL's small-body model (Marsden, Sekanina & Yeomans 1973, AJ 78, 211) with g(r) = (r0/r)².
    """
    b = np.int64(p[_P_NG_BODY]) * _PARTICLE_WORDS
    s = np.int64(p[_P_NG_SUN]) * _PARTICLE_WORDS
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
    g = (p[_P_NG_R0] / r) ** 2
    a1, a2, a3 = p[_P_NG_A], p[_P_NG_A + 1], p[_P_NG_A + 2]
    particles[b + _AX] += g * (a1 * rx + a2 * tx + a3 * nx)
    particles[b + _AX + 1] += g * (a1 * ry + a2 * ty + a3 * ny)
    particles[b + _AX + 2] += g * (a1 * rz + a2 * tz + a3 * nz)


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

    @classmethod
    def from_parameters(cls, parameters) -> ExtraForces:
        """A description (not installed) of the forces a parameter block switches on; the block is copied.

        What :func:`reinstall_extra_forces` needs to put the same forces on another simulation, e.g.
        the block stored in a checkpoint (``CoupledRigidBody.checkpoint``).

        Raises
        ------
        ValueError
            ``parameters`` is not a block of ``_N_PARAMETERS`` finite floats.
        """
        block = np.array(parameters, dtype=float)
        if block.shape != (_N_PARAMETERS,) or not np.all(np.isfinite(block)):
            raise ValueError(f"parameters: expected the {_N_PARAMETERS} finite floats of an install_extra_forces "
                             f"block, got an array of shape {block.shape}.")
        return cls(block, bool(block[_P_USE_J2]), bool(block[_P_USE_GR]))


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
        "build the simulation with spinorbit.coupling.rebound.adapter.simulation_from_de421."
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


def reinstall_extra_forces(sim, handle: ExtraForces) -> ExtraForces:
    """Install on ``sim`` the same forces, with the same parameters, as ``handle`` (from another sim).

    For rebuilt copies of a simulation (the raw pointer does not survive ``sim.copy()``, REBOUND's
    binary or a Simulationarchive): ``sim`` must hold the same particles in the same order, since
    the parameter block refers to particles by index (Earth for J2, the body and the Sun for the
    non-gravitational terms). ``handle`` may come from :func:`extra_forces_in_effect` or
    :meth:`ExtraForces.from_parameters`.
    """
    copy = install_extra_forces(sim, earth_j2=handle.earth_j2, gr=handle.gr,
                                earth_pole=handle.parameters[_P_POLE:_P_POLE + 3])
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
    p[_P_NG_SUN] = sun
    p[_P_NG_A:_P_NG_A + 3] = coefficients[:3]
    p[_P_NG_R0] = r0_au
    p[_P_NG_BODY] = index  # last: the force switches on only once its parameters are complete


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


# ============================================================================================
# Rigid-body rotation coupled to the orbits (BS integrator + one user ODE, docs/coupling.md).
#
# Two raw cfuncs share one float64 parameter block (``RotationHooks.parameters``):
# - ``_rotation_derivatives_cfunc`` is the user ODE's ``derivatives``: (q̇, ω̇) of the body from the
#   particles' positions at the current BS stage (REBOUND updates the particle array before calling
#   it when ``needs_nbody`` is set);
# - ``_coupled_forces_cfunc`` is ``additional_forces``: the EIH + Earth-J2 forces of
#   :func:`install_extra_forces` (if asked for), then the figure's back-reaction on the orbits, read
#   from the ODE's *current stage* ``y1`` (not ``y``, which is the state at the start of the step).
# Both call :func:`_figure_torque_and_reaction`, so torque and back-reaction come from the same
# gravity-field kernel (``gravity_field.figure_force_function_and_gradient_xyz``).
# --------------------------------------------------------------------------------------------
from rebound.integrator import IntegratorConfiguration as _IntegratorConfiguration  # noqa: E402
from rebound.ode import ODE as _ODE  # noqa: E402  (kept next to the code that reads its layout)

from spinorbit.core.dynamics.equations import body_frame_xyz, kinematics_and_euler_into  # noqa: E402
from spinorbit.core.model.gravity_field import BODY_NMAX, FIGURE_SIZE, figure_field_to_degree_xyz  # noqa: E402

_ODE_WORDS = ctypes.sizeof(_ODE) // _WORD
_ODE_REF_WORD = _ODE.ref.offset // _WORD
_ODE_Y_WORD = _ODE.y.offset // _WORD
_ODE_Y1_WORD = _ODE._y1.offset // _WORD
_ODE_SIM_WORD = _ODE.r.offset // _WORD
_SIM_STATUS_BYTE = rebound.Simulation._status.offset
_SIM_T_BYTE = rebound.Simulation.t.offset
assert ctypes.sizeof(dict(rebound.Simulation._fields_)["_status"]) == 4, "sim.status is not a C int"
#: REBOUND's REB_STATUS_USER: ``integrate`` returns quietly; the Python side then raises our error.
_REB_STATUS_USER = 5

#: Most perturbers acting on one figure (the parameter block has a fixed size).
MAX_PERTURBERS = 64
#: Length of the rotation state (q0..q3, ωx, ωy, ωz).
ROTATION_STATE_SIZE = 7

# Parameter block (float64) shared by both cfunc: named offsets.
_R_BODY, _R_COUPLED, _R_N_PERTURBERS, _R_ERROR, _R_N_EXPECTED, _R_USE_EXTRA, _R_ODE, _R_ERROR_T = range(8)
_R_EXTRA = 8  # the install_extra_forces parameter block (_N_PARAMETERS floats)
_R_PERTURBERS = _R_EXTRA + _N_PARAMETERS
_R_DEGREES = _R_PERTURBERS + MAX_PERTURBERS  # highest field degree each perturber sees
_R_MODEL = _R_DEGREES + MAX_PERTURBERS  # the figure array (gravity_field.make_body)
_R_PSEUDO = _R_MODEL + FIGURE_SIZE  # IAS15 route only: index of the first pseudo-particle
# Restore only (RotationHooks.resume_bs_controller): a pending flag, the value of BS's
# first_or_last_step to write at the next step, the integrator state's address and the field's byte
# offset in it (addresses as the bits of a uint64).
_R_BS_PENDING, _R_BS_FLAG, _R_BS_STATE, _R_BS_FLAG_OFFSET = range(_R_PSEUDO + 1, _R_PSEUDO + 5)
_R_SIZE = _R_PSEUDO + 5

#: Error codes the cfuncs write into the parameter block (0: no error).
ERROR_PARTICLE_COUNT = 1.0
ERROR_NONFINITE_STATE = 2.0
ERROR_MESSAGES = {
    ERROR_PARTICLE_COUNT: "the number of particles changed after the rigid body was attached "
    "(particle indices in the coupling are stale); attach the body after adding or removing particles",
    ERROR_NONFINITE_STATE: "the rotation state became NaN or infinite (check the initial state, the "
    "moments and the step-size tolerances)",
}


class RotationCallbackError(RuntimeError):
    """A compiled rotation callback found a problem during ``sim.integrate``; the run was stopped."""


#: ``uint64*`` from an address (REBOUND's struct read as 64-bit words).
_as_uint64_pointer = _address_as_pointer(types.uint64)
#: ``int32*`` from an address (to write REBOUND's C-int ``status``).
_as_int32_pointer = _address_as_pointer(types.int32)


#: The bits of a double as a uint64 (the ODE address is stored bit-exactly in the float block).
_float64_bits = _reinterpret_bits(types.Float, types.uint64)


@jit
def _stop_with_error(words, sim_address, p, code):
    """Record ``code`` (first error wins) and ask REBOUND to stop the run (status = REB_STATUS_USER)."""
    if p[_R_ERROR] == 0.0:
        p[_R_ERROR] = code
        p[_R_ERROR_T] = carray(_as_float64_pointer(sim_address + _SIM_T_BYTE), 1)[0]
    status = carray(_as_int32_pointer(sim_address + _SIM_STATUS_BYTE), 1)
    status[0] = _REB_STATUS_USER


@jit
def _figure_torque_and_reaction(words, sim_address, p, y, apply_reaction):
    """Body-frame torque (Nx, Ny, Nz) on the figure from the chosen particles; optionally the reaction.

    Units: positions au, G·m au³/day², moments Msun·au², so the torque is Msun·au²/day².
    For each perturber with mass m_p at body-frame r, U = G m_p ∫dm/|r − ρ| and
    F_p = ∂U/∂r (``gravity_field``); the kernel is called with μ = G, i.e. per unit perturber mass,
    so a massless perturber also feels the figure. Torque N = m_p (∂U₁/∂r) × r. The reaction
    (``apply_reaction``) adds ∂U₁/∂r, rotated to ICRF, to the perturber's acceleration and
    −(m_p/m_b) times it to the body's; the field excludes the monopole (REBOUND already has the
    point-mass part, and the monopole only adds rounding noise to the torque). Sets an error code
    and stops the run if the particle count changed or y is not finite.
    """
    n = np.int64(words[_SIM_N_WORD])
    if n != np.int64(p[_R_N_EXPECTED]):
        _stop_with_error(words, sim_address, p, ERROR_PARTICLE_COUNT)
        return 0.0, 0.0, 0.0
    for i in range(ROTATION_STATE_SIZE):
        if not np.isfinite(y[i]):
            _stop_with_error(words, sim_address, p, ERROR_NONFINITE_STATE)
            return 0.0, 0.0, 0.0
    particles = carray(_as_float64_pointer(words[_SIM_PARTICLES_WORD]), n * _PARTICLE_WORDS)
    model = p[_R_MODEL:_R_MODEL + FIGURE_SIZE]
    g = _word_as_float64(words[_SIM_G_WORD])
    body = np.int64(p[_R_BODY]) * _PARTICLE_WORDS
    m_body = particles[body + _M]
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    nx = 0.0
    ny = 0.0
    nz = 0.0
    for k in range(np.int64(p[_R_N_PERTURBERS])):
        b = np.int64(p[_R_PERTURBERS + k]) * _PARTICLE_WORDS
        rx = particles[b + _X] - particles[body + _X]
        ry = particles[b + _X + 1] - particles[body + _X + 1]
        rz = particles[b + _X + 2] - particles[body + _X + 2]
        x, yy, z = body_frame_xyz(q0, q1, q2, q3, rx, ry, rz)
        # Degrees ≥ 2 only: the monopole has no torque and REBOUND's point-mass gravity has it.
        degree = np.int64(p[_R_DEGREES + k])
        _, gx, gy, gz = figure_field_to_degree_xyz(x, yy, z, g, model, degree)
        m_p = particles[b + _M]
        nx += m_p * (gy * z - gz * yy)
        ny += m_p * (gz * x - gx * z)
        nz += m_p * (gx * yy - gy * x)
        if apply_reaction:
            # Body → ICRF: M(q) v = body_frame_xyz with the conjugate quaternion.
            ax, ay, az = body_frame_xyz(q0, -q1, -q2, -q3, gx, gy, gz)
            particles[b + _AX] += ax
            particles[b + _AX + 1] += ay
            particles[b + _AX + 2] += az
            ratio = m_p / m_body
            particles[body + _AX] -= ratio * ax
            particles[body + _AX + 1] -= ratio * ay
            particles[body + _AX + 2] -= ratio * az
    return nx, ny, nz


_DERIVATIVES_SIGNATURE = types.void(
    types.CPointer(types.uint64), types.CPointer(types.float64), types.CPointer(types.float64), types.float64
)


@cfunc(_DERIVATIVES_SIGNATURE, cache=True)
def _rotation_derivatives_cfunc(ode, y_dot, y, t):
    """User-ODE ``derivatives``: (q̇, ω̇) with the torque from the particles at this BS stage."""
    ode_words = carray(ode, _ODE_WORDS)
    p = carray(_as_float64_pointer(ode_words[_ODE_REF_WORD]), _R_SIZE)
    sim_address = ode_words[_ODE_SIM_WORD]
    words = carray(_as_uint64_pointer(sim_address), _SIM_WORDS)
    state = carray(y, ROTATION_STATE_SIZE)
    out = carray(y_dot, ROTATION_STATE_SIZE)
    nx, ny, nz = _figure_torque_and_reaction(words, sim_address, p, state, False)
    kinematics_and_euler_into(state, nx, ny, nz, p[_R_MODEL:_R_MODEL + FIGURE_SIZE], out)


@cfunc(types.void(types.CPointer(types.uint64)), cache=True)
def _coupled_forces_cfunc(simulation):
    """``additional_forces``: EIH + Earth J2 (if on), then the figure's back-reaction (if coupled)."""
    words = carray(simulation, _SIM_WORDS)
    p = carray(_as_float64_pointer(words[_SIM_EXTRAS_WORD]), _R_SIZE)
    if p[_R_USE_EXTRA] != 0.0:
        _apply_extra_forces(words, p[_R_EXTRA:_R_EXTRA + _N_PARAMETERS])
    if p[_R_COUPLED] != 0.0:
        ode_words = carray(_as_uint64_pointer(_float64_bits(p[_R_ODE])), _ODE_WORDS)
        # The ODE's current BS stage lives in y1; before the first step y1 is not allocated yet.
        address = ode_words[_ODE_Y1_WORD]
        if address == 0:
            address = ode_words[_ODE_Y_WORD]
        state = carray(_as_float64_pointer(address), ROTATION_STATE_SIZE)
        _figure_torque_and_reaction(words, ode_words[_ODE_SIM_WORD], p, state, True)


_ODE_DERIVATIVES_TYPE = dict(_ODE._fields_)["_derivatives"]
_ODE_PRE_TIMESTEP_TYPE = dict(_ODE._fields_)["_pre_timestep"]
#: Word of the simulation struct holding the integrator's state pointer (``sim.integrator.state``).
_SIM_INTEGRATOR_STATE_BYTE = rebound.Simulation.integrator.offset + _IntegratorConfiguration.state.offset
assert _SIM_INTEGRATOR_STATE_BYTE % _WORD == 0, "sim.integrator.state is not on an 8-byte word"
_SIM_INTEGRATOR_STATE_WORD = _SIM_INTEGRATOR_STATE_BYTE // _WORD


@cfunc(types.void(types.CPointer(types.uint64), types.CPointer(types.float64)), cache=True)
def _resume_bs_controller_cfunc(ode, y):
    """User-ODE ``pre_timestep``: once after a restore, give BS back its ``first_or_last_step``.

    rebound 5.2.2 sets ``first_or_last_step = 1`` whenever an ODE is created: the user ODE when the
    body is attached, and the N-body part's internal ODE at the first step of a simulation rebuilt
    from its binary (which does not hold that ODE). The binary's value is thereby lost, and the
    restored run's first step, allowed to stop its extrapolation early, left the uninterrupted run by
    ~1e-14 (measured, ``tests/test_checkpoint_runs.py``). ``pre_timestep`` runs inside the BS step,
    after both resets and before the extrapolation, so the value written here is the one it uses.
    """
    ode_words = carray(ode, _ODE_WORDS)
    p = carray(_as_float64_pointer(ode_words[_ODE_REF_WORD]), _R_SIZE)
    if p[_R_BS_PENDING] != 0.0:
        p[_R_BS_PENDING] = 0.0
        words = carray(_as_uint64_pointer(ode_words[_ODE_SIM_WORD]), _SIM_INTEGRATOR_STATE_WORD + 1)
        state = words[_SIM_INTEGRATOR_STATE_WORD]
        if state == _float64_bits(p[_R_BS_STATE]):  # the same BS state as at the restore: write
            flag = carray(_as_int32_pointer(state + _float64_bits(p[_R_BS_FLAG_OFFSET])), 1)
            flag[0] = np.int32(p[_R_BS_FLAG])


@dataclass
class RotationHooks:
    """What :func:`attach_rotation_hooks` installed; kept on the simulation for its whole life.

    Attributes
    ----------
    parameters : ndarray
        The float64 block both cfuncs read (``sim.extras`` and the ODE's ``ref`` point to it).
    ode : rebound.ODE
        The user ODE holding (q0, q1, q2, q3, ωx, ωy, ωz); ω in rad/day, q body → ICRF.
    coupled : bool
        True: the figure's back-reaction acts on the orbits; False: one-way (orbits do not feel it).
    extra : ExtraForces or None
        The EIH + Earth-J2 parameters folded into the combined force, if any.
    """

    parameters: np.ndarray
    ode: object
    coupled: bool
    extra: ExtraForces | None
    _keep_alive: tuple = ()

    @property
    def state(self) -> np.ndarray:
        """A copy of the rotation state y = (q, ω) at ``sim.t`` (q body → ICRF, ω body axes rad/day)."""
        return np.ctypeslib.as_array(self.ode.y, shape=(ROTATION_STATE_SIZE,)).copy()

    @state.setter
    def state(self, value) -> None:
        y = np.ctypeslib.as_array(self.ode.y, shape=(ROTATION_STATE_SIZE,))
        y[:] = np.asarray(value, dtype=float)

    @property
    def extra_forces(self) -> ExtraForces | None:
        """The extra-force block folded into the combined force (a copy), or None if none is on.

        Whatever installed it (``earth_j2``/``gr`` when attaching, or :func:`install_extra_forces`
        and :func:`set_nongravitational` before): this block, not the attach arguments, is what acts.
        """
        if self.parameters[_R_USE_EXTRA] == 0.0:
            return None
        return ExtraForces.from_parameters(self.parameters[_R_EXTRA:_R_EXTRA + _N_PARAMETERS])

    @property
    def perturber_degrees(self) -> tuple:
        """Highest degree of the figure's field each perturber sees (in perturber order)."""
        count = int(self.parameters[_R_N_PERTURBERS])
        return tuple(int(d) for d in self.parameters[_R_DEGREES:_R_DEGREES + count])

    @property
    def figure(self) -> np.ndarray:
        """The figure array (``gravity_field.make_body`` layout) in simulation units (view)."""
        return self.parameters[_R_MODEL:_R_MODEL + FIGURE_SIZE]

    def resume_bs_controller(self, sim, first_or_last_step: int) -> None:
        """Have the next BS step of ``sim`` start with ``first_or_last_step`` (a restore's value).

        For a simulation rebuilt from REBOUND's binary: read ``sim.integrator.first_or_last_step``
        before attaching (attaching resets it) and pass it here (``_resume_bs_controller_cfunc``).
        """
        if str(sim.integrator) != "bs":
            raise ForceInstallError(f"resume_bs_controller needs the 'bs' integrator, got {sim.integrator!r}.")
        offset = sim.integrator.callbacks.field_descriptor_list.field_descriptor_for_name("first_or_last_step").offset
        # Kept with the state's address: if the integrator is replaced before the next step, the
        # cfunc sees another state pointer and writes nothing (no write into freed memory).
        words = np.array([sim.integrator.state, offset], dtype=np.uint64).view(np.float64)
        self.parameters[_R_BS_STATE], self.parameters[_R_BS_FLAG_OFFSET] = words
        self.parameters[_R_BS_FLAG] = int(first_or_last_step)
        self.parameters[_R_BS_PENDING] = 1.0

    def raise_if_failed(self) -> None:
        """Raise :class:`RotationCallbackError` if a cfunc recorded an error during the last run."""
        code = float(self.parameters[_R_ERROR])
        if code != 0.0:
            when = float(self.parameters[_R_ERROR_T])
            self.parameters[_R_ERROR] = 0.0
            raise RotationCallbackError(
                f"rotation callback stopped the run at t = {when!r} (TDB days since J2000 for DE421 "
                f"simulations): {ERROR_MESSAGES.get(code, f'unknown error code {code}')}."
            )


def extra_forces_in_effect(sim) -> ExtraForces | None:
    """The extra forces (EIH, Earth J2, non-gravitational) acting on ``sim``'s orbits now, as a copy.

    From :func:`install_extra_forces` (and :func:`set_nongravitational`) directly, or folded into a
    rigid body's combined force by :func:`attach_rotation_hooks`. For rebuilding ``sim`` elsewhere
    (:func:`reinstall_extra_forces`): a copy or a checkpoint that took only the attach arguments
    would lose the forces installed before the body.

    Raises
    ------
    ForceInstallError
        ``sim`` has forces spinorbit did not install (a Python ``additional_forces``, REBOUNDx, a
        pre/post-timestep hook): they cannot be carried to a rebuilt simulation.
    """
    handle = getattr(sim, "_afp", None)
    if isinstance(handle, ExtraForces):
        return ExtraForces.from_parameters(handle.parameters)
    if isinstance(handle, RotationHooks):
        return handle.extra_forces
    if handle is not None or sim._additional_forces or sim._pre_timestep_modifications \
            or sim._post_timestep_modifications or sim.extras:
        raise ForceInstallError(
            "the simulation has forces or hooks spinorbit did not install (a Python additional_forces, "
            "REBOUNDx or a timestep hook); a rebuilt copy would run without them. Use install_extra_forces "
            "and set_nongravitational for the forces, or sample the orbit yourself (one_way.sample_states)."
        )
    return None


def _check_folded_request(block, earth_j2, gr, earth_pole) -> None:
    """Refuse ``earth_j2``/``gr``/``earth_pole`` asked of :func:`attach_rotation_hooks` that the block
    installed earlier does not have: the fold uses that block as it is, and would silently ignore them."""
    missing = [name for name, asked, on in (("earth_j2", earth_j2, block[_P_USE_J2]), ("gr", gr, block[_P_USE_GR]))
               if asked and on == 0.0]
    pole = np.asarray(earth_pole, dtype=float)
    if earth_j2 and block[_P_USE_J2] != 0.0 and not np.array_equal(pole / np.linalg.norm(pole),
                                                                    block[_P_POLE:_P_POLE + 3]):
        missing.append(f"earth_pole={tuple(pole.tolist())} (installed: {tuple(block[_P_POLE:_P_POLE + 3].tolist())})")
    if missing:
        raise ForceInstallError(
            f"install_extra_forces was called on this simulation before the body was attached, without "
            f"{', '.join(missing)}; attaching folds in that block unchanged. Ask for these forces in "
            "install_extra_forces instead (or leave earth_j2/gr off when attaching)."
        )


def attach_rotation_hooks(sim, body: str, perturbers, figure, state, coupled: bool = True,
                          earth_j2: bool = False, gr: bool = False, earth_pole=(0.0, 0.0, 1.0),
                          degrees=None):
    """Integrate the rotation of ``body`` together with the orbits of ``sim`` (BS + one user ODE).

    Parameters
    ----------
    sim : rebound.Simulation
        Integrator must be 'bs' (the only one in which a user ODE and the N-body equations are one
        system; see ``docs/coupling.md``). Any units; the figure must be in the same units.
    body : str
        Name of the particle carrying the figure.
    perturbers : sequence of str
        Particles whose gravity torques the figure (and, if ``coupled``, feels it).
    figure : ndarray
        ``gravity_field.make_body`` array: moments in (sim mass)·(sim length)², mass = the particle's
        mass, reference radius in sim length.
    state : array_like, shape (7,)
        (q0, q1, q2, q3, ωx, ωy, ωz): q body → inertial (scalar first), ω body axes, rad/(sim time).
    coupled : bool
        Add the figure's back-reaction to the orbits (energy and total angular momentum conserved).
    earth_j2, gr, earth_pole
        As in :func:`install_extra_forces`; they run in the same compiled force, before the reaction.
    degrees : sequence of int, optional
        Highest degree of the figure's field each perturber sees (torque and reaction alike, so
        conservation holds); default: the figure's own n_max for all.

    Returns
    -------
    RotationHooks

    Raises
    ------
    ForceInstallError
        Integrator is not BS, hooks already attached, REBOUNDx present, or too many perturbers.
    MissingBodyError
        ``body`` or a perturber is not in ``sim``.
    """
    if str(sim.integrator) != "bs":
        raise ForceInstallError(
            f"the rotation can only be coupled with the 'bs' integrator, got {sim.integrator!r}: other "
            "integrators advance user ODEs after the N-body step with the particles frozen (a 13 degree "
            "attitude error in a year for the Moon). Set sim.integrator = 'bs' first."
        )
    if isinstance(getattr(sim, "_afp", None), RotationHooks):
        raise ForceInstallError("a rigid body is already attached to this simulation (one per simulation).")
    previous = getattr(sim, "_afp", None)
    if sim.extras and not isinstance(previous, ExtraForces):
        raise ForceInstallError(
            "sim.extras is already set (is REBOUNDx attached?); the coupling needs additional_forces itself."
        )
    centre = body_index(sim, body)
    indices = [body_index(sim, name) for name in perturbers]
    if centre in indices:
        raise ValueError(f"the body {body!r} cannot perturb itself; remove it from perturbers.")
    if len(indices) > MAX_PERTURBERS:
        raise ForceInstallError(f"at most {MAX_PERTURBERS} perturbers, got {len(indices)}.")
    figure = np.asarray(figure, dtype=float)
    if figure.shape != (FIGURE_SIZE,):
        raise ValueError(f"figure: expected a gravity_field.make_body array of {FIGURE_SIZE} floats.")
    y0 = np.asarray(state, dtype=float)
    if y0.shape != (ROTATION_STATE_SIZE,) or not np.all(np.isfinite(y0)):
        raise ValueError(f"state: expected 7 finite numbers (q0..q3, wx, wy, wz), got {state!r}.")

    parameters = np.zeros(_R_SIZE)
    parameters[_R_BODY] = centre
    parameters[_R_COUPLED] = float(coupled)
    parameters[_R_N_PERTURBERS] = len(indices)
    parameters[_R_N_EXPECTED] = sim.N
    parameters[_R_PERTURBERS:_R_PERTURBERS + len(indices)] = indices
    parameters[_R_MODEL:_R_MODEL + FIGURE_SIZE] = figure
    n_max = int(figure[BODY_NMAX])
    degrees = [n_max] * len(indices) if degrees is None else [int(d) for d in degrees]
    if len(degrees) != len(indices) or any(d < 2 for d in degrees):
        raise ValueError(f"degrees: expected one degree ≥ 2 per perturber, got {degrees!r}.")
    parameters[_R_DEGREES:_R_DEGREES + len(indices)] = [min(d, n_max) for d in degrees]
    extra = None
    if isinstance(previous, ExtraForces):
        _check_folded_request(previous.parameters, earth_j2, gr, earth_pole)
        # Fold the forces installed earlier into the combined cfunc: their whole block (it indexes
        # this simulation's particles), so that non-gravitational terms carry over with J2 and EIH.
        extra = previous
        parameters[_R_EXTRA:_R_EXTRA + _N_PARAMETERS] = previous.parameters
        parameters[_R_USE_EXTRA] = 1.0
    elif earth_j2 or gr:
        probe = rebound.Simulation()  # fill the EIH/J2 block with install_extra_forces' own code
        probe.add(m=1.0, name="Earth")
        extra = install_extra_forces(probe, earth_j2=earth_j2, gr=gr, earth_pole=earth_pole)
        if earth_j2:
            extra.parameters[_P_EARTH] = body_index(sim, "earth")
        parameters[_R_EXTRA:_R_EXTRA + _N_PARAMETERS] = extra.parameters
        parameters[_R_USE_EXTRA] = 1.0

    ode = sim.create_ode(length=ROTATION_STATE_SIZE, needs_nbody=True)
    y = np.ctypeslib.as_array(ode.y, shape=(ROTATION_STATE_SIZE,))
    y[:] = y0
    parameters[_R_ODE:_R_ODE + 1] = np.array([ctypes.addressof(ode)], dtype=np.uint64).view(np.float64)
    derivatives = _ODE_DERIVATIVES_TYPE(_rotation_derivatives_cfunc.address)
    forces = _ADDITIONAL_FORCES_TYPE(_coupled_forces_cfunc.address)
    pre_timestep = _ODE_PRE_TIMESTEP_TYPE(_resume_bs_controller_cfunc.address)
    hooks = RotationHooks(parameters, ode, bool(coupled), extra,
                          (derivatives, forces, pre_timestep, _rotation_derivatives_cfunc, _coupled_forces_cfunc,
                           _resume_bs_controller_cfunc))
    ode.ref = parameters.ctypes.data
    ode._derivatives = derivatives
    ode._pre_timestep = pre_timestep  # does nothing unless resume_bs_controller was called
    sim._afp = hooks  # keep-alive in REBOUND's own slots (see install_extra_forces)
    sim._extras_ref = parameters
    sim.extras = parameters.ctypes.data
    sim._additional_forces = forces
    if gr or coupled:
        # EIH depends on velocities; the back-reaction depends on the ODE stage, which BS evaluates
        # with the N-body state anyway. The flag is harmless for BS and needed if IAS15 is ever used.
        sim.force_is_velocity_dependent = 1
    return hooks


# ============================================================================================
# The IAS15 route, kept for measurement against BS (docs/coupling.md): the quaternion and its rate
# ride in two massless pseudo-particles after the real bodies (N_active = real bodies):
# a: (x, y, z) = (q0, q1, q2), b: x = q3 (y = z = 0); velocities are q̇. A last-running force
# overwrites their accelerations with q̈ from the same torque kernel and Euler equations.
# --------------------------------------------------------------------------------------------
PSEUDO_PARTICLE_NAMES = ("_spinorbit_q012", "_spinorbit_q3")


@intrinsic
def _pointer_address(typingctx, pointer):
    """The integer address of a pointer (to hand the simulation's address to the error path)."""
    if not isinstance(pointer, types.CPointer):
        return None
    signature = types.uint64(pointer)

    def codegen(context, builder, sig, args):
        return builder.ptrtoint(args[0], context.get_value_type(types.uint64))

    return signature, codegen


@cfunc(types.void(types.CPointer(types.uint64)), cache=True)
def _pseudo_particle_forces_cfunc(simulation):
    """``additional_forces`` of the IAS15 route: EIH + J2, back-reaction, then q̈ on the pseudo-particles."""
    words = carray(simulation, _SIM_WORDS)
    p = carray(_as_float64_pointer(words[_SIM_EXTRAS_WORD]), _R_SIZE)
    if p[_R_USE_EXTRA] != 0.0:
        _apply_extra_forces(words, p[_R_EXTRA:_R_EXTRA + _N_PARAMETERS])
    n = np.int64(words[_SIM_N_WORD])
    if n != np.int64(p[_R_N_EXPECTED]):
        _stop_with_error(words, _pointer_address(simulation), p, ERROR_PARTICLE_COUNT)
        return
    particles = carray(_as_float64_pointer(words[_SIM_PARTICLES_WORD]), n * _PARTICLE_WORDS)
    a = np.int64(p[_R_PSEUDO]) * _PARTICLE_WORDS
    b = a + _PARTICLE_WORDS
    q0, q1, q2, q3 = particles[a + _X], particles[a + _X + 1], particles[a + _X + 2], particles[b + _X]
    d0, d1, d2, d3 = particles[a + _VX], particles[a + _VX + 1], particles[a + _VX + 2], particles[b + _VX]
    norm2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
    # ω = 2 vec(conj(q) ⊗ q̇) / |q|²
    y = np.empty(ROTATION_STATE_SIZE)
    y[0], y[1], y[2], y[3] = q0, q1, q2, q3
    y[4] = 2.0 * (q0 * d1 - d0 * q1 - (q2 * d3 - q3 * d2)) / norm2
    y[5] = 2.0 * (q0 * d2 - d0 * q2 - (q3 * d1 - q1 * d3)) / norm2
    y[6] = 2.0 * (q0 * d3 - d0 * q3 - (q1 * d2 - q2 * d1)) / norm2
    nx, ny, nz = _figure_torque_and_reaction(words, _pointer_address(simulation), p, y, p[_R_COUPLED] != 0.0)
    dy = np.empty(ROTATION_STATE_SIZE)
    kinematics_and_euler_into(y, nx, ny, nz, p[_R_MODEL:_R_MODEL + FIGURE_SIZE], dy)
    wx, wy, wz, ex, ey, ez = y[4], y[5], y[6], dy[4], dy[5], dy[6]
    # q̈ = ½ q̇ ⊗ (0, ω) + ½ q ⊗ (0, ω̇);  (s, v) ⊗ (0, w) = (−v·w, s w + v × w)
    particles[a + _AX] = 0.5 * (-(d1 * wx + d2 * wy + d3 * wz) - (q1 * ex + q2 * ey + q3 * ez))
    particles[a + _AX + 1] = 0.5 * (d0 * wx + d2 * wz - d3 * wy + q0 * ex + q2 * ez - q3 * ey)
    particles[a + _AX + 2] = 0.5 * (d0 * wy + d3 * wx - d1 * wz + q0 * ey + q3 * ex - q1 * ez)
    particles[b + _AX] = 0.5 * (d0 * wz + d1 * wy - d2 * wx + q0 * ez + q1 * ey - q2 * ex)
    particles[b + _AX + 1] = 0.0
    particles[b + _AX + 2] = 0.0


class PseudoParticleHooks(RotationHooks):
    """What :func:`attach_rotation_ias15` installed (IAS15 route); ``state`` is read from the particles."""

    sim: object = None

    @property
    def state(self) -> np.ndarray:
        """(q0..q3, ωx, ωy, ωz) from the pseudo-particles: ω = 2 vec(conj(q) ⊗ q̇)/|q|² (rad/time)."""
        pa, pb = (self.sim.particles[name] for name in PSEUDO_PARTICLE_NAMES)
        q = np.array([pa.x, pa.y, pa.z, pb.x])
        d = np.array([pa.vx, pa.vy, pa.vz, pb.vx])
        omega = 2.0 * (q[0] * d[1:] - d[0] * q[1:] - np.cross(q[1:], d[1:])) / np.dot(q, q)
        return np.concatenate([q, omega])


def attach_rotation_ias15(sim, body: str, perturbers, figure, state, coupled: bool = True,
                          earth_j2: bool = False, gr: bool = False, earth_pole=(0.0, 0.0, 1.0)):
    """The IAS15 route (for measurements): rotation in two massless pseudo-particles.

    Same parameters as :func:`attach_rotation_hooks` (integrator must be 'ias15'; two particles are
    appended and ``N_active`` set to the real bodies; adaptive mode GLOBAL). Returns
    :class:`PseudoParticleHooks`. Not part of the public workflow: ``CoupledRigidBody`` uses BS.
    """
    if str(sim.integrator) != "ias15":
        raise ForceInstallError(f"attach_rotation_ias15 needs sim.integrator = 'ias15', got {sim.integrator!r}.")
    if getattr(sim, "_afp", None) is not None or sim.extras:
        raise ForceInstallError("additional forces are already installed on this simulation.")
    y0 = np.asarray(state, dtype=float)
    q, omega = y0[:4], y0[4:]
    # q̇ = ½ q ⊗ (0, ω)
    q_dot = 0.5 * np.array([-np.dot(q[1:], omega), *(q[0] * omega + np.cross(q[1:], omega))])
    n_real = sim.N
    sim.add(m=0.0, x=q[0], y=q[1], z=q[2], vx=q_dot[0], vy=q_dot[1], vz=q_dot[2], name=PSEUDO_PARTICLE_NAMES[0])
    sim.add(m=0.0, x=q[3], vx=q_dot[3], name=PSEUDO_PARTICLE_NAMES[1])
    sim.N_active = n_real
    sim.testparticle_type = 0
    sim.integrator.adaptive_mode = "global"
    parameters = np.zeros(_R_SIZE)
    centre = body_index(sim, body)
    indices = [body_index(sim, name) for name in perturbers]
    parameters[_R_BODY] = centre
    parameters[_R_COUPLED] = float(coupled)
    parameters[_R_N_PERTURBERS] = len(indices)
    parameters[_R_N_EXPECTED] = sim.N
    parameters[_R_PERTURBERS:_R_PERTURBERS + len(indices)] = indices
    parameters[_R_MODEL:_R_MODEL + FIGURE_SIZE] = figure
    n_max = int(figure[BODY_NMAX])
    parameters[_R_DEGREES:_R_DEGREES + len(indices)] = n_max
    parameters[_R_PSEUDO] = n_real
    extra = None
    if earth_j2 or gr:
        probe = rebound.Simulation()
        probe.add(m=1.0, name="Earth")
        extra = install_extra_forces(probe, earth_j2=earth_j2, gr=gr, earth_pole=earth_pole)
        if earth_j2:
            extra.parameters[_P_EARTH] = body_index(sim, "earth")
        parameters[_R_EXTRA:_R_EXTRA + _N_PARAMETERS] = extra.parameters
        parameters[_R_USE_EXTRA] = 1.0
    forces = _ADDITIONAL_FORCES_TYPE(_pseudo_particle_forces_cfunc.address)
    hooks = PseudoParticleHooks(parameters, None, bool(coupled), extra, (forces, _pseudo_particle_forces_cfunc))
    hooks.sim = sim
    sim._afp = hooks
    sim._extras_ref = parameters
    sim.extras = parameters.ctypes.data
    sim._additional_forces = forces
    sim.force_is_velocity_dependent = 1
    return hooks


# ============================================================================================
# Ctrl-C. REBOUND installs its own SIGINT handler when it integrates and never gives Python's back;
# the handler only counts (the C global ``reb_sigint``), the integration loop stops when the count
# is non-zero, and every ``integrate`` call starts by zeroing it. A coupled run calls ``integrate``
# once per output time, so a Ctrl-C that lands between two calls (or in the last step of one) was
# counted and then zeroed: measured, `spinorbit moon` ran to the end after 1 SIGINT in 4. Reading
# the count before and after each call restores Ctrl-C (a window of one ctypes call remains).
_REB_SIGINT = ctypes.c_int.in_dll(rebound.clibrebound, "reb_sigint")


def _raise_if_interrupted() -> None:
    if _REB_SIGINT.value:
        _REB_SIGINT.value = 0
        raise KeyboardInterrupt


def integrate_interruptibly(sim, t) -> None:
    """``sim.integrate(t)``, raising ``KeyboardInterrupt`` for a Ctrl-C that REBOUND's handler absorbed.

    The simulation is then somewhere between its old time and ``t`` (as after REBOUND's own
    KeyboardInterrupt): stop the run, or resume from a checkpoint.
    """
    _raise_if_interrupted()  # arrived since the last call, while REBOUND's handler was installed
    try:
        sim.integrate(t)
    except KeyboardInterrupt:
        _REB_SIGINT.value = 0  # REBOUND leaves the count set; the next call would stop at once
        raise
    _raise_if_interrupted()  # arrived during the last step, after REBOUND's final check


# ============================================================================================
# Restoring from REBOUND's binary. In rebound 5.2.2 the particles of a simulation rebuilt from
# bytes keep name pointers into the memory of the simulation that was *saved*: while that one is
# alive the names read right; once it is freed they read garbage (measured: 291 of 300 restores gave
# ['Body', 'Body'] for ['Planet', 'Body']), so name lookups could pick the wrong particle. The names
# are therefore stored next to the binary and set again, into memory the new simulation owns.


def simulation_from_binary(data: bytes, names):
    """A ``rebound.Simulation`` from its binary form (``sim.__reduce__()[1][0]``) with ``names`` re-set.

    Parameters
    ----------
    data : bytes
        REBOUND's binary of the simulation.
    names : sequence of str or None
        The particles' names in order (None for unnamed particles), as saved beside ``data``.

    Raises
    ------
    ValueError
        ``names`` does not have one entry per particle.
    """
    import warnings

    with warnings.catch_warnings():
        # REBOUND warns that function pointers are not restored: the caller re-attaches its forces.
        warnings.filterwarnings("ignore", message="You have to reset function pointers")
        sim = rebound.Simulation(data)
    names = list(names)
    if len(names) != sim.N:
        raise ValueError(f"names: expected one name per particle ({sim.N}), got {len(names)}.")
    for particle, name in zip(sim.particles, names):
        if name is not None:
            particle.name = name  # reb_particle_set_name: a copy owned by this simulation
    return sim
