"""REBOUND's memory as the compiled callbacks see it: struct offsets, field types, pointer casts.

Every offset is read from rebound's own ctypes declarations (not hard-coded), so that a REBOUND
version with another layout changes these numbers instead of corrupting memory. The callbacks view
``struct reb_simulation`` and ``struct reb_ode`` as arrays of 64-bit words and a particle array as
float64 words; the names below are word (or byte, where it says so) offsets into those views.

The numba intrinsics at the end reinterpret integers as pointers and 64-bit words as doubles: numba
has no native cast for either. Only modules of :mod:`spinorbit.coupling.rebound` use this module.
"""

from __future__ import annotations

import ctypes

import numpy as np
import rebound
from numba import types
from numba.extending import intrinsic
from rebound.integrator import IntegratorConfiguration
from rebound.ode import ODE

__all__ = [
    "WORD_BYTES",
    "SIM_N_WORD", "SIM_PARTICLES_WORD", "SIM_EXTRAS_WORD", "SIM_G_WORD", "SIM_WORDS",
    "SIM_STATUS_BYTE", "SIM_T_BYTE", "SIM_INTEGRATOR_STATE_WORD", "REB_STATUS_USER",
    "PARTICLE_WORDS", "PARTICLE_X", "PARTICLE_VX", "PARTICLE_AX", "PARTICLE_M",
    "ODE_WORDS", "ODE_REF_WORD", "ODE_Y_WORD", "ODE_Y1_WORD", "ODE_SIM_WORD",
    "ADDITIONAL_FORCES_TYPE", "ODE_DERIVATIVES_TYPE", "ODE_PRE_TIMESTEP_TYPE",
    "as_float64_pointer", "as_uint64_pointer", "as_int32_pointer", "pointer_address",
    "word_as_float64", "float64_bits", "particle_table", "address_bits_as_float64",
]

#: Bytes in one word of the views below.
WORD_BYTES = 8

_SIMULATION_FIELDS = dict(rebound.Simulation._fields_)

# --- struct reb_simulation, as 64-bit words -------------------------------------------------
SIM_N_WORD = rebound.Simulation.N.offset // WORD_BYTES
SIM_PARTICLES_WORD = rebound.Simulation._particles.offset // WORD_BYTES
SIM_EXTRAS_WORD = rebound.Simulation.extras.offset // WORD_BYTES
SIM_G_WORD = rebound.Simulation.G.offset // WORD_BYTES
#: Words a callback must view to reach every field above.
SIM_WORDS = max(SIM_N_WORD, SIM_PARTICLES_WORD, SIM_EXTRAS_WORD, SIM_G_WORD) + 1
#: Byte offsets of the C-int ``status`` and the double ``t`` (read and written from the error path).
SIM_STATUS_BYTE = rebound.Simulation._status.offset
SIM_T_BYTE = rebound.Simulation.t.offset
_SIM_INTEGRATOR_STATE_BYTE = rebound.Simulation.integrator.offset + IntegratorConfiguration.state.offset
#: Word holding the integrator's state pointer (``sim.integrator.state``).
SIM_INTEGRATOR_STATE_WORD = _SIM_INTEGRATOR_STATE_BYTE // WORD_BYTES
#: REBOUND's REB_STATUS_USER: ``integrate`` returns quietly; the Python side then raises our error.
REB_STATUS_USER = 5

# --- struct reb_particle, as float64 words ---------------------------------------------------
PARTICLE_WORDS = ctypes.sizeof(rebound.Particle) // WORD_BYTES
#: First word of position, velocity and acceleration (x, y, z follow), and the mass.
PARTICLE_X, PARTICLE_VX, PARTICLE_AX, PARTICLE_M = (
    getattr(rebound.Particle, field).offset // WORD_BYTES for field in ("x", "vx", "ax", "m"))

# --- struct reb_ode, as 64-bit words ----------------------------------------------------------
ODE_WORDS = ctypes.sizeof(ODE) // WORD_BYTES
ODE_REF_WORD = ODE.ref.offset // WORD_BYTES
ODE_Y_WORD = ODE.y.offset // WORD_BYTES
ODE_Y1_WORD = ODE._y1.offset // WORD_BYTES
ODE_SIM_WORD = ODE.r.offset // WORD_BYTES

for _offset in (rebound.Simulation.N.offset, rebound.Simulation._particles.offset,
                rebound.Simulation.extras.offset, ctypes.sizeof(rebound.Particle), _SIM_INTEGRATOR_STATE_BYTE):
    assert _offset % WORD_BYTES == 0, "REBOUND struct layout is not 8-byte aligned as assumed"
assert ctypes.sizeof(_SIMULATION_FIELDS["N"]) == WORD_BYTES, "sim.N is not a 64-bit word"
assert ctypes.sizeof(_SIMULATION_FIELDS["_status"]) == 4, "sim.status is not a C int"

# --- function-pointer fields: assigning an instance of the field's own ctypes type stores the raw
# address (the public properties would wrap the cfunc in a slow Python thunk).
ADDITIONAL_FORCES_TYPE = _SIMULATION_FIELDS["_additional_forces"]
ODE_DERIVATIVES_TYPE = dict(ODE._fields_)["_derivatives"]
ODE_PRE_TIMESTEP_TYPE = dict(ODE._fields_)["_pre_timestep"]


def _cast_intrinsic(accepts, result, instruction):
    """A numba intrinsic turning one ``accepts`` value into ``result`` with one LLVM cast instruction."""

    @intrinsic
    def cast(typingctx, value):
        if not isinstance(value, accepts):
            return None

        def codegen(context, builder, sig, args):
            return getattr(builder, instruction)(args[0], context.get_value_type(result))

        return result(value), codegen

    return cast


#: ``double*`` from an address (particle arrays, parameter blocks).
as_float64_pointer = _cast_intrinsic(types.Integer, types.CPointer(types.float64), "inttoptr")
#: ``uint64*`` from an address (REBOUND's structs read as 64-bit words).
as_uint64_pointer = _cast_intrinsic(types.Integer, types.CPointer(types.uint64), "inttoptr")
#: ``int32*`` from an address (to write REBOUND's C-int ``status``).
as_int32_pointer = _cast_intrinsic(types.Integer, types.CPointer(types.int32), "inttoptr")
#: The integer address of a ``uint64*`` (to hand the simulation's address to the error path).
pointer_address = _cast_intrinsic(types.CPointer, types.uint64, "ptrtoint")
#: The bits of a 64-bit word as a double (``sim.G`` is read from the word view).
word_as_float64 = _cast_intrinsic(types.Integer, types.float64, "bitcast")
#: The bits of a double as a uint64 (addresses are stored bit-exactly in float64 parameter blocks).
float64_bits = _cast_intrinsic(types.Float, types.uint64, "bitcast")


def address_bits_as_float64(*addresses) -> np.ndarray:
    """Addresses (or byte offsets) as float64 words holding their exact bits (read back by :data:`float64_bits`)."""
    return np.array(addresses, dtype=np.uint64).view(np.float64)


def particle_table(sim) -> np.ndarray:
    """A numpy view (no copy) of ``sim``'s particle array: shape (N, :data:`PARTICLE_WORDS`), float64.

    Valid until particles are added or removed (REBOUND may then reallocate the array).
    """
    n = sim.N
    raw = (ctypes.c_double * (n * PARTICLE_WORDS)).from_address(ctypes.addressof(sim._particles.contents))
    return np.frombuffer(raw, dtype=np.float64).reshape(n, PARTICLE_WORDS)
