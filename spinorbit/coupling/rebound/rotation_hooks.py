"""A rigid body's rotation integrated with REBOUND's orbits: compiled hooks, BS and IAS15 routes.

:func:`attach_rotation_hooks` integrates a rigid body's rotation (q, ω) with the orbits in REBOUND's
BS integrator (``docs/coupling.md``). Two raw cfuncs share one float64 parameter block
(``RotationHooks.parameters``):

- ``_rotation_derivatives_cfunc`` is the user ODE's ``derivatives``: (q̇, ω̇) of the body from the
  particles' positions at the current BS stage (REBOUND updates the particle array before calling
  it when ``needs_nbody`` is set);
- ``_coupled_forces_cfunc`` is ``additional_forces``: the EIH + Earth-J2 forces of
  :mod:`~spinorbit.coupling.rebound.extra_forces` (if asked for), then the figure's back-reaction on
  the orbits, read from the ODE's *current stage* ``y1`` (not ``y``, the state at the start of the step).

Both call :func:`_figure_torque_and_reaction`, so torque and back-reaction come from the same
gravity-field kernel (``gravity_field.figure_field_to_degree_xyz``). A third cfunc,
``_resume_bs_controller_cfunc``, gives a restored run its BS controller state back
(:meth:`RotationHooks.resume_bs_controller`). :func:`attach_rotation_ias15` is the measured
alternative: the rotation rides in two pseudo-particles under IAS15.

Units are the simulation's: for DE421 simulations au, day (TDB), Msun-mass units (GM/G), ω in rad/day.
"""

from __future__ import annotations

import ctypes
from dataclasses import dataclass

import numpy as np
from numba import carray, cfunc, types

from spinorbit.core.dynamics.equations import body_frame_xyz, kinematics_and_euler_into
from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import BODY_NMAX, FIGURE_SIZE, figure_field_to_degree_xyz
from spinorbit.coupling.rebound.extra_forces import (
    EXTRA_SIZE,
    ExtraForces,
    ForceInstallError,
    apply_extra_forces,
    extra_force_parameters,
    hand_forces_to_rebound,
)
from spinorbit.coupling.rebound.extra_forces import EXTRA_POLE, EXTRA_USE_GR, EXTRA_USE_J2
from spinorbit.coupling.rebound.memory_layout import (
    ODE_DERIVATIVES_TYPE,
    ODE_PRE_TIMESTEP_TYPE,
    ODE_REF_WORD,
    ODE_SIM_WORD,
    ODE_WORDS,
    ODE_Y1_WORD,
    ODE_Y_WORD,
    PARTICLE_WORDS,
    REB_STATUS_USER,
    SIM_EXTRAS_WORD,
    SIM_G_WORD,
    SIM_INTEGRATOR_STATE_WORD,
    SIM_N_WORD,
    SIM_PARTICLES_WORD,
    SIM_STATUS_BYTE,
    SIM_T_BYTE,
    SIM_WORDS,
    address_bits_as_float64,
    as_float64_pointer,
    as_int32_pointer,
    as_uint64_pointer,
    float64_bits,
    pointer_address,
    word_as_float64,
)
# Short names for the particle word offsets, read in the index arithmetic of the kernels below.
from spinorbit.coupling.rebound.memory_layout import PARTICLE_AX as _AX
from spinorbit.coupling.rebound.memory_layout import PARTICLE_M as _M
from spinorbit.coupling.rebound.memory_layout import PARTICLE_VX as _VX
from spinorbit.coupling.rebound.memory_layout import PARTICLE_X as _X
from spinorbit.coupling.rebound.simulation import body_index

__all__ = [
    "MAX_PERTURBERS",
    "ROTATION_STATE_SIZE",
    "ERROR_MESSAGES",
    "RotationCallbackError",
    "RotationHooks",
    "attach_rotation_hooks",
    "PSEUDO_PARTICLE_NAMES",
    "PseudoParticleHooks",
    "attach_rotation_ias15",
]

#: Most perturbers acting on one figure (the parameter block has a fixed size).
MAX_PERTURBERS = 64
#: Length of the rotation state (q0..q3, ωx, ωy, ωz).
ROTATION_STATE_SIZE = 7

# Parameter block (float64) shared by both cfunc: named offsets.
_R_BODY, _R_COUPLED, _R_N_PERTURBERS, _R_ERROR, _R_N_EXPECTED, _R_USE_EXTRA, _R_ODE, _R_ERROR_T = range(8)
_R_EXTRA = 8  # the extra-force parameter block (EXTRA_SIZE floats, extra_forces.py)
_R_PERTURBERS = _R_EXTRA + EXTRA_SIZE
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


