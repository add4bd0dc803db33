"""Fukushima's canonical elements of rotational motion and the Andoyer variables under them.

- :mod:`.andoyer` — Andoyer (Serret–Andoyer) variables from an attitude and angular momentum;
- :mod:`.canonical` — the elliptic set-up: rotation mode, parameter m, constants of the free motion;
- :mod:`.paper_maps` — the paper's maps :func:`andoyer_to_canonical` (eq. 4) and
  :func:`canonical_to_andoyer` (eqs. 7–8);
- :mod:`.jacobian` — the Jacobian of section 4, ∂(Andoyer)/∂(canonical);
- :mod:`.equations` — the equations of motion of the elements under a torque (Hamilton's equations
  of the force function in the elements).
"""

