"""The fast core: plain floats, numpy and numba only.

Nothing under ``spinorbit.core`` imports astropy, skyfield or rebound (``tests/test_architecture.py``
enforces it), so the core can be called from numba-compiled loops and from REBOUND callbacks without
Python overhead. Its folders are layers, each importing only the ones before it
(``docs/architecture.md``): ``math`` → ``model`` → ``dynamics`` → ``elements`` → ``free_motion`` →
``integrators`` → ``averaging`` → ``binary``.

The stable entry points, importable from here (scripts written against them keep working):

- the paper's maps :func:`andoyer_to_canonical` (Fukushima eq. 4) and :func:`canonical_to_andoyer`
  (eqs. 7–8);
- the exact torque-free flow (eq. 12) of one or many states: :func:`torque_free_states`,
  :func:`torque_free_states_many`;
- the model builder :func:`make_model` and the perturber sources :func:`fixed_source`,
  :func:`kepler_source`, :func:`sampled_source`, :func:`sampled_source_from_callable`;
- each integrator: :func:`integrate_quaternion` (and :func:`integrate_quaternion_batch` for many members), :func:`integrate_elements`, :func:`integrate_taylor` (and
  :func:`integrate_taylor_batch`),
  :func:`integrate_splitting`, :func:`integrate_with_handover`, :func:`propagate_averaged`;
- state transition matrices and moment-ratio sensitivities: :func:`free_flow_stm` (exact, through
  the elements), :func:`integrate_variational` (DOP853 with its variational equations) and
  :func:`integrate_taylor_variational` (the Taylor method with the recurrences of its variational equations),
  and :func:`mean_elements_stm`, :func:`osculating_elements_stm` (the averaged propagator's mean and
  osculating elements);
- the full two-body problem of a binary asteroid: :func:`make_binary_model` (the mutual potential's
  model array) and :func:`propagate_binary` (relative orbit and both attitudes, DOP853).

They load on first use (PEP 562), so importing one integrator does not import the others. The errors
the core raises are defined in :mod:`spinorbit.core.errors` and exported by the front door
(``from spinorbit import SingularElementsError``; that import loads no astropy either).
"""

import importlib

_ENTRY_POINTS = {
    "andoyer_to_canonical": "spinorbit.core.elements.paper_maps",
    "canonical_to_andoyer": "spinorbit.core.elements.paper_maps",
    "torque_free_states": "spinorbit.core.free_motion.flow",
    "torque_free_states_many": "spinorbit.core.free_motion.flow",
    "make_model": "spinorbit.core.dynamics.equations",
    "fixed_source": "spinorbit.core.model.perturbers",
    "kepler_source": "spinorbit.core.model.perturbers",
    "sampled_source": "spinorbit.core.model.perturbers",
    "sampled_source_from_callable": "spinorbit.core.model.perturbers",
    "integrate_quaternion": "spinorbit.core.integrators.quaternion",
    "integrate_quaternion_batch": "spinorbit.core.integrators.batch_quaternion",
    "integrate_elements": "spinorbit.core.integrators.elements",
    "integrate_taylor": "spinorbit.core.integrators.taylor",
    "integrate_taylor_batch": "spinorbit.core.integrators.batch_taylor",
    "integrate_splitting": "spinorbit.core.integrators.splitting",
    "integrate_with_handover": "spinorbit.core.integrators.handover",
    "propagate_averaged": "spinorbit.core.averaging.propagate",
    "free_flow_stm": "spinorbit.core.free_motion.stm",
    "integrate_variational": "spinorbit.core.integrators.variational",
    "integrate_taylor_variational": "spinorbit.core.integrators.taylor_variational",
    "mean_elements_stm": "spinorbit.core.averaging.mean_variational",
    "osculating_elements_stm": "spinorbit.core.averaging.mean_variational",
    "make_binary_model": "spinorbit.core.binary.equations",
    "propagate_binary": "spinorbit.core.binary.propagate",
}

__all__ = list(_ENTRY_POINTS)


def __getattr__(name):
    if name in _ENTRY_POINTS:
        value = getattr(importlib.import_module(_ENTRY_POINTS[name]), name)
        globals()[name] = value  # later look-ups skip this function
        return value
    raise AttributeError(f"module 'spinorbit.core' has no attribute {name!r}")


def __dir__():
    return sorted(__all__)