@jit
def _stop_with_error(words, sim_address, p, code):
    """Record ``code`` (first error wins) and ask REBOUND to stop the run (status = REB_STATUS_USER)."""
    if p[_R_ERROR] == 0.0:
        p[_R_ERROR] = code
        p[_R_ERROR_T] = carray(as_float64_pointer(sim_address + SIM_T_BYTE), 1)[0]
    status = carray(as_int32_pointer(sim_address + SIM_STATUS_BYTE), 1)
    status[0] = REB_STATUS_USER


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
    n = np.int64(words[SIM_N_WORD])
    if n != np.int64(p[_R_N_EXPECTED]):
        _stop_with_error(words, sim_address, p, ERROR_PARTICLE_COUNT)
        return 0.0, 0.0, 0.0
    for i in range(ROTATION_STATE_SIZE):
        if not np.isfinite(y[i]):
            _stop_with_error(words, sim_address, p, ERROR_NONFINITE_STATE)
            return 0.0, 0.0, 0.0
    particles = carray(as_float64_pointer(words[SIM_PARTICLES_WORD]), n * PARTICLE_WORDS)
    model = p[_R_MODEL:_R_MODEL + FIGURE_SIZE]
    g = word_as_float64(words[SIM_G_WORD])
    body = np.int64(p[_R_BODY]) * PARTICLE_WORDS
    m_body = particles[body + _M]
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    nx = 0.0
    ny = 0.0
    nz = 0.0
    for k in range(np.int64(p[_R_N_PERTURBERS])):
        b = np.int64(p[_R_PERTURBERS + k]) * PARTICLE_WORDS
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
    ode_words = carray(ode, ODE_WORDS)
    p = carray(as_float64_pointer(ode_words[ODE_REF_WORD]), _R_SIZE)
    sim_address = ode_words[ODE_SIM_WORD]
    words = carray(as_uint64_pointer(sim_address), SIM_WORDS)
    state = carray(y, ROTATION_STATE_SIZE)
    out = carray(y_dot, ROTATION_STATE_SIZE)
    nx, ny, nz = _figure_torque_and_reaction(words, sim_address, p, state, False)
    kinematics_and_euler_into(state, nx, ny, nz, p[_R_MODEL:_R_MODEL + FIGURE_SIZE], out)


@jit
def _apply_folded_extra_forces(words):
    """Run the extra forces folded into the rotation block (if any); return the block (via ``sim.extras``)."""
    p = carray(as_float64_pointer(words[SIM_EXTRAS_WORD]), _R_SIZE)
    if p[_R_USE_EXTRA] != 0.0:
        apply_extra_forces(words, p[_R_EXTRA:_R_EXTRA + EXTRA_SIZE])
    return p


