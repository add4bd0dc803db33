"""The fast core: plain floats, numpy and numba only.

Nothing under ``spinorbit.core`` imports astropy, skyfield or rebound (a test enforces this), so the
core can be called from numba-compiled loops and from REBOUND callbacks without Python overhead.
"""
