"""Photometry: how bright a rotating body looks (issue 38; ``docs/photometry.md``).

The plain-float kernels are in :mod:`spinorbit.core.photometry`; this package is their units layer.

- :mod:`.brightness` — the kernel's door, :func:`brightness`: the disk-integrated brightness of a
  shape (facets or an :class:`Ellipsoid`) for body-frame Sun and observer directions, in km², with
  the Lommel–Seeliger, Lambert and Kaasalainen laws, self-shadowing on non-convex shapes;
- :mod:`.errors` — the layer's error types.
"""

from spinorbit.photometry.brightness import Ellipsoid, brightness, shadowing_decision
from spinorbit.photometry.errors import InvalidDirectionsError, PhotometryError

__all__ = ["Ellipsoid", "InvalidDirectionsError", "PhotometryError", "brightness", "shadowing_decision"]
