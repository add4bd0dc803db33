"""The lunar fluid core's angular velocity at J2000.0 TDB, carried from DE421's epoch (generated data).

Written by ``python -m spinorbit.coupling.ship_lunar_core``; do not edit by hand.
``tests/test_lunar_core.py`` recomputes the value and compares it with this one.

Provenance: :func:`spinorbit.coupling.moon.carry_core_angular_velocity` (DE421's lunar model, mantle
and core from the DE421 header at JDEPOC 1969-06-28, driven by DE421's orbits to J2000.0), computed
with spinorbit 0.1.0.dev0, numpy 2.4.6, numba 0.68.1,
Python 3.11.7 on x86_64, 2026-12-02.
"""

#: The inputs (:func:`spinorbit.coupling.moon.core_state_key` at day 0), for the reader.
KEY = {'day': 0.0, 'revision': 1, 'rtol': 1e-12, 'perturbers': ['earth', 'sun', 'venus', 'mars', 'jupiter', 'saturn'], 'mean_motion': 0.22997150410908074, 'sample_tolerance': 1e-09, 'distant_sample_tolerance': 1e-07, 'de421_header_sha256': 'f0dd585ca7af4b2d088ae82e3e0f7598af8649c129207dd70281c030b1c8a22c'}
#: SHA-256 of :data:`KEY` (:func:`spinorbit.coupling.lunar_core.key_digest`): what a run compares.
KEY_SHA256 = '6089ffd0771f9982e4740733b7b698c25ecbb5afd1641f75df694f6285bda3ca'
#: ω_c on DE421's mantle axes at J2000.0 (rad/day).
CORE_OMEGA = (0.006744180495416226, -0.0006058649610478664, 0.22953581874870138)
