"""∂U/∂(Andoyer variables) and ∂U/∂(canonical elements) from the one torque definition.

Paper: T. Fukushima, "Canonical elements of rotational motion", eqs. (10)–(11) (the perturbed
Hamiltonian K = ½ a S² − U and its equations of motion) and section 4 (the Jacobian, evaluated by
:mod:`spinorbit.core.elements.jacobian`). ``docs/elements_integrator.md`` has the derivation in full.

No second force model: U and the body-frame torque N come from
:func:`spinorbit.core.dynamics.equations.force_function_and_torque_xyz`, whose N satisfies δU = N·δθ for an
infinitesimal *active* rotation δθ of the body (body-frame components; the body-frame perturber
position moves by −δθ × r).

Derivation
----------
The attitude (reference frame → body) is R = R3(l) R1(J) R3(g) R1(I) R3(h) with cos J = L/G,
cos I = H/G. For a passive rotation R_k(θ) = exp(−θ [e_k]×), so d R_k/dθ = −[e_k]× R_k, and a change
dx of one angle in the product gives dR = −[a_x]× R dx with a_x the rotation axis carried to the body
frame; dR = −[δθ]× R is exactly the active body rotation δθ = a_x dx. Hence ∂U/∂x = N · a_x with

    l: a = e_z (body C axis)                      ∂U/∂l = N_z
    J: a = R3(l) e_1 = (M × e_z)/|M⊥|             ∂U/∂J = (N_x M_y − N_y M_x)/|M⊥|
    g: a = M/G (angular momentum)                 ∂U/∂g = N·M/G
    I: a = R (e_z × m)/|m⊥|  (node line)          ∂U/∂I = (m × n)_z/|m⊥|
    h: a = R e_z (reference z axis)               ∂U/∂h = n_z

where M is the body momentum, m = Rᵀ M and n = Rᵀ N the momentum and torque in the reference frame,
|M⊥| = G sin J, |m⊥| = G sin I. The momenta enter only through J(L, G) and I(H, G):
∂J/∂L = −1/(G sin J), ∂J/∂G = L/(G² sin J), ∂I/∂H = −1/(G sin I), ∂I/∂G = H/(G² sin I), so

    ∂U/∂L = (M × N)_z / |M⊥|²
    ∂U/∂H = −(m × n)_z / |m⊥|²
    ∂U/∂G = [−L (M × N)_z / |M⊥|² + H (m × n)_z / |m⊥|²] / G

(verified component by component against finite differences of U in ``tests/test_integrate_elements.py``).

Singular sets: ∂U/∂L and the first term of ∂U/∂G grow like 1/sin J, ∂U/∂H and the second term like
1/sin I. They do not cancel in ∂U/∂(elements): near sin I = 0 the node h is undefined and dh/dt =
−∂U/∂H really diverges (a frame choice, avoided by the reference-frame rule of the driver); near
sin J = 0 (spin about ±C, d → c) (S, s) behave like polar coordinates at their centre and ds/dt really
diverges. The RHS reports how close the state is (:func:`singularity_distances`); the driver stops there.
"""

import math

import numpy as np

from spinorbit.core.dynamics.equations import force_function_and_torque_xyz
from spinorbit.core.elements.canonical import (
    EL_H,
    EL_S,
    EL_SMALL_H,
    EL_SMALL_S,
    EL_SMALL_Z,
    EL_Z,
    FLIP_B,
    FLIP_NONE,
    MO_ARG_PER_S,
    MO_G_PER_S,
    MO_MODE,
    MO_PARAM_C,
    MO_PN_COEFF,
    MODE_UNIFORM,
    elliptic_constants,
    motion_from_elements,
    multiply3,
    state_from_elements,
    state_from_elements_motion,
)
from spinorbit.core.elements.jacobian import andoyer_jacobian_motion, canonical_gradient
from spinorbit.core.jit import jit
from spinorbit.core.math.elliptic_integrals import NK_COMPLETE
from spinorbit.core.math.elliptic_periods import MK_K_HI, MK_K_LO
from spinorbit.core.math.rotations import matrix_to_quat

TWO_PI = 2.0 * math.pi

# Indices of ∂U/∂(L, G, H, l, g, h).
DU_L, DU_G, DU_H, DU_SMALL_L, DU_SMALL_G, DU_SMALL_H = range(6)


