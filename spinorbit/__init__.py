"""spinorbit: rotation of rigid bodies coupled to their orbits.

The front door. Public names are listed here; everything else is an implementation detail.
"""

__version__ = "0.1.0.dev0"

__all__ = ["__version__"]
