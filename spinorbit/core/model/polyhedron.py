"""A closed triangulated polyhedron of constant density: its checks and its exact mass properties.

Plain floats (numpy). A mesh is ``vertices`` (n, 3) and ``faces`` (m, 3) of vertex indices, each face
counter-clockwise seen from outside, so that (b − a) × (c − a) points out of the body.

Every integral is a sum over the signed tetrahedra (origin, a, b, c) of the faces (Mirtich 1996,
J. Graphics Tools 1(2) 31; Dobrovolskis 1996, Icarus 124, 698): for a closed surface the signed
volumes of the parts outside the body cancel, whatever the origin. With D = a · (b × c):

- volume  V = Σ D / 6;
- first moment ∫ x dV = Σ (D / 24)(a + b + c);
- second moment ∫ x xᵀ dV = Σ (D / 120)(a aᵀ + b bᵀ + c cᵀ + s sᵀ), s = a + b + c
  (the covariance of a tetrahedron with one vertex at the origin);
- the inertia tensor per unit density about the centre of mass, I = tr(S) E − S with S the second
  moment about the centre of mass.

The degree 2–4 Stokes coefficients integrate the regular solid harmonics rⁿ P_nm(sin φ) e^{imλ}
(degree-n polynomials) over the same tetrahedra with the Grundmann–Möller rule of degree 5
(Grundmann & Möller 1978, SIAM J. Numer. Anal. 15, 282), which is exact for polynomials of degree ≤ 5:
the coefficients are exact to rounding, not approximations of the polyhedron. The moments of any
monomials, ∫ x^α dV (:func:`monomial_moments`, the inertia integrals of the binary), use the same
rule at the lowest odd degree ≥ max |α|.
"""

import math
from itertools import product

import numpy as np

from spinorbit.core.errors import SpinorbitError, require_finite
from spinorbit.core.model.self_intersection import intersecting_faces

__all__ = [
    "InvalidMeshError", "check_closed_mesh", "face_geometry", "mass_properties", "principal_frame",
    "regular_solid_harmonics", "stokes_coefficients", "simplex_rule", "tetrahedron_nodes", "monomial_moments",
]

#: A face whose area is below this fraction of the mesh's squared size is degenerate: its normal is
#: rounding noise (a sliver with area ~1e-16 L² has no direction).
DEGENERATE_AREA_FRACTION = 1e-14
#: Sizes and coordinates a mesh may have (in its own length unit): its second moments are fifth powers of
#: its size and its degree-4 Stokes sums seventh powers, which stay inside double precision for sizes
#: within 1e±40 (1e280 ≪ 1.8e308); nothing physical in any length unit comes near either end.
MESH_SIZE_RANGE = (1e-40, 1e40)
#: Degree of the tetrahedron rule; 5 ≥ 4, the highest Stokes degree, so every integral is exact.
RULE_DEGREE = 5


class InvalidMeshError(SpinorbitError, ValueError):
    """The mesh is not a closed, consistently outward-oriented surface of non-degenerate triangles."""


