"""Benchmarks, each reported as a ratio to a baseline measured in the same run.

1. The CoP decision surface (Eq. 4 margins) on 10**7 states vs ``numpy.add(a, b, out=c)`` on the
   same arrays. Target: <= 2x.
2. ``pushrecovery --help`` start-up vs ``python -c "import click"`` (issue 15). Target: <= 1.5x;
   the bare ``python -c pass`` is printed beside it.
3. One simulated push (pendulum + PD, 1 kHz control) vs the simulated time (real-time factor).
4. One MPC tick (paper settings, QP with 100 variables, the daqp workspace warm-started between
   ticks) vs its control period dt = 0.02 s, averaged over the ticks of a closed-loop run, and
   the same ticks through qpsolvers' other exact back-end (quadprog) for comparison.
5. Optimal-step queries (Eq. 21) per second on 10**5 velocities, vs ``solve_ivp`` with events
   on a sample of the same velocities. Targets: >= 2e6 queries/s and >= 1000x the ODE route.
6. MuJoCo with the controller in the loop (``torso`` + MPC at 50 Hz, 3 s after a push) as a
   real-time factor on one core, against MuJoCo stepping the same model alone for the same
   time, and against the ceiling of any loop: MuJoCo alone plus the MPC's own ticks. Target:
   >= 150x real time (above that ceiling on this machine, docs/performance.md, "Simulation").
7. Pushes per second for a batch (20 pushes, each to recovery or fall) on MuJoCo, ``foot`` +
   ankle PD and ``torso`` + MPC, against the same batch on the analytic pendulum / flywheel.
8. Campaigns (``pushrecovery campaign``): pushes per second on the analytic and MuJoCo backends
   with 1 and 2 local worker processes and 2 workers of a Dask ``LocalCluster``, the overhead
   (wall time x workers minus the work, measured batch by batch in this process) over the work,
   and a Dask task's round trip against a batch's work (target <= 5 %). The machine has 2
   cores, which the campaign's own process shares: 2 workers can at best halve the wall time.
9. Measured-trial analysis (``pushrecovery.analysis``): the real Kistler quiet-standing trial
   (10 s at 1 kHz, force plates only: zero-point integration, filters, margins, strategies) as
   a multiple of real time, and per frame against reading the file alone.
10. The ground plane (``benchmarks/plane.py``): the real-time monitor's single-state query,
   ``bounds`` start-up, 2-D margins and ``classify_states`` on 10**7 states.
11. Steps (``benchmarks/steps.py``): one-step capture regions, N-step thresholds and plans.
12. Campaign batches of pendulum + ankle PD on one core (the compiled loop of issue 17) in
   pushes per second, against the one-push loop on a sample of the same pushes. Target:
   >= 5000 pushes/s. The same for stepping + recovery on the report's full analytic grid
   (ankle, hip with the MPC, steps, falls; the batch builds its own MPCs). Target: >= 500/s.
13. The MPC at N = 50, 100, 200 (``benchmarks/mpc_horizons.py``): tick median and p99 against
   a 100 x 100 mat-vec, and the growth with the horizon (issue 17).
14. MuJoCo at its own speed (``benchmarks/mujoco_speed.py``, issue 17): ``torso`` + MPC against
   MuJoCo alone on the same trajectory, and the lockstep rollout of ``foot`` + ankle PD.
15. Batch analysis of measured trials (``benchmarks/trials.py``, issue 18): 200 generated
   trials on 1 and 2 workers and a Dask LocalCluster (the same tables), trials per second and
   the time per trial-second against reading the files alone; then the Kistler trial in a
   folder of 100 copies through ``pushrecovery analyze --workers 1 --no-plot`` on one core
   against the same trials in process (median, p99, largest). Targets (issue 34): >= 20
   trials/s, <= 0.5 s per trial above the in-process analysis.
16. The whole-body QP (``benchmarks/wbc.py``, issue 19): the G1 (skipped with a one-line
   reason without the robots extra) and biped3d under the WBC at 500 Hz against MuJoCo alone
   on the same controls, the solve and tick median and p99. Target: ratio >= 0.5.
17. A campaign's fixed cost (``benchmarks/campaign_cost.py``): ``pushrecovery campaign`` of 4
   pushes with ``--workers 1`` (in-process) minus ``python -c "import pushrecovery"`` in the
   same rounds, median and largest of 7, for three pairs. Target: median <= 1.5 s.
18. Contact changes in a 1 kHz loop (``benchmarks/realtime.py``, issue 32): the monitor's
   ``set_support`` (single and double support, every pose and yaw new) and the plane recovery
   controller's re-plan tick, median, p99 and largest over every call against a 100 x 100
   mat-vec; building a monitor and a controller. Targets: median <= 50 µs, p99 <= 200 µs,
   build <= 50 ms.
19. Probabilities of uncertain states (``benchmarks/probability.py``, issue 37): P(ankle) of
   one state against the certain ``classify`` (goal <= 10x) and of 10**6 states against
   ``numpy.add`` per state (goal <= 20x); a state's every level, line and plane.
"""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
import timeit
from pathlib import Path

