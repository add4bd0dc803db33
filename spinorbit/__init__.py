"""spinorbit: rotation of rigid bodies coupled to their orbits.

The front door. Public names are listed here; everything else is an implementation detail.

- :class:`RigidBody` — principal moments and the axes that go with them.
- :class:`RotationState` — attitude and spin; mode, periods, canonical elements, exact free motion.
- :mod:`spinorbit.scene` — :class:`~spinorbit.scene.Scene`, a run described declaratively (body,
  perturbers, orbit, times, tolerance); its ``plan()`` says how it will run and why, ``run()`` does it.
- :mod:`spinorbit.ensemble` — :class:`~spinorbit.ensemble.Ensemble`, many Scenes from a table of
  parameters, on any executor, one outcome table.
- :mod:`spinorbit.special` — elliptic functions and integrals for every parameter m ≥ 0.
- :mod:`spinorbit.core` — the plain-float core (paper-named maps ``andoyer_to_canonical`` and
  ``canonical_to_andoyer``).
"""

__version__ = "0.1.0.dev0"

# The front door is lazy (PEP 562): importing ``spinorbit.core`` — e.g. inside a REBOUND callback or a
# numba-only worker — must not pull in astropy through this package's __init__.
_PUBLIC = {
    "RigidBody": ".body",
    "InvalidBodyError": ".body",
    "RotationState": ".state",
    "CanonicalElements": ".state",
    "InvalidStateError": ".state",
    "SingularElementsError": ".core.errors",
    "SpinorbitError": ".core.errors",
    "NonFiniteError": ".core.errors",
    "InputError": ".core.errors",
}

__all__ = [*_PUBLIC, "__version__"]


def __getattr__(name):
    if name in _PUBLIC:
        import importlib

        return getattr(importlib.import_module(_PUBLIC[name], __name__), name)
    raise AttributeError(f"module 'spinorbit' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
