"""Long spans: the rotation averaged away, mean canonical elements propagated.

- :mod:`.mean_equations` — the averaged equations over the (s, z) torus of the free motion;
- :mod:`.short_period` — the short-period corrections between mean and osculating elements;
- :mod:`.propagate` — :func:`~spinorbit.core.averaging.propagate.propagate_averaged`, with the
  hand-over to the full integrator where averaging fails (``docs/averaged.md``).
"""