import numpy as np

from pushrecovery import load_params
from pushrecovery.control import make_controller
from pushrecovery.sim.push import PUSH_DURATION, Push
from pushrecovery.sim.registry import make_plant
from pushrecovery.sim.simulate import simulate
from pushrecovery.surfaces.cop import cop_margin

N = 10**7
REPEAT = 7


def best(func, number=1):
    return min(timeit.repeat(func, number=number, repeat=REPEAT)) / number


def surface() -> float:
    params = load_params()
    rng = np.random.default_rng(0)
    x, xdot = rng.normal(0.05, 0.1, N), rng.normal(0.0, 0.3, N)
    out = np.empty(N)
    baseline = best(lambda: np.add(x, xdot, out=out))
    margin = best(lambda: cop_margin(x, xdot, params, out=out))
    ratio = margin / baseline
    print(
        f"surface on 1e7 states: {margin * 1e3:.1f} ms; numpy.add {baseline * 1e3:.1f} ms; "
        f"ratio {ratio:.2f} (target <= 2)"
    )
    return ratio


def startup() -> float:
    env = {**os.environ, "PYTHONDONTWRITEBYTECODE": "1"}
    exe = Path(sys.executable).with_name("pushrecovery")

    def run(cmd):
        return lambda: subprocess.run(cmd, check=True, capture_output=True, env=env)

    bare = min(timeit.repeat(run([sys.executable, "-c", "pass"]), number=1, repeat=REPEAT))
    click = min(timeit.repeat(run([sys.executable, "-c", "import click"]), number=1, repeat=REPEAT))
    cli = min(timeit.repeat(run([str(exe), "--help"]), number=1, repeat=REPEAT))
    print(
        f"pushrecovery --help: {cli * 1e3:.0f} ms; python -c 'import click' {click * 1e3:.0f} ms, "
        f"ratio {cli / click:.2f} (target <= 1.5); bare python {bare * 1e3:.0f} ms"
    )
    return cli / click


def realtime() -> float:
    params = load_params()
    plant, ctrl = make_plant("pendulum", params), make_controller("ankle-pd", params)
    state = np.array([0.0, 0.3])
    run = simulate(plant, ctrl, state)
    wall = best(lambda: simulate(plant, ctrl, state))
    factor = run.time[-1] / wall
    print(
        f"pendulum + PD push, {run.time[-1]:.2f} s simulated at 1 kHz: {wall * 1e3:.1f} ms "
        f"({factor:.0f}x faster than real time)"
    )
    return factor


