"""Long runs (issue 7), slow: 10⁶ steps of each integrator under a torque, 10⁷ torque-free rotations.

The runs are those of ``benchmarks/stability.py`` (which plots them in docs/stability.md); here
their outcome is asserted against the reasons below. The 10⁶-step energy bound of the symplectic
splitting is ``tests/test_integrate_splitting.py::test_energy_error_bounded_over_1e6_steps``.
"""

import numpy as np
import pytest

from benchmarks.stability import energy_runs, growth_exponent, torque_free_long

EPS = np.finfo(float).eps


@pytest.mark.slow
def test_energy_of_the_non_symplectic_integrators_drifts_linearly_and_within_tolerance():
    """DOP853 and the element integrator are not symplectic: their local errors have a systematic
    energy component, so |ΔE| grows ∝ n (measured exponents 1.00, 1.00, 0.98), and it cannot exceed
    rtol per step (measured 0.014 rtol·n for DOP853 at 1e-10, 0.0027 for DOP853 at 1e-13 and
    1.3e-4 for the elements at 1e-10)."""
    runs = energy_runs(1_000_000)
    for label, (steps, errors) in runs.items():
        if "splitting" in label:
            assert errors.max() < 1e-9  # bounded (ENERGY_BOUND of test_integrate_splitting.py); measured 1.5e-10
            assert abs(growth_exponent(steps, errors)) < 0.3
            continue
        rtol = float(label.rsplit("rtol ", 1)[1])
        assert 0.8 < growth_exponent(steps, errors) < 1.2, label
        assert errors[-1] < rtol * steps[-1], label


@pytest.mark.slow
def test_torque_free_flow_over_1e7_rotations_is_at_rounding():
    """|M| and E to a few ε at 3000 times (measured 1 ε and 3 ε); the attitude error against 40-digit
    mpmath stays at rounding (measured ≤ 5.6e-16 rad) while the floor, the state's own sensitivity
    to its inputs, grows to 1.7e-7 rad: nothing accumulates."""
    free = torque_free_long(10**7)
    assert free["momentum"].max() <= 4 * EPS
    assert free["energy"].max() <= 8 * EPS
    assert np.all(free["phase"] <= 8 * EPS)
    assert np.all(free["phase"] <= free["floor"])
