"""Verdict probabilities of an uncertain state: exact masses against sampling, certain verdicts.

Every probability is checked against 10⁶ states drawn from the same Gaussian and classified
one by one by the certain verdicts (``classify_states``, ``sagittal_verdicts``, the N-step
polygons), within 4 standard errors of the sample (a fixed seed); latency against the LIPM's
own solution (cosh and sinh of ωτ, not the capture point's e^{ωτ}).
"""

import dataclasses
import math
import re

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.support import Stance, Support
from pushrecovery.presets import load_params
from pushrecovery.surfaces.classify import classify
from pushrecovery.surfaces.classify.many import classify_states
from pushrecovery.surfaces.probability import (
    MAX_LATENCY_GROWTH,
    StateGaussian,
    delayed_capture_point,
    verdict_probabilities,
)
from pushrecovery.surfaces.step.regions import StepRegions
from pushrecovery.surfaces.strategy import Strategy
from pushrecovery.surfaces.verdicts import sagittal_verdicts

P = load_params()
N = 1_000_000


def within(observed_hits, p, n=N):
    se = math.sqrt(max(p * (1.0 - p), 1e-12) / n)
    return abs(observed_hits / n - p) <= 4.0 * se


def levels_of(codes, steps, max_steps):
    """Per state: 0 ankle, 1 hip, 1 + k for k steps, 2 + max_steps for fall."""
    level = np.where(codes == 3, 2 + max_steps, codes.astype(np.int64))
    return np.where(codes == 2, 1 + steps, level)


def lipm_delay(x, v, p, omega, tau):
    """The LIPM x'' = ω²(x − p) with p held for τ, in closed form (cosh, sinh)."""
    c, s = math.cosh(omega * tau), math.sinh(omega * tau)
    return p + (x - p) * c + v / omega * s, (x - p) * omega * s + v * c


@pytest.mark.parametrize(
    ("mean", "cov"),
    [
        ((0.0, 0.5), ((1e-4, 0.0), (0.0, 0.01))),
        ((0.02, 0.9), ((4e-4, 1e-3), (1e-3, 0.04))),  # correlated, mostly steps
        ((-0.01, -0.6), ((1e-4, 0.0), (0.0, 0.09))),  # backward
    ],
)
def test_sagittal_probabilities_against_a_million_states(mean, cov):
    found = verdict_probabilities(StateGaussian(np.array(mean), np.array(cov)), P)
    rng = np.random.default_rng(1)
    x, v = rng.multivariate_normal(mean, cov, N).T
    verdicts = sagittal_verdicts(x, v, P)
    level = levels_of(classify_states(x, v, P), verdicts.line.steps, P.max_steps)
    counts = np.bincount(level, minlength=3 + P.max_steps)
    expected = [found.ankle, found.hip, *found.steps, found.fall]
    for k, p in enumerate(expected):
        assert within(counts[k], p), (k, counts[k] / N, p)
    assert sum(expected) == pytest.approx(1.0, abs=1e-12)
    assert found.method == "exact" and found.error == 0.0


def test_plane_probabilities_against_a_million_states():
    mean = np.array([0.01, 0.02, 2.5, -1.5])  # hard pushes: 1 to 11 steps, or a fall
    cov = np.diag([1e-4, 1e-4, 0.6, 0.6])
    cov[2, 3] = cov[3, 2] = 0.18
    support = Support.from_params(P, Stance.LEFT)
    found = verdict_probabilities(StateGaussian(mean, cov), P, support=support)
    rng = np.random.default_rng(2)
    x, y, vx, vy = rng.multivariate_normal(mean, cov, N).T
    codes = classify_states(vx * 0 + x, vx, P, y=y, ydot=vy, support=support)
    counts = np.bincount(codes, minlength=4)
    for code, p in enumerate([found.ankle, found.hip, sum(found.steps), found.fall]):
        assert within(counts[code], p), (code, counts[code] / N, p)
    # Steps by count: the first N-step polygon holding the capture point, on the step states.
    regions = StepRegions.of(P, support)
    omega = P.omega
    stepping = codes == 2
    px, py = x[stepping] + vx[stepping] / omega, y[stepping] + vy[stepping] / omega
    needed = np.zeros(len(px), dtype=np.int64)
    for polygon, n in zip(regions.polygons, regions.steps, strict=True):
        fresh = (needed == 0) & (polygon.signed_distance(px, py) > 0.0)
        needed[fresh] = n
    by_count = np.bincount(needed, minlength=P.max_steps + 1)
    assert by_count[0] == 0
    for k, p in enumerate(found.steps, start=1):
        assert within(by_count[k], p), (k, by_count[k] / N, p)
    assert min(found.steps[:4]) > 0.03 and found.fall > 0.01  # several levels in play


