"""The full two-body problem of two rigid figures: mutual potential, coupled equations, propagation.

Lowest first: :mod:`.monomials` (the multi-index tables), :mod:`.inertia_integrals` (a body's
integrals ∫ xⁱ yʲ zᵏ dm: ellipsoids, spheres, polyhedra), :mod:`.mutual_potential` (U, the force and
both torques from one expansion), :mod:`.solar_tide` (the Sun's degree-2 tide and torques),
:mod:`.equations` (the state layout, dy/dt, energy and angular momentum) and :mod:`.propagate` (the
DOP853 engine of :mod:`spinorbit.core.integrators.dop853` on those equations), then
:mod:`.boundedness` (whether the pair is still bound: the orbit's energy, the Hill radius) and
:mod:`.libration` (the secondary's rotation in canonical elements).
"""
