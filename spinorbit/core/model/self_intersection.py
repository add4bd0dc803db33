"""Does a closed triangulated surface cross itself? Pairs of faces that intersect, found fast.

A surface that passes the edge checks of :func:`spinorbit.core.model.polyhedron.check_closed_mesh`
(closed, two-manifold, one orientation) can still pass through itself: two overlapping spheres in
one file, or a vertex pushed through the far side. Its signed-tetrahedron integrals then count the
overlap twice (or negatively), without a word. This module finds such faces.

- **Broad phase**: each face's axis-aligned bounding box is binned on a uniform grid (cells about
  twice the median face size, coarsened until each face sits in 27 cells on average at most); the
  (face, cell) entries are sorted by cell, and only faces that share a cell and whose boxes overlap
  are compared, each pair once (in the cell holding the low corner of their boxes' overlap). Work
  and memory grow as the number of faces, not its square.
- **Narrow phase** (exact arithmetic tests on doubles, no tolerance beyond the parallel test):

  - faces with no common vertex intersect when an edge of one meets the other (Möller–Trumbore on
    the segment, boundaries included: in a valid mesh such faces never touch). Coplanar faces are
    compared in their plane: a proper crossing of two edges, or a vertex of one inside the other;
  - faces with one common vertex v: their planes meet in a line through v, and each face cuts it in a
    segment from v. The faces overlap beyond v exactly when the edge opposite v of one of them meets
    the other face; coplanar, when edges cross properly or a vertex other than v lies inside the other;
  - faces with a common edge: intersect only when coplanar and folded onto each other (their third
    vertices on the same side of the edge).
"""

import math

import numpy as np

from spinorbit.core.jit import jit

#: Average cells per face the grid may reach before it is coarsened (a face's box spans ≤ 3 cells a side).
MAX_ENTRIES_PER_FACE = 27
#: Faces whose normals' cross product is below this fraction of their product are parallel: their
#: crossings are tested in the plane (1e-12 ≈ the angle to which doubles resolve a normal, times 1e4).
PARALLEL = 1e-12


@jit
def _sub(a, b):
    return a[0] - b[0], a[1] - b[1], a[2] - b[2]


@jit
def _cross(a, b):
    return a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]


@jit
def _dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@jit
def segment_meets_triangle(p, q, a, b, c):
    """True if the segment p–q meets the triangle abc (boundaries included); False if parallel to its plane."""
    d = _sub(q, p)
    e1 = _sub(b, a)
    e2 = _sub(c, a)
    h = _cross(d, e2)
    det = _dot(e1, h)
    scale = math.sqrt(_dot(d, d) * _dot(e1, e1) * _dot(e2, e2))
    if not abs(det) > PARALLEL * scale:
        return False
    s = _sub(p, a)
    u = _dot(s, h) / det
    if u < 0.0 or u > 1.0:
        return False
    k = _cross(s, e1)
    v = _dot(d, k) / det
    if v < 0.0 or u + v > 1.0:
        return False
    t = _dot(e2, k) / det
    return 0.0 <= t <= 1.0


