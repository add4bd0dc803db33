"""Real bodies with published states and orbits, and where each number came from.

- :mod:`.asteroids` — (99942) Apophis (JPL#218) and (4179) Toutatis.
- :mod:`.didymos` — Didymos and Dimorphos, the full-two-body example case of GUBAS;
- :mod:`.dart` — Didymos and Dimorphos from the published values, before and after DART's impact.
"""