def mpc() -> float:
    from pushrecovery.control.mpc import MPCController

    params = load_params()
    # The states of a closed-loop run after a large push (torque and CoP limits active), so
    # that warm starts see the active-set changes of a real run, not one repeated state.
    run = simulate(
        make_plant("flywheel", params),
        MPCController(params),
        np.array([0.0, 0.0, 0.6, 0.0]),
        duration=3.0,
    )
    states = run.states[:-1]
    timings = {}
    for solver in ("daqp", "quadprog"):
        controller = MPCController(params, solver=solver)

        def ticks(controller=controller):
            controller.reset(states[0])
            for k, state in enumerate(states):
                controller.compute(0.02 * k, state)

        timings[solver] = best(ticks, number=1) / len(states)
    factor = 0.02 / timings["daqp"]
    print(
        f"MPC tick (daqp) over a {len(states)}-tick closed-loop run: "
        f"{timings['daqp'] * 1e3:.3f} ms per 20 ms period ({factor:.0f}x faster than real "
        f"time); quadprog {timings['quadprog'] * 1e3:.2f} ms"
    )
    return factor


def stepping() -> tuple[float, float]:
    import math

    from scipy.integrate import solve_ivp

    from pushrecovery.models.stepping import solve_step_angle

    params = load_params()
    length, gravity = params.leg_length, params.gravity
    speeds = np.random.default_rng(1).uniform(0.1, 3.0, 100_000)
    solve_step_angle(speeds[:2000], 0.0, length, gravity)  # load the kernel outside the timing
    fast = best(lambda: solve_step_angle(speeds, 0.0, length, gravity), number=3)
    rate = speeds.size / fast

    def event(t, y):
        theta, theta_rate = y
        after = length * theta_rate * math.cos(2 * theta) / math.cos(theta)
        return -length * math.sin(theta) + after * math.sqrt(length * math.cos(theta) / gravity)

    event.terminal = True

    def ode(v0):
        return solve_ivp(
            lambda t, y: [y[1], gravity / length * math.sin(y[0])],
            (0.0, 10.0),
            [0.0, v0 / length],
            events=event,
            rtol=1e-10,
            atol=1e-12,
        )

    sample = speeds[:50]
    slow = best(lambda: [ode(v) for v in sample], number=1) / sample.size
    ratio = slow * rate
    print(
        f"optimal step: {rate:.3g} queries/s on 1e5 velocities; solve_ivp with events "
        f"{1 / slow:.3g} queries/s; ratio {ratio:.0f}x (targets >= 2e6/s, >= 1000x)"
    )
    return rate, ratio


def mujoco_realtime() -> float:
    from pushrecovery.sim.simulate import RestCriterion

    params = load_params()
    plant, ctrl = make_plant("torso", params, "mujoco"), make_controller("mpc", params)
    never = RestCriterion(duration=1e3)  # run the whole 3 s
    push = Push.from_impulse(40.0, params.mass)

    def loop():
        plant.reset(0.0, 0.0)
        simulate(plant, ctrl, plant.apply_push(push), duration=3.0, rest=never)

    def bare():
        plant.reset(0.0, 0.0)
        plant._mj.mj_step(plant.model, plant.data, nstep=3000)

    def ticks():
        ctrl.reset(states[0])
        for k, state in enumerate(states):
            ctrl.compute(0.02 * k, state)

    plant.reset(0.0, 0.0)
    states = simulate(plant, ctrl, plant.apply_push(push), duration=3.0, rest=never).states[:-1]
    # The settling before each run (0.3 s of physics) is in both timings.
    settle = best(lambda: plant.reset(0.0, 0.0), number=1)
    wall = best(loop) - settle
    physics = best(bare) - settle
    # The fastest any loop could be: MuJoCo alone plus the MPC's own ticks, nothing between.
    ceiling = physics + best(ticks)
    factor = 3.0 / wall
    print(
        f"MuJoCo torso + MPC at 50 Hz, 3 s after a push: {wall * 1e3:.0f} ms "
        f"({factor:.0f}x faster than real time; MuJoCo alone {3.0 / physics:.0f}x; "
        f"MuJoCo + MPC ticks, nothing between {3.0 / ceiling:.0f}x; "
        f"loop / physics {wall / physics:.1f}) (target >= 150x)"
    )
    return factor