@jit
def working_elements(elements):
    """(working elements with S ≥ 0, flip) of paper-named elements whose sign of S carries the sense.

    S < 0 means rotation about −C (SAM) or −A (LAM): the working frame is the body turned by π about B
    (``FLIP_B``) and the working elements are (−S, Z, H, −s, z, h) (:mod:`spinorbit.core.elements.canonical`).
    """
    work = elements.copy()
    if elements[EL_S] < 0.0:
        work[EL_S] = -elements[EL_S]
        work[EL_SMALL_S] = -elements[EL_SMALL_S]
        return work, FLIP_B
    return work, FLIP_NONE


@jit
def attitude_and_momentum(elements, ic):
    """Backward map of signed elements: attitude R (reference → body, (3, 3)) and body momentum M (3,)."""
    work, flip = working_elements(elements)
    return state_from_elements(work, flip, ic)


@jit
def inertial_quaternion(attitude, frame):
    """Quaternion (body → inertial) of R_inertial = R_ref · F, F the (3, 3) inertial → reference matrix."""
    r_inertial = multiply3(attitude, frame)
    return matrix_to_quat(np.ascontiguousarray(r_inertial.T))


@jit
def andoyer_gradient_from_torque(attitude, momentum, nx, ny, nz):
    """∂U/∂(L, G, H, l, g, h) from the body torque N (module docstring for the derivation).

    Parameters
    ----------
    attitude : (3, 3) ndarray
        R, reference frame → body.
    momentum : (3,) ndarray
        Body angular momentum M (momentum unit).
    nx, ny, nz : float
        Body-frame torque with δU = N·δθ (energy unit).

    Returns
    -------
    (6,) ndarray
        ∂U/∂L, ∂U/∂G, ∂U/∂H (energy per momentum unit = rad/time) and ∂U/∂l, ∂U/∂g, ∂U/∂h (energy/rad).
        Not finite at sin J = 0 or sin I = 0.
    """
    mx, my, mz = momentum[0], momentum[1], momentum[2]
    big_g = math.sqrt(mx * mx + my * my + mz * mz)
    # Reference-frame momentum m = Rᵀ M and torque n = Rᵀ N.
    m0 = attitude[0, 0] * mx + attitude[1, 0] * my + attitude[2, 0] * mz
    m1 = attitude[0, 1] * mx + attitude[1, 1] * my + attitude[2, 1] * mz
    m2 = attitude[0, 2] * mx + attitude[1, 2] * my + attitude[2, 2] * mz
    n0 = attitude[0, 0] * nx + attitude[1, 0] * ny + attitude[2, 0] * nz
    n1 = attitude[0, 1] * nx + attitude[1, 1] * ny + attitude[2, 1] * nz
    n2 = attitude[0, 2] * nx + attitude[1, 2] * ny + attitude[2, 2] * nz
    body_perp2 = mx * mx + my * my  # (G sin J)²
    body_cross = (mx * ny - my * nx) / body_perp2  # (M × N)_z / |M⊥|²
    du_big_h, du_h = andoyer_h_partials(m0, m1, n0, n1, n2)
    out = np.empty(6)
    out[DU_L] = body_cross
    out[DU_G] = (-mz * body_cross - m2 * du_big_h) / big_g
    out[DU_H] = du_big_h
    out[DU_SMALL_L] = nz
    out[DU_SMALL_G] = (nx * mx + ny * my + nz * mz) / big_g
    out[DU_SMALL_H] = du_h
    return out


@jit(inline="always")
def andoyer_h_partials(m0, m1, n0, n1, n2):
    """(∂U/∂H, ∂U/∂h) from the reference-frame momentum m and torque n alone (the part of
    :func:`andoyer_gradient_from_torque` without the attitude): −(m × n)_z/|m⊥|² and n_z, m⊥ = G sin I.
    For callers that hold the torque in the reference frame already (the torus grids of
    :mod:`spinorbit.core.averaging.short_period`)."""
    return -(m0 * n1 - m1 * n0) / (m0 * m0 + m1 * m1), n2


