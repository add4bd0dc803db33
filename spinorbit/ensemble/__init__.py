"""Ensembles of Scenes, or of members that run themselves: Monte Carlo over unknown phases and parameters,
on any executor (``docs/ensembles.md``).

- :mod:`~spinorbit.ensemble.ensemble` — :class:`Ensemble`: members from ``make_scene(**row)``, fixed
  chunks, one outcome table, checkpoints, failures and reruns;
- :mod:`~spinorbit.ensemble.samplers` — parameters drawn from one seed per member; the free motion's phases;
- :mod:`~spinorbit.ensemble.executors` — in this process, a process pool, any Executor, Dask;
- :mod:`~spinorbit.ensemble.store` — completed chunks in checksummed, atomic checkpoint files;
- :mod:`~spinorbit.ensemble.outcomes` — a member's outcome row from its SceneResult;
- :mod:`~spinorbit.ensemble.free` — torque-free members in one vectorised call of the exact free flow;
- :mod:`~spinorbit.ensemble.apophis` — the Apophis 2029 encounter over phase and moment-ratio uncertainty;
- :mod:`~spinorbit.ensemble.self_run` — members that run themselves (not Scenes);
- :mod:`~spinorbit.ensemble.dart` — DART's period change over the published uncertainties (members that
  run themselves: full-two-body runs, not Scenes).
"""

from spinorbit.ensemble.ensemble import Ensemble
from spinorbit.ensemble.errors import EnsembleError, EnsembleInterrupted
from spinorbit.ensemble.executors import ExecutorError
from spinorbit.ensemble.free import free_members_table
from spinorbit.ensemble.samplers import Normal, SamplerError, Uniform, member_seed, sample_parameters, state_at_phase

__all__ = ["Ensemble", "EnsembleError", "EnsembleInterrupted", "ExecutorError", "Normal", "free_members_table", "SamplerError", "Uniform",
           "member_seed", "sample_parameters", "state_at_phase"]