def check_closed_mesh(vertices, faces):
    """Check that a mesh bounds a solid, and return it as float and int arrays.

    Parameters
    ----------
    vertices : array_like, shape (n, 3)
        Vertex coordinates (any length unit).
    faces : array_like of int, shape (m, 3)
        Vertex indices of each triangle, counter-clockwise seen from outside.

    Returns
    -------
    vertices : ndarray (n, 3) float64
    faces : ndarray (m, 3) int64

    Raises
    ------
    InvalidMeshError
        Wrong shapes, indices out of range, repeated indices in a face, degenerate faces, an open
        or non-manifold surface (an edge not shared by exactly two faces), inconsistent orientation
        (an edge traversed twice in the same direction), a surface that crosses itself (two faces
        intersecting other than at their shared vertices and edge), or inverted normals (negative volume).
    NonFiniteError
        NaN or inf in the vertices.
    """
    vertices = np.asarray(vertices, dtype=float)
    if vertices.ndim != 2 or vertices.shape[1] != 3 or vertices.shape[0] < 4:
        raise InvalidMeshError(f"vertices: expected an (n, 3) array with n ≥ 4 (a tetrahedron at least); got shape "
                               f"{vertices.shape}. Give one row of x, y, z per vertex.")
    require_finite("vertices", vertices, "finite vertex coordinates")
    faces_in = np.asarray(faces)
    if faces_in.ndim != 2 or faces_in.shape[1] != 3 or faces_in.shape[0] < 4:
        raise InvalidMeshError(f"faces: expected an (m, 3) array of vertex indices (triangles), m ≥ 4; got shape "
                               f"{faces_in.shape}. Split polygons into triangles first.")
    if not np.issubdtype(faces_in.dtype, np.integer):
        raise InvalidMeshError(f"faces: expected integer vertex indices; got dtype {faces_in.dtype}.")
    faces = faces_in.astype(np.int64)
    if faces.min() < 0 or faces.max() >= vertices.shape[0]:
        raise InvalidMeshError(f"faces: vertex indices must lie in 0..{vertices.shape[0] - 1}; got the range "
                               f"{faces.min()}..{faces.max()}. (OBJ files count from 1; the readers convert.)")
    repeated = np.nonzero((faces[:, 0] == faces[:, 1]) | (faces[:, 1] == faces[:, 2]) | (faces[:, 0] == faces[:, 2]))[0]
    if repeated.size:
        raise InvalidMeshError(f"faces {repeated[:5].tolist()} repeat a vertex: a triangle needs three distinct "
                               "vertices. Remove them from the mesh.")
    scale = float(np.ptp(vertices, axis=0).max())
    reach = float(np.abs(vertices).max())
    if not (MESH_SIZE_RANGE[0] <= scale and reach <= MESH_SIZE_RANGE[1]):
        raise InvalidMeshError(
            f"vertices: the mesh spans {scale:.4g} with coordinates up to {reach:.4g} (its length unit), outside "
            f"[{MESH_SIZE_RANGE[0]:g}, {MESH_SIZE_RANGE[1]:g}]: its second moments (size⁵) and Stokes sums would "
            "overflow or underflow double precision. Give the vertices in a length unit that makes them "
            "ordinary numbers (a Shape takes any length Quantity).")
    _, areas, _ = face_geometry(vertices, faces)
    degenerate = np.nonzero(areas <= DEGENERATE_AREA_FRACTION * scale * scale)[0]
    if degenerate.size:
        raise InvalidMeshError(f"faces {degenerate[:5].tolist()} ({degenerate.size} in all) have zero area "
                               f"(below {DEGENERATE_AREA_FRACTION:g} of the size squared): their normals are "
                               "undefined. Remove or merge the collinear vertices.")
    _check_edges(faces)
    _check_no_self_intersection(vertices, faces)
    volume = float(mass_properties(vertices, faces)[0])
    if not volume > 0:
        raise InvalidMeshError(f"the mesh's signed volume is {volume!r} ≤ 0: its faces are ordered clockwise seen "
                               "from outside (inverted normals). Reverse the order of every face's vertices.")
    return vertices, faces


#: Intersecting face pairs named in the message of a self-intersecting mesh.
SHOWN_INTERSECTIONS = 5


def _check_no_self_intersection(vertices, faces):
    """Refuse a surface that crosses itself (:mod:`spinorbit.core.model.self_intersection`)."""
    # One compiled signature: C-contiguous float64 and int64, whatever layout the caller's arrays have.
    count, pairs = intersecting_faces(np.ascontiguousarray(vertices, dtype=np.float64),
                                      np.ascontiguousarray(faces, dtype=np.int64), SHOWN_INTERSECTIONS)
    if count:
        shown = ", ".join(f"{int(i)} and {int(j)}" for i, j in pairs)
        raise InvalidMeshError(
            f"the surface crosses itself: {count} pairs of faces intersect (faces {shown}"
            f"{', …' if count > len(pairs) else ''}; numbered from 0). Its volume and moments would count the "
            "overlap twice. Repair the mesh: merge overlapping parts into one surface, or move the vertices that "
            "poke through.")


