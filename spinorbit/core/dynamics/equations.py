"""THE equations of motion of a perturbed rigid body in Euler parameters + body angular velocity.

State y = (q0, q1, q2, q3, ωx, ωy, ωz): q the scalar-first unit quaternion (body → inertial,
``docs/conventions.md``), ω the body-frame angular velocity (rad/time) on the principal axes with
moments A ≤ B ≤ C::

    q̇ = ½ q ⊗ (0, ω)
    I ω̇ = Iω × ω + N,   N = Σ_perturbers (∂U/∂r) × r     (gravity_field.py for U and the sign)

r is the perturber's position in the body frame, r = R r_inertial with R = M(q)ᵀ.

A 10-component state (q, ω, ω_c) with a model array that ends with an interior block is the Moon of
the JPL ephemerides (elastic mantle with tides around a fluid core): :func:`lunar_rhs_into`, built from
:mod:`spinorbit.core.model.lunar_interior`; :func:`rhs_into` dispatches on the state's length, so the same
integrators run both. Every back end
(the numba integrator, scipy's ``solve_ivp`` through :func:`scipy_rhs`, the benchmark peers) calls
:func:`rhs`; nothing else defines the dynamics.

**The model** is ONE flat float64 array (jitclasses cannot be cached; a tuple of arrays costs two
atomic reference-count updates per array at every numba call boundary, measured ~130 ns per RHS call
with eight arrays, more than the whole torque-free RHS)::

    model = concatenate([figure (FIGURE_SIZE floats, gravity_field.make_body),
                         perturber block (perturbers.pack_perturbers, at offset MODEL_PERTURBERS),
                         thermal block (thermal.pack_thermal, optional; its offset in figure[FIG_THERMAL])])

Build it with :func:`make_model`. Any other integrator (the canonical-element equations, a splitting
scheme) takes the same array and calls :func:`force_function_and_torque_xyz` (scalars, no allocation)
or :func:`total_torque` / :func:`force_function`.

Energy: with time-independent perturbers, E = T − U (T = ½ ωᵀ I ω) is conserved, because
dT/dt = ω·N and dU/dt = (∂U/∂r)·(−ω × r) = ω·N (tested).
"""

import math

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.model.gravity_field import (
    BODY_A,
    BODY_B,
    BODY_C,
    BODY_MASS,
    FIG_THERMAL,
    FIGURE_SIZE,
    figure_field_without_monopole_xyz,
    make_body,
)
from spinorbit.core.model.lunar_interior import (
    IN_CORE_A,
    IN_CORE_C,
    IN_DISTORTION_ROWS,
    IN_EARTH_J2R2,
    IN_EARTH_ROW,
    IN_POLE_X,
    IN_POLE_Y,
    IN_POLE_Z,
    IN_TAU,
    INTERIOR_SIZE,
    INTERIOR_STATE_SIZE,
    core_mantle_torque,
    distortion,
    figure_figure_torque,
    j2_hessian,
    point_mass_torque,
    rotate_about,
    symmetric_solve,
    symmetric_times,
)
from spinorbit.core.model.perturbers import (
    PERTURBER_ROW,
    pack_perturbers,
    perturber_position_xyz,
    sampled_velocity_xyz,
)
from spinorbit.core.model.thermal import TH_SUN_ROW, thermal_force_torque_xyz

STATE_SIZE = 7

#: Offset of the perturber block in the model array (the figure comes first).
MODEL_PERTURBERS = FIGURE_SIZE