@pytest.mark.parametrize("plane", [False, True])
def test_a_zero_covariance_gives_the_certain_verdict(plane):
    rng = np.random.default_rng(3)
    for _ in range(40):
        x, y = rng.uniform(-0.05, 0.1, 2)
        vx, vy = rng.uniform(-2.5, 2.5, 2)
        if plane:
            state = StateGaussian(np.array([x, y, vx, vy]), np.zeros((4, 4)))
            certain = classify(x, vx, P, y=y, ydot=vy)
        else:
            state = StateGaussian(np.array([x, vx]), np.zeros((2, 2)))
            certain = classify(x, vx, P)
        found = verdict_probabilities(state, P)
        level = {Strategy.ANKLE: 0, Strategy.HIP: 1, Strategy.FALL: 2 + P.max_steps}.get(
            certain.strategy, 1 + (certain.steps or 0)
        )
        expected = [0.0] * (3 + P.max_steps)
        expected[level] = 1.0
        assert [found.ankle, found.hip, *found.steps, found.fall] == expected
        assert found.capture_point_mean[0] == pytest.approx(certain.capture_point, abs=1e-15)


def test_latency_closed_form_is_the_lipm_with_the_cop_held():
    omega, p = P.omega, 0.03
    x0, v0, tau = 0.01, 0.4, 0.08

    def lipm(t, s):
        return [s[1], omega**2 * (s[0] - p)]

    run = solve_ivp(lipm, (0.0, tau), [x0, v0], rtol=1e-12, atol=1e-14)
    x, v = run.y[:, -1]
    mean, cov = delayed_capture_point([x0 + v0 / omega], [[0.0]], omega, tau, [p])
    assert mean[0] == pytest.approx(x + v / omega, abs=1e-10)
    assert cov[0, 0] == 0.0