@jit
def singularity_distances(elements, attitude, momentum, ic):
    """(1 − m or 1 − μ, sin J, sin I, sin J_A, sin P) of a state: how far it is from the elements' singular sets.

    1 − m → 0 at the separatrix (and the mode changes across it); sin J → 0 at spin about ±C (the
    centre of the SAM elements); sin I → 0 when the angular momentum is along the reference z axis;
    sin J_A = |M × A axis| / G → 0 at spin about ±A (the centre of the LAM elements, S → Z, where
    the Jacobian's 1/√(a − d) terms overflow); sin P → 0 at the permanent rotations of an exactly
    symmetric body (:func:`singularity_distances_of_motion`). A permanent rotation returns a separatrix distance of 0.
    """
    work, _ = working_elements(elements)
    return singularity_distances_of_motion(motion_from_elements(work[EL_S], work[EL_Z], ic), attitude, momentum, ic)


@jit
def singularity_distances_of_motion(mo, attitude, momentum, ic):
    """(1 − m or 1 − μ, sin J, sin I, sin J_A, sin P) of a motion, its body attitude and body momentum.

    sin P is the sine of the angle of M from the equal-moment plane of an exactly symmetric body
    (|M_x|/G for B = C, |M_z|/G for A = B; 1 for a triaxial body, which has no such set): there the
    motion is next to a permanent rotation, its gap d − c = (a − c) sin² P (resp. a − d) is a
    difference of nearly equal numbers, resolved by (S, Z) only to ≈ ε d, so the phase the elements
    carry is wrong by ≈ ε / sin² P (``canonical.symmetric_gap_resolved`` refuses only below ≈ 4ε).
    """
    _a, _b, _c, a_b, b_c, _a_c = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    sep = 0.0 if mo[MO_MODE] == MODE_UNIFORM else mo[MO_PARAM_C]
    big_g = math.sqrt(momentum[0] ** 2 + momentum[1] ** 2 + momentum[2] ** 2)
    sin_j = math.hypot(momentum[0], momentum[1]) / big_g
    sin_j_a = math.hypot(momentum[1], momentum[2]) / big_g
    m0 = attitude[0, 0] * momentum[0] + attitude[1, 0] * momentum[1] + attitude[2, 0] * momentum[2]
    m1 = attitude[0, 1] * momentum[0] + attitude[1, 1] * momentum[1] + attitude[2, 1] * momentum[2]
    sin_i = math.hypot(m0, m1) / big_g
    sin_p = 1.0
    if b_c <= 0.0 < a_b:
        sin_p = abs(momentum[0]) / big_g
    elif a_b <= 0.0 < b_c:
        sin_p = abs(momentum[2]) / big_g
    return sep, sin_j, sin_i, sin_j_a, sin_p


@jit
def elements_rhs_into(t, elements, model, frame, ic, dy):
    """Paper eq. (11) for signed elements: writes d(S, Z, H, s, z, h)/dt into ``dy``.

    dS/dt = ∂U/∂s, dZ/dt = ∂U/∂z, dH/dt = ∂U/∂h, ds/dt = a S − ∂U/∂S, dz/dt = −∂U/∂Z, dh/dt = −∂U/∂H,
    with ∂U/∂(elements) = Jᵀ ∂U/∂(Andoyer) (:func:`spinorbit.core.elements.jacobian.andoyer_jacobian`).

    Parameters
    ----------
    t : float
        Time (model unit).
    elements : (6,) ndarray
        (S, Z, H, s, z, h), S signed; H, h referred to the frame ``frame``.
    model : ndarray
        :func:`spinorbit.core.dynamics.equations.make_model`.
    frame : (3, 3) ndarray
        Inertial → reference rotation F (perturber positions are inertial).
    ic : tuple
        :func:`spinorbit.core.elements.canonical.inertia_constants`.
    dy : (6,) ndarray
        Output.

    Returns
    -------
    sep, sin_j, sin_i, sin_j_a, sin_p : float
        :func:`singularity_distances` of the state (computed from quantities the RHS has anyway).
    """
    # The motion and elliptic constants of (S, Z) once, for both the backward map and the Jacobian.
    work, flip = working_elements(elements)
    mo = motion_from_elements(work[EL_S], work[EL_Z], ic)
    mk, pk = elliptic_constants(mo)
    attitude, momentum = state_from_elements_motion(work, flip, mo, mk, pk)
    q = inertial_quaternion(attitude, frame)
    _, nx, ny, nz = force_function_and_torque_xyz(t, q[0], q[1], q[2], q[3], model)
    elements_rhs_of_torque(elements, ic, mo, mk, attitude, momentum, nx, ny, nz, dy)
    return singularity_distances_of_motion(mo, attitude, momentum, ic)


