"""The set-up of eight torque-free states at once: their R_F and AGM in one ``<8 x double>`` register.

One state's set-up (:mod:`.flow_constants`) is bound by the square roots and divisions of its
double-double phase constants, its two Carlson R_F and its compensated AGM. Here eight states that
share their moments run the set-up's scalar parts one by one and those three together in one
register (:func:`.phase_constants.phase_constants_lanes`, :func:`.carlson.rf_pair_lanes`,
:func:`.complete_agm.complete_k_pi_lanes`: every lane the scalar result bit for bit): the motion
constants, the phase constants in lanes, the kind of each motion and its integrals' arguments, the
integrals in lanes, then :func:`.flow_constants.set_up_finish` one by one. A block of states
that the lanes cannot take whole (another kind of motion in a lane: the separatrix, an integral the
motion does not need) takes the scalar integrals lane by lane, with the same results.
"""

from spinorbit.core.free_motion.flow_constants import (
    INTEGRALS_SIZE,
    KIND_PERIODIC,
    KIND_UNIFORM,
    ST_AMPLITUDE_COS,
    ST_AMPLITUDE_SIN,
    ST_F_HI,
    ST_F_LO,
    ST_KIND,
    ST_PC_HI,
    ST_PC_LO,
    ST_POLE_X,
    ST_POLE_Y,
    ST_POLE_Z,
    STAGE_SIZE,
    UNIFORM_STAGE,
    integrals_of_state,
    set_up_finish,
    set_up_motion,
    set_up_phase,
)
from spinorbit.core.free_motion.phase_constants import phase_constants_lanes
from spinorbit.core.elements.canonical import MODE_SAM, MODE_UNIFORM, elliptic_constants
from spinorbit.core.jit import INLINE, jit
from spinorbit.core.math.carlson import rf_pair_lanes
from spinorbit.core.math.complete_agm import complete_k_pi_lanes
from spinorbit.core.math.lanes import WIDTH, broadcast, lane_of, load_lanes, store_lanes

BLOCK = WIDTH  # states per block

__all__ = ["BLOCK", "INTEGRALS_SIZE", "STAGE_SIZE", "finish_lane", "set_up_block_start", "integrals_of_block"]


@jit(inline=INLINE)
def set_up_block_start(flows, mos, stages, motions, quaternions, momenta, first, big_a, big_b, big_c, ic, inertia_dd):
    """:func:`.flow_constants.set_up_start` of states first … first + 7 (shared moments) into
    flows[lane], mos[lane] and the columns of ``stages`` (STAGE_SIZE, BLOCK), with the phase constants
    of all eight in lanes (``motions``: a (4, BLOCK) scratch array). True if every lane needs both R_F
    and the AGM (the lanes' integrals), False if any does not."""
    for lane in range(BLOCK):
        i = first + lane
        mode, mx, my, mz = set_up_motion(flows[lane], mos[lane], quaternions[i], momenta[i], big_a, big_b, big_c, ic)
        motions[0, lane], motions[1, lane], motions[2, lane], motions[3, lane] = mode, mx, my, mz
    # a uniform rotation's lanes compute constants nobody reads (no lane's arithmetic raises)
    phases = phase_constants_lanes(load_lanes(motions[0], 0) == MODE_SAM, load_lanes(motions[1], 0),
                                   load_lanes(motions[2], 0), load_lanes(motions[3], 0), inertia_dd)
    all_periodic = True
    for lane in range(BLOCK):
        mode = int(motions[0, lane])
        if mode == MODE_UNIFORM:
            staged = UNIFORM_STAGE
        else:
            staged = set_up_phase(flows[lane], mos[lane], mode, motions[1, lane], motions[2, lane], motions[3, lane],
                                  lane_of(phases, lane), ic)
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


@jit(inline=INLINE)
def finish_lane(flows, mos, stages, integrals, lane, quaternion, momentum, ic):
    """:func:`.flow_constants.set_up_finish` of one lane of the block; returns its (mk, pk)."""
    staged = stages[:, lane]
    if staged[ST_KIND] == KIND_UNIFORM:
        return elliptic_constants(mos[lane])  # unused by a uniform rotation, as in flow_constants_buffers
    values = (integrals[0, lane], integrals[1, lane], integrals[2, lane], integrals[3, lane], integrals[4, lane],
              integrals[5, lane])
    return set_up_finish(flows[lane], mos[lane], quaternion, momentum, ic, staged, values)
