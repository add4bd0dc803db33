"""What acts on a body: its figure's gravity field and the perturbers' positions.

- :mod:`.gravity_field` — the body's figure (moments, Stokes coefficients to degree 4) and its
  force function U and gradient;
- :mod:`.perturbers` — perturber sources (fixed, Kepler, sampled Hermite) packed into one flat array;
- :mod:`.lunar_interior` — the Moon of the JPL ephemerides: elastic mantle with tides, fluid core.

A model array is built by :func:`spinorbit.core.dynamics.equations.make_model` from these pieces.
"""
