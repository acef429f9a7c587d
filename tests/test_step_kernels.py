"""The step decision: one pure-Python function (models/step_scalar.py), run interpreted or
compiled by numba; the compiled loops load from numba's disk cache in a new process; the
bounds path loads neither numba nor scipy."""

import dataclasses
import os
import re
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from pushrecovery import InvalidParameterError, load_params
from pushrecovery.kernels import stepping as kernels
from pushrecovery.surfaces.step import (
    StepDecision,
    compiled_plan_step,
    plan_step,
    plan_steps,
    step_critical_velocity,
    step_thresholds,
)

P = load_params()
FIELDS = [f.name for f in dataclasses.fields(StepDecision)]
#: The same Python function, interpreted or compiled: LLVM's and CPython's sin/cos/pow may
#: round differently in the last bit, which the decision amplifies at most through the
#: cancellation 1 − cos θ0 of a nearly upright leg (seen: ≤ 1e-13 rad between the two).
SAME_CODE = 1e-12

# (x [m], ẋ [m/s]): backward and forward, beyond reach and past the leg, and slow falls (a
# leaning CoM below the top of the pendulum, with a negative upright-equivalent energy).
states = st.one_of(
    st.tuples(st.floats(-1.5, 1.5), st.floats(-10.0, 10.0)),
    st.tuples(st.floats(-0.4, 0.4), st.floats(-0.6, 0.6)),
)
bodies = st.builds(
    lambda height, gravity, heel, toe, reach: dataclasses.replace(
        P,
        com_height=height,
        gravity=gravity,
        heel=heel,
        toe=toe,
        leg_length=height,
        max_step_length=reach * height,
    ),
    st.floats(0.6, 1.4),
    st.floats(3.0, 20.0),
    st.floats(-0.25, -0.01),
    st.floats(0.01, 0.3),
    st.floats(0.02, 1.95),
)


def scalar_rows(x, xdot, params, heel=None, toe=None):
    """plan_step for each state: (n, 8) floats in the order of FIELDS."""
    x, xdot = np.broadcast_arrays(np.asarray(x, dtype=float), np.asarray(xdot, dtype=float))
    heel = np.broadcast_to(params.heel if heel is None else heel, x.shape)
    toe = np.broadcast_to(params.toe if toe is None else toe, x.shape)
    rows = [
        dataclasses.astuple(plan_step(*args, params, heel=h, toe=t))
        for *args, h, t in zip(x.flat, xdot.flat, heel.flat, toe.flat, strict=True)
    ]
    return np.array(rows, dtype=float).reshape(-1, len(FIELDS))


def assert_same(plan, rows):
    for k, name in enumerate(FIELDS):
        got = np.asarray(getattr(plan, name), dtype=float).reshape(-1)
        if name in ("direction", "ready", "feasible"):
            np.testing.assert_array_equal(got, rows[:, k], err_msg=name)
        else:
            np.testing.assert_allclose(got, rows[:, k], rtol=0, atol=SAME_CODE, err_msg=name)


def kernel_plan(x, xdot, params, *, parallel):
    x = np.asarray(x, dtype=float)
    heel, toe = np.full_like(x, params.heel), np.full_like(x, params.toe)
    args = (params.com_height, params.gravity, params.max_step_length)
    values, flags = kernels.plan(x, np.asarray(xdot, float), heel, toe, *args, parallel=parallel)
    names = ("direction", "theta", "step_length", "shortest", "longest", "margin")
    fields = dict(zip(names, values, strict=True)) | {"ready": flags[0], "feasible": flags[1]}
    return type("Plan", (), fields)


@settings(max_examples=150)
@given(st.lists(states, min_size=1, max_size=48), bodies)
def test_vectorised_paths_match_the_scalar(state_list, params):
    x, xdot = np.array(state_list).T
    rows = scalar_rows(x, xdot, params)
    assert_same(plan_steps(x, xdot, params), rows)  # pure Python up to 32 states, then numba
    assert_same(kernel_plan(x, xdot, params, parallel=False), rows)
    assert_same(kernel_plan(x, xdot, params, parallel=True), rows)


