"""Disk-integrated phase functions: H, G1, G2 (Muinonen et al. 2010) and Kaasalainen's linear-exponential.

**H, G1, G2** (Muinonen et al. 2010, Icarus 209, 542) as sbpy defines it
(``sbpy.photometry.HG1G2``): the reduced magnitude is H − 2.5 log₁₀ Φ(α) with

    Φ(α) = G1 Φ1(α) + G2 Φ2(α) + (1 − G1 − G2) Φ3(α),

each basis function a cubic spline through Muinonen et al.'s nodes with their end slopes, continued
by straight lines beyond the end nodes and clipped at 0 (so Φ1 = 1 − 6α/π and Φ2 = 1 − 9α/(5π)
below 7.5°, and Φ3 = 0 beyond 30°). :data:`HG1G2_NODES` holds the nodes (radians) as sbpy has them.

**Linear-exponential** (Kaasalainen, Torppa & Muinonen 2001, Icarus 153, 37): the factor
f(α) = A₀ exp(−α/D) + kα + 1 that multiplies the scattering law; A₀ is the opposition surge's
amplitude, D its width (radians) and k the slope (per radian, negative for a darkening body).
"""


import numpy as np

__all__ = ["HG1G2_NODES", "ClampedSpline", "hg1g2_basis", "hg1g2_phase", "linear_exponential"]

#: (nodes α (rad), values, (slope at the first node, slope at the last)) of Φ1, Φ2, Φ3 (Muinonen et al.
#: 2010; the numbers of sbpy.photometry.iau.HG12BaseClass).
HG1G2_NODES = (
    (np.radians([7.5, 30.0, 60.0, 90.0, 120.0, 150.0]),
     np.array([7.5e-1, 3.3486016e-1, 1.3410560e-1, 5.1104756e-2, 2.1465687e-2, 3.6396989e-3]),
     (-1.9098593, -9.1328612e-2)),
    (np.radians([7.5, 30.0, 60.0, 90.0, 120.0, 150.0]),
     np.array([9.25e-1, 6.2884169e-1, 3.1755495e-1, 1.2716367e-1, 2.2373903e-2, 1.6505689e-4]),
     (-5.7295780e-1, -8.6573138e-8)),
    (np.radians([0.0, 0.3, 1.0, 2.0, 4.0, 8.0, 12.0, 20.0, 30.0]),
     np.array([1.0, 8.3381185e-1, 5.7735424e-1, 4.2144772e-1, 2.3174230e-1, 1.0348178e-1, 6.1733473e-2,
               1.6107006e-2, 0.0]),
     (-1.0630097, 0.0)),
)


class ClampedSpline:
    """The cubic spline through (x_i, y_i) with given first derivatives at both ends, straight beyond them.

    The interior node slopes solve the tridiagonal system of C² continuity (de Boor 1978, ch. IV), and
    each interval is the cubic Hermite polynomial of its two values and slopes.
    """

    def __init__(self, x, y, end_slopes):
        x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
        h, r = np.diff(x), np.diff(y) / np.diff(x)
        n = x.size
        matrix, rhs = np.zeros((n - 2, n - 2)), np.zeros(n - 2)
        for i in range(1, n - 1):  # h_i s_{i−1} + 2(h_{i−1} + h_i) s_i + h_{i−1} s_{i+1} = 3(r_{i−1} h_i + r_i h_{i−1})
            row = i - 1
            matrix[row, row] = 2.0 * (h[i - 1] + h[i])
            rhs[row] = 3.0 * (r[i - 1] * h[i] + r[i] * h[i - 1])
            if i > 1:
                matrix[row, row - 1] = h[i]
            else:
                rhs[row] -= h[i] * end_slopes[0]
            if i < n - 2:
                matrix[row, row + 1] = h[i - 1]
            else:
                rhs[row] -= h[i - 1] * end_slopes[1]
        slopes = np.concatenate([[end_slopes[0]], np.linalg.solve(matrix, rhs), [end_slopes[1]]])
        self.x, self.y, self.slopes = x, y, slopes
        self.c2 = (3.0 * r - 2.0 * slopes[:-1] - slopes[1:]) / h
        self.c3 = (slopes[:-1] + slopes[1:] - 2.0 * r) / h**2

    def __call__(self, alpha):
        alpha = np.asarray(alpha, dtype=float)
        i = np.clip(np.searchsorted(self.x, alpha, side="right") - 1, 0, self.x.size - 2)
        t = alpha - self.x[i]
        inside = self.y[i] + t * (self.slopes[i] + t * (self.c2[i] + t * self.c3[i]))
        below = self.y[0] + (alpha - self.x[0]) * self.slopes[0]
        above = self.y[-1] + (alpha - self.x[-1]) * self.slopes[-1]
        return np.where(alpha < self.x[0], below, np.where(alpha >= self.x[-1], above, inside))


_BASIS = tuple(ClampedSpline(*nodes) for nodes in HG1G2_NODES)


def hg1g2_basis(phase_angle):
    """(Φ1, Φ2, Φ3) at the phase angle α (radians), each clipped at 0 (module docstring)."""
    return tuple(np.maximum(spline(phase_angle), 0.0) for spline in _BASIS)


def hg1g2_phase(phase_angle, g1, g2):
    """Φ(α) = G1 Φ1 + G2 Φ2 + (1 − G1 − G2) Φ3: the disk-integrated brightness relative to α = 0."""
    phi1, phi2, phi3 = hg1g2_basis(phase_angle)
    return g1 * phi1 + g2 * phi2 + (1.0 - g1 - g2) * phi3


def linear_exponential(phase_angle, amplitude, width, slope):
    """f(α) = A₀ exp(−α/D) + kα + 1 (α and D in radians, k per radian; Kaasalainen et al. 2001)."""
    alpha = np.asarray(phase_angle, dtype=float)
    return amplitude * np.exp(-alpha / width) + slope * alpha + 1.0
