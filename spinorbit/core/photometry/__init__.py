"""Disk-integrated brightness of a shape: the plain-float kernels of :mod:`spinorbit.photometry`.

- :mod:`.scattering` — the scattering laws (Lommel–Seeliger, Lambert, Kaasalainen et al. 2001) and the
  compiled facet sum over facets × epochs, eight epochs per SIMD register;
- :mod:`.phase_functions` — H, G1, G2 (Muinonen et al. 2010, as sbpy defines it) and Kaasalainen's
  linear-exponential factor;
- :mod:`.ellipsoid` — the closed forms the facet sum is validated against: the Lommel–Seeliger ellipsoid
  at any geometry (Muinonen & Lumme 2015), the Lambertian ellipsoid at opposition, and both spheres'
  phase integrals.

Directions are unit 3-vectors in the body frame; areas are in the square of the shape's length unit,
so a brightness is an area (``docs/photometry.md``, "Units").
"""
