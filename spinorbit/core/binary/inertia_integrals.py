"""A rigid body's inertia integrals T^α = ∫ x^α dm on its own axes, and their rotation to other axes.

The inertia integrals of Hou, Scheeres & Xin (2017, CeMDA 127, 369, eq. 9) in multi-index form: one
number per monomial of :mod:`.monomials`, degree 0 being the mass and degree 1 zero (the origin is
the centre of mass). Degree 2 is the inertia tensor (:func:`inertia_tensor`); degrees 3 and 4 carry
the shape beyond it.

Homogeneous triaxial ellipsoid, semi-axes a, b, c (closed form): the odd integrals vanish and, with
α = 2(i, j, k) and n = i + j + k,

    T^α = m a^{2i} b^{2j} c^{2k} · 3/(2n + 3) · (2i − 1)!! (2j − 1)!! (2k − 1)!! / (2n + 1)!!

(the average of x^{2i} y^{2j} z^{2k} over the unit sphere is (2i−1)!!(2j−1)!!(2k−1)!!/(2n+1)!!, and
∫₀¹ r^{2n} r² dr / ∫₀¹ r² dr = 3/(2n + 3) gives the ball; (−1)!! = 1). It gives T^{200} = m a²/5,
T^{400} = 3 m a⁴/35, T^{220} = m a² b²/35. A homogeneous sphere is the case a = b = c; its mutual
potential is exactly that of a point mass because every derivative tensor of 1/R is traceless.

Homogeneous polyhedron (:func:`polyhedron_integrals`): ρ ∫ x^α dV over its tetrahedra by the
Grundmann–Möller rule of :func:`spinorbit.core.model.polyhedron.monomial_moments`, exact to rounding,
about the centre of mass on the principal axes (A ≤ B ≤ C on x, y, z); degree 3 no longer vanishes.
"""

import numpy as np

from spinorbit.core.binary.monomials import DEGREE_START, EXPONENTS, MAX_ORDER, UP, index_of, monomials_to_degree
from spinorbit.core.jit import jit
from spinorbit.core.model.polyhedron import mass_properties, monomial_moments, principal_frame

#: Length of a body's integral table: every monomial up to the highest supported order.
INTEGRALS_SIZE = monomials_to_degree(MAX_ORDER)


def _double_factorial_odd(k):
    """(2k − 1)!! for k ≥ 0, with (−1)!! = 1."""
    out = 1.0
    for j in range(1, k + 1):
        out *= 2 * j - 1
    return out


def ellipsoid_integrals(mass, semi_axes):
    """Inertia integrals T^α of a homogeneous ellipsoid on its principal axes, |α| ≤ MAX_ORDER.

    Parameters
    ----------
    mass : float
        Mass (mass unit, e.g. kg).
    semi_axes : sequence of 3 floats
        Semi-axes (a, b, c) along the body x, y, z axes (length unit, e.g. m); any order.

    Returns
    -------
    ndarray (INTEGRALS_SIZE,)
        T^α in mass·length^|α|, indexed as :data:`spinorbit.core.binary.monomials.EXPONENTS`.
    """
    a = np.asarray(semi_axes, dtype=float)
    out = np.zeros(INTEGRALS_SIZE)
    for index in range(INTEGRALS_SIZE):
        alpha = EXPONENTS[index]
        if np.any(alpha % 2):
            continue
        half = alpha // 2
        n = int(half.sum())
        sphere_average = (_double_factorial_odd(int(half[0])) * _double_factorial_odd(int(half[1]))
                          * _double_factorial_odd(int(half[2])) / _double_factorial_odd(n + 1))
        out[index] = mass * float(np.prod(a ** alpha)) * 3.0 / (2 * n + 3) * sphere_average
    return out


def sphere_integrals(mass, radius):
    """Inertia integrals of a homogeneous sphere (an ellipsoid with a = b = c = radius)."""
    return ellipsoid_integrals(mass, (radius, radius, radius))


def polyhedron_integrals(vertices, faces, density):
    """Inertia integrals of a constant-density closed polyhedron on its principal axes about its centre of mass.

    Parameters
    ----------
    vertices : ndarray (n, 3)
        Vertex positions on any axes about any origin (length unit, e.g. m), of a mesh checked by
        :func:`spinorbit.core.model.polyhedron.check_closed_mesh`.
    faces : ndarray (m, 3) int
        Outward-oriented triangles.
    density : float
        Mass per unit volume (mass/length³).

    Returns
    -------
    integrals : ndarray (INTEGRALS_SIZE,)
        T^α = ρ ∫ x^α dV, indexed as :data:`spinorbit.core.binary.monomials.EXPONENTS` (degree 1 is zero
        to rounding and set to 0: the origin is the centre of mass).
    center_of_mass : ndarray (3,)
        On the input axes.
    to_principal : ndarray (3, 3)
        Proper rotation with x_principal = to_principal @ (x − center_of_mass).
    principal_vertices : ndarray (n, 3)
        The vertices on the principal axes about the centre of mass.
    """
    _, center, inertia = mass_properties(vertices, faces)
    _, rotation = principal_frame(inertia)
    principal_vertices = (vertices - center) @ rotation.T
    integrals = density * monomial_moments(principal_vertices, faces, EXPONENTS[:INTEGRALS_SIZE])
    integrals[DEGREE_START[1]:DEGREE_START[2]] = 0.0
    return integrals, center, rotation, principal_vertices