@pytest.mark.parametrize("size", [1, 32, 33, kernels.PARALLEL_MIN_SIZE - 1, 5000])
def test_every_size_takes_the_same_decision(size):
    rng = np.random.default_rng(size)
    x, xdot = rng.uniform(-0.8, 0.8, size), rng.uniform(-6.0, 6.0, size)
    heel, toe = rng.uniform(-0.2, -0.01, size), rng.uniform(0.01, 0.3, size)
    assert_same(plan_steps(x, xdot, P, heel=heel, toe=toe), scalar_rows(x, xdot, P, heel, toe))


@settings(max_examples=150)
@given(states, bodies)
def test_compiled_plan_step_matches_plan_step(state, params):
    x, xdot = state
    planner = compiled_plan_step()
    args = (params.heel, params.toe, params.com_height, params.gravity, params.max_step_length)
    compiled = np.array(planner(x, xdot, *args), dtype=float)
    expected = np.array(dataclasses.astuple(plan_step(x, xdot, params)), dtype=float)
    np.testing.assert_allclose(compiled, expected, rtol=0, atol=SAME_CODE)
    assert compiled[:3].tolist() == expected[:3].tolist()  # direction, ready, feasible


def test_compiled_plan_step_never_compiles_again():
    planner = compiled_plan_step()
    assert planner is compiled_plan_step()
    assert len(planner.signatures) == 1
    as_ints = planner(0, 1, -0.05, 0.15, 1, 9.81, 1)  # converted, not a new specialisation
    assert len(planner.signatures) == 1
    assert as_ints == planner(0.0, 1.0, -0.05, 0.15, 1.0, 9.81, 1.0)


def test_heel_and_toe_arrays_replace_the_params_per_state():
    rng = np.random.default_rng(7)
    n = 300  # compiled, one thread
    x, xdot = rng.uniform(-0.5, 0.5, n), rng.uniform(-4.0, 4.0, n)  # both step directions
    heel, toe = rng.uniform(-0.2, -0.01, n), rng.uniform(0.01, 0.3, n)
    plan = plan_steps(x, xdot, P, heel=heel, toe=toe)
    for i in range(n):
        alone = plan_steps(x[i], xdot[i], dataclasses.replace(P, heel=heel[i], toe=toe[i]))
        for name in FIELDS:
            got, want = float(getattr(plan, name)[i]), float(getattr(alone, name))
            assert got == pytest.approx(want, abs=SAME_CODE, nan_ok=True), (i, name)
    assert np.any(plan.direction < 0) and np.any(plan.feasible)


def test_edges_broadcast_with_the_states():
    x, xdot = np.linspace(-0.2, 0.2, 4)[:, None], np.linspace(-3.0, 3.0, 50)[:, None, None]
    heel = np.linspace(-0.15, -0.02, 5)
    plan = plan_steps(x, xdot, P, heel=heel)
    assert plan.theta.shape == (50, 4, 5)
    column = plan_steps(x[:, 0], xdot[..., 0], dataclasses.replace(P, heel=heel[3]))
    np.testing.assert_allclose(plan.margin[..., 3], column.margin, rtol=0, atol=SAME_CODE)


def test_default_edges_are_the_params():
    x, xdot = np.linspace(-0.3, 0.3, 40), np.linspace(-3.0, 3.0, 40)
    default, explicit = plan_steps(x, xdot, P), plan_steps(x, xdot, P, heel=P.heel, toe=P.toe)
    for name in FIELDS:
        np.testing.assert_array_equal(getattr(default, name), getattr(explicit, name))


def test_inverted_foot_is_refused():
    with pytest.raises(InvalidParameterError, match="heel must be < toe"):
        plan_steps([0.0, 0.1], [1.0, 1.0], P, heel=[-0.05, 0.2], toe=0.15)
    with pytest.raises(InvalidParameterError, match="heel must be < toe"):
        plan_step(0.0, 1.0, P, toe=-0.1)


def test_shapes_of_one_and_no_state():
    one = plan_steps(0.0, 1.2, P)
    assert one.theta.shape == () and one.feasible.dtype == np.bool_ and bool(one.feasible)
    none = plan_steps([], [], P)
    assert none.theta.shape == (0,) and none.ready.dtype == np.bool_


