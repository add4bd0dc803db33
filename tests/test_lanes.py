"""Eight states in one register (spinorbit.core.math.lanes): every lane is the scalar kernel, bit for bit.

The lane forms promise more than closeness: each lane performs the scalar code's IEEE operations in
the scalar code's order, so the tests compare with ``==`` (``assert_array_equal``, NaN equal to NaN),
over inputs spread across the kernels' whole domains, edge values included. Accuracy itself is the
scalar kernels' and is tested against mpmath and heyoka elsewhere (tests/test_torque_free.py,
tests/test_special_integrals.py).
"""

import math

import numpy as np
import pytest

from spinorbit.core.elements.canonical import MODE_LAM, MODE_SAM
from spinorbit.core.free_motion.flow import torque_free_states, torque_free_states_many
from spinorbit.core.free_motion.phase_constants import moment_constants, phase_constants_dd, phase_constants_lanes
from spinorbit.core.jit import jit
from spinorbit.core.math.carlson import rf, rf_pair_lanes
from spinorbit.core.math.complete_agm import complete_k_pi_dd, complete_k_pi_lanes
from spinorbit.core.math.ddouble import dd_sqrt, dd_sqrt_lanes, fma, parity
from spinorbit.core.math.lanes import (
    QUAD_WIDTH,
    WIDTH,
    lane_of,
    load_broadcast_quad,
    load_lanes,
    load_quad,
    quad,
    quad_lane,
    quad_shuffle,
    select,
    store_lanes,
    store_quad,
)

EDGES = np.array([0.0, -0.0, 1.0, -1.0, 0.5, 3.0, 1e-310, 1e300, math.inf, -math.inf, math.nan, 2.0**-52])


@jit(cache=False)
def _arithmetic_lanes(x, y, z, out):
    for start in range(0, x.shape[0], WIDTH):
        a, b, c = load_lanes(x, start), load_lanes(y, start), load_lanes(z, start)
        store_lanes(out[0], start, a + b)
        store_lanes(out[1], start, a - b)
        store_lanes(out[2], start, a * b)
        store_lanes(out[3], start, a / b)
        store_lanes(out[4], start, math.sqrt(a))
        store_lanes(out[5], start, fma(a, b, c))
        store_lanes(out[6], start, abs(-a))
        store_lanes(out[7], start, 2.5 * a - b / 3.0)
        store_lanes(out[8], start, select(a <= b, a, b))
        store_lanes(out[9], start, select(a == b, 1.0, select(a > b, 2.0, 0.0)))
        store_lanes(out[10], start, max(a, b, c))


@jit(cache=False)
def _arithmetic_scalar(x, y, z, out):
    for i in range(x.shape[0]):
        a, b, c = x[i], y[i], z[i]
        out[0, i], out[1, i], out[2, i], out[3, i] = a + b, a - b, a * b, a / b
        out[4, i], out[5, i], out[6, i] = math.sqrt(a), fma(a, b, c), abs(-a)
        out[7, i] = 2.5 * a - b / 3.0
        out[8, i] = a if a <= b else b
        out[9, i] = 1.0 if a == b else (2.0 if a > b else 0.0)
        out[10, i] = max(a, b, c)


def test_lane_arithmetic_is_the_scalar_arithmetic():
    rng = np.random.default_rng(1)
    n = 8 * 400
    with np.errstate(all="ignore"):  # inf · 0 among the edge values
        x, y, z = (rng.choice(EDGES, n) * np.where(rng.random(n) < 0.5, 1.0, rng.lognormal(0.0, 30.0, n))
                   for _ in range(3))
    lanes, scalar = np.full((11, n), 7.0), np.full((11, n), -7.0)
    _arithmetic_lanes(x, y, z, lanes)
    _arithmetic_scalar(x, y, z, scalar)
    np.testing.assert_array_equal(lanes, scalar)
    # signed zeros too (assert_array_equal takes -0.0 == 0.0)
    np.testing.assert_array_equal(np.signbit(lanes), np.signbit(scalar))


_REVERSED_WITH_ZERO = quad_shuffle((3, 2, 1, 4))