@cfunc(types.void(types.CPointer(types.uint64)), cache=True)
def _coupled_forces_cfunc(simulation):
    """``additional_forces``: EIH + Earth J2 (if on), then the figure's back-reaction (if coupled)."""
    words = carray(simulation, SIM_WORDS)
    p = _apply_folded_extra_forces(words)
    if p[_R_COUPLED] != 0.0:
        ode_words = carray(as_uint64_pointer(float64_bits(p[_R_ODE])), ODE_WORDS)
        # The ODE's current BS stage lives in y1; before the first step y1 is not allocated yet.
        address = ode_words[ODE_Y1_WORD]
        if address == 0:
            address = ode_words[ODE_Y_WORD]
        state = carray(as_float64_pointer(address), ROTATION_STATE_SIZE)
        _figure_torque_and_reaction(words, ode_words[ODE_SIM_WORD], p, state, True)


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
    ode_words = carray(ode, ODE_WORDS)
    p = carray(as_float64_pointer(ode_words[ODE_REF_WORD]), _R_SIZE)
    if p[_R_BS_PENDING] != 0.0:
        p[_R_BS_PENDING] = 0.0
        words = carray(as_uint64_pointer(ode_words[ODE_SIM_WORD]), SIM_INTEGRATOR_STATE_WORD + 1)
        state = words[SIM_INTEGRATOR_STATE_WORD]
        if state == float64_bits(p[_R_BS_STATE]):  # the same BS state as at the restore: write
            flag = carray(as_int32_pointer(state + float64_bits(p[_R_BS_FLAG_OFFSET])), 1)
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

        Whatever installed it (``earth_j2``/``gr`` when attaching, or :func:`~spinorbit.coupling.rebound.extra_forces.install_extra_forces`
        and :func:`set_nongravitational` before): this block, not the attach arguments, is what acts.
        """
        if self.parameters[_R_USE_EXTRA] == 0.0:
            return None
        return ExtraForces.from_parameters(self.parameters[_R_EXTRA:_R_EXTRA + EXTRA_SIZE])

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
        words = address_bits_as_float64(sim.integrator.state, offset)
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


def _check_folded_request(block, earth_j2, gr, earth_pole) -> None:
    """Refuse ``earth_j2``/``gr``/``earth_pole`` asked of :func:`attach_rotation_hooks` that the block
    installed earlier does not have: the fold uses that block as it is, and would silently ignore them."""
    missing = [name for name, asked, on in (("earth_j2", earth_j2, block[EXTRA_USE_J2]), ("gr", gr, block[EXTRA_USE_GR]))
               if asked and on == 0.0]
    pole = np.asarray(earth_pole, dtype=float)
    if earth_j2 and block[EXTRA_USE_J2] != 0.0 and not np.array_equal(pole / np.linalg.norm(pole),
                                                                    block[EXTRA_POLE:EXTRA_POLE + 3]):
        missing.append(f"earth_pole={tuple(pole.tolist())} (installed: {tuple(block[EXTRA_POLE:EXTRA_POLE + 3].tolist())})")
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
        As in :func:`~spinorbit.coupling.rebound.extra_forces.install_extra_forces`; they run in the same compiled force, before the reaction.
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
    parameters = _rotation_parameters(sim, body, perturbers, figure, coupled, degrees)
    y0 = _checked_rotation_state(state)
    if isinstance(previous, ExtraForces):
        _check_folded_request(previous.parameters, earth_j2, gr, earth_pole)
        # Fold the forces installed earlier into the combined cfunc: their whole block (it indexes
        # this simulation's particles), so that non-gravitational terms carry over with J2 and EIH.
        extra = previous
    else:
        extra = _requested_extra_forces(sim, earth_j2, gr, earth_pole)
    _fold_extra_forces(parameters, extra)

    ode = sim.create_ode(length=ROTATION_STATE_SIZE, needs_nbody=True)
    y = np.ctypeslib.as_array(ode.y, shape=(ROTATION_STATE_SIZE,))
    y[:] = y0
    parameters[_R_ODE:_R_ODE + 1] = address_bits_as_float64(ctypes.addressof(ode))
    derivatives = ODE_DERIVATIVES_TYPE(_rotation_derivatives_cfunc.address)
    pre_timestep = ODE_PRE_TIMESTEP_TYPE(_resume_bs_controller_cfunc.address)
    hooks = RotationHooks(parameters, ode, bool(coupled), extra)
    ode.ref = parameters.ctypes.data
    ode._derivatives = derivatives
    ode._pre_timestep = pre_timestep  # does nothing unless resume_bs_controller was called
    forces = hand_forces_to_rebound(sim, hooks, parameters, _coupled_forces_cfunc)
    hooks._keep_alive = (derivatives, forces, pre_timestep, _rotation_derivatives_cfunc, _coupled_forces_cfunc,
                         _resume_bs_controller_cfunc)
    if gr or coupled:
        # EIH depends on velocities; the back-reaction depends on the ODE stage, which BS evaluates
        # with the N-body state anyway. The flag is harmless for BS and needed if IAS15 is ever used.
        sim.force_is_velocity_dependent = 1
    return hooks


def _checked_rotation_state(state) -> np.ndarray:
    y0 = np.asarray(state, dtype=float)
    if y0.shape != (ROTATION_STATE_SIZE,) or not np.all(np.isfinite(y0)):
        raise ValueError(f"state: expected 7 finite numbers (q0..q3, wx, wy, wz), got {state!r}.")
    return y0


def _rotation_parameters(sim, body, perturbers, figure, coupled, degrees) -> np.ndarray:
    """The parameter block of the rotation callbacks for ``sim``'s particles as they are now."""
    centre = body_index(sim, body)
    indices = [body_index(sim, name) for name in perturbers]
    if centre in indices:
        raise ValueError(f"the body {body!r} cannot perturb itself; remove it from perturbers.")
    if len(indices) > MAX_PERTURBERS:
        raise ForceInstallError(f"at most {MAX_PERTURBERS} perturbers, got {len(indices)}.")
    figure = np.asarray(figure, dtype=float)
    if figure.shape != (FIGURE_SIZE,):
        raise ValueError(f"figure: expected a gravity_field.make_body array of {FIGURE_SIZE} floats.")
    n_max = int(figure[BODY_NMAX])
    degrees = [n_max] * len(indices) if degrees is None else [int(d) for d in degrees]
    if len(degrees) != len(indices) or any(d < 2 for d in degrees):
        raise ValueError(f"degrees: expected one degree ≥ 2 per perturber, got {degrees!r}.")
    parameters = np.zeros(_R_SIZE)
    parameters[_R_BODY] = centre
    parameters[_R_COUPLED] = float(coupled)
    parameters[_R_N_PERTURBERS] = len(indices)
    parameters[_R_N_EXPECTED] = sim.N
    parameters[_R_PERTURBERS:_R_PERTURBERS + len(indices)] = indices
    parameters[_R_MODEL:_R_MODEL + FIGURE_SIZE] = figure
    parameters[_R_DEGREES:_R_DEGREES + len(indices)] = [min(d, n_max) for d in degrees]
    return parameters