def test_thresholds_unchanged():
    # Recorded from the implementation before the pure-Python decision (compiled closures);
    # 1e-9 m/s is the bisection tolerance.
    assert step_thresholds(P) == pytest.approx((-2.4793487444533078, 2.5861709467411194), abs=1e-9)
    short = load_params(overrides={"max_step_length": 0.6})
    assert step_thresholds(short) == pytest.approx(
        (-0.895088765791636, 1.3836856111090716), abs=1e-9
    )
    assert step_critical_velocity(0.0, 1.0, P) == step_thresholds(P)[1]


def run_python(code, **env):
    result = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        capture_output=True,
        text=True,
        timeout=600,
        env={k: v for k, v in os.environ.items() if not k.startswith("NUMBA_")} | env,
    )
    assert result.returncode == 0, result.stderr
    return result.stdout + result.stderr


def test_bounds_path_loads_neither_numba_nor_scipy():
    out = run_python(
        """
        import sys
        from pushrecovery import load_params
        from pushrecovery.models.stepping import solve_step_angle
        from pushrecovery.surfaces.bounds import bounds_data
        from pushrecovery.surfaces.step import plan_step, plan_steps, step_thresholds
        P = load_params()
        step_thresholds(P)
        plan_step(0.0, 1.2, P)
        plan_steps([0.0, 0.1], [1.2, -1.0], P)  # a few states: pure Python too
        solve_step_angle([1.0, 2.0], 0.0, 1.0, 9.81)
        bounds_data(P)
        print(sorted(m for m in ("numba", "llvmlite", "scipy") if m in sys.modules))
        """
    )
    assert out.strip() == "[]"


def test_small_arrays_stay_off_the_thread_pool():
    out = run_python(
        f"""
        import numba, numpy as np
        from pushrecovery import load_params
        from pushrecovery.surfaces.step import compiled_plan_step, plan_steps
        P = load_params()
        compiled_plan_step()(0.0, 1.2, -0.05, 0.15, 1.0, 9.81, 1.0)
        plan_steps(np.zeros({kernels.PARALLEL_MIN_SIZE - 1}), 1.2, P)
        try:
            print("pool started:", numba.threading_layer())
        except ValueError:
            print("no pool")
        plan_steps(np.zeros({kernels.PARALLEL_MIN_SIZE}), 1.2, P)
        print("then:", numba.threading_layer())
        """
    )
    assert "no pool" in out and "then:" in out


CACHE_SCRIPT = """
import numpy as np
from pushrecovery import load_params
from pushrecovery.kernels.stepping import PARALLEL_MIN_SIZE
from pushrecovery.models.stepping import solve_step_angle
from pushrecovery.surfaces.cop import cop_margin
from pushrecovery.surfaces.step import compiled_plan_step, plan_steps
P = load_params()
for n in (100, PARALLEL_MIN_SIZE):  # one thread, then the pool
    plan_steps(np.linspace(-0.3, 0.3, n), 1.2, P)
    solve_step_angle(np.linspace(0.1, 3.0, n), 0.0, 1.0, 9.81)
compiled_plan_step()(0.0, 1.2, -0.05, 0.15, 1.0, 9.81, 1.0)
cop_margin(np.zeros(1 << 16), np.zeros(1 << 16), P)  # its fused kernel
# The ground plane: the monitor (its fixed-signature step decision), the vectorised verdicts
# (region codes, the in-place step tests) and the planar margins.
from pushrecovery.surfaces.classify import classify_states
from pushrecovery.surfaces.monitor import BalanceMonitor
from pushrecovery.surfaces.plane import cop_margin_xy
from pushrecovery.ground import Support
BalanceMonitor(P).query(0.0, 0.0, 1.2, 0.3)
big = np.linspace(-1.0, 1.0, 1 << 17)
classify_states(0.1 * big, big, P)
classify_states(0.1 * big, big, P, y=0.05 * big, ydot=big)
cop_margin_xy(0.1 * big, 0.1 * big, big, big, Support.from_params(P), P)
# Steps: the foothold region with its centre, and a plan.
from pushrecovery.surfaces.classify import classify
from pushrecovery.surfaces.capture.region import capture_region
capture_region(0.0, 0.1, 1.5, -0.4, P, Support.from_params(P, "left"))
classify(0.0, 2.6, P, y=0.0, ydot=0.0)
from pushrecovery.surfaces.capture.plan import capture_plan
from pushrecovery.surfaces.n_step import step_options
capture_plan(np.array([0.9, 0.2]), P, step_options(P, Support.from_params(P, "left"))[0], 2)
"""
KERNELS = {
    "step_scalar.decide",
    "step_scalar.decide_serial",
    "step_scalar.decide_parallel",
    "step_scalar.solve_serial",
    "step_scalar.solve_parallel",
    "capture_point.capture_margins",
    "plane_codes.locate_steps",
    "plane_codes.mark_regions",
    "plane_codes.sagittal_codes",
    "plane_codes._codes_4",
    "plane_codes._margins_4",
    "polygons.foothold_kernel",
    "polygons.decompose_loop",
    "polygons.minkowski_loop",
    "polygons.loop_signed_distance",
}


