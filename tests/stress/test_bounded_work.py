"""Bounded work (issue 14, class 5): every integrator and command estimates its work before it starts.

Generated runs (spins, spans, tolerances, caps) go to every integrator with a ``max_steps``: a run
whose estimate exceeds the cap is refused before the first step with :class:`WorkLimitError` naming
the estimate and the knobs (and fast: no step is taken); a run under the cap either completes within
it or is stopped by the kernel at the cap. The estimate of the adaptive integrators is checked to be
a lower bound of the steps actually taken, so no run that fits is refused. The commands refuse over
their row caps with the count and the option to change.
"""

import math
import time

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from spinorbit.core.dynamics.equations import make_model
from spinorbit.core.dynamics.validation import MAX_OUTPUT_ROWS, rotation_turns
from spinorbit.core.errors import WorkLimitError
from spinorbit.core.integrators.dop853 import IntegrationError
from spinorbit.core.integrators.elements import integrate_elements_fixed_step
from spinorbit.core.integrators.quaternion import integrate_fixed_step, integrate_quaternion, minimum_steps
from spinorbit.core.integrators.splitting import integrate_splitting
from spinorbit.core.integrators.taylor import TAYLOR_STEPS_PER_TURN, integrate_taylor, integrate_taylor_fixed_step

from tests.stress._cli import run_cli



EXAMPLES = 40
MOMENTS = (1.0, 2.0, 2.5)
#: Refusals must come before any work: well under the time of one compiled step loop.
REFUSAL_SECONDS = 0.5


def state(spin_direction, spin):
    omega = np.array(spin_direction, dtype=float)
    omega = omega / np.linalg.norm(omega) * spin
    return np.r_[1.0, 0.0, 0.0, 0.0, omega]


directions = st.tuples(st.floats(0.05, 1), st.floats(0.05, 1), st.floats(0.05, 1))


@settings(max_examples=EXAMPLES)
@given(directions, st.floats(0.1, 10.0), st.floats(1.0, 200.0), st.sampled_from([1e-4, 1e-8, 1e-12]))
def test_dop853_estimate_is_a_lower_bound_of_the_steps_taken(direction, spin, turns, rtol):
    y0 = state(direction, spin)
    span = turns * 2 * math.pi / spin
    _, stats = integrate_quaternion(y0, 0.0, [span], make_model(MOMENTS), rtol=rtol, return_stats=True)
    assert minimum_steps(y0, 0.0, span, rtol) <= stats["accepted"]
    _, taylor = integrate_taylor(y0, 0.0, [span], make_model(MOMENTS), tol=max(rtol, 1e-12), return_stats=True)
    assert rotation_turns(y0, 0.0, span) * TAYLOR_STEPS_PER_TURN <= taylor["steps"]


RUNS = {
    "integrate_quaternion": lambda y0, span, cap: integrate_quaternion(y0, 0.0, [span], make_model(MOMENTS),
                                                                       rtol=1e-10, max_steps=cap),
    "integrate_taylor": lambda y0, span, cap: integrate_taylor(y0, 0.0, [span], make_model(MOMENTS), max_steps=cap),
    "integrate_splitting": lambda y0, span, cap: integrate_splitting(y0, 0.0, [span], make_model(MOMENTS), 0.05,
                                                                     max_steps=cap),
    "integrate_fixed_step": lambda y0, span, cap: integrate_fixed_step(y0, 0.0, span, int(span * 20) + 1,
                                                                       make_model(MOMENTS), max_steps=cap),
    "integrate_elements_fixed_step": lambda y0, span, cap: integrate_elements_fixed_step(
        y0, 0.0, span, int(span * 20) + 1, make_model(MOMENTS), max_steps=cap),
    "integrate_taylor_fixed_step": lambda y0, span, cap: integrate_taylor_fixed_step(
        y0, 0.0, span, int(span * 20) + 1, make_model(MOMENTS), 6, max_steps=cap),
}


