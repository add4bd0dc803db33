"""REBOUND behind one door: every ``import rebound``, raw pointer, struct offset and compiled callback.

Only the modules of this package import ``rebound`` or ``ctypes`` (``tests/test_architecture.py``
checks it); the rest of spinorbit uses the names exported here. Each module holds one concept:

- :mod:`~spinorbit.coupling.rebound.memory_layout`: REBOUND's struct offsets, field types and the
  numba pointer casts the callbacks read memory with;
- :mod:`~spinorbit.coupling.rebound.simulation`: a ``rebound.Simulation`` from DE421, particles by
  name, perturber positions read from the particle array;
- :mod:`~spinorbit.coupling.rebound.extra_forces`: the compiled EIH + Earth-J2 + non-gravitational
  force, installed as a raw C pointer;
- :mod:`~spinorbit.coupling.rebound.rotation_hooks`: a rigid body's rotation integrated with the
  orbits (BS user ODE and back-reaction; the IAS15 pseudo-particle route);
- :mod:`~spinorbit.coupling.rebound.small_body`: a massless small body among DE421's planets with
  the force model of the Apophis orbit (EIH, Earth J2, its own non-gravitational terms);
- :mod:`~spinorbit.coupling.rebound.snapshot`: copies of a simulation (binary, names, forces in effect);
- :mod:`~spinorbit.coupling.rebound.interrupts`: Ctrl-C across many ``integrate`` calls.

Units: DE421 simulations are in ("AU", "day", "Msun"), ``t`` in TDB days since J2000 (``docs/coupling.md``).
"""

from spinorbit.coupling.rebound.extra_forces import (
    ExtraForces,
    ForceInstallError,
    install_extra_forces,
    reinstall_extra_forces,
    set_nongravitational,
)
from spinorbit.coupling.rebound.interrupts import integrate_interruptibly, step_interruptibly
from spinorbit.coupling.rebound.rotation_hooks import (
    MAX_PERTURBERS,
    ROTATION_STATE_SIZE,
    PseudoParticleHooks,
    RotationCallbackError,
    RotationHooks,
    attach_rotation_hooks,
    attach_rotation_ias15,
)
from spinorbit.coupling.rebound.simulation import (
    DEFAULT_BODIES,
    MissingBodyError,
    body_index,
    perturber_positions,
    simulation_from_de421,
)
from spinorbit.coupling.rebound.small_body import CENTRES, small_body_simulation
from spinorbit.coupling.rebound.snapshot import (
    SimulationSnapshot,
    extra_forces_in_effect,
    simulation_binary,
    simulation_from_binary,
)

__all__ = [
    "DEFAULT_BODIES",
    "MissingBodyError",
    "ForceInstallError",
    "ExtraForces",
    "simulation_from_de421",
    "install_extra_forces",
    "set_nongravitational",
    "reinstall_extra_forces",
    "extra_forces_in_effect",
    "body_index",
    "perturber_positions",
    "RotationCallbackError",
    "RotationHooks",
    "attach_rotation_hooks",
    "PseudoParticleHooks",
    "attach_rotation_ias15",
    "MAX_PERTURBERS",
    "ROTATION_STATE_SIZE",
    "integrate_interruptibly",
    "step_interruptibly",
    "simulation_binary",
    "simulation_from_binary",
    "SimulationSnapshot",
    "CENTRES",
    "small_body_simulation",
]
