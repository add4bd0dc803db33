"""Torque-free rotation in closed form: the exact flow, with no integration.

- :mod:`.flow` — the free flow of any triaxial body in every mode (eq. 12: one angle linear in time);
- :mod:`.regular_precession` — axisymmetric bodies in closed form;
- :mod:`.summary` — mode, sense, periods and energy ratio of a free motion.
"""
