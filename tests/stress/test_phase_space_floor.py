"""Phase-space sweep against the machine-precision floor of each state (issue 7).

Extends ``test_phase_space.py`` (separatrix gaps ±1e-12 and ±1e-6, f = 1e-12 and 1e12, spin 1e-12 rad
from −C and +A, spin rates 1e±100) and replaces its fixed multiples of ε by a floor measured at each
state:

* **floor of a map** = the change of its output (rotation angle + |ΔM|/G) when each input is moved by
  two ulps (``FLOOR_ULPS``), summed in quadrature, plus ε (the output cannot be better than one rounding of O(1)
  numbers). It is the error the map would show if it were computed exactly from correctly rounded
  inputs, so it is the right yardstick near the singular sets, where the conditioning explodes
  (spin 1e-12 rad from C, or M 1e-12 rad from the reference z axis: L = G cos J and H = G cos I
  cannot resolve J or I below √(2 ulp) ≈ 1.5e-8 rad, so the round trip loses the 1e-12 rad and the
  floor is ~1e-8; a body spherical to 1e-12: the energy interval is 1e-12 wide, one ulp of S moves
  the state by 5e-4 rad). This is why the element integrator turns its reference frame and stops
  near spin about C (``spinorbit.core.integrators.elements.MIN_SIN_J``, ``spinorbit.core.integrators.handover``).
* **round trip** state → canonical elements (eq. 4) → state (eqs. 7–8): within ``ROUND_TRIP_FLOORS``
  floors of the backward map (measured ≤ 0.71 over the sweep).
* **group property** of the exact flow (restart at t1): within ``GROUP_FLOORS`` floors of the flow
  from t1 (measured ≤ 1.2).
"""

import math

import numpy as np
import pytest

from spinorbit.core import torque_free_states
from spinorbit.core.elements.canonical import (
    MODE_UNIFORM,
    elements_from_state,
    inertia_constants,
    state_from_elements,
)
from spinorbit.core.math.rotations import (
    attitude_to_quat,
    quat_to_attitude,
    rotation_angle_between,
)

from .test_phase_space import CASES, Q_GENERIC, nearly_symmetric, separatrix_state

EPS = np.finfo(float).eps
#: The forward map rounds each element (≤ a few ulp), the backward map adds its own roundings: a
#: round trip is about one floor; two leaves room above the measured 0.71.
ROUND_TRIP_FLOORS = 2.0
#: The restart state at t1 is rounded (≤ ½ ulp per input: ≤ ¼ floor), and each of the two flows
#: evaluated adds its own rounding of the order of one floor: two floors (measured ≤ 1.2).
GROUP_FLOORS = 2.0
#: Inputs are moved by two ulps, not one: a computed input can sit an ulp outside the domain of the
#: next map (the forward map may return |H| = Z + 1 ulp at I ≈ 0, which the backward map clips to
#: I = 0), where one ulp inwards would still be clipped and show no sensitivity at all.
FLOOR_ULPS = 2

EXTRA_CASES = [
    *[(f"separatrix gap {g:+.0e}", (1.0, 2.0, 2.5), separatrix_state((1.0, 2.0, 2.5), g)) for g in (1e-12, -1e-12, 1e-6, -1e-6)],
    *[(f"f = {f:.0e}", nearly_symmetric(f), np.array([0.5, 0.4, 0.7])) for f in (1e-12, 1e12)],
    ("spin 1e-12 rad from -C", (1.0, 2.0, 2.5), np.array([0.0, 1e-12, -1.0])),
    ("spin 1e-12 rad from +A", (1.0, 2.0, 2.5), np.array([1.0, 0.0, 1e-12])),
    # symmetric bodies next to the permanent rotation in the equal-moment plane, just above the gap
    # that S and Z resolve (canonical.symmetric_gap_resolved): the round trip degrades like ε d / gap
    # (1.4e-4 rad at 1e-6, 0.18 rad at 1e-7), which is this floor, not a defect of the maps: measured
    # round trip 0.02–0.23 floors, group property of the closed-form flow ≤ 0.54 floors
    *[(f"B = C, spin {x:.0e} from the B-C plane", (0.5, 1.0, 1.0), np.array([0.5 * x, 1.0, 0.0]))
      for x in (1e-3, 1e-6, 1e-7)],
    ("A = B, spin 1e-6 from the A-B plane", (1.0, 1.0, 2.0), np.array([0.6, -0.8, 2e-6])),
    ("slow spin 1e-100", (0.61, 0.965, 1.0), 1e-100 * np.array([0.2, 0.3, 1.0])),
    ("fast spin 1e100", (0.61, 0.965, 1.0), 1e100 * np.array([0.2, 0.3, 1.0])),
]
SWEEP = [c for c in CASES + EXTRA_CASES if c[0] != "sphere"]  # a sphere has no elements and no flow constants