@jit
def elements_rhs_of_torque(elements, ic, mo, mk, attitude, momentum, nx, ny, nz, dy):
    """Eq. (11) at one point of the elements from a given body torque N: d(S, Z, H, s, z, h)/dt into ``dy``.

    The tail of :func:`elements_rhs_into` once the backward map (``mo``, ``mk``, ``attitude``,
    ``momentum``) is known. Apart from ds/dt's a S, the rates are linear in N, so a caller that needs
    the mean over many torques at one attitude (the orbit average of the recoil,
    :func:`spinorbit.core.averaging.thermal_mean.mean_thermal_rates`) may pass their mean.
    """
    du_andoyer = andoyer_gradient_from_torque(attitude, momentum, nx, ny, nz)
    du = canonical_gradient(du_andoyer, andoyer_jacobian_motion(elements, ic, mo, mk))
    a, _b, _c, _a_b, _b_c, _a_c = ic  # inertia_constants: (a, b, c, a − b, b − c, a − c)
    dy[EL_S] = du[EL_SMALL_S]
    dy[EL_Z] = du[EL_SMALL_Z]
    dy[EL_H] = du[EL_SMALL_H]
    dy[EL_SMALL_S] = a * elements[EL_S] - du[EL_S]
    dy[EL_SMALL_Z] = -du[EL_Z]
    dy[EL_SMALL_H] = -du[EL_H]


@jit
def force_function_of_elements(t, elements, model, frame, ic):
    """U(t, elements) (energy): the force function at the attitude of the signed elements."""
    attitude, _ = attitude_and_momentum(elements, ic)
    q = inertial_quaternion(attitude, frame)
    return force_function_and_torque_xyz(t, q[0], q[1], q[2], q[3], model)[0]


@jit
def reduce_phase(elements, ic):
    """Shift s by whole periods of the torque-free motion into |κ s| ≤ 2K, compensating in z, in place.

    The backward map (eqs. 7–8) is invariant under (s, z) → (s − P, z + Δg) with P = 4K/κ the period
    of the body momentum in s and Δg = (c/√(ad)) P + C_g · 4Π(n|m) the advance of g over one period
    (pn(x + 4K) = pn(x) + 4Π). A map with Φ∘T = Φ between two branches of the canonical map Φ is
    canonical, and K = ½ a S² − U∘Φ is invariant, so eq. (11) is unchanged by it: the shift changes
    the representation, not the motion. Why shift at all: ∂(l, g)/∂(S, Z) contain terms proportional
    to s (the dependence of the frequencies on S and Z), so with an unbounded s the RHS of s and z
    carries oscillations whose amplitude grows with the number of turns, and the steps shrink.

    Returns the number of periods removed (0: nothing done).
    """
    work, _ = working_elements(elements)
    mo = motion_from_elements(work[EL_S], work[EL_Z], ic)
    if mo[MO_MODE] == MODE_UNIFORM or not (mo[MO_PARAM_C] > 0.0):
        return 0.0
    mk, pk = elliptic_constants(mo)
    four_k = 4.0 * (mk[MK_K_HI] + mk[MK_K_LO])
    arg = work[EL_SMALL_S] * mo[MO_ARG_PER_S]
    periods = np.rint(arg / four_k)
    if periods == 0.0:
        return 0.0
    period_s = four_k / mo[MO_ARG_PER_S]
    advance_g = mo[MO_G_PER_S] * period_s + mo[MO_PN_COEFF] * 4.0 * pk[NK_COMPLETE]
    shifted = work[EL_SMALL_S] - periods * period_s
    elements[EL_SMALL_S] = -shifted if elements[EL_S] < 0.0 else shifted
    z = elements[EL_SMALL_Z] + periods * advance_g
    elements[EL_SMALL_Z] = z - TWO_PI * np.rint(z / TWO_PI)  # z is an angle: keep it in [−π, π] as well
    return periods
