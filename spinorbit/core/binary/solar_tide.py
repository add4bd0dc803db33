"""The Sun's degree-2 tide on a binary whose barycentre follows a Keplerian heliocentric orbit.

With s the Sun's position relative to the binary's barycentre (inertial axes, a
:func:`spinorbit.core.model.perturbers.kepler_source` with ``sign=-1`` built from the barycentre's
heliocentric elements), r_A = −(m_B/M) R and r_B = (m_A/M) R the two centres of mass and μ = G M_sun:

- the tidal acceleration of the relative orbit is the degree-2 term of the difference of the Sun's
  point-mass accelerations on B and on A, a = μ/|s|³ (3 ŝ (ŝ·R) − R); the next term is smaller by
  ~|R|/|s| (1e-8 for Didymos at 1 au);
- the torque on each body is the degree-2 (MacCullagh) gravity-gradient torque of a point mass at
  d_X = s − r_X, on the body's axes: N_X = (3μ/|d|⁵) d × (I_X d), d = M_Xᵀ d_X (``core/model/
  gravity_field.py``, ``degree2_torque_closed_form``, written for a full inertia tensor).

The barycentre's orbit is prescribed: the binary's reaction on it (its figure's pull on the Sun) is
not fed back, and neither is the tide's degree-3 part. Energy and angular momentum of the pair are no
longer conserved; the power of the tide, ν Ṙ·a + ω_A·N_A + ω_B·N_B (:func:`spinorbit.core.binary.equations.tide_power`), is their rate.
"""

import math

from spinorbit.core.jit import jit
from spinorbit.core.model.perturbers import kepler_position_xyz


@jit(inline="always")
def tidal_acceleration_xyz(mu, sx, sy, sz, rx, ry, rz):
    """a = μ/|s|³ (3 ŝ (ŝ·R) − R): the degree-2 solar tide on the relative position R (inertial)."""
    s2 = sx * sx + sy * sy + sz * sz
    k = mu / (s2 * math.sqrt(s2))
    projection = 3.0 * (sx * rx + sy * ry + sz * rz) / s2
    return k * (projection * sx - rx), k * (projection * sy - ry), k * (projection * sz - rz)


@jit(inline="always")
def gravity_gradient_torque_xyz(mu, dx, dy, dz, matrix, inertia, offset):
    """N = (3μ/|d|⁵) d × (I d) on the body's axes, d the point mass's position on the body's axes.

    ``dx, dy, dz`` are inertial; ``matrix`` is the body → inertial matrix as a row-major 9-tuple; the
    body's inertia tensor is row-major at ``inertia[offset:offset + 9]``.
    """
    bx = matrix[0] * dx + matrix[3] * dy + matrix[6] * dz
    by = matrix[1] * dx + matrix[4] * dy + matrix[7] * dz
    bz = matrix[2] * dx + matrix[5] * dy + matrix[8] * dz
    ix = inertia[offset] * bx + inertia[offset + 1] * by + inertia[offset + 2] * bz
    iy = inertia[offset + 3] * bx + inertia[offset + 4] * by + inertia[offset + 5] * bz
    iz = inertia[offset + 6] * bx + inertia[offset + 7] * by + inertia[offset + 8] * bz
    d2 = bx * bx + by * by + bz * bz
    k = 3.0 * mu / (d2 * d2 * math.sqrt(d2))
    return k * (by * iz - bz * iy), k * (bz * ix - bx * iz), k * (bx * iy - by * ix)


@jit(inline="always")
def sun_position_xyz(t, block, offset):
    """The Sun relative to the barycentre at t from the Kepler parameter row at block[offset:]."""
    return kepler_position_xyz(t, block, offset)