def cache_events(out):
    events = {"saved": set(), "loaded": set()}
    for action, path in re.findall(r"\[cache\] data (saved|loaded) (?:to|from) '(.+?)'", out):
        events[action].add(Path(path).name.rsplit("-", 1)[0])
    return events


def test_kernels_load_from_the_disk_cache_in_a_new_process(tmp_path):
    env = {"NUMBA_CACHE_DIR": str(tmp_path), "NUMBA_DEBUG_CACHE": "1"}
    first = cache_events(run_python(CACHE_SCRIPT, **env))
    assert KERNELS <= first["saved"]  # compiled once, into the empty cache
    files = sorted((p.name, p.stat().st_size) for p in tmp_path.rglob("*.nb[ic]"))
    second = cache_events(run_python(CACHE_SCRIPT, **env))
    assert second["saved"] == set()  # nothing compiled in the new process ...
    assert KERNELS <= second["loaded"]  # ... everything loaded
    assert sorted((p.name, p.stat().st_size) for p in tmp_path.rglob("*.nb[ic]")) == files


def test_pure_loops_run_uncompiled():
    # The loops of step_scalar are plain Python too (prange is range there).
    from pushrecovery.kernels import step_scalar

    x = np.linspace(-0.4, 0.4, 7)
    heel, toe = np.full(7, P.heel), np.full(7, P.toe)
    values, flags = np.empty((6, 7)), np.empty((2, 7), dtype=bool)
    args = (P.com_height, P.gravity, P.max_step_length)
    step_scalar.decide_each(x, 5 * x, heel, toe, *args, values, flags)
    compiled = kernels.plan(x, 5 * x, heel, toe, *args)
    np.testing.assert_allclose(values, compiled[0], rtol=0, atol=SAME_CODE)
    np.testing.assert_array_equal(flags, compiled[1])
    np.testing.assert_array_equal(np.isnan(values[1]), ~flags[0])  # theta: NaN where not ready


def test_feasibility_without_angles_equals_the_plan():
    # The angle-free test (two evaluations of ξ⁺, monotone in θ) against the full decision with
    # its three Newton solves, on states spanning every branch (backward, slow falls, beyond
    # reach, stance leg pulling). They may differ only where ξ⁺ at
    # the limiting angle is within the solver's 1e-15 of the toe: none in this sample.
    from pushrecovery.kernels import step_scalar

    rng = np.random.default_rng(11)
    for body in (P, load_params(overrides={"max_step_length": 0.4, "toe": 0.25})):
        x, xdot = rng.uniform(-0.8, 0.8, 200_000), rng.uniform(-4.5, 4.5, 200_000)
        args = (body.heel, body.toe, body.com_height, body.gravity, body.max_step_length)
        full = plan_steps(x, xdot, body).feasible
        assert 0.05 < full.mean() < 0.8  # both answers are common
        for i in range(0, 200_000, 37):
            assert step_scalar.feasible(x[i], xdot[i], *args) == full[i]
