"""Bad input to spinorbit.special: specific exceptions whose message says what to do."""

import math

import numpy as np
import pytest

from spinorbit import special


def test_negative_parameter_is_rejected_but_rounding_is_not():
    with pytest.raises(ValueError, match=r"m must be ≥ 0, got m = -0.1"):
        special.ellipj(1.0, -0.1)
    assert special.ellipk(-1e-17) == special.ellipk(0.0)  # a rounded m = 0 is accepted


def test_inconsistent_mc_is_rejected():
    with pytest.raises(ValueError, match=r"mc must be the complementary parameter"):
        special.ellipk(0.3, mc=0.6)
    # mc exact while m = fl(1 − mc) is rounded: accepted
    assert math.isfinite(special.ellipk(1.0 - 1e-15, mc=1e-15))


def test_shapes_that_do_not_broadcast_are_named():
    with pytest.raises(ValueError, match=r"u\(3,\), m\(2,\)"):
        special.ellipj(np.zeros(3), np.full(2, 0.5))
    with pytest.raises(ValueError, match=r"do not broadcast"):
        special.ellippi(np.zeros(4), np.zeros(3), 0.5)


@pytest.mark.parametrize("function", [special.ellippi, special.pn])
def test_divergent_characteristic_is_rejected(function):
    with pytest.raises(ValueError, match=r"integral diverges"):
        function(1.5, 0.3, 0.5) if function is special.ellippi else function(0.3, 1.5, 0.5)


def test_documented_nan_cases():
    assert math.isnan(special.pn(1.0, 2.0, 2.0))  # n = m > 1: non-integrable at turning points
    assert math.isnan(special.ellipf(1.0, 4.0))  # m sin²φ > 1
    assert math.isnan(special.ellipj(np.nan, 0.5)[0])
    assert math.isnan(special.ellipj(1.0, np.nan)[0])


def test_non_numeric_input_is_a_type_error():
    with pytest.raises(TypeError, match=r"u must be a real number"):
        special.am("one", 0.5)


def test_scalar_in_float_out_array_in_array_out():
    assert type(special.am(1.0, 0.5)) is float
    assert isinstance(special.am([1.0], 0.5), np.ndarray)
    assert special.ellipj(np.zeros((0, 3)), 0.5)[0].shape == (0, 3)