@pytest.mark.parametrize("latency", [0.06, (0.02, 0.12)])
def test_latency_against_states_carried_through_the_delay(latency):
    mean, cov = np.array([0.0, 0.3]), np.array([[1e-4, 0.0], [0.0, 0.01]])
    held = 0.5 * (P.heel + P.toe)  # the default: the middle of the foot
    found = verdict_probabilities(StateGaussian(mean, cov), P, latency=latency)
    rng = np.random.default_rng(4)
    x, v = rng.multivariate_normal(mean, cov, N).T
    tau = latency if not isinstance(latency, tuple) else rng.uniform(*latency, N)
    c, s = np.cosh(P.omega * tau), np.sinh(P.omega * tau)
    x, v = held + (x - held) * c + v / P.omega * s, (x - held) * P.omega * s + v * c
    verdicts = sagittal_verdicts(x, v, P)
    level = levels_of(classify_states(x, v, P), verdicts.line.steps, P.max_steps)
    counts = np.bincount(level, minlength=3 + P.max_steps)
    for k, p in enumerate([found.ankle, found.hip, *found.steps, found.fall]):
        assert within(counts[k], p), (k, counts[k] / N, p)
    if isinstance(latency, tuple):
        assert found.method == "latency quadrature" and found.error < 1e-9
        xi = x + v / P.omega  # the mixture's mean and spread at the command
        assert found.capture_point_mean[0] == pytest.approx(xi.mean(), abs=4 * xi.std() / 1e3)
        assert found.capture_point_cov[0][0] == pytest.approx(xi.var(), rel=0.01)
    # Latency only moves mass outward: the ankle's share shrinks.
    assert found.ankle < verdict_probabilities(StateGaussian(mean, cov), P).ankle


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"mean": [0.0, 0.1, 0.2], "cov": np.eye(3)}, r"shape \(n, 2\) or \(n, 4\)"),
        ({"mean": [0.0, 0.1], "cov": np.eye(4)}, r"cov must have shape \(2, 2\)"),
        ({"mean": [0.0, 0.1], "cov": [[1.0, 0.2], [0.3, 1.0]]}, "symmetric"),
        ({"mean": [0.0, 0.1], "cov": [[1.0, 2.0], [2.0, 1.0]]}, "positive semi-definite"),
        ({"mean": [0.0, math.nan], "cov": np.eye(2)}, "mean must be finite"),
    ],
)
def test_bad_states_are_refused(kwargs, match):
    with pytest.raises(InvalidParameterError, match=match):
        StateGaussian(np.asarray(kwargs["mean"], dtype=float), np.asarray(kwargs["cov"]))


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"latency": -0.01}, "latency"),
        ({"latency": math.nan}, "latency"),
        ({"latency": (0.1, 0.05)}, "low <= high"),
        ({"latency": (0.1,)}, "range"),
        ({"latency": 10.0}, re.escape(f"e^(omega tau) <= {MAX_LATENCY_GROWTH:g}")),
        ({"cop": [0.0, 0.1]}, r"cop must be 1 numbers"),
        ({"support": Support.from_params(P)}, "support applies to a plane state"),
    ],
)
def test_bad_options_are_refused(kwargs, match):
    state = StateGaussian(np.array([0.0, 0.3]), np.eye(2) * 1e-4)
    with pytest.raises(InvalidParameterError, match=match):
        verdict_probabilities(state, P, **kwargs)


def _cli(capsys, *args):
    from pushrecovery.cli import main

    with pytest.raises(SystemExit) as info:
        main(["classify", *args])
    captured = capsys.readouterr()
    return info.value.code, captured.out, captured.err


def test_classify_cli_adds_the_probabilities(capsys):
    import json

    code, out, _ = _cli(capsys, "--x", "0", "--xdot", "0.5", "--cov", "1e-4,0,0,0.01", "--json")
    assert code == 0
    data = json.loads(out)
    expected = verdict_probabilities(
        StateGaussian(np.array([0.0, 0.5]), np.diag([1e-4, 0.01])), P
    ).to_dict()
    assert data["probabilities"] == expected and data["strategy"] == "hip"  # keys kept
    code, out, _ = _cli(capsys, "--x", "0", "--xdot", "0.5", "--ydot", "0.3", "--latency",
                        "0.02:0.06", "--json")  # fmt: skip
    found = json.loads(out)["probabilities"]
    assert code == 0 and found["method"] == "latency quadrature"
    assert len(found["capture_point_mean"]) == 2
    code, out, _ = _cli(capsys, "--x", "0", "--xdot", "0.5", "--json")
    assert "probabilities" not in json.loads(out)  # only when asked


@pytest.mark.parametrize(
    ("args", "match"),
    [
        (("--cov", "1,2,3"), "--cov must be 4 numbers"),
        (("--cov", "a,b,c,d"), "--cov must be 4 comma-separated numbers"),
        (("--cov", "1,2,2,1"), "positive semi-definite"),
        (("--ydot", "0.1", "--cov", "1,0,0,1"), "--cov must be 16 numbers"),
        (("--latency", "a:b"), "--latency must be S or LOW:HIGH"),
        (("--latency", "-0.1"), "latency"),
        (("--latency", "0.2:0.1"), "low <= high"),
    ],
)
def test_classify_cli_refuses_bad_uncertainty_in_one_line(capsys, args, match):
    code, _, err = _cli(capsys, "--x", "0", "--xdot", "0.5", *args)
    assert code == 2 and err.count("\n") == 1 and match in err


