"""Shape files: Wavefront OBJ and the implicitly connected quadrilateral (ICQ) format.

- **OBJ**: ``v x y z`` lines and ``f i j k …`` lines counting vertices from 1 (negative indices
  count back from the last vertex; ``i/t/n`` forms keep the vertex index). Polygons with more than
  three vertices are split into a fan of triangles. Other records (``vn``, ``vt``, ``g``, ``o``,
  ``s``, ``usemtl``, comments) are ignored.
- **ICQ** (Gaskell's SPC format, used by the PDS Small Bodies Node; https://sbib.psi.edu/spc_wiki/SHAPE.TXT):
  a first line with q, then 6 (q + 1)² lines of x y z: six faces of a cube, each a (q + 1) × (q + 1)
  grid listed row by row (j outer, i inner). Vertices on shared cube edges are written once per cube
  face with the same coordinates; they are merged here, leaving 6 q² + 2 vertices and 12 q² triangles.
  Each grid cell (i, j)–(i + 1, j)–(i + 1, j + 1)–(i, j + 1) becomes two triangles; the six cube
  faces have the same handedness, so the orientation is fixed by the sign of the volume.

Neither format states the unit of its numbers (PDS and radar models are usually in km, DAMIT's
convex models are scaled to no particular size), so the readers take it as an argument with no
default, ``read_obj(path, unit=u.km)``: units are never guessed (``docs/conventions.md``, "Units").
The writers write in ``unit`` (km by default) and say so in the OBJ header.

Every reading error names the file and line, says what was expected and what arrived.
"""

from __future__ import annotations

import math
import os

import numpy as np
from astropy import units as u

from spinorbit.core.errors import SpinorbitError
from spinorbit.core.model.polyhedron import InvalidMeshError
from spinorbit.quantities import QuantityInputError, value_in
from spinorbit.runs.atomic import atomic_path
from spinorbit.shape.mesh import Shape

__all__ = ["ShapeFileError", "read_obj", "write_obj", "read_icq", "write_icq", "icq_mesh", "icq_grid"]

#: The cube-face frames of the ICQ grid: centre c, i-direction e1, j-direction e2 (e1 × e2 = c on every
#: face), the one assignment for which the shared edges of SHAPE.TXT coincide
#: (v(I,0,1) = v(I,Q,0), v(I,0,2) = v(0,I,0), …, with faces counted from 0).
ICQ_FACE_FRAMES = (
    ((0, 0, 1), (1, 0, 0), (0, 1, 0)),
    ((0, 1, 0), (1, 0, 0), (0, 0, -1)),
    ((-1, 0, 0), (0, 1, 0), (0, 0, -1)),
    ((0, -1, 0), (-1, 0, 0), (0, 0, -1)),
    ((1, 0, 0), (0, -1, 0), (0, 0, -1)),
    ((0, 0, -1), (1, 0, 0), (0, -1, 0)),
)
ICQ_CUBE_FACES = 6


class ShapeFileError(SpinorbitError, ValueError):
    """A shape file that cannot be read: unknown records, wrong counts, numbers that are not numbers."""


def _file_unit(reader: str, unit) -> u.UnitBase:
    """The length unit a reader was given for the numbers of its file, checked."""
    if unit is None:
        raise QuantityInputError(f"{reader} expects the length unit of the file's numbers, which the file does not "
                                 f"state: {reader}(path, unit=u.km) (or u.m, ...); got no unit: units are never "
                                 "guessed.")
    try:
        unit = u.Unit(unit)
    except (TypeError, ValueError):
        raise QuantityInputError(f"{reader}: unit expects a length unit such as u.km; got {unit!r}, which astropy "
                                 "cannot read.") from None
    value_in("unit", 1.0 * unit, u.km, "u.km")  # a length, or the refusal naming what arrived
    return unit


def read_obj(path, unit=None, name=None) -> Shape:
    """Read a Wavefront OBJ file into a :class:`Shape`.

    Parameters
    ----------
    path : str or path-like
    unit : astropy unit of length
        The unit of the file's vertex coordinates (OBJ states none): ``u.km``, ``u.m``, or ``"km"``.
        Required; None is refused.
    name : str, optional
        The shape's name (default: the file's name without extension).

    Raises
    ------
    QuantityInputError
        No ``unit``, or one that is not a length.
    ShapeFileError
        A ``v`` line without three numbers, an ``f`` line with fewer than three indices or an index
        out of range, or a file with no faces.
    InvalidMeshError
        The surface is not closed and outward oriented (see :class:`Shape`).
    """
    unit = _file_unit("read_obj", unit)
    vertices, faces = [], []
    with open(path, encoding="utf-8") as stream:
        for number, line in enumerate(stream, start=1):
            words = line.split("#", 1)[0].split()
            if not words:
                continue
            if words[0] == "v":
                vertices.append(_obj_vertex(path, number, words))
            elif words[0] == "f":
                faces += _obj_face(path, number, words, len(vertices))
    if not faces:
        raise ShapeFileError(f"{path}: expected 'v x y z' and 'f i j k' lines of a Wavefront OBJ shape; found "
                             f"{len(vertices)} vertices and no faces. Is this an OBJ file (an ICQ file is read "
                             "with read_icq)?")
    return _shape(path, np.array(vertices) * unit, np.array(faces, dtype=np.int64), name)