def batch() -> None:
    params = load_params()
    setups = {
        "foot + ankle-pd": ("foot", "pendulum", "ankle-pd", [0.0, 0.3]),
        "torso + mpc": ("torso", "flywheel", "mpc", [0.0, 0.0, 0.3, 0.0]),
    }
    speeds = np.linspace(-0.5, 0.9, 20)
    for label, (model, analytic, name, start) in setups.items():
        plant, reference = make_plant(model, params, "mujoco"), make_plant(analytic, params)
        ctrl = make_controller(name, params)
        starts = []
        for v in speeds:
            state = np.array(start, dtype=float)
            state[len(start) // 2] = v
            starts.append(state)

        def mujoco_batch(plant=plant, ctrl=ctrl):
            for v in speeds:
                plant.reset(0.0, 0.0)
                simulate(plant, ctrl, plant.apply_push(Push(v)), duration=6.0)

        def analytic_batch(reference=reference, ctrl=ctrl, starts=starts):
            for state in starts:
                simulate(reference, ctrl, state, duration=6.0)

        fast, slow = best(analytic_batch, number=1), best(mujoco_batch, number=1)
        print(
            f"batch of {speeds.size} pushes, {label}: MuJoCo {speeds.size / slow:.0f} pushes/s; "
            f"analytic {speeds.size / fast:.0f} pushes/s; ratio {slow / fast:.1f}"
        )


def campaigns() -> None:
    """Pushes per second of campaigns on 1 and 2 local workers and a Dask LocalCluster.

    The work is measured apart: every batch run one after the other in this process
    (``run_batch``, warm). The overhead is what the workers spend beyond it, as a share of
    it: (workers x wall time - work) / work, start-up, scheduling, Parquet and the join
    included (the Dask workers are started beforehand, as a real cluster's; the local pool is
    not). Also the scheduler's own round trip of one empty task on the same cluster against
    the work of one batch (target <= 5 % with the default batches, which the pendulum campaign
    takes: ``CampaignSpec.batch``, 32,000 pushes in 16 batches; the MuJoCo one runs 10 per
    batch, 0.16 s of work, for its rates).
    """
    import shutil
    import tempfile
    import time

    from distributed import Client, LocalCluster

    from pushrecovery.campaign import CampaignSpec, run_campaign
    from pushrecovery.campaign.pushes import run_batch

    params = load_params()
    specs = {
        "analytic pendulum + ankle-pd": CampaignSpec(
            "analytic", "pendulum", "ankle-pd", params,
            x0=(-0.03, 0.12, 1.0), xdot=(-0.6, 0.9, 1.0), samples=32_000,
        ),
        "mujoco torso + mpc": CampaignSpec(
            "mujoco", "torso", "mpc", params,
            x0=(-0.03, 0.12, 0.03), xdot=(-0.6, 0.9, 0.1), batch_size=10,
        ),
    }  # fmt: skip
    root = Path(tempfile.mkdtemp(prefix="pushrecovery-bench-"))

    def wall(spec, name, **kwargs):
        start = time.perf_counter()
        run_campaign(spec, root / name, **kwargs)
        elapsed = time.perf_counter() - start
        shutil.rmtree(root / name)
        return elapsed

    try:
        with LocalCluster(n_workers=2, threads_per_worker=1, processes=True) as cluster:
            with Client(cluster) as client:
                client.submit(int, 0, pure=False).result()
                begin = time.perf_counter()
                for k in range(50):  # one at a time: the round trip, not the throughput
                    client.submit(int, k, pure=False).result()
                task = (time.perf_counter() - begin) / 50
            for label, spec in specs.items():
                # Imports, compiled kernels and the Dask workers warm.
                run_batch(spec, 0)
                wall(spec, "warm", workers=1, max_batches=1)
                wall(spec, "warm", scheduler=cluster.scheduler_address, max_batches=2)
                begin = time.perf_counter()
                for batch in range(spec.batches):
                    run_batch(spec, batch)
                work = time.perf_counter() - begin
                walls = {
                    "1 worker": wall(spec, "one", workers=1),
                    "2 workers": wall(spec, "two", workers=2),
                    "dask 2 workers": wall(spec, "dask", scheduler=cluster.scheduler_address),
                }
                rates = ", ".join(f"{n} {spec.size / w:.0f}/s" for n, w in walls.items())
                one = (walls["1 worker"] - work) / work
                two = (2 * walls["2 workers"] - work) / work
                dask = (2 * walls["dask 2 workers"] - work) / work
                print(
                    f"campaign {label}, {spec.size} pushes in {spec.batches} batches of "
                    f"{spec.batch} ({work / spec.batches:.2f} s of work each, "
                    f"{spec.size / work:.0f}/s in this process): {rates}; overhead / work "
                    f"(workers x wall - work): 1 worker {one:+.0%}, 2 workers {two:+.0%} (both "
                    f"with the pool's start-up), dask {dask:+.0%}; a Dask task's round trip "
                    f"{task * 1e3:.1f} ms = {task / (work / spec.batches):.1%} of a batch's work"
                    + (" (target <= 5 %: the default batches)" if spec.batch_size is None else "")
                )
    finally:
        shutil.rmtree(root, ignore_errors=True)


def mujoco_campaign() -> float:
    """A MuJoCo torso + MPC campaign's physics rate against raw mj_step of the same model.

    The campaign's batches run in this process, warm (its steps: each push's 10 ms force and
    its run until decided, one per millisecond); the baseline is ``mujoco.mj_step`` alone on
    the torso model, as many steps, in the same run. Target >= 0.7 (issue 31).
    """
    import time

    import mujoco

    from pushrecovery.campaign import CampaignSpec
    from pushrecovery.campaign.pushes import run_batch
    from pushrecovery.sim.mujoco.models import TIMESTEP
    from pushrecovery.sim.registry import make_plant

    params = load_params()
    spec = CampaignSpec(
        "mujoco", "torso", "mpc", params,
        x0=(-0.03, 0.12, 0.03), xdot=(-0.6, 0.9, 0.1), batch_size=10,
    )  # fmt: skip
    run_batch(spec, 0)  # imports, compiled kernels, the model warm
    begin = time.perf_counter()
    rows = [row for batch in range(spec.batches) for row in run_batch(spec, batch)[1]]
    work = time.perf_counter() - begin
    steps = sum(round(row["time"] / TIMESTEP) + round(PUSH_DURATION / TIMESTEP) for row in rows)
    plant = make_plant("torso", params, "mujoco")
    plant.reset(0.0, 0.0)
    model, data = plant.model, plant.data
    begin = time.perf_counter()
    for _ in range(steps):
        mujoco.mj_step(model, data)
    raw = time.perf_counter() - begin
    ratio = raw / work
    print(
        f"campaign mujoco torso + mpc, {len(rows)} pushes ({steps} physics steps) in this "
        f"process: {steps / work:.0f} steps/s; raw mj_step of the same model {steps / raw:.0f} "
        f"steps/s; ratio {ratio:.2f} (target >= 0.7{'' if ratio >= 0.7 else ': MISSED'})"
    )
    return ratio


def batched() -> float:
    """Pushes per second on one core: pendulum + ankle PD campaign batches (compiled loop)."""
    import time

    from pushrecovery.campaign import CampaignSpec
    from pushrecovery.campaign.pushes import push_rows, run_batch

    params = load_params()
    spec = CampaignSpec(
        "analytic", "pendulum", "ankle-pd", params,
        x0=(-0.03, 0.12, 0.01), xdot=(-0.6, 0.9, 0.01), batch_size=100_000,
    )  # fmt: skip
    run_batch(spec, 0)  # load the compiled loop
    start = time.perf_counter()
    _, rows = run_batch(spec, 0)
    rate = len(rows) / (time.perf_counter() - start)
    sample = spec.pushes(0)[::48]  # the same pushes through the one-push loop
    start = time.perf_counter()
    push_rows(spec, sample, engine="loop")
    loop = len(sample) / (time.perf_counter() - start)
    print(
        f"campaign batch, pendulum + ankle-pd, one core: {rate:.0f} pushes/s ({len(rows)} "
        f"pushes; target >= 5000), {rate / loop:.0f}x the one-push loop's {loop:.0f}/s"
    )
    return rate


def batched_stepping() -> float:
    """Pushes per second on one core: stepping + recovery campaign batches (compiled loop)."""
    import time
    from collections import Counter

    from pushrecovery.campaign import CampaignSpec
    from pushrecovery.campaign.pushes import push_rows, run_batch

    params = load_params()
    # The report's full analytic grid: ankle, hip (the MPC's QPs), one to three steps, falls.
    spec = CampaignSpec(
        "analytic", "stepping", "recovery", params,
        x0=(-0.04, 0.14, 0.02), xdot=(-3.5, 3.5, 0.05), batch_size=100_000,
    )  # fmt: skip
    # Load the compiled loop with another, small campaign: the batch below builds its MPCs
    # (one per stance height) as a campaign worker does.
    run_batch(dataclasses.replace(spec, x0=(0.0, 0.0, 0.1), xdot=(0.5, 3.0, 0.5)), 0)
    start = time.perf_counter()
    _, rows = run_batch(spec, 0)
    rate = len(rows) / (time.perf_counter() - start)
    sample = spec.pushes(0)[::20]  # the same pushes through the one-push loop
    start = time.perf_counter()
    push_rows(spec, sample, engine="loop")
    loop = len(sample) / (time.perf_counter() - start)
    used = Counter(row["used"] for row in rows)
    print(
        f"campaign batch, stepping + recovery, one core: {rate:.0f} pushes/s ({len(rows)} "
        f"pushes: {dict(sorted(used.items()))}; target >= 500), {rate / loop:.0f}x the "
        f"one-push loop's {loop:.0f}/s"
    )
    return rate


def analysis() -> None:
    import biomdp

    from pushrecovery.analysis.readers import read_c3d_recording
    from pushrecovery.analysis.trial import analyze, body_for

    path = Path(biomdp.__file__).parent / "tests" / "datasets" / "kistler_COP.c3d"
    params = load_params()

    def whole():
        trial = read_c3d_recording(path)
        found, _ = body_for(trial, mass=None, com_height=None, gravity=params.gravity)
        return analyze(trial, load_params(overrides=found))

    read = best(lambda: read_c3d_recording(path), number=1)
    total = best(whole, number=1)
    frames = len(whole().time)
    duration = frames / 1000.0
    print(
        f"analysis: Kistler trial ({frames} frames, {duration:g} s) in {total * 1e3:.0f} ms: "
        f"{duration / total:.0f}x real time, {frames / total:.3g} frames/s; "
        f"reading the file alone {read * 1e3:.0f} ms (ratio {total / read:.1f})"
    )


def main() -> int:
    import campaign_cost
    import mpc_horizons
    import mujoco_speed
    import plane
    import probability
    import realtime as contact_changes
    import steps
    import trials
    import wbc

    plane_failed = plane.main()
    steps_failed = steps.main()
    mpc_failed = mpc_horizons.main()
    mujoco_failed = mujoco_speed.main()
    trials_failed = trials.main()
    wbc_failed = wbc.main()
    cost_failed = campaign_cost.main()
    realtime_failed = contact_changes.main()
    probability_failed = probability.main()
    ratio = surface()
    cli = startup()
    realtime()
    mpc()
    step_rate, step_ratio = stepping()
    physics = mujoco_realtime()
    batch()
    batch_rate = batched()
    step_batch_rate = batched_stepping()
    campaigns()
    campaign_ratio = mujoco_campaign()
    analysis()
    failed = ratio > 2.0 or cli > 1.5 or step_rate < 2e6 or step_ratio < 1000 or physics < 150
    failed = failed or bool(plane_failed) or bool(steps_failed) or bool(mpc_failed)
    failed = failed or bool(mujoco_failed) or bool(trials_failed) or bool(wbc_failed)
    failed = failed or batch_rate < 5000 or step_batch_rate < 500 or bool(cost_failed)
    failed = failed or campaign_ratio < 0.7 or bool(realtime_failed) or bool(probability_failed)
    print("targets met" if not failed else "TARGET MISSED")
    return int(failed)


if __name__ == "__main__":
    sys.exit(main())
