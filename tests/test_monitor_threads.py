"""One thread switches the monitor's support while another queries: no torn verdict.

A verdict is torn when its fields come from two supports (the CoP margin of the old one with
the step count of the new). ``set_support`` installs one immutable state with one assignment
and ``query`` reads it once, so each verdict must equal one of the two supports' verdicts
exactly, with an upper-body state or without. The interpreter's switch interval is cut to a
microsecond so that the threads interleave inside the calls; both loops are bounded by counts,
not by time.
"""

import sys
import threading

from pushrecovery import load_params
from pushrecovery.ground.support import FootPose, Support
from pushrecovery.surfaces.monitor import BalanceMonitor

P = load_params()
QUERIES = 20_000
MOST_SWITCHES = 200_000


def test_a_query_sees_the_old_or_the_new_support_never_a_mix():
    monitor = BalanceMonitor(P)
    double = Support.from_params(P)
    single = Support.from_params(P, "left", left=FootPose(0.05, 0.1, 0.3))
    state = (0.04, 0.02, 0.45, 0.35)  # every field of its verdict differs between the two
    torso = {"pitch": (0.3, -0.5), "roll": (-0.2, 0.4)}  # every other query: the upper body's
    expected, leaning = [], []
    for support in (double, single):
        monitor.set_support(support)
        expected.append(monitor.query(*state))
        leaning.append(monitor.query(*state, **torso))
    for pair in (expected, leaning):
        assert all(
            getattr(pair[0], field) != getattr(pair[1], field)
            for field in ("strategy", "cop_margin", "cmp_margin", "step_margin")
        )
    assert expected[1].cmp_margin != leaning[1].cmp_margin
    seen = []
    done = threading.Event()

    def switch() -> None:
        for i in range(MOST_SWITCHES):
            if done.is_set():
                return
            monitor.set_support(single if i % 2 else double)

    def query() -> None:
        for i in range(QUERIES):
            seen.append(monitor.query(*state, **torso) if i % 2 else monitor.query(*state))
        done.set()

    interval = sys.getswitchinterval()
    sys.setswitchinterval(1e-6)
    try:
        threads = [threading.Thread(target=switch), threading.Thread(target=query)]
        for thread in threads:
            thread.start()
        for thread in threads:
            thread.join()
    finally:
        sys.setswitchinterval(interval)
    assert len(seen) == QUERIES
    torn = [v for i, v in enumerate(seen) if v not in (leaning if i % 2 else expected)]
    assert not torn, f"{len(torn)} torn verdicts, e.g. {torn[0]}"
    assert all(any(verdict == e for verdict in seen) for e in expected + leaning)  # all seen
