"""hypothesis fuzzing of the public constructors and converters (issue 7, "Bad input").

Every input, however wild (NaN, inf, huge, tiny, wrong length), must end in one of two ways: a valid
object whose invariants hold, or the documented exception (InvalidBodyError, InvalidStateError,
TypeError, SingularElementsError). Any other exception — ZeroDivisionError, LinAlgError, an
IndexError from deep inside — is a bug this file is meant to find. Valid states also go through
the public round trips (Euler angles, Andoyer variables, canonical elements).
"""

import math

import numpy as np
import pytest
from hypothesis import assume, given
from hypothesis import strategies as st

from spinorbit import RigidBody, RotationState
from spinorbit.body import InvalidBodyError
from spinorbit.core import SingularElementsError
from spinorbit.core.rotations import euler313_to_attitude
from spinorbit.state import ANDOYER_G_RANGE, InvalidStateError

#: Any float, including NaN, ±inf, subnormals and ±1e308.
wild = st.floats(allow_nan=True, allow_infinity=True)
moderate = st.floats(-1e3, 1e3)
positive = st.floats(1e-3, 1e3)
#: Rotation-matrix orthonormality of a valid state (rounding of a 3×3 product, a few ulp).
ORTHONORMAL_TOLERANCE = 1e-14


def physical_moments():
    return st.tuples(positive, positive, positive).filter(lambda m: sum(m) >= 2 * max(m) * (1 + 1e-9))


@given(st.lists(wild, min_size=0, max_size=5))
def test_rigid_body_from_anything_is_valid_or_refused(values):
    try:
        body = RigidBody(values)
    except InvalidBodyError:
        return
    moments = np.array(body.principal_moments)
    assert moments.shape == (3,) and np.all(np.isfinite(moments)) and np.all(moments > 0)
    assert np.all(np.diff(moments) >= 0)
    assert moments[0] + moments[1] >= moments[2] * (1 - 1e-12)


@given(physical_moments(), st.lists(wild, min_size=4, max_size=4), st.lists(wild, min_size=3, max_size=3))
def test_rotation_state_from_anything_is_valid_or_refused(moments, q, omega):
    try:
        state = RotationState(RigidBody(moments), q, omega)
    except InvalidStateError:
        return
    assert abs(np.linalg.norm(state.quaternion) - 1.0) < 1e-15 * 4
    assert np.all(np.isfinite(state.angular_velocity.value))


@given(physical_moments(), st.lists(st.lists(wild, min_size=3, max_size=3), min_size=3, max_size=3))
def test_from_matrix_accepts_only_rotations(moments, rows):
    try:
        state = RotationState.from_matrix(RigidBody(moments), rows, [0.1, 0.2, 0.3])
    except InvalidStateError:
        return
    r = state.attitude_matrix
    assert np.abs(r @ r.T - np.eye(3)).max() < ORTHONORMAL_TOLERANCE * 10
    assert np.abs(r - np.array(rows)).max() < 1e-6  # accepted means: it already was a rotation


@given(physical_moments(), moderate, moderate, moderate, st.tuples(moderate, moderate, moderate))
def test_euler313_round_trip(moments, phi, theta, psi, omega):
    state = RotationState.from_euler313(RigidBody(moments), phi, theta, psi, list(omega))
    assert np.abs(state.attitude_matrix - euler313_to_attitude(phi, theta, psi)).max() < 1e-14


@given(physical_moments(), wild, wild, wild, moderate, moderate, moderate)
def test_from_andoyer_keeps_the_momentum_invariants(moments, big_l, big_g, big_h, l, g, h):
    body = RigidBody(moments)
    try:
        state = RotationState.from_andoyer(body, big_l, big_g, big_h, l, g, h)
    except InvalidStateError:
        assert not (math.isfinite(big_l) and math.isfinite(big_h) and ANDOYER_G_RANGE[0] <= big_g <= ANDOYER_G_RANGE[1]
                    and abs(big_l) <= big_g and abs(big_h) <= big_g)
        return
    back = state.andoyer_variables(reference="inertial")
    # G, L, H are momentum components (well conditioned): recovered to rounding of |M| = G.
    assert abs(back[1] - big_g) <= 1e-13 * big_g
    assert abs(back[0] - big_l) <= 1e-13 * big_g
    assert abs(back[2] - big_h) <= 1e-13 * big_g


def _near_symmetric_permanent_rotation(moments, omega, fraction=1e-3):
    """A body with two equal moments spinning within ``fraction`` of its equal-moment plane.

    The known defect of the canonical maps recorded by the strict xfail below (found by this fuzzing;
    e.g. moments (724, 1, 724), ω = (0, 3e-4, 709) maps back to a non-finite attitude): excluded here
    so the fuzzing keeps testing everything else, and kept visible by the xfail until it is fixed.
    """
    m, w = np.asarray(moments, float), np.asarray(omega, float)
    for unique in range(3):
        others = [i for i in range(3) if i != unique]
        if abs(m[others[0]] - m[others[1]]) <= 1e-12 * m.max():
            return abs(w[unique]) < fraction * np.linalg.norm(w)
    return False


@given(physical_moments(), st.lists(st.floats(-1, 1), min_size=4, max_size=4), st.tuples(moderate, moderate, moderate))
def test_canonical_elements_round_trip_or_singular(moments, q, omega):
    assume(np.linalg.norm(q) > 0.1 and np.linalg.norm(omega) > 1e-3)
    assume(not _near_symmetric_permanent_rotation(moments, omega))
    body = RigidBody(moments)
    state = RotationState(body, np.array(q) / np.linalg.norm(q), list(omega))
    try:
        elements = state.canonical_elements()
    except SingularElementsError:  # permanent rotations, exact separatrix arcs: documented
        return
    # |s| ~ 1/(distance to a permanent rotation): beyond 1e12 the double s cannot place the phase to
    # better than ~1e-4 rad (docs/design.md, conditioning); that set is the xfail test below.
    assume(abs(elements.s) < 1e12)
    back = RotationState.from_canonical_elements(body, elements)
    # Away from the singular sets the round trip holds to ~1e-13 (tests/test_canonical.py measures the
    # conditioning near them); random draws land near them rarely, so only sanity is demanded here.
    assert np.all(np.isfinite(back.attitude_matrix)) and np.all(np.isfinite(back.angular_velocity.value))
    assert np.abs(back.attitude_matrix @ back.attitude_matrix.T - np.eye(3)).max() < 1e-13
    kinetic = [float(np.dot(s.angular_velocity.value * np.array(body.moments), s.angular_velocity.value))
               for s in (state, back)]
    assert abs(kinetic[1] - kinetic[0]) <= 1e-9 * kinetic[0]


@pytest.mark.xfail(strict=True, raises=InvalidStateError, reason=(
    "found by the fuzzing above, not fixed here (core canonical maps): a symmetric body (B = C) spinning "
    "within 1e-100 rad/day of its equal-moment plane gets finite elements (s = 4e100) that map back to a "
    "non-finite attitude; should raise SingularElementsError like the exact permanent rotation does"))
def test_elements_next_to_a_symmetric_permanent_rotation_map_back_or_raise():
    body = RigidBody((1.0, 1.0, 0.5))
    state = RotationState(body, [0.0, 0.0, 0.0, 1.0], [1.0, 0.0, 1e-100])
    try:
        elements = state.canonical_elements()
    except SingularElementsError:
        return
    back = RotationState.from_canonical_elements(body, elements)
    assert np.all(np.isfinite(back.attitude_matrix))
