"""Old import paths, kept for one release with a :class:`DeprecationWarning`.

The package was reorganised by concept (``docs/architecture.md``). Scripts written against the flat
layout (``spinorbit.core.integrate_quaternion``, ``spinorbit.checkpoint``, …) keep working: a finder
on :data:`sys.meta_path` answers each old name in :data:`MOVED_MODULES` with the module that now owns
the concept, after one warning naming the new path. The table is the one place that knows the old
layout; remove it, and this module, in the release after 0.1.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import sys
import types
import warnings

#: Old module path -> the module(s) that now hold its public names (searched in order).
MOVED_MODULES: dict[str, tuple[str, ...]] = {
    "spinorbit.core._jit": ("spinorbit.core.jit",),
    "spinorbit.core.ddouble": ("spinorbit.core.math.ddouble",),
    "spinorbit.core.elliptic": ("spinorbit.core.math.elliptic", "spinorbit.core.math.carlson",
                                "spinorbit.core.math.elliptic_periods", "spinorbit.core.math.jacobi",
                                "spinorbit.core.math.elliptic_integrals"),
    "spinorbit.core.rotations": ("spinorbit.core.math.rotations",),
    "spinorbit.core.gravity_field": ("spinorbit.core.model.gravity_field",),
    "spinorbit.core.perturbers": ("spinorbit.core.model.perturbers",),
    "spinorbit.core.lunar_interior": ("spinorbit.core.model.lunar_interior",),
    "spinorbit.core.andoyer": ("spinorbit.core.elements.andoyer",),
    "spinorbit.core.canonical": ("spinorbit.core.elements.canonical",),
    "spinorbit.core.jacobian": ("spinorbit.core.elements.jacobian",),
    "spinorbit.core.element_forces": ("spinorbit.core.elements.equations",),
    "spinorbit.core.torque_free": ("spinorbit.core.free_motion.flow", "spinorbit.core.free_motion.flow_constants"),
    "spinorbit.core.regular_precession": ("spinorbit.core.free_motion.regular_precession",),
    "spinorbit.core.motion_summary": ("spinorbit.core.free_motion.summary",),
    "spinorbit.core._dop853_tableau": ("spinorbit.core.integrators.dop853_tableau",),
    "spinorbit.core.integrate_quaternion": ("spinorbit.core.integrators.quaternion", "spinorbit.core.integrators.dop853"),
    "spinorbit.core.integrate_elements": ("spinorbit.core.integrators.elements", "spinorbit.core.integrators.dop853"),
    "spinorbit.core.integrate_taylor": ("spinorbit.core.integrators.taylor", "spinorbit.core.integrators.taylor_recurrences"),
    "spinorbit.core.integrate_splitting": ("spinorbit.core.integrators.splitting",),
    "spinorbit.core.integrate_handover": ("spinorbit.core.integrators.handover",),
    "spinorbit.core.averaged": ("spinorbit.core.averaging.mean_equations",),
    "spinorbit.core.short_period": ("spinorbit.core.averaging.short_period",),
    "spinorbit.core.propagate_averaged": ("spinorbit.core.averaging.propagate",),
    "spinorbit.planner": ("spinorbit.scene.bounds", "spinorbit.scene.plan", "spinorbit.scene.tolerances"),
    "spinorbit.scene_bodies": ("spinorbit.scene.many",),
    "spinorbit.atomic": ("spinorbit.runs.atomic",),
    "spinorbit.checkpoint": ("spinorbit.runs.checkpoint",),
    "spinorbit.resumable": ("spinorbit.runs.resumable",),
    "spinorbit.asteroids": ("spinorbit.data.asteroids",),
    # The adapter is split by concept (simulation, extra_forces, rotation_hooks, snapshot, interrupts);
    # its door exports every public name the adapter had.
    "spinorbit.coupling.chunked_run": ("spinorbit.coupling.long_run",),
}

#: Old modules whose path is now a package, or a module that gave names away: the names it does not
#: hold itself are forwarded by its ``__getattr__`` (:func:`forward_attribute`).
MOVED_NAMES: dict[str, tuple[str, ...]] = {
    "spinorbit.core.dynamics": ("spinorbit.core.dynamics.equations", "spinorbit.core.dynamics.validation"),
    "spinorbit.core.elements": ("spinorbit.core.elements.paper_maps",),
    "spinorbit.scene": ("spinorbit.scene.scene", "spinorbit.scene.inputs", "spinorbit.scene.integrator_choice",
                        "spinorbit.scene.tolerances", "spinorbit.scene.plan", "spinorbit.scene.bounds"),
    # A module that kept its path but lost the sampler to spinorbit.coupling.sampling.
    "spinorbit.coupling.one_way": ("spinorbit.coupling.rebound", "spinorbit.coupling.sampling"),
}


def _warn(old: str, new: str) -> None:
    # Point the warning at the user's import line. warnings.warn itself skips importlib's frames
    # when it counts stacklevel, so only this file's frames and a package __getattr__ are counted.
    frame, level = sys._getframe(1), 2
    while frame is not None:
        code = frame.f_code
        if code.co_filename == __file__ or code.co_name == "__getattr__":
            level += 1
        elif not code.co_filename.startswith("<frozen importlib"):
            break
        frame = frame.f_back
    warnings.warn(f"{old} has moved to {new}; the old path will be removed in the next release "
                  f"(docs/architecture.md)", DeprecationWarning, stacklevel=level)


def _lookup(modules: tuple[str, ...], name: str):
    for module_name in modules:
        module = importlib.import_module(module_name)
        if hasattr(module, name):
            return module_name, getattr(module, name)
    return None, None


class _MovedModules(types.ModuleType):
    """Stands at an old path whose names now live in several modules."""

    def __init__(self, old: str, new: tuple[str, ...]):
        super().__init__(old, f"Moved: see {', '.join(new)}.")
        self._new = new

    def __getattr__(self, name: str):
        where, value = _lookup(self._new, name)
        if where is None:
            raise AttributeError(f"module {self.__name__!r} (moved to {', '.join(self._new)}) has no attribute {name!r}")
        return value


class _Loader(importlib.abc.Loader):
    def create_module(self, spec):
        new = MOVED_MODULES[spec.name]
        _warn(spec.name, " and ".join(new))
        if len(new) == 1:
            return importlib.import_module(new[0])
        return _MovedModules(spec.name, new)

    def exec_module(self, module):
        pass


class _Finder(importlib.abc.MetaPathFinder):
    def find_spec(self, fullname, path, target=None):
        if fullname in MOVED_MODULES:
            return importlib.machinery.ModuleSpec(fullname, _Loader())
        return None


def install() -> None:
    """Put the finder on :data:`sys.meta_path` once (called by ``spinorbit/__init__.py``)."""
    if not any(isinstance(finder, _Finder) for finder in sys.meta_path):
        sys.meta_path.insert(0, _Finder())


def forward_attribute(package: str, name: str):
    """``__getattr__`` of a package that replaced a module: forward an old name with a warning.

    The name is then set on the package, so the warning is given once, not at every look-up.
    """
    where, value = _lookup(MOVED_NAMES[package], name)
    if where is None:
        raise AttributeError(f"module {package!r} has no attribute {name!r}")
    _warn(f"{package}.{name}", f"{where}.{name}")
    setattr(sys.modules[package], name, value)
    return value
