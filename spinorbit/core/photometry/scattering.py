"""Scattering laws and the facet sum of a shape's disk-integrated brightness.

A facet k of area A_k and outward unit normal n_k, lit from the body-frame unit direction ŝ of the
Sun and seen from the unit direction ô of the observer, has μ₀ = n_k·ŝ and μ = n_k·ô. On a convex
surface it contributes when both are positive, and the disk-integrated brightness is::

    L(ŝ, ô) = Σ_k A_k S(μ₀, μ)  over the facets with μ₀ > 0 and μ > 0,

with the laws of Kaasalainen, Torppa & Muinonen (2001, Icarus 153, 37: their law without its phase
factor f(α), which :mod:`spinorbit.photometry` applies to the whole sum)::

    Lommel–Seeliger  S = μ μ₀ / (μ + μ₀)
    Lambert          S = μ μ₀
    Kaasalainen      S = μ μ₀ / (μ + μ₀) + c μ μ₀      (c: the Lambert weight, 0.1 in their paper)

all three as S = μ μ₀ (w_LS / (μ + μ₀) + w_L). L has the unit of A_k (an area): the flux that
reaches an observer at distance Δ, for an incident solar flux F☉, is F☉ (ϖ/4π) L / Δ² for a
Lommel–Seeliger surface of single-scattering albedo ϖ and F☉ (A_L/π) L / Δ² for a Lambert surface
of albedo A_L, so ratios of L are ratios of flux.

**Speed.** The sum runs over epochs in groups of sixteen (two :class:`~spinorbit.core.math.lanes.Lanes`
of eight) and over all facets for each group: a facet's normal and area are loaded once per sixteen
epochs, the two accumulators are independent chains, and the tests μ > 0, μ₀ > 0 are lane masks, so
the loop has no branch (``benchmarks/bench_photometry.py``).
"""

import numpy as np

from spinorbit.core.jit import jit
from spinorbit.core.math.lanes import broadcast, load_lanes, select, store_lanes

__all__ = ["LAWS", "EPOCH_GROUP", "DEFAULT_LAMBERT_WEIGHT", "law_weights", "facet_sum", "facet_sum_kernel",
           "padded_columns"]

#: The laws by name, and the weights (w_LS, w_L) of S = μ μ₀ (w_LS/(μ + μ₀) + w_L); Kaasalainen's
#: Lambert weight is the argument c of :func:`law_weights`.
LAWS = ("lommel-seeliger", "lambert", "kaasalainen")
#: The Lambert weight c of Kaasalainen et al. (2001), who take c = 0.1.
DEFAULT_LAMBERT_WEIGHT = 0.1
#: Epochs per pass over the facets: two registers of eight doubles.
EPOCH_GROUP = 16


def law_weights(law, lambert_weight=DEFAULT_LAMBERT_WEIGHT):
    """(w_LS, w_L) of a law by name (:data:`LAWS`); ``lambert_weight`` is c of "kaasalainen" only.

    Raises
    ------
    ValueError
        An unknown law, or a Kaasalainen weight c that is negative or not finite.
    """
    if law == "lommel-seeliger":
        return 1.0, 0.0
    if law == "lambert":
        return 0.0, 1.0
    if law == "kaasalainen":
        c = float(lambert_weight)
        if not (np.isfinite(c) and c >= 0.0):
            raise ValueError(f"lambert_weight: expected a finite c ≥ 0 (Kaasalainen et al. 2001: S_LS + c S_L, "
                             f"c ≈ 0.1); got {lambert_weight!r}.")
        return 1.0, c
    raise ValueError(f"law: expected one of {', '.join(repr(name) for name in LAWS)}; got {law!r}.")


@jit
def facet_sum_kernel(nx, ny, nz, areas, sx, sy, sz, ox, oy, oz, w_ls, w_l, out):
    """out[j] = Σ_k A_k S(n_k·ŝ_j, n_k·ô_j) (module docstring), facets with both cosines positive.

    Structure-of-arrays input: facet normals (nx, ny, nz) and areas (m,); Sun and observer directions
    (sx, sy, sz), (ox, oy, oz) and ``out`` of a length that is a multiple of :data:`EPOCH_GROUP`
    (pad with zero vectors: they contribute nothing).
    """
    for g in range(0, sx.shape[0], EPOCH_GROUP):
        sx0, sy0, sz0 = load_lanes(sx, g), load_lanes(sy, g), load_lanes(sz, g)
        ox0, oy0, oz0 = load_lanes(ox, g), load_lanes(oy, g), load_lanes(oz, g)
        h = g + 8
        sx1, sy1, sz1 = load_lanes(sx, h), load_lanes(sy, h), load_lanes(sz, h)
        ox1, oy1, oz1 = load_lanes(ox, h), load_lanes(oy, h), load_lanes(oz, h)
        total0 = broadcast(0.0)
        total1 = broadcast(0.0)
        for k in range(nx.shape[0]):
            ax, ay, az, area = nx[k], ny[k], nz[k], areas[k]
            # A masked-off lane may divide 0 by 0; select discards it (error_model="numpy": no trap).
            mu0 = ax * sx0 + ay * sy0 + az * sz0
            mu = ax * ox0 + ay * oy0 + az * oz0
            total0 = total0 + select((mu > 0.0) & (mu0 > 0.0), area * mu * mu0 * (w_ls / (mu + mu0) + w_l), 0.0)
            mu0 = ax * sx1 + ay * sy1 + az * sz1
            mu = ax * ox1 + ay * oy1 + az * oz1
            total1 = total1 + select((mu > 0.0) & (mu0 > 0.0), area * mu * mu0 * (w_ls / (mu + mu0) + w_l), 0.0)
        store_lanes(out, g, total0)
        store_lanes(out, h, total1)


def padded_columns(vectors, length):
    """The three columns of (n, 3) ``vectors`` as C-contiguous arrays of ``length`` ≥ n, zero-padded."""
    columns = np.zeros((3, length))
    columns[:, : vectors.shape[0]] = vectors.T
    return columns[0], columns[1], columns[2]


def facet_sum(normals, areas, sun_directions, observer_directions, w_ls, w_l):
    """L_j = Σ_k A_k S(n_k·ŝ_j, n_k·ô_j) for every epoch j: the facet sum of a convex surface.

    Parameters
    ----------
    normals : ndarray (m, 3)
        Outward unit normals of the facets (body frame).
    areas : ndarray (m,)
        Facet areas (any unit; L has that unit).
    sun_directions, observer_directions : ndarray (n, 3)
        Unit vectors from the body to the Sun and to the observer (body frame), checked by the caller.
    w_ls, w_l : float
        The law's weights (:func:`law_weights`).

    Returns
    -------
    ndarray (n,)
        L in the unit of ``areas``; 0 where no facet faces both the Sun and the observer.
    """
    n = sun_directions.shape[0]
    length = -(-n // EPOCH_GROUP) * EPOCH_GROUP
    out = np.empty(length)
    nx, ny, nz = (np.ascontiguousarray(normals[:, i], dtype=float) for i in range(3))
    facet_sum_kernel(nx, ny, nz, np.ascontiguousarray(areas, dtype=float), *padded_columns(sun_directions, length),
                     *padded_columns(observer_directions, length), float(w_ls), float(w_l), out)
    return out[:n]
