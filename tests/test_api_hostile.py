"""Hostile values through the documented public API (issue 16): a result or a named error.

Every call below either returns finite numbers or raises one of the project's errors
(:class:`InvalidParameterError`, :class:`ParameterTypeError`): never a ``ZeroDivisionError``,
``OverflowError``, ``IndexError`` or numba typing error, never a silent NaN. ``make fuzz``
runs the same properties with many more examples (``HYPOTHESIS_PROFILE=fuzz``).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from pushrecovery import load_params
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

PARAMS = load_params()
NAMED = (InvalidParameterError, ParameterTypeError)

#: Values no body has, and values of the wrong type.
HOSTILE = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 5e-324, 1e-300, 1e15, 1e300, -1e300, 1e308]),
    st.integers(min_value=-(10**30), max_value=10**30),
    st.none(),
    st.text(max_size=3),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=3),
)


def _finite(result: Any) -> bool:
    """Every number in ``result`` (scalars, arrays, dataclasses' numeric fields) is finite."""
    if isinstance(result, bool | int | str) or result is None:
        return True
    if isinstance(result, float):
        return math.isfinite(result)
    if isinstance(result, np.ndarray):
        return not np.issubdtype(result.dtype, np.floating) or bool(np.isfinite(result).all())
    if isinstance(result, tuple | list):
        return all(_finite(r) for r in result)
    return True


def _holds(call: Callable[[], Any]) -> None:
    """The call returns finite numbers or raises a named error, with no warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        try:
            result = call()
        except NAMED:
            return
    assert _finite(result), result


def _catalogue() -> dict[str, Callable[[Any], Any]]:
    from pushrecovery.control.base import make_controller
    from pushrecovery.ground import Support
    from pushrecovery.models.flywheel import (
        bang_bang_switch_time,
        flywheel_discrete,
        flywheel_propagate,
    )
    from pushrecovery.models.lipm import lipm_state, lipm_transition
    from pushrecovery.models.pendulum import pendulum_acceleration
    from pushrecovery.models.stepping import step_solution
    from pushrecovery.sim.critical import critical_push
    from pushrecovery.sim.registry import make_plant
    from pushrecovery.sim.simulate import simulate
    from pushrecovery.surfaces.bounds import bounds_data, plane_bounds
    from pushrecovery.surfaces.capture.region import capture_region
    from pushrecovery.surfaces.classify import classify
    from pushrecovery.surfaces.classify.many import classify_states
    from pushrecovery.surfaces.cmp import cmp_margin
    from pushrecovery.surfaces.cop import (
        capture_margin,
        capture_point,
        cop_margin,
        cop_region,
        critical_velocity,
    )
    from pushrecovery.surfaces.monitor import BalanceMonitor
    from pushrecovery.surfaces.step import plan_step, plan_steps, step_thresholds

    region = cop_region(PARAMS)
    pd = make_controller("ankle-pd", PARAMS)
    support = Support.from_params(PARAMS)
    monitor = BalanceMonitor(PARAMS)

    def run(state: Any) -> Any:
        plant = make_plant("pendulum", PARAMS)
        return simulate(plant, make_controller("ankle-pd", PARAMS), state, duration=0.05)

    return {
        "classify(params=v)": lambda v: classify(0.0, 0.1, v),
        "classify(y=v)": lambda v: classify(0.0, 0.1, PARAMS, y=v),
        "classify(support=v)": lambda v: classify(0.0, 0.1, PARAMS, support=v),
        "classify_states(v)": lambda v: classify_states(v, 0.1, PARAMS),
        "cop_margin(v)": lambda v: cop_margin(v, 0.1, PARAMS),
        "cmp_margin(params=v)": lambda v: cmp_margin(0.0, 0.1, v),
        "BalanceMonitor(v)": lambda v: BalanceMonitor(v),
        "BalanceMonitor.query(v)": lambda v: monitor.query(v, 0.0, 0.1, 0.0),
        "capture_region(x=v)": lambda v: capture_region(v, 0.0, 0.5, 0.0, PARAMS, support),
        "capture_region(swing_time=v)": lambda v: capture_region(
            0.0, 0.0, 0.5, 0.0, PARAMS, support, v
        ),
        "capture_region(steps=v)": lambda v: capture_region(
            0.0, 0.0, 0.5, 0.0, PARAMS, support, steps=v
        ),
        "plane_bounds(support=v)": lambda v: plane_bounds(PARAMS, v),
        "plan_step(v)": lambda v: plan_step(v, 0.5, PARAMS),
        "step_thresholds(v)": lambda v: step_thresholds(v),
        "lipm_state(t=v)": lambda v: lipm_state(v, 0.0, 0.1, 0.0, PARAMS.omega),
        "lipm_state(omega=v)": lambda v: lipm_state(0.01, 0.0, 0.1, 0.0, v),
        "lipm_transition(dt=v)": lambda v: lipm_transition(PARAMS.omega, v),
        "flywheel_propagate(dt=v)": lambda v: flywheel_propagate(
            np.zeros(4), (0.0, 0.0), PARAMS, v
        ),
        "bang_bang_switch_time(v)": lambda v: bang_bang_switch_time(
            v, 0.0, PARAMS, cop=0.15, direction=1.0
        ),
        "make_plant(v)": lambda v: make_plant(v, PARAMS),
        "make_controller(v)": lambda v: make_controller(v, PARAMS),
        "simulate(initial_state=v)": run,
        "critical_push(x0=v)": lambda v: critical_push(PARAMS, "lipm", "ankle-pd", v, "forward"),
        "load_params(overrides=v)": lambda v: load_params(overrides=v),
        "load_params(mass=v)": lambda v: load_params(overrides={"mass": v}),
        "load_params(gravity=v)": lambda v: bounds_data(load_params(overrides={"gravity": v})),
        "load_params(max_steps=v)": lambda v: load_params(overrides={"max_steps": v}),
        "capture_point(0, 1, omega=v)": lambda v: capture_point(0.0, 1.0, v),
        "capture_margin(v, 0.1)": lambda v: capture_margin(v, 0.1, PARAMS.omega, region),
        "capture_margin(omega=v)": lambda v: capture_margin(0.0, 0.1, v, region),
        "critical_velocity(0, direction=v)": lambda v: critical_velocity(0.0, v, PARAMS),
        "classify(v, 0.1)": lambda v: classify(v, 0.1, PARAMS),
        "classify(0, v)": lambda v: classify(0.0, v, PARAMS),
        "plan_steps(0, v)": lambda v: plan_steps(0.0, v, PARAMS),
        "flywheel_discrete(dt=v)": lambda v: flywheel_discrete(PARAMS, v),
        "pendulum_acceleration(length=v)": lambda v: pendulum_acceleration(
            0.1, 0.0, 0.0, 72.0, v, 9.81
        ),
        "step_solution(v0=v)": lambda v: step_solution(v, 1.0, 9.81, -0.05, 0.15),
        "Controller.command(0, v)": lambda v: pd.command(0.0, v),
        "Controller.command(v, state)": lambda v: pd.command(v, np.array([0.0, 0.1])),
    }


CATALOGUE = _catalogue()


@pytest.mark.parametrize("name", sorted(CATALOGUE))
@given(value=HOSTILE)
def test_hostile_values_give_a_result_or_a_named_error(name: str, value: Any) -> None:
    _holds(lambda: CATALOGUE[name](value))


@pytest.mark.parametrize(
    ("call", "words"),
    [
        (lambda: load_params(overrides=1), "overrides must be a mapping"),
        (lambda: CATALOGUE["capture_margin(omega=v)"](-0.0), "omega must be > 0"),
        (lambda: CATALOGUE["pendulum_acceleration(length=v)"](0.0), "length must be in"),
        (lambda: CATALOGUE["flywheel_discrete(dt=v)"](1e15), "dt must be in"),
        (lambda: CATALOGUE["Controller.command(0, v)"](np.array(0.0)), "1-D array"),
        (lambda: CATALOGUE["critical_velocity(0, direction=v)"](0), "direction must be"),
    ],
)
def test_the_issues_api_examples_name_the_parameter(call: Callable[[], Any], words: str) -> None:
    with pytest.raises(NAMED, match=words):
        call()


def test_plan_steps_refuses_infinite_states() -> None:
    from pushrecovery.surfaces.step import plan_steps

    with pytest.raises(InvalidParameterError, match="xdot must be finite"):
        plan_steps(1e300, -1e400, PARAMS)
