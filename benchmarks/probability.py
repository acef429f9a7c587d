"""P(ankle) under a Gaussian state estimate (issue 37) against the certain verdict, in one run.

1. One state: ``ankle_probability`` (the line's closed form) against the certain single-state
   ``classify`` of the same state, every call timed (median, p99, largest). Goal: median <= 10x.
2. 10**6 states: ``ankle_probability`` on the line against ``numpy.add`` of two arrays of the
   same length, per state. Goal: <= 20x.
3. For information: one state's full ``verdict_probabilities`` on the line and on the plane
   (double support, every level of 11 steps), a plane state's ``ankle_probability`` and a
   ``ProbabilityMonitor`` query on the line and the plane.
"""

from __future__ import annotations

import sys
import time
import timeit

import numpy as np

from pushrecovery import load_params
from pushrecovery.ground.support import Support
from pushrecovery.surfaces.classify import classify
from pushrecovery.surfaces.probability import (
    ProbabilityMonitor,
    StateGaussian,
    ankle_probability,
    verdict_probabilities,
)

CALLS = 5000
BULK = 10**6
TARGET_SINGLE, TARGET_BULK = 10.0, 20.0


def _each(call, calls: int = CALLS) -> np.ndarray:
    """Wall time of every call [µs] (after 100 warm-up calls)."""
    for _ in range(100):
        call()
    times = np.empty(calls)
    clock = time.perf_counter_ns
    for i in range(calls):
        start = clock()
        call()
        times[i] = (clock() - start) / 1e3
    return times


def _line(label: str, times: np.ndarray, baseline: float | None = None) -> str:
    text = (
        f"{label}: median {np.median(times):.1f} µs, p99 {np.percentile(times, 99):.1f} µs, "
        f"largest {times.max():.0f} µs"
    )
    if baseline is not None:
        text += f" ({np.median(times) / baseline:.1f}x the certain classify's median)"
    return text


def main() -> int:
    params = load_params()
    cov = np.diag([1e-4, 0.01])
    certain = _each(lambda: classify(0.0, 0.5, params))
    single = _each(lambda: ankle_probability([0.0, 0.5], cov, params))
    baseline = float(np.median(certain))
    ratio = float(np.median(single)) / baseline
    print(_line("Certain classify, one sagittal state", certain))
    met_single = ratio <= TARGET_SINGLE
    print(_line("P(ankle), one sagittal state", single, baseline)
          + f" (goal <= {TARGET_SINGLE:.0f}x{'' if met_single else ': MISSED'})")  # fmt: skip

    rng = np.random.default_rng(0)
    means = np.column_stack([rng.normal(0.0, 0.01, BULK), rng.normal(0.5, 0.1, BULK)])
    a, b, c = np.ones(BULK), np.ones(BULK), np.empty(BULK)
    add = min(timeit.repeat(lambda: np.add(a, b, out=c), number=10, repeat=5)) / 10
    bulk = min(timeit.repeat(lambda: ankle_probability(means, cov, params), number=1, repeat=5))
    bulk_ratio = bulk / add
    met_bulk = bulk_ratio <= TARGET_BULK
    print(
        f"P(ankle), {BULK:.0e} sagittal states: {bulk / BULK * 1e9:.1f} ns a state, "
        f"{bulk_ratio:.0f}x numpy.add on arrays of the same length ({add / BULK * 1e9:.2f} ns "
        f"a state; goal <= {TARGET_BULK:.0f}x{'' if met_bulk else ': MISSED'}: two normal "
        "CDFs a state)"
    )
    line_state = StateGaussian(np.array([0.0, 0.5]), cov)
    plane_state = StateGaussian(np.array([0.0, 0.0, 0.5, 0.2]), np.diag([1e-4, 1e-4, 0.01, 0.01]))
    verdict_probabilities(plane_state, params)  # builds the support's regions once
    print(_line("  every level, one sagittal state",
                _each(lambda: verdict_probabilities(line_state, params), 500)))  # fmt: skip
    print(_line("  every level, one plane state (double support, 11 steps)",
                _each(lambda: verdict_probabilities(plane_state, params), 100)))  # fmt: skip
    plane_ankle = _each(lambda: ankle_probability(plane_state.mean, plane_state.cov, params), 500)
    print(_line("  P(ankle), one plane state", plane_ankle))
    line_monitor = ProbabilityMonitor(params)
    plane_monitor = ProbabilityMonitor(params, Support.from_params(params))
    line_query = _each(lambda: line_monitor.query(line_state.mean, line_state.cov), 2000)
    print(_line("  ProbabilityMonitor.query, line", line_query))
    plane_query = _each(lambda: plane_monitor.query(plane_state.mean, plane_state.cov), 500)
    print(_line("  ProbabilityMonitor.query, plane (double support)", plane_query))
    return int(not (met_single and met_bulk))


if __name__ == "__main__":
    sys.exit(main())