def make_model(moments, sources=(), mass=0.0, reference_radius=1.0, stokes_c=None, stokes_s=None,
               normalized=False, thermal=None, thermal_sun=0):
    """Build the model array from a body description and a list of perturber sources.

    Parameters
    ----------
    moments, mass, reference_radius, stokes_c, stokes_s, normalized
        As in :func:`spinorbit.core.model.gravity_field.make_body`.
    sources : sequence
        Perturber sources from :mod:`spinorbit.core.model.perturbers` (may be empty: torque-free).
    thermal : ndarray, optional
        A thermal block (:func:`spinorbit.core.model.thermal.pack_thermal`, in the model's units):
        sunlight's recoil torque joins the torque sum, with the Sun at ``sources[thermal_sun]``.
    thermal_sun : int
        Index of the Sun among ``sources``.

    Returns
    -------
    model : ndarray (float64, 1-d)
        [figure, number of perturbers, perturber rows, samples, thermal block] (see the module docstring).
    """
    figure = make_body(moments, mass, reference_radius, stokes_c, stokes_s, normalized)
    sources = list(sources)
    parts = [figure, pack_perturbers(sources, base=MODEL_PERTURBERS)]
    if thermal is not None:
        if not 0 <= thermal_sun < len(sources):
            raise ValueError(f"thermal_sun: expected the index of the Sun among the {len(sources)} sources; got "
                             f"{thermal_sun!r}. Sunlight's recoil needs the Sun's position: add it as a source.")
        block = np.array(thermal, dtype=float)
        block[TH_SUN_ROW] = MODEL_PERTURBERS + 1 + thermal_sun * PERTURBER_ROW
        figure[FIG_THERMAL] = sum(part.size for part in parts)
        parts.append(block)
    return np.ascontiguousarray(np.concatenate(parts))


def perturber_count(model):
    """Number of perturbers in a model array."""
    return int(model[MODEL_PERTURBERS])


@jit
def body_frame_xyz(q0, q1, q2, q3, rx, ry, rz):
    """r_body = M(q)ᵀ r_inertial for a quaternion of any non-zero norm (divides by |q|²), as 3 floats.

    Dividing by |q|² makes the right-hand side well defined at the RK stages, where q is off the unit
    sphere by the local error; the integrator renormalises after each step. The result depends on q
    only through q/|q|.
    """
    w, x, y, z = q0, q1, q2, q3
    inv = 1.0 / (w * w + x * x + y * y + z * z)
    return (inv * ((w * w + x * x - y * y - z * z) * rx + 2.0 * (x * y + w * z) * ry + 2.0 * (x * z - w * y) * rz),
            inv * (2.0 * (x * y - w * z) * rx + (w * w - x * x + y * y - z * z) * ry + 2.0 * (y * z + w * x) * rz),
            inv * (2.0 * (x * z + w * y) * rx + 2.0 * (y * z - w * x) * ry + (w * w - x * x - y * y + z * z) * rz))


@jit
def body_frame_position(q, r_inertial):
    """Array form of :func:`body_frame_xyz`."""
    x, y, z = body_frame_xyz(q[0], q[1], q[2], q[3], r_inertial[0], r_inertial[1], r_inertial[2])
    return np.array([x, y, z])


@jit(inline="always")  # RHS hot path: no array crosses a call boundary (see perturbers.py)
def perturber_force_function_and_torque_xyz(q0, q1, q2, q3, ix, iy, iz, mu, model):
    """(U, Nx, Ny, Nz) of one perturber of gravitational parameter mu at inertial position (ix, iy, iz)
    relative to the body: the one torque definition, for callers that evaluate the perturbers'
    positions once for many attitudes (the torus grids of :mod:`spinorbit.core.averaging.short_period`).
    """
    x, y, z = body_frame_xyz(q0, q1, q2, q3, ix, iy, iz)
    # Torque from the field without the monopole: its radial gradient has no torque but would
    # add rounding noise (see gravity_field.figure_field_without_monopole_xyz).
    u_k, gx, gy, gz = figure_field_without_monopole_xyz(x, y, z, mu, model)
    u = u_k + mu * model[BODY_MASS] / math.sqrt(x * x + y * y + z * z)
    # N = (∂U/∂r) × r
    return u, gy * z - gz * y, gz * x - gx * z, gx * y - gy * x


@jit(inline="always")  # RHS hot path: no array crosses a call boundary (see perturbers.py)
def force_function_and_torque_xyz(t, q0, q1, q2, q3, model):
    """(U, Nx, Ny, Nz) summed over all perturbers: the one torque definition, allocation-free.

    U in energy units (force function, −potential energy); N = Σ (∂U/∂r) × r in the body frame.
    """
    u = 0.0
    nx = 0.0
    ny = 0.0
    nz = 0.0
    for k in range(int(model[MODEL_PERTURBERS])):
        row = MODEL_PERTURBERS + 1 + k * PERTURBER_ROW
        ix, iy, iz = perturber_position_xyz(t, model, row)
        u_k, nx_k, ny_k, nz_k = perturber_force_function_and_torque_xyz(q0, q1, q2, q3, ix, iy, iz,
                                                                        model[row + 1], model)
        u += u_k
        nx += nx_k
        ny += ny_k
        nz += nz_k
    if model[FIG_THERMAL] > 0.0:  # sunlight's recoil (YORP): a torque without a force function
        tx, ty, tz = thermal_torque_xyz(t, q0, q1, q2, q3, model)
        nx += tx
        ny += ty
        nz += tz
    return u, nx, ny, nz