def test_the_docs_example_prints_what_it_says(capsys):
    from pathlib import Path

    page = (Path(__file__).parent.parent / "docs" / "uncertainty.md").read_text()
    blocks = re.findall(r"```python\n(.*?)```", page, flags=re.S)
    assert len(blocks) == 2
    namespace: dict = {}
    for block in blocks:  # in order, in one namespace, as a reader runs them
        exec(compile(block, "docs/uncertainty.md", "exec"), namespace)
        promised = re.search(r"# prints: (.*)", block)
        assert promised is not None
        assert capsys.readouterr().out.strip() == promised.group(1).strip()


def test_many_states_at_once_equal_each_state_alone():
    from pushrecovery.surfaces.probability import ankle_probability, verdict_probability_table

    rng = np.random.default_rng(5)
    means = np.column_stack([rng.uniform(-0.02, 0.05, 6), rng.uniform(-1.5, 2.5, 6)])
    cov = np.array([[1e-4, 2e-4], [2e-4, 0.02]])
    table = verdict_probability_table(means, cov, P, latency=0.03)
    for k, mean in enumerate(means):
        alone = verdict_probabilities(StateGaussian(mean, cov), P, latency=0.03)
        assert table.levels[k].tolist() == pytest.approx([*alone.by_level, alone.fall], abs=1e-15)
    assert table.levels.sum(axis=1) == pytest.approx(np.ones(6), abs=1e-12)
    # P(ankle) alone: the table's first column (the line's closed form, and the general path
    # with one covariance per state).
    assert ankle_probability(means, cov, P, latency=0.03) == pytest.approx(table.ankle, abs=1e-15)
    each = np.stack([cov * (1 + k) for k in range(6)])
    assert ankle_probability(means, each, P) == pytest.approx(
        verdict_probability_table(means, each, P).ankle, abs=1e-15
    )
    plane = np.column_stack([means[:, 0], means[:, 0], means[:, 1], 0.5 * means[:, 1]])
    cov4 = np.diag([1e-4, 1e-4, 0.02, 0.02])
    support = Support.from_params(P, Stance.RIGHT)
    assert ankle_probability(plane, cov4, P, support=support) == pytest.approx(
        verdict_probability_table(plane, cov4, P, support=support).ankle, abs=1e-15
    )
    assert float(ankle_probability(means[0], cov, P, latency=0.03)) == pytest.approx(
        table.ankle[0], abs=1e-15
    )


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda f: f(np.zeros((3, 3)), np.eye(3), P), r"shape \(n, 2\) or \(n, 4\)"),
        (lambda f: f(np.zeros((3, 2)), np.ones((2, 2, 2)), P), r"cov must have shape"),
        (lambda f: f(np.zeros(2), np.eye(2), P, support=Support.from_params(P)), "plane state"),
        (lambda f: f(np.zeros(2), np.eye(2), P, latency=(0.0, 0.1)), "latency"),
        (lambda f: f(np.zeros(2), np.eye(2), "P"), "params"),
    ],
)
def test_ankle_probability_refuses_bad_input(call, match):
    from pushrecovery.errors import PushRecoveryError
    from pushrecovery.surfaces.probability import ankle_probability

    with pytest.raises(PushRecoveryError, match=match):
        call(ankle_probability)


def test_delayed_capture_point_refuses_bad_input():
    with pytest.raises(InvalidParameterError, match="omega"):
        delayed_capture_point([0.1], [[1e-3]], -3.0, 0.02, [0.0])
    with pytest.raises(InvalidParameterError, match="mean must be finite"):
        delayed_capture_point([math.nan], [[1e-3]], 3.0, 0.02, [0.0])


