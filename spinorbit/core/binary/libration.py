"""The secondary's rotation read off a binary run: libration angle and Fukushima's canonical elements.

- **Libration angle** φ: the azimuth, in B's equatorial (x, y) plane, of the line from B to A,
  with d = M_Bᵀ(−R): φ = ½ atan2(2 d_x d_y, d_x² − d_y²) ∈ (−π/2, π/2], i.e. modulo π, since the
  ellipsoid's long axis is the same line whichever end faces the primary. In the synchronous state
  φ is the physical libration (0 at exact synchronism).
- **Canonical elements** (S, Z, H, s, z, h) of B's rotation (:func:`spinorbit.core.elements.canonical.
  elements_from_state`, the paper's eq. 4), with B's attitude and body angular momentum I_B ω_B;
  with them the mode (SAM/LAM, i.e. tumbling about the short or long axis) and the torque-free
  periods P_ψ, P_φ of :func:`spinorbit.core.free_motion.summary.motion_summary` (principal axes A ≤ B ≤ C
  of B, as for an ellipsoid with a ≥ b ≥ c on x, y, z).
"""

import math

import numpy as np

from spinorbit.core.binary.equations import M_INERTIA_B, OMEGA_B, POSITION, QUAT_B
from spinorbit.core.elements.canonical import elements_from_state, inertia_constants
from spinorbit.core.free_motion.summary import motion_summary
from spinorbit.core.jit import jit
from spinorbit.core.math.rotations import quat_to_matrix

#: Columns of :func:`secondary_rotation_table`.
(COL_LIBRATION, COL_S, COL_Z, COL_H, COL_SMALL_S, COL_SMALL_Z, COL_SMALL_H, COL_MODE, COL_ENERGY_RATIO,
 COL_P_PSI, COL_P_PHI) = range(11)
ROTATION_COLUMNS = 11


@jit
def libration_angle(y):
    """φ (rad, in (−π/2, π/2]): azimuth of the line to the primary on B's equatorial plane, modulo π."""
    m_b = quat_to_matrix(y[QUAT_B:QUAT_B + 4])
    d = -(m_b.T @ y[POSITION:POSITION + 3])
    return 0.5 * math.atan2(2.0 * d[0] * d[1], d[0] * d[0] - d[1] * d[1])


@jit
def secondary_rotation_table(ys, model):
    """Per row of ys: φ, the canonical elements of B, its mode, E/E0 and the free periods P_ψ, P_φ."""
    a_mom = model[M_INERTIA_B]
    b_mom = model[M_INERTIA_B + 4]
    c_mom = model[M_INERTIA_B + 8]
    ic = inertia_constants(a_mom, b_mom, c_mom)
    out = np.empty((ys.shape[0], ROTATION_COLUMNS))
    for k in range(ys.shape[0]):
        y = ys[k]
        out[k, COL_LIBRATION] = libration_angle(y)
        attitude = quat_to_matrix(y[QUAT_B:QUAT_B + 4]).T.copy()
        momentum = np.array([a_mom * y[OMEGA_B], b_mom * y[OMEGA_B + 1], c_mom * y[OMEGA_B + 2]])
        elements, _, _ = elements_from_state(attitude, momentum, ic)
        for j in range(6):
            out[k, COL_S + j] = elements[j]
        mode, ratio, p_psi, p_phi, _ = motion_summary(momentum[0], momentum[1], momentum[2], a_mom, b_mom, c_mom)
        out[k, COL_MODE] = mode
        out[k, COL_ENERGY_RATIO] = ratio
        out[k, COL_P_PSI] = p_psi
        out[k, COL_P_PHI] = p_phi
    return out