@jit(inline="always")
def thermal_torque_xyz(t, q0, q1, q2, q3, model):
    """Body-frame recoil torque of the model's thermal block (:mod:`spinorbit.core.model.thermal`), Sun
    at its perturber row."""
    base = int(model[FIG_THERMAL])
    ix, iy, iz = perturber_position_xyz(t, model, int(model[base + TH_SUN_ROW]))
    x, y, z = body_frame_xyz(q0, q1, q2, q3, ix, iy, iz)
    _, _, _, tx, ty, tz = thermal_force_torque_xyz(x, y, z, math.sqrt(x * x + y * y + z * z), model, base)
    return tx, ty, tz


@jit
def total_force_function_and_torque(t, q, model):
    """U (energy) and body-frame torque N (energy, (3,) array) of all perturbers at time t, attitude q."""
    u, nx, ny, nz = force_function_and_torque_xyz(t, q[0], q[1], q[2], q[3], model)
    return u, np.array([nx, ny, nz])


@jit
def inertial_torques_along(times, quaternions, model):
    """Inertial torque M(q) N(t, q) (energy units, (n, 3)) at each (times[j], quaternions[j]).

    The scene planner's free-motion bound (:mod:`spinorbit.scene.planner`) evaluates the one torque
    definition, :func:`force_function_and_torque_xyz`, along a given attitude history; M(q)ᵀ of the
    conjugate quaternion is M(q), so :func:`body_frame_xyz` turns the body torque into the inertial one.
    """
    n = times.shape[0]
    out = np.empty((n, 3))
    for j in range(n):
        q0, q1, q2, q3 = quaternions[j, 0], quaternions[j, 1], quaternions[j, 2], quaternions[j, 3]
        _, nx, ny, nz = force_function_and_torque_xyz(times[j], q0, q1, q2, q3, model)
        out[j, 0], out[j, 1], out[j, 2] = body_frame_xyz(q0, -q1, -q2, -q3, nx, ny, nz)
    return out


@jit
def total_torque(t, q, model):
    """Body-frame torque N(t, q) of all perturbers (energy units)."""
    return total_force_function_and_torque(t, q, model)[1]


@jit
def force_function(t, q, model):
    """Force function U(t, q) of all perturbers (energy units; U = −potential energy)."""
    return force_function_and_torque_xyz(t, q[0], q[1], q[2], q[3], model)[0]


@jit(inline="always")
def rhs_into(t, y, model, dy):
    """Write dy/dt into ``dy`` (no allocation; the integrators' inner call).

    A 10-component state (q, ω, ω_c) is the mantle-and-core model of :func:`lunar_rhs_into` (its
    model array ends with an interior block); a 7-component one is the rigid body.
    """
    if y.shape[0] == INTERIOR_STATE_SIZE:
        lunar_rhs_into(t, y, model, dy)
        return
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    if model[MODEL_PERTURBERS] > 0.0:
        _, nx, ny, nz = force_function_and_torque_xyz(t, q0, q1, q2, q3, model)
    else:
        nx = ny = nz = 0.0
    kinematics_and_euler_into(y, nx, ny, nz, model, dy)


@jit(inline="always")
def kinematics_and_euler_into(y, nx, ny, nz, model, dy):
    """dy/dt for a given body-frame torque N: q̇ = ½ q ⊗ (0, ω) and Euler's equations.

    The one place where the equations of motion are written; :func:`rhs_into` (torque from the
    perturber table) and the REBOUND coupling (torque from the simulation's particles, see
    ``spinorbit/coupling/rebound/rotation_hooks.py``) both end here. ``model`` needs only the figure head
    (A, B, C at BODY_A..BODY_C).
    """
    a_mom, b_mom, c_mom = model[BODY_A], model[BODY_B], model[BODY_C]
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    wx, wy, wz = y[4], y[5], y[6]
    # q̇ = ½ q ⊗ (0, ω)
    dy[0] = 0.5 * (-q1 * wx - q2 * wy - q3 * wz)
    dy[1] = 0.5 * (q0 * wx + q2 * wz - q3 * wy)
    dy[2] = 0.5 * (q0 * wy - q1 * wz + q3 * wx)
    dy[3] = 0.5 * (q0 * wz + q1 * wy - q2 * wx)
    # Euler: A ω̇x = (B − C) ωy ωz + Nx, cyclic.
    dy[4] = ((b_mom - c_mom) * wy * wz + nx) / a_mom
    dy[5] = ((c_mom - a_mom) * wz * wx + ny) / b_mom
    dy[6] = ((a_mom - b_mom) * wx * wy + nz) / c_mom