def test_a_body_known_up_to_a_spread_against_sampling_bodies_and_states():
    from scipy.stats import truncnorm

    from pushrecovery.surfaces.probability import TRUNCATION, BodySpread

    spread = BodySpread(mass=6.0, com_height=0.05, foot_length=0.02, torque_max=15.0)
    mean, cov = np.array([0.0, 0.55]), np.diag([1e-4, 0.01])
    found = verdict_probabilities(StateGaussian(mean, cov), P, spread=spread)
    assert found.method == "quasi-Monte Carlo over the body" and 0.0 < found.error < 2e-3
    # Plain Monte Carlo: 2,000 bodies from the truncated normals, 500 states each.
    rng = np.random.default_rng(6)
    bodies, per_body = 2000, 500
    z = truncnorm.rvs(-TRUNCATION, TRUNCATION, size=(bodies, 4), random_state=rng)
    counts = np.zeros(3 + P.max_steps)
    for row in z:
        scale = 1.0 + spread.foot_length * row[2] / (P.toe - P.heel)
        body = dataclasses.replace(
            P,
            mass=P.mass + spread.mass * row[0],
            com_height=P.com_height + spread.com_height * row[1],
            heel=P.heel * scale,
            toe=P.toe * scale,
            torque_max=P.torque_max + spread.torque_max * row[3],
        )
        x, v = rng.multivariate_normal(mean, cov, per_body).T
        level = levels_of(classify_states(x, v, body), sagittal_verdicts(x, v, body).line.steps,
                          P.max_steps)  # fmt: skip
        counts += np.bincount(level, minlength=3 + P.max_steps)
    n = bodies * per_body
    for k, p in enumerate([found.ankle, found.hip, *found.steps, found.fall]):
        se = math.sqrt(max(p * (1 - p), 1e-12) / n + found.error**2)
        assert abs(counts[k] / n - p) <= 4.0 * se, (k, counts[k] / n, p)
    # The spread matters here: the certain body gives other numbers.
    exact = verdict_probabilities(StateGaussian(mean, cov), P)
    assert abs(exact.hip - found.hip) > 10 * found.error


def test_a_zero_spread_is_the_exact_answer():
    from pushrecovery.surfaces.probability import BodySpread

    state = StateGaussian(np.array([0.0, 0.5]), np.diag([1e-4, 0.01]))
    found = verdict_probabilities(state, P, spread=BodySpread(), samples=4, replicates=2)
    exact = verdict_probabilities(state, P)
    assert found.by_level == pytest.approx(exact.by_level, abs=1e-15) and found.error == 0.0


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"spread": {"mass": -1.0}}, "mass"),
        ({"spread": {"com_height": math.nan}}, "com_height"),
        ({"spread": {"com_height": 0.5}}, "spread: the body"),
        ({"samples": 48}, "power of 2"),
        ({"samples": 1}, "samples"),
        ({"replicates": 1}, "replicates"),
        ({"seed": -1}, "seed"),
    ],
)
def test_bad_spreads_are_refused(kwargs, match):
    from pushrecovery.surfaces.probability import BodySpread

    state = StateGaussian(np.array([0.0, 0.5]), np.diag([1e-4, 0.01]))
    with pytest.raises(InvalidParameterError, match=match):
        spread = BodySpread(**kwargs.pop("spread", {"mass": 1.0}))
        verdict_probabilities(state, P, spread=spread, **kwargs)


def test_the_margin_for_a_one_percent_fall_probability():
    """docs/uncertainty.md: m = z σ_ξ + (b − p)(1 − e^{−ωτ}) puts P(beyond the toe) at 1 %."""
    from scipy.special import ndtri

    from pushrecovery.surfaces.probability import ankle_probability

    sx, sv, tau = 0.005, 0.05, 0.05
    omega, held = P.omega, 0.5 * (P.heel + P.toe)
    sigma = math.sqrt(sx**2 + (sv / omega) ** 2)
    margin = -ndtri(0.01) * sigma + (P.toe - held) * (1.0 - math.exp(-omega * tau))
    assert margin == pytest.approx(0.0534, abs=5e-5)  # the table's 53 mm
    xi = P.toe - margin  # the estimate: x = 0, xdot = ω ξ
    outside = 1.0 - ankle_probability([0.0, xi * omega], np.diag([sx**2, sv**2]), P, latency=tau)
    assert outside == pytest.approx(0.01, abs=1e-9)  # the heel side adds ~1e-12


