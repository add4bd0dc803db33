"""Torque-free rotation in closed form: the exact flow, with no integration.

- :mod:`.flow_constants` — the set-up of the free flow: the double-double constants of one motion,
  formed once per state (the ``FL_*`` layout);
- :mod:`.flow` — the free flow of any triaxial body in every mode (eq. 12: one angle linear in time),
  evaluated at each time and looped over states and times;
- :mod:`.regular_precession` — axisymmetric bodies in closed form;
- :mod:`.summary` — mode, sense, periods and energy ratio of a free motion;
- :mod:`.members` — many members at once, each with its own moments and times (ensembles).
"""