@jit
def _orient2(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@jit
def _strictly_inside_2d(px, py, t):
    """Point (px, py) strictly inside the 2-D triangle t (3, 2), either orientation."""
    d1 = _orient2(t[0, 0], t[0, 1], t[1, 0], t[1, 1], px, py)
    d2 = _orient2(t[1, 0], t[1, 1], t[2, 0], t[2, 1], px, py)
    d3 = _orient2(t[2, 0], t[2, 1], t[0, 0], t[0, 1], px, py)
    return (d1 > 0 and d2 > 0 and d3 > 0) or (d1 < 0 and d2 < 0 and d3 < 0)


@jit
def coplanar_overlap(ta, tb, drop, shared_a, shared_b):
    """Coplanar triangles ta, tb (3, 3) overlap: edges crossing properly, or a non-shared vertex strictly inside.

    ``drop`` is the axis left out of the projection (the normal's largest component); ``shared_a`` /
    ``shared_b`` flag the vertices the two faces share (not tested for containment).
    """
    pa = np.empty((3, 2))
    pb = np.empty((3, 2))
    col = 0
    for axis in range(3):
        if axis != drop:
            for k in range(3):
                pa[k, col] = ta[k, axis]
                pb[k, col] = tb[k, axis]
            col += 1
    for i in range(3):
        p0x, p0y, p1x, p1y = pa[i, 0], pa[i, 1], pa[(i + 1) % 3, 0], pa[(i + 1) % 3, 1]
        for j in range(3):
            q0x, q0y, q1x, q1y = pb[j, 0], pb[j, 1], pb[(j + 1) % 3, 0], pb[(j + 1) % 3, 1]
            o1 = _orient2(p0x, p0y, p1x, p1y, q0x, q0y)
            o2 = _orient2(p0x, p0y, p1x, p1y, q1x, q1y)
            o3 = _orient2(q0x, q0y, q1x, q1y, p0x, p0y)
            o4 = _orient2(q0x, q0y, q1x, q1y, p1x, p1y)
            if o1 * o2 < 0 and o3 * o4 < 0:
                return True
    for k in range(3):
        if not shared_b[k] and _strictly_inside_2d(pb[k, 0], pb[k, 1], pa):
            return True
        if not shared_a[k] and _strictly_inside_2d(pa[k, 0], pa[k, 1], pb):
            return True
    return False


@jit
def faces_intersect(vertices, faces, i, j):
    """True if faces i and j of the mesh intersect other than along the vertices and edge they share."""
    fa = faces[i]
    fb = faces[j]
    ta = np.empty((3, 3))
    tb = np.empty((3, 3))
    for k in range(3):
        for axis in range(3):
            ta[k, axis] = vertices[fa[k], axis]
            tb[k, axis] = vertices[fb[k], axis]
    shared_a = np.zeros(3, dtype=np.bool_)
    shared_b = np.zeros(3, dtype=np.bool_)
    common = 0
    for k in range(3):
        for m in range(3):
            if fa[k] == fb[m]:
                shared_a[k] = True
                shared_b[m] = True
                common += 1
    na = _cross(_sub(ta[1], ta[0]), _sub(ta[2], ta[0]))
    nb = _cross(_sub(tb[1], tb[0]), _sub(tb[2], tb[0]))
    axb = _cross(na, nb)
    coplanar = False
    if math.sqrt(_dot(axb, axb)) <= PARALLEL * math.sqrt(_dot(na, na) * _dot(nb, nb)):
        # Parallel planes: the same plane when b's vertices lie on a's (to the same relative level).
        size = math.sqrt(_dot(na, na))
        offset = 0.0
        for k in range(3):
            offset = max(offset, abs(_dot(na, _sub(tb[k], ta[0]))))
        reach = 0.0
        for k in range(3):
            reach = max(reach, math.sqrt(_dot(_sub(tb[k], ta[0]), _sub(tb[k], ta[0]))))
        coplanar = offset <= PARALLEL * size * max(reach, 1e-300)
        if not coplanar:
            return False
    if coplanar:
        drop = 0
        if abs(na[1]) > abs(na[drop]):
            drop = 1
        if abs(na[2]) > abs(na[drop]):
            drop = 2
        if common == 2:
            # Folded onto each other: the third vertices on the same side of the shared edge.
            return coplanar_overlap(ta, tb, drop, shared_a, shared_b) or _folded(ta, tb, shared_a, shared_b, na)
        return coplanar_overlap(ta, tb, drop, shared_a, shared_b)
    if common == 2:
        return False  # two planes through one edge meet only along it
    if common == 1:
        ka = 0
        while not shared_a[ka]:
            ka += 1
        kb = 0
        while not shared_b[kb]:
            kb += 1
        # The edge opposite the shared vertex of each face, against the other face.
        return (segment_meets_triangle(ta[(ka + 1) % 3], ta[(ka + 2) % 3], tb[0], tb[1], tb[2])
                or segment_meets_triangle(tb[(kb + 1) % 3], tb[(kb + 2) % 3], ta[0], ta[1], ta[2]))
    for k in range(3):
        if segment_meets_triangle(ta[k], ta[(k + 1) % 3], tb[0], tb[1], tb[2]):
            return True
        if segment_meets_triangle(tb[k], tb[(k + 1) % 3], ta[0], ta[1], ta[2]):
            return True
    return False


@jit
def _folded(ta, tb, shared_a, shared_b, na):
    """Coplanar faces sharing an edge lie on the same side of it (one folded back onto the other)."""
    ka = 0
    while shared_a[ka]:
        ka += 1
    kb = 0
    while shared_b[kb]:
        kb += 1
    e0 = 0
    while not shared_a[e0]:
        e0 += 1
    e1 = e0 + 1
    while not shared_a[e1]:
        e1 += 1
    edge = _sub(ta[e1], ta[e0])
    side_a = _dot(_cross(edge, _sub(ta[ka], ta[e0])), na)
    side_b = _dot(_cross(edge, _sub(tb[kb], ta[e0])), na)
    return side_a * side_b > 0


@jit
def _cell_range(lo, hi, origin, cell, counts):
    """Integer cell ranges (3, 2) of a box on the grid."""
    out = np.empty((3, 2), dtype=np.int64)
    for axis in range(3):
        out[axis, 0] = min(int((lo[axis] - origin[axis]) / cell), counts[axis] - 1)
        out[axis, 1] = min(int((hi[axis] - origin[axis]) / cell), counts[axis] - 1)
    return out


@jit
def _grid(lows, highs, cell):
    origin = np.empty(3)
    counts = np.empty(3, dtype=np.int64)
    for axis in range(3):
        origin[axis] = lows[:, axis].min()
        counts[axis] = int((highs[:, axis].max() - origin[axis]) / cell) + 1
    return origin, counts


@jit
def _entry_count(lows, highs, cell):
    origin, counts = _grid(lows, highs, cell)
    total = 0
    for f in range(lows.shape[0]):
        r = _cell_range(lows[f], highs[f], origin, cell, counts)
        total += (r[0, 1] - r[0, 0] + 1) * (r[1, 1] - r[1, 0] + 1) * (r[2, 1] - r[2, 0] + 1)
    return total


@jit
def _entries(lows, highs, cell, total):
    """(cell key, face) of every cell each face's box covers, in face order."""
    origin, counts = _grid(lows, highs, cell)
    keys = np.empty(total, dtype=np.int64)
    owners = np.empty(total, dtype=np.int64)
    n = 0
    for f in range(lows.shape[0]):
        r = _cell_range(lows[f], highs[f], origin, cell, counts)
        for x in range(r[0, 0], r[0, 1] + 1):
            for y in range(r[1, 0], r[1, 1] + 1):
                for z in range(r[2, 0], r[2, 1] + 1):
                    keys[n] = (x * counts[1] + y) * counts[2] + z
                    owners[n] = f
                    n += 1
    return keys, owners


@jit
def _scan_cells(vertices, faces, lows, highs, keys, owners, cell, max_report):
    """Compare the faces of each cell (entries sorted by key) pair by pair: (count, first pairs)."""
    origin, counts = _grid(lows, highs, cell)
    total = keys.shape[0]
    found = 0
    report = np.empty((max_report, 2), dtype=np.int64)
    corner = np.empty(3)
    start = 0
    while start < total:
        key = keys[start]
        stop = start
        while stop < total and keys[stop] == key:
            stop += 1
        for s in range(start, stop):
            fa = owners[s]
            for t in range(s + 1, stop):
                fb = owners[t]
                overlap = True
                for axis in range(3):
                    corner[axis] = max(lows[fa, axis], lows[fb, axis])
                    if corner[axis] > min(highs[fa, axis], highs[fb, axis]):
                        overlap = False
                if not overlap:
                    continue
                home = _cell_range(corner, corner, origin, cell, counts)
                if (home[0, 0] * counts[1] + home[1, 0]) * counts[2] + home[2, 0] != key:
                    continue  # the pair is compared in the cell of its overlap's low corner only
                if faces_intersect(vertices, faces, fa, fb):
                    if found < max_report:
                        report[found, 0] = min(fa, fb)
                        report[found, 1] = max(fa, fb)
                    found += 1
        start = stop
    return found, report[:min(found, max_report)].copy()


def intersecting_faces(vertices, faces, max_report):
    """(number of intersecting face pairs, (k, 2) array of the first k ≤ max_report of them, i < j).

    ``vertices`` (n, 3) float64 and ``faces`` (m, 3) int64, C-contiguous, of a closed, two-manifold
    mesh (checked by the caller: the pair tests assume that faces meet only at shared vertices and
    edges). The boxes and the sort are numpy; the binning and the pair scan are compiled.
    """
    corners = vertices[faces]
    lows = np.ascontiguousarray(corners.min(axis=1))
    highs = np.ascontiguousarray(corners.max(axis=1))
    size = float((highs.max(axis=0) - lows.min(axis=0)).max())
    # At least 1e-5 of the size, so that the cell keys (≤ 1e15) stay far inside int64.
    cell = max(2.0 * float(np.median((highs - lows).max(axis=1))), 1e-5 * size, 1e-300)
    while (total := _entry_count(lows, highs, cell)) > MAX_ENTRIES_PER_FACE * len(faces) + 64:
        cell *= 2.0
    keys, owners = _entries(lows, highs, cell, total)
    order = np.argsort(keys, kind="stable")
    return _scan_cells(vertices, faces, lows, highs, keys[order], owners[order], cell, int(max_report))