@jit(cache=False)
def _arithmetic_quads(x, y, z, out):
    for start in range(0, x.shape[0], QUAD_WIDTH):
        a, b, c = load_quad(x, start), load_quad(y, start), load_quad(z, start)
        store_quad(out[0], start, a + b)
        store_quad(out[1], start, a - b)
        store_quad(out[2], start, a * b)
        store_quad(out[3], start, a / b)
        store_quad(out[4], start, fma(a, b, c))
        store_quad(out[5], start, -a * 2.5 + b / 3.0)
        store_quad(out[6], start, _REVERSED_WITH_ZERO(a))
        store_quad(out[7], start, fma(load_broadcast_quad(y, start + 1), a, c))
        packed = quad(quad_lane(a, 0), quad_lane(b, 1), quad_lane(c, 2), quad_lane(a, 3))
        store_quad(out[8], start, packed)


@jit(cache=False)
def _arithmetic_quads_scalar(x, y, z, out):
    for start in range(0, x.shape[0], QUAD_WIDTH):
        for lane in range(QUAD_WIDTH):
            i = start + lane
            a, b, c = x[i], y[i], z[i]
            out[0, i], out[1, i], out[2, i], out[3, i] = a + b, a - b, a * b, a / b
            out[4, i], out[5, i] = fma(a, b, c), -a * 2.5 + b / 3.0
            out[6, i] = x[start + 3 - lane] if lane < 3 else 0.0
            out[7, i] = fma(y[start + 1], a, c)
            out[8, i] = (x[i], y[i], z[i], x[i])[lane]


def test_quad_arithmetic_is_the_scalar_arithmetic():
    """Quad (four doubles): arithmetic, fma, shuffles with zeros, lanes, loads, stores and broadcasts per lane."""
    rng = np.random.default_rng(2)
    n = 4 * 400
    with np.errstate(all="ignore"):
        x, y, z = (rng.choice(EDGES, n) * np.where(rng.random(n) < 0.5, 1.0, rng.lognormal(0.0, 30.0, n))
                   for _ in range(3))
    quads, scalar = np.full((9, n), 7.0), np.full((9, n), -7.0)
    _arithmetic_quads(x, y, z, quads)
    _arithmetic_quads_scalar(x, y, z, scalar)
    np.testing.assert_array_equal(quads, scalar)
    np.testing.assert_array_equal(np.signbit(quads), np.signbit(scalar))


def test_a_quad_shuffle_takes_only_lanes_or_zero():
    with pytest.raises(ValueError, match="four lanes in 0..4"):
        quad_shuffle((0, 1, 2))
    with pytest.raises(ValueError, match="four lanes in 0..4"):
        quad_shuffle((0, 1, 2, 5))


@jit(cache=False)
def _integrals_both(columns, scalar, lanes):
    for i in range(columns.shape[1]):
        c = columns[:, i]
        scalar[0, i], scalar[1, i], scalar[2, i], scalar[3, i] = complete_k_pi_dd(c[0], c[1], c[2], c[3])
        scalar[4, i], scalar[5, i] = rf(c[4], c[5], c[6]), rf(c[7], c[8], c[9])
        scalar[6, i], scalar[7, i] = dd_sqrt(c[2], c[3])
    for start in range(0, columns.shape[1], WIDTH):
        k_pi = complete_k_pi_lanes(load_lanes(columns[0], start), load_lanes(columns[1], start),
                                   load_lanes(columns[2], start), load_lanes(columns[3], start))
        pair = rf_pair_lanes(load_lanes(columns[4], start), load_lanes(columns[5], start), load_lanes(columns[6], start),
                             load_lanes(columns[7], start), load_lanes(columns[8], start), load_lanes(columns[9], start))
        root = dd_sqrt_lanes(load_lanes(columns[2], start), load_lanes(columns[3], start))
        for k in range(4):
            store_lanes(lanes[k], start, k_pi[k])
        store_lanes(lanes[4], start, pair[0])
        store_lanes(lanes[5], start, pair[1])
        store_lanes(lanes[6], start, root[0])
        store_lanes(lanes[7], start, root[1])