def _check_edges(faces):
    """Every directed edge once and its reverse once: closed, two-manifold at the edges, one orientation."""
    count = faces.shape[0]
    starts = faces.ravel()
    ends = np.roll(faces, -1, axis=1).ravel()
    directed = np.stack([starts, ends], axis=1)
    unique_directed, multiplicity = np.unique(directed, axis=0, return_counts=True)
    if multiplicity.max() > 1:
        a, b = unique_directed[np.argmax(multiplicity)]
        raise InvalidMeshError(f"the edge {a}→{b} is traversed {multiplicity.max()} times in the same direction: the "
                               "faces are not consistently oriented (or the edge is shared by more than two faces). "
                               "Orient every face counter-clockwise seen from outside.")
    undirected = np.sort(directed, axis=1)
    _, uses = np.unique(undirected, axis=0, return_counts=True)
    if np.any(uses != 2):
        bad = int(np.sum(uses != 2))
        raise InvalidMeshError(f"{bad} edges of the {count}-face mesh belong to {sorted(set(uses[uses != 2].tolist()))} faces "
                               "instead of exactly two: the surface is open (holes) or not a manifold. Close the "
                               "holes before computing mass properties.")


def face_geometry(vertices, faces):
    """Unit outward normals, areas and centroids of the faces.

    Returns
    -------
    normals : ndarray (m, 3)
        Unit normals (b − a) × (c − a) / |…|.
    areas : ndarray (m,)
        Areas (length²).
    centroids : ndarray (m, 3)
        (a + b + c) / 3.
    """
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    doubled = np.cross(b - a, c - a)
    norm = np.linalg.norm(doubled, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        normals = doubled / norm[:, None]
    return normals, 0.5 * norm, (a + b + c) / 3.0


def mass_properties(vertices, faces):
    """Volume, centre of mass and inertia tensor per unit density of a closed mesh, exactly.

    Parameters
    ----------
    vertices : ndarray (n, 3)
    faces : ndarray (m, 3) int

    Returns
    -------
    volume : float
        length³.
    center_of_mass : ndarray (3,)
        length, in the vertices' frame.
    inertia : ndarray (3, 3)
        Inertia tensor about the centre of mass divided by the density (length⁵), in the vertices'
        frame: multiply by the density for mass · length².
    """
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    volume = det.sum() / 6.0
    center = (det[:, None] * (a + b + c)).sum(axis=0) / (24.0 * volume)
    # Second pass about the centre of mass: no parallel-axis cancellation for a mesh far from its origin.
    a, b, c = a - center, b - center, c - center
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    s = a + b + c
    shift = (det[:, None] * s).sum(axis=0) / (24.0 * volume)  # rounding of the first pass
    second = (np.einsum("i,ij,ik->jk", det, a, a) + np.einsum("i,ij,ik->jk", det, b, b)
              + np.einsum("i,ij,ik->jk", det, c, c) + np.einsum("i,ij,ik->jk", det, s, s)) / 120.0
    second -= volume * np.outer(shift, shift)
    center = center + shift
    inertia = np.trace(second) * np.eye(3) - second
    return float(volume), center, 0.5 * (inertia + inertia.T)


def principal_frame(inertia):
    """Principal moments A ≤ B ≤ C and the proper rotation onto the principal axes.

    Parameters
    ----------
    inertia : ndarray (3, 3)
        Symmetric inertia tensor in some frame.

    Returns
    -------
    moments : ndarray (3,)
        A ≤ B ≤ C.
    rotation : ndarray (3, 3)
        Proper rotation (det +1) whose rows are the principal axes: x_principal = rotation @ x.
        Each axis is signed so that its largest component is positive (a deterministic choice; the
        third axis then follows from the right-hand rule).
    """
    moments, vectors = np.linalg.eigh(0.5 * (inertia + inertia.T))
    rows = vectors.T.copy()
    for k in range(2):
        if rows[k, np.argmax(np.abs(rows[k]))] < 0:
            rows[k] *= -1.0
    rows[2] = np.cross(rows[0], rows[1])
    return moments, rows


def simplex_rule(degree=RULE_DEGREE):
    """Grundmann–Möller rule on the unit tetrahedron {u ≥ 0, Σu ≤ 1}, exact to polynomial ``degree`` (odd).

    Returns
    -------
    points : ndarray (k, 3)
        Barycentric coordinates (u1, u2, u3) of the nodes (u0 = 1 − Σ).
    weights : ndarray (k,)
        Weights summing to the tetrahedron's volume, 1/6 (some are negative).
    """
    s = (degree - 1) // 2
    dimension = 3
    points, weights = [], []
    for i in range(s + 1):
        denominator = degree + dimension - 2 * i
        weight = (-1) ** i * 2.0 ** (-2 * s) * denominator ** degree / (
            math.factorial(i) * math.factorial(degree + dimension - i))
        for beta in product(range(s - i + 1), repeat=dimension + 1):
            if sum(beta) == s - i:
                points.append([(2 * b + 1) / denominator for b in beta[1:]])
                weights.append(weight)
    return np.array(points), np.array(weights)


def regular_solid_harmonics(points, degree_max):
    """rⁿ P_nm(sin φ) cos mλ and rⁿ P_nm(sin φ) sin mλ at Cartesian points (no Condon–Shortley phase).

    Recurrences of the associated Legendre functions multiplied by rⁿ (Montenbruck & Gill 2000, §3.2.4):
    R_mm = (2m − 1)(x + iy) R_{m−1,m−1}, (n − m) R_nm = (2n − 1) z R_{n−1,m} − (n + m − 1) r² R_{n−2,m}.

    Returns
    -------
    cos_part, sin_part : ndarray (degree_max + 1, degree_max + 1, k)
        Indexed [n, m, point]; zero for m > n.
    """
    x, y, z = points[..., 0], points[..., 1], points[..., 2]
    r2 = x * x + y * y + z * z
    shape = (degree_max + 1, degree_max + 1) + x.shape
    real, imag = np.zeros(shape), np.zeros(shape)
    real[0, 0] = 1.0
    for m in range(degree_max + 1):
        if m > 0:
            factor = 2 * m - 1
            real[m, m] = factor * (x * real[m - 1, m - 1] - y * imag[m - 1, m - 1])
            imag[m, m] = factor * (x * imag[m - 1, m - 1] + y * real[m - 1, m - 1])
        for n in range(m + 1, degree_max + 1):
            below = (n + m - 1) * r2 if n >= m + 2 else 0.0
            far = n - 2 if n >= m + 2 else m
            real[n, m] = ((2 * n - 1) * z * real[n - 1, m] - below * real[far, m]) / (n - m)
            imag[n, m] = ((2 * n - 1) * z * imag[n - 1, m] - below * imag[far, m]) / (n - m)
    return real, imag


def stokes_coefficients(vertices, faces, reference_radius, degree_max=4):
    """Unnormalised Stokes coefficients C_nm, S_nm of a constant-density polyhedron, exactly.

    C_nm + i S_nm = (2 − δ_m0) (n − m)!/(n + m)! · (1 / (V R_refⁿ)) ∫ rⁿ P_nm(sin φ) e^{imλ} dV, the
    convention of :mod:`spinorbit.core.model.gravity_field` (geodesy, no Condon–Shortley phase),
    about the vertices' origin and on their axes (shift to the centre of mass and rotate to the
    principal axes first for a figure: then C_10 = C_11 = S_11 = C_21 = S_21 = S_22 = 0).

    Parameters
    ----------
    vertices : ndarray (n, 3)
        length.
    faces : ndarray (m, 3) int
    reference_radius : float
        R_ref (same length unit).
    degree_max : int
        Highest degree, ≤ 4 (the rule is exact to degree 5).

    Returns
    -------
    c, s : ndarray (degree_max + 1, degree_max + 1)
        Indexed [n, m] (dimensionless).
    """
    if not 0 <= degree_max <= RULE_DEGREE:
        raise ValueError(f"degree_max: expected 0..{RULE_DEGREE} (the exact tetrahedron rule's degree); got "
                         f"{degree_max!r}.")
    points, weights, det = tetrahedron_nodes(vertices, faces)
    real, imag = regular_solid_harmonics(points, degree_max)
    integral_real = np.einsum("nmkf,k,f->nm", real, weights, det)
    integral_imag = np.einsum("nmkf,k,f->nm", imag, weights, det)
    volume = det.sum() / 6.0
    c_out = np.zeros((degree_max + 1, degree_max + 1))
    s_out = np.zeros_like(c_out)
    for n in range(degree_max + 1):
        for m in range(n + 1):
            factor = (2.0 - (m == 0)) * math.factorial(n - m) / math.factorial(n + m) / (volume * reference_radius ** n)
            c_out[n, m] = factor * integral_real[n, m]
            s_out[n, m] = factor * integral_imag[n, m]
    return c_out, s_out


def tetrahedron_nodes(vertices, faces, degree=RULE_DEGREE):
    """Nodes, weights and signed volume factors of the rule of ``degree`` over the tetrahedra (0, a, b, c).

    ∫_V f dV = Σ_{k,f} weights[k] · det[f] · f(points[k, f]) exactly for polynomials f of degree ≤ ``degree``
    (the signed volumes of the parts outside the body cancel for a closed surface).

    Returns
    -------
    points : ndarray (k, m, 3)
        Node k of face f at Σ_j u_kj v_j, (a, b, c) = the face's vertices (length).
    weights : ndarray (k,)
        The rule's weights on the unit tetrahedron (sum 1/6).
    det : ndarray (m,)
        a · (b × c), the Jacobian of each tetrahedron (length³; negative where it lies outside).
    """
    nodes, weights = simplex_rule(degree)
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    det = np.einsum("ij,ij->i", a, np.cross(b, c))
    points = (nodes[:, 0, None, None] * a + nodes[:, 1, None, None] * b + nodes[:, 2, None, None] * c)
    return points, weights, det


def monomial_moments(vertices, faces, exponents):
    """∫ x^α dV over a closed polyhedron for each row α of ``exponents``, exactly (to rounding).

    The tetrahedron rule's degree is the lowest odd one ≥ max |α| (Grundmann–Möller rules have odd
    degree), so every monomial is integrated exactly.

    Parameters
    ----------
    vertices : ndarray (n, 3)
        length, about the origin the moments are taken about and on the axes they are taken on.
    faces : ndarray (m, 3) int
    exponents : array_like of int, shape (p, 3)
        (α_x, α_y, α_z) of each monomial, all ≥ 0.

    Returns
    -------
    ndarray (p,)
        ∫ x^α_x y^α_y z^α_z dV (length^(3 + |α|)).
    """
    exponents = np.asarray(exponents)
    if exponents.ndim != 2 or exponents.shape[1] != 3 or not np.issubdtype(exponents.dtype, np.integer) \
            or np.any(exponents < 0):
        raise ValueError(f"exponents: expected a (p, 3) array of non-negative integers (α_x, α_y, α_z); got shape "
                         f"{exponents.shape} and dtype {exponents.dtype}.")
    highest = int(exponents.sum(axis=1).max()) if exponents.shape[0] else 0
    degree = max(1, highest + (1 - highest % 2))
    points, weights, det = tetrahedron_nodes(vertices, faces, degree)
    weighted = weights[:, None] * det[None, :]
    powers = [np.ones(points.shape[:2] + (3,))]
    for _ in range(highest):
        powers.append(powers[-1] * points)
    out = np.empty(exponents.shape[0])
    for row, (ax, ay, az) in enumerate(exponents):
        values = powers[ax][..., 0] * powers[ay][..., 1] * powers[az][..., 2]
        out[row] = float(np.sum(weighted * values))
    return out