@settings(max_examples=EXAMPLES)
@given(st.sampled_from(sorted(RUNS)), directions, st.floats(0.5, 5.0), st.floats(1.0, 1e12), st.integers(1, 4000))
def test_runs_over_their_cap_are_refused_up_front_else_bounded(name, direction, spin, span, cap):
    y0 = state(direction, spin)
    clock = time.perf_counter()
    try:
        RUNS[name](y0, span, cap)
    except WorkLimitError as error:
        assert time.perf_counter() - clock < REFUSAL_SECONDS  # refused before the work
        message = str(error)
        assert f"max_steps = {cap}" in message and "raise max_steps" in message and "steps" in message, message
        return
    except IntegrationError as error:  # under the estimate, over the cap in fact: the kernel's own stop
        assert "max_steps" in str(error) and name in ("integrate_quaternion", "integrate_taylor")
        return
    assert span * 20 <= cap + 1 or name in ("integrate_quaternion", "integrate_taylor")


@pytest.mark.parametrize("name", sorted(RUNS))
def test_an_absurd_run_is_refused_at_once_with_the_estimate(name):
    clock = time.perf_counter()
    with pytest.raises(WorkLimitError, match=r"needs about [0-9.e+]+ steps .*max_steps = 1000"):
        RUNS[name](state((0.1, 0.2, 1.0), 1.0), 1e9, 1000)
    assert time.perf_counter() - clock < REFUSAL_SECONDS


@pytest.mark.parametrize("cap", [0, -1, 2.5, True, "many"])
def test_max_steps_must_be_a_positive_whole_number(cap):
    with pytest.raises(ValueError, match="max_steps: expected a positive whole number"):
        integrate_splitting(state((0.1, 0.2, 1.0), 1.0), 0.0, [1.0], make_model(MOMENTS), 0.1, max_steps=cap)


def test_more_output_rows_than_the_cap_are_refused_before_allocating():
    times = np.broadcast_to(np.float64(1.0), (MAX_OUTPUT_ROWS + 1,))  # no memory for a real array of times
    with pytest.raises(WorkLimitError, match="MAX_OUTPUT_ROWS"):
        integrate_quaternion(state((0.1, 0.2, 1.0), 1.0), 0.0, times, make_model(MOMENTS))


# ------------------------------------------------------------------------------- commands
@settings(max_examples=EXAMPLES)
@given(st.floats(-12.0, -5.0), st.floats(-3.0, -1.3))
def test_commands_refuse_row_counts_over_their_caps_with_the_knob(log_step, log_moon_step):
    # the Moon's steps stay above a minute (6.9e-4 d), the finest spacing its models resolve
    step, moon_step = f"{10.0 ** log_step:.3g}", f"{10.0 ** log_moon_step:.3g}"
    cases = [(["torque-free", "--moments", "1", "2", "2.5", "--omega", "1", "2", "3", "--span", "100", "d",
               "--step", step, "d"], "use a larger --step"),
             (["moon", "--span", "50", "yr", "--step", moon_step, "d"], "use a larger --step")]
    for argv, knob in cases:
        clock = time.perf_counter()
        status, err = run_cli(argv)
        assert status == 2 and len(err.splitlines()) == 1 and knob in err and "more than" in err, err
        assert time.perf_counter() - clock < REFUSAL_SECONDS


def test_scene_commands_cap_their_output_times():
    status, err = run_cli(["toutatis", "--n-times", "100001", "--plan"])
    assert status == 2 and "--n-times expects a whole number in [2, 100000]" in err


def test_the_averaged_propagator_refuses_an_absurd_run_at_once():
    from spinorbit.core.averaging.propagate import propagate_averaged
    from spinorbit.core.model.perturbers import kepler_source

    model = make_model(MOMENTS, [kepler_source(1.0, 20.0, 0.1, 0.3, 0.0, 0.0, 0.0)])
    clock = time.perf_counter()
    with pytest.raises(WorkLimitError, match=r"propagate_averaged: this run needs about 1e\+12 steps.*max_steps = 1000"):
        propagate_averaged(state((0.1, 0.2, 1.0), 1.0), 0.0, [1e10], model, max_step=0.01, max_steps=1000)
    assert time.perf_counter() - clock < REFUSAL_SECONDS  # refused before the mean elements are set up