def test_integrals_in_lanes_are_the_scalar_integrals():
    # the AGM over f = −n from 0 to 1e30 and p_c from 1e-16 to 1 (its tested domain), each lane stopping
    # after its own number of steps; R_F over 40 decades with zeros; dd_sqrt with zeros
    rng = np.random.default_rng(2)
    n = 8 * 500
    f = np.where(rng.random(n) < 0.15, 0.0, 10.0 ** rng.uniform(-8.0, 30.0, n))
    pc = 10.0 ** rng.uniform(-16.0, 0.0, n)
    rf_args = 10.0 ** rng.uniform(-20.0, 20.0, (6, n))
    rf_args[2, ::5] = 0.0
    rf_args[3, 1::7] = 0.0
    columns = np.vstack([f, f * 1e-17 * rng.normal(size=n), pc, pc * 1e-17 * rng.normal(size=n), rf_args])
    columns[2, ::9] = 0.0  # √0 in dd_sqrt (the AGM lanes there are the scalar NaNs)
    scalar, lanes = np.empty((8, n)), np.empty((8, n))
    _integrals_both(columns, scalar, lanes)
    np.testing.assert_array_equal(lanes, scalar)


@jit(cache=False)
def _phase_both(modes, momenta, inertia_dd, scalar, lanes):
    for i in range(modes.shape[0]):
        scalar[i] = phase_constants_dd(int(modes[i]), momenta[0, i], momenta[1, i], momenta[2, i], inertia_dd)
    for start in range(0, modes.shape[0], WIDTH):
        values = phase_constants_lanes(load_lanes(modes, start) == MODE_SAM, load_lanes(momenta[0], start),
                                       load_lanes(momenta[1], start), load_lanes(momenta[2], start), inertia_dd)
        for lane in range(WIDTH):
            one_lane = lane_of(values, lane)
            for k in range(11):
                lanes[start + lane, k] = one_lane[k]


@pytest.mark.parametrize("moments", [(0.61, 0.965, 1.0), (2.0 / 3.0, 1.0, 2.0), (1.0, 1.0 + 1e-12, 3.0)])
def test_phase_constants_in_lanes_are_the_scalar_ones(moments):
    # SAM and LAM lanes mixed in every block, momenta over ten decades
    rng = np.random.default_rng(3)
    n = 8 * 200
    modes = rng.choice([float(MODE_SAM), float(MODE_LAM)], n)
    momenta = rng.normal(size=(3, n)) * 10.0 ** rng.uniform(-5.0, 5.0, n)
    _, inertia_dd = moment_constants(*moments)
    scalar, lanes = np.empty((n, 11)), np.empty((n, 11))
    _phase_both(modes, momenta, inertia_dd, scalar, lanes)
    np.testing.assert_array_equal(lanes, scalar)


def test_parity_is_the_remainder_of_two():
    values = np.concatenate([np.arange(-1000.0, 1001.0), [2.0**52, 2.0**52 + 1.0, -(2.0**53), math.inf, -math.inf,
                                                         math.nan, -0.0]])
    expected = [abs(float(v)) % 2.0 for v in values]  # Python's float remainder (NaN for ±inf and NaN)
    np.testing.assert_array_equal([parity(float(v)) for v in values], expected)


def test_blocks_of_states_equal_one_by_one():
    # shared moments: runs of eight take the lanes, with lanes of every kind among them (no rotation,
    # a uniform rotation about A, the separatrix about B, LAM and SAM), and a tail shorter than a block
    rng = np.random.default_rng(4)
    n = 8 * 30 + 5
    quaternions = rng.normal(size=(n, 4))
    quaternions /= np.linalg.norm(quaternions, axis=1, keepdims=True)
    momenta = rng.normal(size=(n, 3))
    momenta[::37] = 0.0
    momenta[4::41, 1:] = 0.0
    momenta[6::43] = [0.0, 1.3, 0.0]
    times = np.array([-3.0, 0.0, 0.25, 40.0, 1e5])
    for moments in ((0.61, 0.965, 1.0), (2.0 / 3.0, 1.0, 2.0), (1.0, 1.0, 2.0)):
        for closed_forms in (True, False):
            q, m = torque_free_states_many(quaternions, momenta, moments, times, closed_forms)
            for i in range(n):
                qi, mi = torque_free_states(quaternions[i], momenta[i], *moments, times, closed_forms)
                np.testing.assert_array_equal(q[i], qi)
                np.testing.assert_array_equal(m[i], mi)
