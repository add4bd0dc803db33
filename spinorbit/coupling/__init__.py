"""The rotation coupled to orbits: REBOUND behind one door (:mod:`spinorbit.coupling.rebound`), the
perturber sampler (``sampling``), the one-way propagation (``one_way``), the rigid body integrated
with REBOUND's orbits (``rigid_body``), runs to output times with checkpoints (``long_run``) and the
Moon against DE421 from any date (``moon``) and the Moon models' free modes (``lunar_free_modes``)."""
