"""The set-up of eight torque-free states at once: their R_F and AGM in one ``<8 x double>`` register.

One state's set-up (:mod:`.flow_constants`) is bound by the square roots and divisions of its
double-double phase constants, its two Carlson R_F and its compensated AGM. Here eight states that
share their moments run the set-up's scalar parts one by one and those three together in one
register (:func:`.phase_constants.phase_constants_lanes`, :func:`.carlson.rf_pair_lanes`,
:func:`.complete_agm.complete_k_pi_lanes`: every lane the scalar result bit for bit): the motion
constants in lanes (each lane's mode and flip chosen alone), the phase constants in lanes, the kind
of each motion and its integrals' arguments, the integrals in lanes, the node frames' arithmetic in lanes, then each lane's atan2 and
:func:`.flow_constants.set_up_finish` one by one. A block of states
that the lanes cannot take whole (another kind of motion in a lane: the separatrix, an integral the
motion does not need) takes the scalar integrals lane by lane, with the same results.
"""

import math

from spinorbit.core.elements.canonical import (
    MO_ARG_PER_S,
    MO_COS_L_W,
    MO_D,
    MO_G,
    MO_G_PER_S,
    MO_MODE,
    MO_PARAM,
    MO_PARAM_C,
    MO_PN_COEFF,
    MO_PN_N,
    MO_S,
    MO_S_RATE,
    MO_SIN_L_W,
    MO_X_AMP,
    MO_Y_AMP,
    MO_Z_AMP,
    MODE_SAM,
    MODE_UNIFORM,
    choose_flip,
    elliptic_constants,
    energy_differences,
    motion_lam_terms,
    motion_sam_terms,
    motion_shared_terms,
)
from spinorbit.core.free_motion.flow_constants import (
    FL_FLIP_X,
    FL_FLIP_Y,
    FL_FLIP_Z,
    INTEGRALS_SIZE,
    KIND_PERIODIC,
    KIND_UNIFORM,
    ST_AMPLITUDE_COS,
    ST_AMPLITUDE_SIN,
    ST_F_HI,
    ST_F_LO,
    ST_KIND,
    ST_MX,
    ST_MY,
    ST_PC_HI,
    ST_PC_LO,
    ST_POLE_X,
    ST_POLE_Y,
    ST_POLE_Z,
    STAGE_SIZE,
    UNIFORM_STAGE,
    integrals_of_state,
    set_up_finish,
    motion_into_flow,
    set_up_phase,
)
from spinorbit.core.free_motion.node_frame import node_arguments, node_of_state, node_quaternion, node_rotations
from spinorbit.core.free_motion.phase_constants import phase_constants_lanes
from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.carlson import rf_pair_lanes
from spinorbit.core.math.complete_agm import complete_k_pi_lanes
from spinorbit.core.math.lanes import WIDTH, broadcast, lane_of, load_lanes, select, select_tuple, store_lanes

BLOCK = WIDTH  # states per block

__all__ = ["BLOCK", "MOTION_SIZE", "NODE_SIZE", "finish_lane", "integrals_of_block", "nodes_of_block",
           "set_up_block_start"]


# Rows of the block's motion scratch (one per quantity, contiguous across lanes): the body momenta, the
# energy differences, mode and flip, the motion constants formed in lanes, the working-frame momenta.
(MOTION_M0_X, MOTION_M0_Y, MOTION_M0_Z, MOTION_G, MOTION_D_C, MOTION_A_D, MOTION_B_D, MOTION_MODE, MOTION_FLIP,
 MOTION_MX, MOTION_MY, MOTION_MZ, MOTION_TERMS) = range(13)
MOTION_TERM_COUNT = 14  # the MO_* values motion_constants_into forms past MO_MODE and MO_G, in MOTION_TERM_SLOTS order
MOTION_TERM_SLOTS = (MO_D, MO_S, MO_S_RATE, MO_G_PER_S, MO_X_AMP, MO_PARAM, MO_PARAM_C, MO_ARG_PER_S, MO_PN_COEFF,
                     MO_PN_N, MO_Y_AMP, MO_Z_AMP, MO_SIN_L_W, MO_COS_L_W)
MOTION_SIZE = MOTION_TERMS + MOTION_TERM_COUNT