@jit
def _delayed_distortion(t, q0, q1, q2, q3, wx, wy, wz, ax, ay, az, model, block, out, rate):
    """ΔI and dΔI/dt from the Earth's state and the mantle spin at t − τ (lunar_interior.distortion).

    The delayed attitude is the present one turned back about ω by |ω|τ (ω − τ ω̇/2 as the mean
    rate over the delay); the delayed ω is ω − τ ω̇. Both neglect ω̈ τ², ~1e-8 of the delay's effect.
    """
    tau = block[IN_TAU]
    row = int(block[IN_EARTH_ROW])
    mu = model[row + 1]
    ex, ey, ez = perturber_position_xyz(t - tau, model, row)
    vx, vy, vz = sampled_velocity_xyz(t - tau, model, row)
    mx, my, mz = wx - 0.5 * tau * ax, wy - 0.5 * tau * ay, wz - 0.5 * tau * az
    rx, ry, rz = body_frame_xyz(q0, q1, q2, q3, ex, ey, ez)
    rx, ry, rz = rotate_about(mx, my, mz, tau, rx, ry, rz)
    ux, uy, uz = body_frame_xyz(q0, q1, q2, q3, vx, vy, vz)
    ux, uy, uz = rotate_about(mx, my, mz, tau, ux, uy, uz)
    dx, dy_, dz = wx - tau * ax, wy - tau * ay, wz - tau * az
    # Body-frame derivative of the delayed position: inertial velocity minus ω × r.
    ux, uy, uz = ux - (dy_ * rz - dz * ry), uy - (dz * rx - dx * rz), uz - (dx * ry - dy_ * rx)
    distortion(block, rx, ry, rz, ux, uy, uz, mu, dx, dy_, dz, ax, ay, az, out, rate)