def test_latency_against_a_lipm_whose_controller_acts_late():
    """A controller that reacts τ late (CoP held at the foot's middle until then, at the toe
    after: the ankle's best) stops the LIPM exactly when ξ(τ) = p + (ξ − p)e^{ωτ} is inside the
    foot. Simulated with solve_ivp from states 1 mm either side of the predicted limit."""
    omega, held, tau = P.omega, 0.5 * (P.heel + P.toe), 0.08
    limit = held + (P.toe - held) * math.exp(-omega * tau)  # ξ(0) whose ξ(τ) is the toe

    def stops(xi0: float) -> bool:
        def lipm(t, s, p):
            return [s[1], omega**2 * (s[0] - p)]

        delayed = solve_ivp(lipm, (0.0, tau), [0.0, xi0 * omega], args=(held,), rtol=1e-12,
                            atol=1e-14)  # fmt: skip
        moving = lambda t, s, p: s[1]  # noqa: E731 - the CoM comes to rest
        moving.terminal, moving.direction = True, -1
        away = lambda t, s, p: s[0] - 1.0  # noqa: E731 - or leaves over the toe
        away.terminal = True
        run = solve_ivp(lipm, (0.0, 10.0), delayed.y[:, -1], args=(P.toe,), events=[moving, away],
                        rtol=1e-12, atol=1e-14)  # fmt: skip
        return len(run.t_events[0]) > 0

    assert stops(limit - 1e-3) and not stops(limit + 1e-3)
    # The probabilities put the same limit at their 50 % point for a symmetric estimate.
    cov = np.diag([0.0, (1e-3 * omega) ** 2])
    half = (
        1.0
        - verdict_probabilities(
            StateGaussian(np.array([0.0, limit * omega]), cov), P, latency=tau
        ).ankle
    )
    assert half == pytest.approx(0.5, abs=1e-9)


@pytest.mark.parametrize(("plane", "region"), [(False, "cop"), (False, "cmp"), (True, "cop")])
def test_margin_quantiles_against_a_million_states(plane, region):
    """P(margin <= q_α) of 10⁶ drawn states is α within 4 standard errors."""
    from pushrecovery.surfaces.cmp import cmp_offset
    from pushrecovery.surfaces.probability import margin_quantiles

    levels = (0.01, 0.05, 0.5, 0.95, 0.99)
    rng = np.random.default_rng(8)
    if plane:
        state = StateGaussian(np.array([0.0, 0.0, 0.3, 0.2]), np.diag([1e-4, 1e-4, 0.01, 0.01]))
        x, y, vx, vy = rng.multivariate_normal(state.mean, state.cov, N).T
        polygon = Support.from_params(P).polygon
        margin = polygon.signed_distance(x + vx / P.omega, y + vy / P.omega)
    else:
        state = StateGaussian(np.array([0.0, 0.3]), np.diag([1e-4, 0.01]))
        x, v = rng.multivariate_normal(state.mean, state.cov, N).T
        xi = x + v / P.omega
        grow = cmp_offset(P) if region == "cmp" else 0.0
        margin = np.minimum(xi - (P.heel - grow), P.toe + grow - xi)
    found = margin_quantiles(state, P, levels, region=region)
    assert found.error < 5e-5  # the plane's round corners bracketed to 15 µm
    for alpha, value in zip(levels, found.values, strict=True):
        assert within(np.count_nonzero(margin <= value), alpha), (alpha, value)