def _obj_vertex(path, number, words):
    try:
        if len(words) < 4:
            raise ValueError
        values = [float(w) for w in words[1:4]]
    except ValueError:
        raise ShapeFileError(f"{path}, line {number}: expected 'v x y z' with three numbers; got "
                             f"{' '.join(words)!r}.") from None
    if not all(math.isfinite(v) for v in values):
        raise ShapeFileError(f"{path}, line {number}: expected 'v x y z' with three finite numbers; got "
                             f"{' '.join(words)!r} (NaN or inf is no position).")
    return values


def _obj_face(path, number, words, vertex_count):
    try:
        indices = [int(w.split("/")[0]) for w in words[1:]]
    except ValueError:
        raise ShapeFileError(f"{path}, line {number}: expected 'f i j k' with integer vertex indices; got "
                             f"{' '.join(words)!r}.") from None
    if len(indices) < 3:
        raise ShapeFileError(f"{path}, line {number}: a face needs at least three vertices; got {len(indices)}.")
    resolved = []
    for index in indices:
        position = index - 1 if index > 0 else vertex_count + index
        if index == 0 or not 0 <= position < vertex_count:
            raise ShapeFileError(f"{path}, line {number}: vertex index {index} does not name one of the "
                                 f"{vertex_count} vertices read so far (OBJ counts from 1; negative counts back).")
        resolved.append(position)
    return [(resolved[0], resolved[k], resolved[k + 1]) for k in range(1, len(resolved) - 1)]


def _shape(path, vertices, faces, name):
    try:
        return Shape(vertices, faces, name=name or os.path.splitext(os.path.basename(path))[0])
    except InvalidMeshError as error:
        raise InvalidMeshError(f"{path}: {error}") from None


def write_obj(path, shape: Shape, unit=u.km) -> None:
    """Write a Shape as a Wavefront OBJ file (coordinates in ``unit``, km by default, named in the header;
    17 significant digits; atomically). Read it back with ``read_obj(path, unit)``."""
    unit = _file_unit("write_obj", unit)
    values = shape.vertices.to_value(unit)
    lines = [f"# {shape.name or 'shape'}: {values.shape[0]} vertices, {len(shape)} faces, {unit.to_string()}\n"]
    lines += [f"v {x!r} {y!r} {z!r}\n" for x, y, z in values.tolist()]
    lines += [f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in shape.faces.tolist()]
    with atomic_path(path) as temporary, open(temporary, "w", encoding="utf-8") as stream:
        stream.writelines(lines)


def read_icq(path, unit=None, name=None) -> Shape:
    """Read an ICQ shape file into a :class:`Shape`.

    Parameters
    ----------
    path : str or path-like
    unit : astropy unit of length
        The unit of the file's coordinates (ICQ states none; Gaskell's SPC models are in km): ``u.km``.
        Required; None is refused.
    name : str, optional

    Raises
    ------
    QuantityInputError
        No ``unit``, or one that is not a length.
    ShapeFileError
        No integer q ≥ 1 on the first line, a line without three numbers, or a vertex count other
        than 6 (q + 1)².
    InvalidMeshError
        Shared cube-edge vertices that do not coincide, or a surface that is not closed.
    """
    unit = _file_unit("read_icq", unit)
    with open(path, encoding="utf-8") as stream:
        lines = stream.read().splitlines()
    try:
        q = int(lines[0].split()[0]) if lines else 0
    except (ValueError, IndexError):
        q = 0
    if q < 1:
        raise ShapeFileError(f"{path}, line 1: expected the ICQ resolution q (a positive integer); got "
                             f"{(lines[0] if lines else '')!r}. Is this an ICQ file (OBJ files are read with read_obj)?")
    rows = [line for line in lines[1:] if line.strip()]
    expected = ICQ_CUBE_FACES * (q + 1) ** 2
    if len(rows) != expected:
        raise ShapeFileError(f"{path}: an ICQ file with q = {q} has 6 (q + 1)² = {expected} vertex lines after the "
                             f"first; got {len(rows)}. The file is truncated or q is wrong.")
    grid = np.empty((expected, 3))
    for k, row in enumerate(rows):
        words = row.split()
        try:
            if len(words) != 3:
                raise ValueError
            grid[k] = [float(w) for w in words]
        except ValueError:
            raise ShapeFileError(f"{path}, vertex line {k + 1}: expected three numbers 'x y z'; got {row!r}.") from None
        if not np.all(np.isfinite(grid[k])):
            raise ShapeFileError(f"{path}, vertex line {k + 1}: expected three finite numbers 'x y z'; got {row!r} "
                                 "(NaN or inf is no position).")
    vertices, faces = icq_mesh(grid.reshape(ICQ_CUBE_FACES, q + 1, q + 1, 3) * unit, source=str(path))
    return _shape(path, vertices, faces, name)


