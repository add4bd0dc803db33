"""The Taylor recurrences compiled on member rows (eight members in SIMD lanes, ``QuadLanes``) against the
same recurrences on one member: every member's coefficients the one-member form's bit for bit, with its
own moments, state, step bound and tolerance, hence its own orbit-series truncation orders (issue 39).

No tolerance: the lanes form runs each member's arithmetic in the one-member form's order (component c
of member l is element 8c + l of one vector), and the products past a member's own truncation order read
zeros, which leave every sum's bits as they are."""

import numpy as np
from _batch_members import members

from spinorbit.core.dynamics.equations import MODEL_PERTURBERS
from spinorbit.core.integrators.taylor_recurrences import seed_perturbers, series_array, taylor_coefficients_into
from spinorbit.core.jit import jit
from spinorbit.core.math.lanes import load_lanes


@jit
def _coefficients_in_lanes(model_rows, series, n_pert, order, h_bounds, orbit_tols, orbit_orders):
    taylor_coefficients_into(0.0, model_rows, series, n_pert, order, load_lanes(h_bounds, 0),
                             load_lanes(orbit_tols, 0), orbit_orders)


def test_eight_members_in_lanes_are_each_the_one_member_recurrences_bits():
    y0s, models, rng = members(8, seed=11)
    order, n_pert = 12, int(models[0][MODEL_PERTURBERS])
    h_bounds = 0.05 * (1.0 + 4.0 * rng.random(8))  # each member its own step bound: its own orbit orders
    orbit_tols = 1e-10 * (1.0 + 100.0 * rng.random(8))
    lanes = np.zeros((order + 1, series_array(n_pert, order).shape[1], 8))
    expected, expected_orders = [], []
    for lane in range(8):
        s = series_array(n_pert, order)
        s[0, :7] = y0s[lane]
        s[0, :4] /= np.linalg.norm(y0s[lane, :4])
        orbit_orders = np.zeros(n_pert, dtype=np.int64)
        seed_perturbers(0.3, models[lane], s, n_pert, np.inf, 1.0, 0.0, orbit_orders, True)
        lanes[:, :, lane] = s
        taylor_coefficients_into(0.3, models[lane], s, n_pert, order, h_bounds[lane], orbit_tols[lane], orbit_orders)
        expected.append(s)
        expected_orders.append(orbit_orders)
    lane_orders = np.zeros((n_pert, 8))
    _coefficients_in_lanes(np.ascontiguousarray(np.array(models).T), lanes, n_pert, order, h_bounds, orbit_tols,
                           lane_orders)
    assert len({tuple(o) for o in expected_orders}) > 2  # members truncated at different orders side by side
    for lane in range(8):
        assert lane_orders[:, lane].tolist() == expected_orders[lane].tolist(), lane
        assert lanes[:, :7, lane].tobytes() == expected[lane][:, :7].tobytes(), lane