def test_a_zero_covariance_gives_the_certain_margin():
    from pushrecovery.surfaces.probability import margin_quantiles

    for mean in ([0.01, 0.4], [0.0, 1.2]):
        certain = classify(mean[0], mean[1], P).margins["cop"]
        found = margin_quantiles(StateGaussian(np.array(mean), np.zeros((2, 2))), P)
        assert found.values == pytest.approx((certain,) * 5, abs=1e-15) and found.error == 0.0
    plane = StateGaussian(np.array([0.0, 0.02, 0.3, 0.1]), np.zeros((4, 4)))
    certain = classify(0.0, 0.3, P, y=0.02, ydot=0.1).margins["cop"]
    assert margin_quantiles(plane, P, (0.5,)).values == pytest.approx((certain,), abs=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"levels": (0.0, 0.5)}, r"levels must be probabilities in \(0, 1\)"),
        ({"levels": ()}, "levels"),
        ({"region": "step"}, "region must be 'cop' or 'cmp'"),
        ({"latency": (0.0, 0.1)}, "latency"),
        ({"support": Support.from_params(P)}, "plane state"),
    ],
)
def test_margin_quantiles_refuse_bad_input(kwargs, match):
    from pushrecovery.errors import PushRecoveryError
    from pushrecovery.surfaces.probability import margin_quantiles

    state = StateGaussian(np.array([0.0, 0.3]), np.diag([1e-4, 0.01]))
    with pytest.raises(PushRecoveryError, match=match):
        margin_quantiles(state, P, **kwargs)


def test_the_monitor_gives_the_verdict_probabilities_tick_after_tick():
    from pushrecovery.surfaces.probability import ProbabilityMonitor

    rng = np.random.default_rng(9)
    line = ProbabilityMonitor(P, latency=0.03)
    support = Support.from_params(P, Stance.LEFT)
    plane = ProbabilityMonitor(P, support, latency=0.03)
    for _ in range(10):
        mean = np.array([rng.uniform(-0.03, 0.08), rng.uniform(-1.0, 3.0)])
        cov = np.diag([rng.uniform(1e-5, 1e-3), rng.uniform(1e-3, 0.2)])
        found = line.query(mean, cov)
        exact = verdict_probabilities(StateGaussian(mean, cov), P, latency=0.03)
        assert (found.ankle, found.hip, found.step, found.fall) == pytest.approx(
            (exact.ankle, exact.hip, sum(exact.steps), exact.fall), abs=1e-12
        )
        mean4 = np.array([mean[0], 0.05, mean[1], rng.uniform(-1.5, 1.5)])
        cov4 = np.diag([cov[0, 0], cov[0, 0], cov[1, 1], cov[1, 1]])
        found = plane.query(mean4, cov4)
        exact = verdict_probabilities(StateGaussian(mean4, cov4), P, support=support, latency=0.03)
        assert (found.ankle, found.hip, found.step, found.fall) == pytest.approx(
            (exact.ankle, exact.hip, sum(exact.steps), exact.fall), abs=1e-12
        )


def test_the_monitor_swaps_its_support_whole():
    import threading

    from pushrecovery.surfaces.probability import ProbabilityMonitor

    left, right = Support.from_params(P, Stance.LEFT), Support.from_params(P, Stance.RIGHT)
    monitor = ProbabilityMonitor(P, left)
    mean, cov = np.array([0.0, 0.05, 0.4, 0.5]), np.diag([1e-4, 1e-4, 0.01, 0.01])
    answers = {monitor.query(mean, cov)}
    monitor.set_support(right)
    answers.add(monitor.query(mean, cov))
    assert len(answers) == 2  # the supports answer differently
    seen, stop = [], threading.Event()

    def switch() -> None:
        while not stop.is_set():
            monitor.set_support(left)
            monitor.set_support(right)

    worker = threading.Thread(target=switch)
    worker.start()
    try:
        seen = [monitor.query(mean, cov) for _ in range(300)]
    finally:
        stop.set()
        worker.join()
    assert set(seen) <= answers  # the old support's answer or the new one's, never a mix


def test_the_monitor_refuses_bad_input():
    from pushrecovery.surfaces.probability import ProbabilityMonitor

    line = ProbabilityMonitor(P)
    with pytest.raises(InvalidParameterError, match="one state of 2 numbers"):
        line.query(np.zeros(4), np.eye(4))
    with pytest.raises(InvalidParameterError, match="no support"):
        line.set_support(Support.from_params(P))
    with pytest.raises(InvalidParameterError, match="positive semi-definite"):
        line.query(np.zeros(2), np.array([[1.0, 2.0], [2.0, 1.0]]))
    with pytest.raises(InvalidParameterError, match="latency"):
        ProbabilityMonitor(P, latency=-1.0)