@jit(inline=INLINE)
def set_up_block_start(flows, mos, stages, motions, quaternions, momenta, first, big_a, big_b, big_c, ic, inertia_dd):
    """:func:`.flow_constants.set_up_start` of states first … first + 7 (shared moments) into
    flows[lane], mos[lane] and the columns of ``stages`` (STAGE_SIZE, BLOCK), with the motion and the
    phase constants of all eight in lanes (``motions``: a (MOTION_SIZE, BLOCK) scratch array). True if
    every lane needs both R_F and the AGM (the lanes' integrals), False if any does not."""
    a, _b, c, a_b, b_c, a_c = ic
    for lane in range(BLOCK):
        i = first + lane
        motions[MOTION_M0_X, lane], motions[MOTION_M0_Y, lane] = momenta[i, 0], momenta[i, 1]
        motions[MOTION_M0_Z, lane] = momenta[i, 2]
    # canonical.motion_from_momentum_into in lanes: the energy differences, then each lane's mode and
    # flip (branches), then the motion constants with each lane keeping its mode's terms
    g2, d_c, a_d, b_d = energy_differences(load_lanes(motions[MOTION_M0_X], 0), load_lanes(motions[MOTION_M0_Y], 0),
                                           load_lanes(motions[MOTION_M0_Z], 0), a_b, b_c, a_c)
    big_g = math.sqrt(g2)
    store_lanes(motions[MOTION_G], 0, big_g)
    store_lanes(motions[MOTION_D_C], 0, d_c)
    store_lanes(motions[MOTION_A_D], 0, a_d)
    store_lanes(motions[MOTION_B_D], 0, b_d)
    for lane in range(BLOCK):
        motions[MOTION_MODE, lane], motions[MOTION_FLIP, lane] = choose_flip(
            motions[MOTION_M0_X, lane], motions[MOTION_M0_Z, lane], motions[MOTION_B_D, lane], a_b, b_c)
    shared = motion_shared_terms(big_g, d_c, a_d, a, c, a_c)
    sqrt_ad = shared[5]
    terms = select_tuple(load_lanes(motions[MOTION_MODE], 0) == MODE_SAM,
                         motion_sam_terms(big_g, d_c, a_d, b_d, a_b, b_c, a_c, sqrt_ad),
                         motion_lam_terms(big_g, d_c, a_d, b_d, a_b, b_c, a_c, sqrt_ad))
    for k in range(5):
        store_lanes(motions[MOTION_TERMS + k], 0, shared[k])
    for k in range(9):
        store_lanes(motions[MOTION_TERMS + 5 + k], 0, terms[k])
    for lane in range(BLOCK):
        i, mo = first + lane, mos[lane]
        mode = motions[MOTION_MODE, lane]
        mo[:] = 0.0
        mo[MO_MODE], mo[MO_G] = mode, motions[MOTION_G, lane]
        if mode != MODE_UNIFORM:
            for k in range(MOTION_TERM_COUNT):
                mo[MOTION_TERM_SLOTS[k]] = motions[MOTION_TERMS + k, lane]
        motions[MOTION_MODE, lane], motions[MOTION_MX, lane], motions[MOTION_MY, lane], motions[MOTION_MZ, lane] = \
            motion_into_flow(flows[lane], mo, quaternions[i], momenta[i], int(motions[MOTION_FLIP, lane]), big_a,
                             big_b, big_c)
    # a uniform rotation's lanes compute constants nobody reads (no lane's arithmetic raises)
    phases = phase_constants_lanes(load_lanes(motions[MOTION_MODE], 0) == MODE_SAM, load_lanes(motions[MOTION_MX], 0),
                                   load_lanes(motions[MOTION_MY], 0), load_lanes(motions[MOTION_MZ], 0), inertia_dd)
    all_periodic = True
    for lane in range(BLOCK):
        mode = int(motions[MOTION_MODE, lane])
        if mode == MODE_UNIFORM:
            staged = UNIFORM_STAGE
        else:
            staged = set_up_phase(flows[lane], mos[lane], mode, motions[MOTION_MX, lane], motions[MOTION_MY, lane],
                                  motions[MOTION_MZ, lane], lane_of(phases, lane), ic)
        for k in range(STAGE_SIZE):
            stages[k, lane] = staged[k]
        all_periodic = all_periodic and staged[ST_KIND] == KIND_PERIODIC
    return all_periodic


@jit(inline=INLINE)
def integrals_of_block(stages, integrals, all_periodic):
    """The integrals of the block's eight states into the columns of ``integrals`` (INTEGRALS_SIZE, BLOCK):
    in eight lanes where every state needs them all, else :func:`.flow_constants.integrals_of_state` lane by lane."""
    if not all_periodic:
        for lane in range(BLOCK):
            values = integrals_of_state(stages[:, lane])
            for k in range(INTEGRALS_SIZE):
                integrals[k, lane] = values[k]
        return
    c = load_lanes(stages[ST_AMPLITUDE_COS], 0)
    s = load_lanes(stages[ST_AMPLITUDE_SIN], 0)
    pc = load_lanes(stages[ST_PC_HI], 0)
    rf_am, rf_pole = rf_pair_lanes(c * c, c * c + pc * (s * s), broadcast(1.0), load_lanes(stages[ST_POLE_X], 0),
                                   load_lanes(stages[ST_POLE_Y], 0), load_lanes(stages[ST_POLE_Z], 0))
    kh, kl, pih, pil = complete_k_pi_lanes(load_lanes(stages[ST_F_HI], 0), load_lanes(stages[ST_F_LO], 0), pc,
                                           load_lanes(stages[ST_PC_LO], 0))
    store_lanes(integrals[0], 0, rf_am)
    store_lanes(integrals[1], 0, rf_pole)
    store_lanes(integrals[2], 0, kh)
    store_lanes(integrals[3], 0, kl)
    store_lanes(integrals[4], 0, pih)
    store_lanes(integrals[5], 0, pil)


