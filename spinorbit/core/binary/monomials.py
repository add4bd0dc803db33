"""Multi-index tables of the mutual-potential expansion: monomials x^α = xᵅ¹ yᵅ² zᵅ³ up to a degree.

Every table is built once at import with numpy and frozen into the compiled kernels as constants.
A monomial is addressed by its index in :data:`EXPONENTS` (sorted by degree, then lexicographically
descending), so a degree-n block is contiguous: ``DEGREE_START[n] : DEGREE_START[n + 1]``.
"""

import math

import numpy as np

#: Highest expansion order of the mutual potential. The force needs derivatives of 1/R one degree
#: higher, so the tables run to MAX_ORDER + 1. Raising it only changes this constant (the cost per
#: evaluation grows as the number of (β, γ) pairs, :data:`PAIR_END`).
MAX_ORDER = 4
#: Highest monomial degree in the tables (derivatives of 1/R for the force).
MAX_DEGREE = MAX_ORDER + 1


def _exponents(max_degree):
    rows = []
    for n in range(max_degree + 1):
        for ax in range(n, -1, -1):
            for ay in range(n - ax, -1, -1):
                rows.append((ax, ay, n - ax - ay))
    return np.array(rows, dtype=np.int64)


#: Exponents (α_x, α_y, α_z) of every monomial of degree ≤ MAX_DEGREE.
EXPONENTS = _exponents(MAX_DEGREE)
N_MONOMIALS = EXPONENTS.shape[0]
#: Index of the first monomial of each degree (and one past the last degree).
DEGREE_START = np.array([n * (n + 1) * (n + 2) // 6 for n in range(MAX_DEGREE + 2)], dtype=np.int64)


def monomials_to_degree(n):
    """Number of monomials of degree ≤ n (the length of an integral table to order n)."""
    return int(DEGREE_START[n + 1])


_LOOKUP = {tuple(int(v) for v in row): i for i, row in enumerate(EXPONENTS)}


def index_of(ax, ay, az):
    """Index of the monomial x^ax y^ay z^az in :data:`EXPONENTS`."""
    return _LOOKUP[(ax, ay, az)]


def _neighbours(step):
    table = np.full((N_MONOMIALS, 3), -1, dtype=np.int64)
    for i, row in enumerate(EXPONENTS):
        for axis in range(3):
            shifted = list(row)
            shifted[axis] += step
            table[i, axis] = _LOOKUP.get(tuple(int(v) for v in shifted), -1)
    return table


#: UP[m, i]: index of α + e_i (−1 above MAX_DEGREE); DOWN[m, i]: index of α − e_i (−1 if α_i = 0).
UP = _neighbours(+1)
DOWN = _neighbours(-1)
DOWN2 = _neighbours(-2)

#: ROTATED[m, i, b]: index of α − e_i + e_b (the monomial an infinitesimal rotation mixes in), −1 if α_i = 0.
ROTATED = np.full((N_MONOMIALS, 3, 3), -1, dtype=np.int64)
for _m, _row in enumerate(EXPONENTS):
    for _i in range(3):
        for _b in range(3):
            if _row[_i] > 0:
                _shifted = list(_row)
                _shifted[_i] -= 1
                _shifted[_b] += 1
                ROTATED[_m, _i, _b] = _LOOKUP[tuple(int(v) for v in _shifted)]


def _pairs(max_order):
    """(β, γ, β + γ, (−1)^|γ| / (β! γ!)) for |β| + |γ| ≤ max_order, |β|, |γ| ≠ 1, sorted by |β| + |γ|."""
    rows = []
    for beta_i, beta in enumerate(EXPONENTS):
        for gamma_i, gamma in enumerate(EXPONENTS):
            nb, ng = int(beta.sum()), int(gamma.sum())
            # Degree-1 integrals vanish (the origins are the centres of mass): skipped exactly.
            if nb + ng > max_order or nb == 1 or ng == 1:
                continue
            total = tuple(int(v) for v in beta + gamma)
            factorials = np.prod([math.factorial(int(v)) for v in beta]) * np.prod(
                [math.factorial(int(v)) for v in gamma])
            rows.append((nb + ng, beta_i, gamma_i, _LOOKUP[total], (-1.0) ** ng / factorials))
    rows.sort(key=lambda row: row[0])
    order = np.array([row[0] for row in rows], dtype=np.int64)
    table = np.array([row[1:4] for row in rows], dtype=np.int64)
    coefficient = np.array([row[4] for row in rows], dtype=np.float64)
    end = np.array([int(np.searchsorted(order, n, side="right")) for n in range(max_order + 1)], dtype=np.int64)
    return table, coefficient, end


#: PAIRS[p] = (β, γ, β + γ) monomial indices of the term p of the expansion (Hou, Scheeres & Xin
#: 2017, eq. 20 in multi-index form); PAIR_COEFFICIENT[p] = (−1)^|γ| / (β! γ!); the terms of order
#: ≤ n are PAIRS[:PAIR_END[n]].
PAIRS, PAIR_COEFFICIENT, PAIR_END = _pairs(MAX_ORDER)
PAIR_BETA, PAIR_GAMMA, PAIR_SUM = 0, 1, 2