def attitude_near_momentum(momentum, angle_from_z):
    """Scalar-first quaternion whose inertial z axis is ``angle_from_z`` rad from the body momentum."""
    direction = momentum / np.linalg.norm(momentum)
    axis = np.cross(direction, [0.0, 0.0, 1.0])
    angle = math.atan2(np.linalg.norm(axis), direction[2]) - angle_from_z
    axis = axis / np.linalg.norm(axis) if np.linalg.norm(axis) > 0 else np.array([1.0, 0.0, 0.0])
    return np.r_[math.cos(angle / 2), math.sin(angle / 2) * axis]


def quaternion_for(attitude_kind, momentum):
    return Q_GENERIC if attitude_kind == "generic" else attitude_near_momentum(momentum, 1e-12)


def state_distance(q1, m1, q2, m2, scale):
    return rotation_angle_between(q1, q2) + float(np.linalg.norm(m1 - m2)) / scale


def one_ulp_floor(values, evaluate, reference, scale):
    """ε + the quadrature sum over inputs of the output change for ``FLOOR_ULPS`` ulps of that input.

    Both directions are tried and the larger change kept: at a boundary of the domain (H = G at
    I = 0) the ulp outwards is clipped by the map and moves nothing, the ulp inwards moves I by
    √(2 ulp) ≈ 1.5e-8 rad.
    """
    total = 0.0
    for i in range(values.size):
        changes = [0.0]
        for towards in (np.inf, -np.inf):
            moved = values.copy()
            for _ in range(FLOOR_ULPS):
                moved[i] = np.nextafter(moved[i], towards)
            change = state_distance(*evaluate(moved), *reference, scale)
            if math.isfinite(change):  # outside the domain (|H| > G): not a representable state
                changes.append(change)
        total += max(changes) ** 2
    return EPS + math.sqrt(total)


@pytest.mark.parametrize("label, body, momentum", SWEEP, ids=[c[0] for c in SWEEP])
@pytest.mark.parametrize("attitude_kind", ["generic", "momentum 1e-12 rad from z"])
def test_round_trip_through_the_elements_is_at_the_floor(label, body, momentum, attitude_kind):
    ic = inertia_constants(*body)
    q0 = quaternion_for(attitude_kind, momentum)
    elements, flip, mode = elements_from_state(quat_to_attitude(q0), momentum, ic)
    assert mode != MODE_UNIFORM and np.all(np.isfinite(elements))
    scale = float(np.linalg.norm(momentum))

    def backward(el):
        attitude, m = state_from_elements(el, flip, ic)
        return attitude_to_quat(attitude), m

    back = backward(elements)
    floor = one_ulp_floor(elements, backward, back, scale)
    error = state_distance(q0, momentum, *back, scale)
    assert error <= ROUND_TRIP_FLOORS * floor, (error, floor)


@pytest.mark.parametrize("label, body, momentum", SWEEP, ids=[c[0] for c in SWEEP])
@pytest.mark.parametrize("attitude_kind", ["generic", "momentum 1e-12 rad from z"])
def test_group_property_is_at_the_floor(label, body, momentum, attitude_kind):
    q0 = quaternion_for(attitude_kind, momentum)
    rate = np.linalg.norm(momentum / np.array(body))
    t1, t2 = 3.7 / rate, 11.3 / rate
    q, m = torque_free_states(q0, momentum, *body, np.array([t1, t1 + t2]))
    scale = float(np.linalg.norm(momentum))

    def flow(state):
        qq, mm = torque_free_states(state[:4], state[4:], *body, np.array([t2]))
        return qq[0], mm[0]

    restart = np.r_[q[0], m[0]]
    again = flow(restart)
    floor = one_ulp_floor(restart, flow, again, scale)
    error = state_distance(q[1], m[1], *again, scale)
    assert error <= GROUP_FLOORS * floor, (error, floor)
