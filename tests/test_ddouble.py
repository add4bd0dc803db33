"""The error-free product of spinorbit.core.math.ddouble against exact rational arithmetic."""

from fractions import Fraction

import numpy as np

from spinorbit.core.math.ddouble import dd_mul, two_prod

# Products drawn over this many decades each side of 1 (the Veltkamp split it replaced overflowed
# above ~1e300; the fused multiply-add has no such limit short of the product's own overflow).
DECADES = 140
SAMPLES = 20000


def test_two_prod_is_exact():
    rng = np.random.default_rng(11)
    a = rng.uniform(-1.0, 1.0, SAMPLES) * 10.0 ** rng.uniform(-DECADES, DECADES, SAMPLES)
    b = rng.uniform(-1.0, 1.0, SAMPLES) * 10.0 ** rng.uniform(-DECADES, DECADES, SAMPLES)
    for x, y in zip(a.tolist(), b.tolist()):
        p, e = two_prod(x, y)
        assert p == x * y
        assert Fraction(p) + Fraction(e) == Fraction(x) * Fraction(y), (x, y, p, e)
        assert abs(e) <= abs(np.spacing(p)) / 2


def test_two_prod_beyond_the_split_range():
    # Veltkamp's split of 1e305 overflows (2^27 · 1e305 = inf); the product's error term is still exact
    x, y = 1.2345678901234567e305, 1.0000000000000002e-10
    p, e = two_prod(x, y)
    assert Fraction(p) + Fraction(e) == Fraction(x) * Fraction(y)


def test_dd_mul_matches_rationals():
    rng = np.random.default_rng(12)
    for _ in range(2000):
        ah, bh = rng.uniform(0.5, 2.0, 2)
        al, bl = ah * 1e-17 * rng.uniform(-1, 1), bh * 1e-17 * rng.uniform(-1, 1)
        ph, pl = dd_mul(ah, al, bh, bl)
        exact = (Fraction(ah) + Fraction(al)) * (Fraction(bh) + Fraction(bl))
        # double-double product: relative error ≤ 7u², u = 2^-53 (Joldes, Muller, Popescu 2017, DWTimesDW1)
        assert abs(Fraction(ph) + Fraction(pl) - exact) <= Fraction(7, 2**106) * abs(exact)