# The block's node frames: the inputs gathered into rows (one per quantity, contiguous across lanes) and
# what node_rotations and node_arguments give for each lane, with whether the lane is regular.
(NODE_W, NODE_X, NODE_Y, NODE_Z, NODE_M0_X, NODE_M0_Y, NODE_M0_Z, NODE_FLIP_X, NODE_FLIP_Y,
 NODE_G_Y, NODE_G_X, NODE_COS_I, NODE_SIN_I, NODE_SIN_H, NODE_COS_H, NODE_REGULAR) = range(16)
NODE_SIZE = 16


@jit(inline=INLINE)
def nodes_of_block(flows, stages, nodes, quaternions, momenta, first):
    """The regular case of :func:`.node_frame.node_of_state` (J ≠ 0, I ≠ 0) for the block's eight
    states in lanes, into the columns of ``nodes`` (NODE_SIZE, BLOCK); each lane's atan2 and node
    quaternion are :func:`finish_lane`'s (a lane that is not regular takes the scalar function there)."""
    for lane in range(BLOCK):
        i = first + lane
        nodes[NODE_W, lane], nodes[NODE_X, lane] = quaternions[i, 0], quaternions[i, 1]
        nodes[NODE_Y, lane], nodes[NODE_Z, lane] = quaternions[i, 2], quaternions[i, 3]
        nodes[NODE_M0_X, lane], nodes[NODE_M0_Y, lane], nodes[NODE_M0_Z, lane] = momenta[i, 0], momenta[i, 1], momenta[i, 2]
        nodes[NODE_FLIP_X, lane], nodes[NODE_FLIP_Y, lane] = flows[lane, FL_FLIP_X], flows[lane, FL_FLIP_Y]
    mx, my = load_lanes(stages[ST_MX], 0), load_lanes(stages[ST_MY], 0)
    perp2 = mx * mx + my * my
    inv = 1.0 / math.sqrt(perp2)
    i0, i1, big_h, r0, r1, r2, inv_g, across = node_rotations(
        load_lanes(nodes[NODE_W], 0), load_lanes(nodes[NODE_X], 0), load_lanes(nodes[NODE_Y], 0),
        load_lanes(nodes[NODE_Z], 0), load_lanes(nodes[NODE_M0_X], 0), load_lanes(nodes[NODE_M0_Y], 0),
        load_lanes(nodes[NODE_M0_Z], 0), load_lanes(nodes[NODE_FLIP_X], 0), load_lanes(nodes[NODE_FLIP_Y], 0),
        mx * inv, my * inv)
    inv = 1.0 / across
    sh, ch = i0 * inv, -i1 * inv
    g_y, g_x, cos_i, sin_i = node_arguments(big_h, r0, r1, r2, inv_g, across, sh, ch)
    store_lanes(nodes[NODE_G_Y], 0, g_y)
    store_lanes(nodes[NODE_G_X], 0, g_x)
    store_lanes(nodes[NODE_COS_I], 0, cos_i)
    store_lanes(nodes[NODE_SIN_I], 0, sin_i)
    store_lanes(nodes[NODE_SIN_H], 0, sh)
    store_lanes(nodes[NODE_COS_H], 0, ch)
    store_lanes(nodes[NODE_REGULAR], 0, select((perp2 > 0.0) & (across > 0.0), 1.0, 0.0))


@jit(inline=INLINE)
def finish_lane(flows, mos, stages, integrals, nodes, lane, quaternion, momentum, ic):
    """:func:`.flow_constants.set_up_finish` of one lane of the block; returns its (mk, pk)."""
    staged = stages[:, lane]
    if staged[ST_KIND] == KIND_UNIFORM:
        return elliptic_constants(mos[lane])  # unused by a uniform rotation, as in flow_constants_buffers
    if nodes[NODE_REGULAR, lane] > 0.0:
        g0 = math.atan2(nodes[NODE_G_Y, lane], nodes[NODE_G_X, lane])
        qn = node_quaternion(nodes[NODE_COS_I, lane], nodes[NODE_SIN_I, lane], nodes[NODE_SIN_H, lane],
                             nodes[NODE_COS_H, lane])
    else:
        g0, qn = node_of_state(quaternion, momentum[0], momentum[1], momentum[2], flows[lane, FL_FLIP_X],
                               flows[lane, FL_FLIP_Y], flows[lane, FL_FLIP_Z], staged[ST_MX], staged[ST_MY])
    values = (integrals[0, lane], integrals[1, lane], integrals[2, lane], integrals[3, lane], integrals[4, lane],
              integrals[5, lane])
    return set_up_finish(flows[lane], mos[lane], ic, staged, values, g0, qn)