@jit
def lunar_rhs_into(t, y, model, dy):
    """dy/dt of the mantle-and-core model (``spinorbit.core.model.lunar_interior``; DE4xx lunar equations).

    State y = (q, ω, ω_c): mantle attitude, mantle angular velocity and core angular velocity, both
    on the mantle axes. Torques: every perturber on the undistorted figure I_T (degrees 2..n_max, the
    rigid body's :func:`force_function_and_torque_xyz`), the first ``distortion_rows`` perturbers on
    ΔI, the Earth's J₂ on I_T + ΔI, and the core–mantle torque. ω̇ is solved twice: the first pass
    (ω̇ ≈ 0 in the delayed terms) gives the ω̇ used for the delayed spin and dΔI/dt in the second.
    """
    base = model.shape[0] - INTERIOR_SIZE
    block = model[base:]
    q0, q1, q2, q3 = y[0], y[1], y[2], y[3]
    wx, wy, wz = y[4], y[5], y[6]
    cx, cy, cz = y[7], y[8], y[9]
    _, nx, ny, nz = force_function_and_torque_xyz(t, q0, q1, q2, q3, model)
    row = int(block[IN_EARTH_ROW])
    # Earth → Moon in the mantle frame, and the Earth's pole there (figure–figure torque).
    ex, ey, ez = perturber_position_xyz(t, model, row)
    sx, sy, sz = body_frame_xyz(q0, q1, q2, q3, -ex, -ey, -ez)
    px, py, pz = body_frame_xyz(q0, q1, q2, q3, block[IN_POLE_X], block[IN_POLE_Y], block[IN_POLE_Z])
    hessian = np.empty(6)
    j2_hessian(block, model[row + 1], sx, sy, sz, px, py, pz, hessian)
    core_a, core_c = block[IN_CORE_A], block[IN_CORE_C]
    ncx, ncy, ncz = core_mantle_torque(block, wx, wy, wz, cx, cy, cz)
    delta = np.empty(6)
    rate = np.empty(6)
    total = np.empty(6)
    mantle = np.empty(6)
    ax = ay = az = 0.0
    for _ in range(2):
        _delayed_distortion(t, q0, q1, q2, q3, wx, wy, wz, ax, ay, az, model, block, delta, rate)
        for i in range(6):
            total[i] = delta[i]
        total[0] += model[BODY_A]
        total[1] += model[BODY_B]
        total[2] += model[BODY_C]
        for i in range(6):
            mantle[i] = total[i]
        mantle[0] -= core_a
        mantle[1] -= core_a
        mantle[2] -= core_c
        tx, ty, tz = nx + ncx, ny + ncy, nz + ncz
        for k in range(int(block[IN_DISTORTION_ROWS])):
            r_row = row + k * PERTURBER_ROW
            ix, iy, iz = perturber_position_xyz(t, model, r_row)
            bx, by, bz = body_frame_xyz(q0, q1, q2, q3, ix, iy, iz)
            fx, fy, fz = point_mass_torque(delta, model[r_row + 1], bx, by, bz)
            tx, ty, tz = tx + fx, ty + fy, tz + fz
        if block[IN_EARTH_J2R2] != 0.0:
            fx, fy, fz = figure_figure_torque(total, hessian)
            tx, ty, tz = tx + fx, ty + fy, tz + fz
        lx, ly, lz = symmetric_times(mantle, wx, wy, wz)
        gx, gy, gz = symmetric_times(rate, wx, wy, wz)
        ax, ay, az = symmetric_solve(mantle, tx - gx - (wy * lz - wz * ly), ty - gy - (wz * lx - wx * lz),
                                     tz - gz - (wx * ly - wy * lx))
    kinematics_and_euler_into(y, 0.0, 0.0, 0.0, model, dy)  # q̇ (ω̇ overwritten below)
    dy[4], dy[5], dy[6] = ax, ay, az
    # Core: I_c ω̇_c = −ω × I_c ω_c − N_cmb.
    jx, jy, jz = core_a * cx, core_a * cy, core_c * cz
    dy[7] = (-(wy * jz - wz * jy) - ncx) / core_a
    dy[8] = (-(wz * jx - wx * jz) - ncy) / core_a
    dy[9] = (-(wx * jy - wy * jx) - ncz) / core_c


@jit
def rhs(t, y, model):
    """dy/dt of the state y = (q, ω) at time t: the one definition of the dynamics."""
    dy = np.empty(y.shape[0])
    rhs_into(t, y, model, dy)
    return dy


@jit
def kinetic_energy(y, model):
    """T = ½ ωᵀ I ω (energy)."""
    return 0.5 * (model[BODY_A] * y[4] ** 2 + model[BODY_B] * y[5] ** 2 + model[BODY_C] * y[6] ** 2)


@jit
def total_energy(t, y, model):
    """E = T − U (energy), conserved when the perturbers are at rest."""
    return kinetic_energy(y, model) - force_function(t, y[0:4], model)


@jit
def inertial_angular_momentum(y, model):
    """Angular momentum M(q) I ω in the inertial frame (mass·length²/time)."""
    w, x, yy, z = y[0], y[1], y[2], y[3]
    inv = 1.0 / (w * w + x * x + yy * yy + z * z)
    lx, ly, lz = model[BODY_A] * y[4], model[BODY_B] * y[5], model[BODY_C] * y[6]
    out = np.empty(3)
    out[0] = inv * ((w * w + x * x - yy * yy - z * z) * lx + 2.0 * (x * yy - w * z) * ly + 2.0 * (x * z + w * yy) * lz)
    out[1] = inv * (2.0 * (x * yy + w * z) * lx + (w * w - x * x + yy * yy - z * z) * ly + 2.0 * (yy * z - w * x) * lz)
    out[2] = inv * (2.0 * (x * z - w * yy) * lx + 2.0 * (yy * z + w * x) * ly + (w * w - x * x - yy * yy + z * z) * lz)
    return out


def scipy_rhs(model):
    """A ``fun(t, y)`` for ``scipy.integrate.solve_ivp`` that calls the compiled :func:`rhs`.

    The Python-level call per evaluation is what scipy's solvers cost anyway; the dynamics are the
    same compiled definition the numba integrator uses.
    """

    def fun(t, y):
        return rhs(float(t), np.ascontiguousarray(y, dtype=float), model)

    return fun