def icq_mesh(grid, source="ICQ grid"):
    """Vertices and outward triangles of an ICQ grid, shared cube-edge vertices merged.

    Parameters
    ----------
    grid : Quantity (6, q + 1, q + 1, 3)
        grid[f, j, i] is vertex (i, j) of cube face f (a length).

    Returns
    -------
    vertices : Quantity (6 q² + 2, 3), km
    faces : ndarray (12 q², 3) int
    """
    grid = value_in("grid", grid, u.km, "grid_km * u.km")
    q = grid.shape[1] - 1
    flat = grid.reshape(-1, 3)
    vertices, inverse = np.unique(flat, axis=0, return_inverse=True)
    inverse = inverse.reshape(ICQ_CUBE_FACES, q + 1, q + 1)
    expected = 6 * q * q + 2
    if vertices.shape[0] != expected:
        raise InvalidMeshError(f"{source}: an ICQ grid with q = {q} has {expected} distinct vertices once the shared "
                               f"cube edges are merged; got {vertices.shape[0]}. The shared edge vertices must repeat "
                               "the same coordinates on each cube face (or two distinct vertices coincide).")
    corner = inverse[:, :-1, :-1]
    right = inverse[:, :-1, 1:]
    up = inverse[:, 1:, :-1]
    diagonal = inverse[:, 1:, 1:]
    faces = np.concatenate([np.stack([corner, right, diagonal], axis=-1).reshape(-1, 3),
                            np.stack([corner, diagonal, up], axis=-1).reshape(-1, 3)])
    a, b, c = (vertices[faces[:, k]] for k in range(3))
    if np.einsum("ij,ij->i", a, np.cross(b, c)).sum() < 0:  # the file's cube is mirrored: reverse every face
        faces = faces[:, ::-1]
    return vertices * u.km, np.ascontiguousarray(faces)


def icq_grid(radius_function, q):
    """An ICQ grid of a star-shaped body: vertex (i, j) of face f at radius_function(direction) · direction.

    Parameters
    ----------
    radius_function : callable
        Unit directions (k, 3) → radii (k,), a length Quantity.
    q : int
        Resolution (q × q cells per cube face).

    Returns
    -------
    Quantity (6, q + 1, q + 1, 3)
        km, in the layout of :func:`write_icq`.
    """
    steps = -1.0 + 2.0 * np.arange(q + 1) / q
    grid = np.empty((ICQ_CUBE_FACES, q + 1, q + 1, 3))
    for f, (centre, e1, e2) in enumerate(ICQ_FACE_FRAMES):
        cube = (np.array(centre, float) + steps[None, :, None] * np.array(e1, float)
                + steps[:, None, None] * np.array(e2, float))
        directions = cube / np.linalg.norm(cube, axis=-1, keepdims=True)
        radii = value_in("radius_function's radii", radius_function(directions.reshape(-1, 3)), u.km,
                         "np.ones(len(directions)) * u.km")
        grid[f] = directions * np.asarray(radii).reshape(q + 1, q + 1, 1)
    # Shared edges: the same float on every cube face (the cube coordinates are ±1 and k/q exactly
    # for each face, but the normalisation may differ in the last bit: take one face's value).
    vertices, inverse = np.unique(np.round(grid.reshape(-1, 3), 12), axis=0, return_inverse=True)
    first = np.full(vertices.shape[0], -1)
    flat = grid.reshape(-1, 3)
    for k, group in enumerate(inverse.ravel()):
        if first[group] < 0:
            first[group] = k
    return flat[first[inverse.ravel()]].reshape(grid.shape) * u.km


def write_icq(path, grid, unit=u.km) -> None:
    """Write an ICQ grid (a length Quantity of shape (6, q + 1, q + 1, 3)) as an ICQ file with coordinates in
    ``unit`` (km by default; atomically). Read it back with ``read_icq(path, unit)``."""
    unit = _file_unit("write_icq", unit)
    grid = np.asarray(value_in("grid", grid, unit, "grid_km * u.km"), dtype=float)
    if grid.ndim != 4 or grid.shape[0] != ICQ_CUBE_FACES or grid.shape[1] != grid.shape[2] or grid.shape[3] != 3:
        raise ValueError(f"grid: expected shape (6, q + 1, q + 1, 3) (cube face, j, i, xyz); got {grid.shape}.")
    lines = [f"{grid.shape[1] - 1:>8d}\n"] + [f"{x!r} {y!r} {z!r}\n" for x, y, z in grid.reshape(-1, 3).tolist()]
    with atomic_path(path) as temporary, open(temporary, "w", encoding="utf-8") as stream:
        stream.writelines(lines)