def point_mass_integrals(mass):
    """Inertia integrals of a point mass: the mass alone."""
    out = np.zeros(INTEGRALS_SIZE)
    out[0] = mass
    return out


def inertia_tensor(integrals):
    """The inertia tensor I = tr(T₂) 1 − T₂ from the degree-2 integrals (mass·length²)."""
    t = integrals
    return np.array([
        [t[_YY] + t[_ZZ], -t[_XY], -t[_XZ]],
        [-t[_XY], t[_XX] + t[_ZZ], -t[_YZ]],
        [-t[_XZ], -t[_YZ], t[_XX] + t[_YY]],
    ])


def rotate_integrals(integrals, rotation, order, out):
    """T'^β = ∫ (C ρ)^β dm on axes rotated by the 3×3 matrix C (v' = C v), degrees 0..order, into out.

    Allocating convenience around :func:`rotate_integrals_into` (tests, set-up).
    """
    scratch = np.zeros(INTEGRALS_SIZE)
    rotate_integrals_into(integrals, np.ascontiguousarray(rotation, dtype=float).ravel(), order, out, scratch,
                          np.zeros(INTEGRALS_SIZE))


_XX, _YY, _ZZ = index_of(2, 0, 0), index_of(0, 2, 0), index_of(0, 0, 2)
_XY, _XZ, _YZ = index_of(1, 1, 0), index_of(1, 0, 1), index_of(0, 1, 1)


@jit(inline="always")
def rotate_second_moments(integrals, rotation, out):
    """Degree 2 of :func:`rotate_integrals_into`: T' = C T Cᵀ for the symmetric second moments, in scalars."""
    txx, tyy, tzz = integrals[_XX], integrals[_YY], integrals[_ZZ]
    txy, txz, tyz = integrals[_XY], integrals[_XZ], integrals[_YZ]
    c00, c01, c02 = rotation[0], rotation[1], rotation[2]
    c10, c11, c12 = rotation[3], rotation[4], rotation[5]
    c20, c21, c22 = rotation[6], rotation[7], rotation[8]
    # Rows of C T.
    a00 = c00 * txx + c01 * txy + c02 * txz
    a01 = c00 * txy + c01 * tyy + c02 * tyz
    a02 = c00 * txz + c01 * tyz + c02 * tzz
    a10 = c10 * txx + c11 * txy + c12 * txz
    a11 = c10 * txy + c11 * tyy + c12 * tyz
    a12 = c10 * txz + c11 * tyz + c12 * tzz
    a20 = c20 * txx + c21 * txy + c22 * txz
    a21 = c20 * txy + c21 * tyy + c22 * tyz
    a22 = c20 * txz + c21 * tyz + c22 * tzz
    out[_XX] = a00 * c00 + a01 * c01 + a02 * c02
    out[_YY] = a10 * c10 + a11 * c11 + a12 * c12
    out[_ZZ] = a20 * c20 + a21 * c21 + a22 * c22
    out[_XY] = a00 * c10 + a01 * c11 + a02 * c12
    out[_XZ] = a00 * c20 + a01 * c21 + a02 * c22
    out[_YZ] = a10 * c20 + a11 * c21 + a12 * c22


@jit(inline="always")  # RHS hot path: no call boundary for the arrays to cross
def rotate_integrals_into(integrals, rotation, order, out, poly, spare):
    """T'^β = ∫ (C ρ)^β dm: the integrals on axes rotated by C (row-major (9,), v' = C v), into out.

    Each (Cρ)^β = Π_p (Σ_j C_{i_p j} ρ_j) is expanded as a product of linear forms, one factor at a
    time, as a polynomial in ρ whose coefficients are then contracted with the body's integrals
    (Hou et al. 2017, eq. 24, without the explicit rotation-matrix tensors). ``poly`` and ``spare`` are
    scratch of at least DEGREE_START[order + 1] floats (no allocation: this runs in the RHS). Degree 2
    is the same product written out, T'₂ = C T₂ Cᵀ (:func:`rotate_second_moments`): it is the whole
    cost at order 2, and the loop form took 0.5 µs of the RHS's 1 µs there (measured).
    """
    out[0] = integrals[0]
    for index in range(DEGREE_START[1], DEGREE_START[2]):
        out[index] = 0.0
    if order >= 2:
        rotate_second_moments(integrals, rotation, out)
    for degree in range(3, order + 1):
        for index in range(DEGREE_START[degree], DEGREE_START[degree + 1]):
            # poly := 1, then multiply by the linear form of each axis in the multi-index β.
            poly[0] = 1.0
            current = 0
            for axis in range(3):
                for _ in range(EXPONENTS[index, axis]):
                    for k in range(DEGREE_START[current + 1], DEGREE_START[current + 2]):
                        spare[k] = 0.0
                    for k in range(DEGREE_START[current], DEGREE_START[current + 1]):
                        c = poly[k]
                        if c != 0.0:
                            for j in range(3):
                                spare[UP[k, j]] += c * rotation[3 * axis + j]
                    for k in range(DEGREE_START[current + 1], DEGREE_START[current + 2]):
                        poly[k] = spare[k]
                    current += 1
            acc = 0.0
            for k in range(DEGREE_START[degree], DEGREE_START[degree + 1]):
                acc += poly[k] * integrals[k]
            out[index] = acc
