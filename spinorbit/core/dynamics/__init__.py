"""The one definition of the equations of motion (quaternion + body angular velocity).

:mod:`.equations` holds Euler's equations, the torque sum from one force function U, the energy and
angular-momentum diagnostics, and the model-array layout; every integrator and every benchmark peer
evaluates the dynamics through it. :mod:`.python_reference` is its pure-Python transcription, for the
baselines that must not use compiled code (scipy with a plain-Python right-hand side); a test holds
the two equal. :mod:`.validation` holds the checks every integrator's wrapper makes on its input
(state, output times, sampled span) before compiled code runs.
"""