def _requested_extra_forces(sim, earth_j2, gr, earth_pole) -> ExtraForces | None:
    """The EIH/J2 forces asked for when attaching (not installed on their own), or None."""
    if not (earth_j2 or gr):
        return None
    return ExtraForces(extra_force_parameters(sim, earth_j2, gr, earth_pole), bool(earth_j2), bool(gr))


def _fold_extra_forces(parameters, extra: ExtraForces | None) -> None:
    """Put ``extra``'s block into the rotation block: the combined force then runs it first."""
    if extra is not None:
        parameters[_R_EXTRA:_R_EXTRA + EXTRA_SIZE] = extra.parameters
        parameters[_R_USE_EXTRA] = 1.0


# ============================================================================================
# The IAS15 route, kept for measurement against BS (docs/coupling.md): the quaternion and its rate
# ride in two massless pseudo-particles after the real bodies (N_active = real bodies):
# a: (x, y, z) = (q0, q1, q2), b: x = q3 (y = z = 0); velocities are q̇. A last-running force
# overwrites their accelerations with q̈ from the same torque kernel and Euler equations.
# --------------------------------------------------------------------------------------------
PSEUDO_PARTICLE_NAMES = ("_spinorbit_q012", "_spinorbit_q3")


@cfunc(types.void(types.CPointer(types.uint64)), cache=True)
def _pseudo_particle_forces_cfunc(simulation):
    """``additional_forces`` of the IAS15 route: EIH + J2, back-reaction, then q̈ on the pseudo-particles."""
    words = carray(simulation, SIM_WORDS)
    p = _apply_folded_extra_forces(words)
    n = np.int64(words[SIM_N_WORD])
    if n != np.int64(p[_R_N_EXPECTED]):
        _stop_with_error(words, pointer_address(simulation), p, ERROR_PARTICLE_COUNT)
        return
    particles = carray(as_float64_pointer(words[SIM_PARTICLES_WORD]), n * PARTICLE_WORDS)
    a = np.int64(p[_R_PSEUDO]) * PARTICLE_WORDS
    b = a + PARTICLE_WORDS
    q0, q1, q2, q3 = particles[a + _X], particles[a + _X + 1], particles[a + _X + 2], particles[b + _X]
    d0, d1, d2, d3 = particles[a + _VX], particles[a + _VX + 1], particles[a + _VX + 2], particles[b + _VX]
    norm2 = q0 * q0 + q1 * q1 + q2 * q2 + q3 * q3
    # ω = 2 vec(conj(q) ⊗ q̇) / |q|²
    y = np.empty(ROTATION_STATE_SIZE)
    y[0], y[1], y[2], y[3] = q0, q1, q2, q3
    y[4] = 2.0 * (q0 * d1 - d0 * q1 - (q2 * d3 - q3 * d2)) / norm2
    y[5] = 2.0 * (q0 * d2 - d0 * q2 - (q3 * d1 - q1 * d3)) / norm2
    y[6] = 2.0 * (q0 * d3 - d0 * q3 - (q1 * d2 - q2 * d1)) / norm2
    nx, ny, nz = _figure_torque_and_reaction(words, pointer_address(simulation), p, y, p[_R_COUPLED] != 0.0)
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
    y0 = _checked_rotation_state(state)
    q, omega = y0[:4], y0[4:]
    # q̇ = ½ q ⊗ (0, ω)
    q_dot = 0.5 * np.array([-np.dot(q[1:], omega), *(q[0] * omega + np.cross(q[1:], omega))])
    n_real = sim.N
    sim.add(m=0.0, x=q[0], y=q[1], z=q[2], vx=q_dot[0], vy=q_dot[1], vz=q_dot[2], name=PSEUDO_PARTICLE_NAMES[0])
    sim.add(m=0.0, x=q[3], vx=q_dot[3], name=PSEUDO_PARTICLE_NAMES[1])
    sim.N_active = n_real
    sim.testparticle_type = 0
    sim.integrator.adaptive_mode = "global"
    parameters = _rotation_parameters(sim, body, perturbers, figure, coupled, degrees=None)
    parameters[_R_PSEUDO] = n_real
    extra = _requested_extra_forces(sim, earth_j2, gr, earth_pole)
    _fold_extra_forces(parameters, extra)
    hooks = PseudoParticleHooks(parameters, None, bool(coupled), extra)
    hooks.sim = sim
    forces = hand_forces_to_rebound(sim, hooks, parameters, _pseudo_particle_forces_cfunc)
    hooks._keep_alive = (forces, _pseudo_particle_forces_cfunc)
    sim.force_is_velocity_dependent = 1
    return hooks

