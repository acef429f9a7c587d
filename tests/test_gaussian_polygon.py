"""P(X in a convex polygon) for a 2-D Gaussian X: Owen's T against quadrature and sampling.

The quadrature integrates the density over the polygon as an outer adaptive integral in x of
the exact inner normal integral in y (the conditional of y given x), split at the vertices'
x so that the integrand is smooth on each piece: an independent route to 1e-9.
"""

import itertools
import math

import numpy as np
import pytest
from scipy import integrate
from scipy.special import ndtr

from pushrecovery.errors import InvalidParameterError
from pushrecovery.ground.gaussian import (
    MAX_UNION,
    gaussian_mass,
    gaussian_union_mass,
    maximal,
)
from pushrecovery.ground.minkowski import clip
from pushrecovery.ground.polygon import convex_hull, rectangle
from pushrecovery.ground.support import Support
from pushrecovery.presets import load_params
from pushrecovery.surfaces.step.regions import StepRegions

P = load_params()
FOOT = rectangle(-0.05, 0.15, 0.10)
PENTAGON = convex_hull([[0.15, 0.05], [-0.05, 0.05], [-0.05, -0.05], [0.15, -0.05], [0.2, 0.0]])
TRIANGLE = convex_hull([[0.0, 0.0], [0.3, 0.05], [0.1, 0.25]])
STEP_REGION = StepRegions.of(P, Support.from_params(P)).polygons[0]  # 68 edges


def quadrature(mean, cov, polygon):
    """∫∫ over the polygon of the N(mean, cov) density (module docstring)."""
    sx, sy = math.sqrt(cov[0][0]), math.sqrt(cov[1][1])
    rho = cov[0][1] / (sx * sy)
    conditional_sd = sy * math.sqrt(1.0 - rho**2)

    def chord(x):
        low, high = -math.inf, math.inf
        for (nx, ny), b in zip(polygon.normals, polygon.offsets, strict=True):
            if ny > 0.0:
                high = min(high, (b - nx * x) / ny)
            elif ny < 0.0:
                low = max(low, (b - nx * x) / ny)
        return low, high

    def inner(x):
        low, high = chord(x)
        if not low < high:
            return 0.0
        m = mean[1] + rho * sy / sx * (x - mean[0])
        density = math.exp(-0.5 * ((x - mean[0]) / sx) ** 2) / (sx * math.sqrt(2.0 * math.pi))
        return density * (ndtr((high - m) / conditional_sd) - ndtr((low - m) / conditional_sd))

    cuts = np.unique(polygon.vertices[:, 0])
    return sum(
        integrate.quad(inner, a, b, epsabs=1e-13, epsrel=1e-12, limit=400)[0]
        for a, b in itertools.pairwise(cuts)
    )


CASES = [
    (FOOT, (0.05, 0.0), ((1e-3, 0.0), (0.0, 1e-3))),
    (FOOT, (0.2, 0.08), ((4e-3, 1.5e-3), (1.5e-3, 2e-3))),
    (PENTAGON, (0.1, 0.02), ((4e-3, 1.5e-3), (1.5e-3, 2e-3))),
    (PENTAGON, (-0.3, 0.4), ((1e-2, -9.9e-3), (-9.9e-3, 1e-2))),  # rho = -0.99, far outside
    (TRIANGLE, (0.12, 0.1), ((1e-4, 0.0), (0.0, 4e-4))),
    (STEP_REGION, (0.3, 0.1), ((0.05, 0.02), (0.02, 0.03))),
    (STEP_REGION, (0.9, -0.3), ((0.01, 0.0), (0.0, 0.02))),
]


@pytest.mark.parametrize(("polygon", "mean", "cov"), CASES)
def test_owens_t_sum_equals_quadrature(polygon, mean, cov):
    exact = float(gaussian_mass(mean, cov, polygon))
    assert exact == pytest.approx(quadrature(mean, cov, polygon), abs=1e-9)
    assert 0.0 <= exact <= 1.0


def test_a_million_samples_agree_within_their_standard_error():
    rng = np.random.default_rng(20261207)
    for polygon, mean, cov in CASES[:4]:
        samples = rng.multivariate_normal(mean, cov, 1_000_000)
        observed = polygon.contains(samples[:, 0], samples[:, 1]).mean()
        p = float(gaussian_mass(mean, cov, polygon))
        se = math.sqrt(max(p * (1.0 - p), 1e-12) / len(samples))
        assert abs(observed - p) <= 4.0 * se, (observed, p, se)


def test_many_means_at_once_and_one_covariance_per_mean():
    means = np.array([[0.05, 0.0], [0.2, 0.08], [3.0, 3.0]])
    cov = np.array([[4e-3, 1.5e-3], [1.5e-3, 2e-3]])
    together = gaussian_mass(means, cov, FOOT)
    alone = [float(gaussian_mass(m, cov, FOOT)) for m in means]
    # One mean alone takes a scalar path: the same sum, to the last bits.
    assert together.shape == (3,) and together.tolist() == pytest.approx(alone, abs=1e-15)
    assert together[2] < 1e-15
    covs = np.stack([cov, 2 * cov, 0.5 * cov])
    each = gaussian_mass(means, covs, FOOT)
    alone = [float(gaussian_mass(m, c, FOOT)) for m, c in zip(means, covs, strict=True)]
    assert each.tolist() == pytest.approx(alone, abs=1e-15)


def test_a_polygon_far_larger_than_the_spread_holds_all_the_mass():
    huge = rectangle(-1e3, 1e3, 2e3)
    assert float(gaussian_mass((0.3, -0.2), ((1.0, 0.2), (0.2, 0.5)), huge)) == pytest.approx(
        1.0, abs=1e-14
    )


def test_singular_covariances_are_exact():
    inside, outside, boundary = (0.05, 0.0), (0.5, 0.0), (0.15, 0.0)
    zero = np.zeros((2, 2))
    assert float(gaussian_mass(inside, zero, FOOT)) == 1.0
    assert float(gaussian_mass(outside, zero, FOOT)) == 0.0
    assert float(gaussian_mass(boundary, zero, FOOT)) == 0.0  # strictly inside, as the verdicts
    # Rank 1 along x: the chord of the foot [-0.05, 0.15] at y = 0.
    sd = 0.07
    line = np.array([[sd**2, 0.0], [0.0, 0.0]])
    expected = ndtr((0.15 - 0.05) / sd) - ndtr((-0.05 - 0.05) / sd)
    assert float(gaussian_mass(inside, line, FOOT)) == pytest.approx(expected, abs=1e-15)
    # The limit of regular covariances shrinking onto the line.
    thin = line + np.diag([0.0, 1e-16])
    assert float(gaussian_mass(inside, thin, FOOT)) == pytest.approx(expected, abs=1e-6)
    # Rank 1 along a diagonal, against the quadrature of the same line.
    u = np.array([1.0, 1.0]) / math.sqrt(2.0)
    diagonal = 0.01 * np.outer(u, u)

    def along(s):
        x, y = 0.05 + s * u[0], 0.0 + s * u[1]
        return (
            float(FOOT.point_signed_distance(x, y) > 0.0)
            * math.exp(-s * s / 0.02)
            / math.sqrt(0.02 * math.pi)
        )

    # The chord runs from y = -0.05 to y = 0.05 along the diagonal: s in ±0.05√2.
    chord = 0.05 * math.sqrt(2.0)
    assert float(gaussian_mass(inside, diagonal, FOOT)) == pytest.approx(
        ndtr(chord / 0.1) - ndtr(-chord / 0.1), abs=1e-15
    )
    assert integrate.quad(along, -1, 1, points=[-chord, chord])[0] == pytest.approx(
        float(gaussian_mass(inside, diagonal, FOOT)), abs=1e-9
    )


def test_unions_by_inclusion_and_exclusion():
    turned = FOOT.transformed(0.05, 0.03, 0.4)
    mean, cov = (0.1, 0.02), ((4e-3, 1.5e-3), (1.5e-3, 2e-3))
    rng = np.random.default_rng(7)
    samples = rng.multivariate_normal(mean, cov, 1_000_000)
    hit = FOOT.contains(samples[:, 0], samples[:, 1]) | turned.contains(
        samples[:, 0], samples[:, 1]
    )
    p = float(gaussian_union_mass(mean, cov, [FOOT, turned]))
    assert abs(hit.mean() - p) <= 4.0 * math.sqrt(p * (1 - p) / len(samples))
    # A polygon inside another adds nothing; the same polygon twice counts once.
    inner = rectangle(0.0, 0.1, 0.05)
    alone = float(gaussian_mass(mean, cov, FOOT))
    assert float(gaussian_union_mass(mean, cov, [inner, FOOT, FOOT])) == pytest.approx(alone)
    assert maximal([inner, FOOT, FOOT]) == [FOOT]
    # Disjoint: the masses add.
    far = FOOT.transformed(1.0, 0.0, 0.0)
    assert clip(FOOT, far) is None
    assert float(gaussian_union_mass(mean, cov, [FOOT, far])) == pytest.approx(
        alone + float(gaussian_mass(mean, cov, far)), abs=1e-15
    )


def test_the_intersection_of_two_rectangles_is_their_overlap():
    a, b = rectangle(0.0, 2.0, 2.0), rectangle(1.0, 3.0, 1.0)  # y in ±1 and ±0.5
    common = clip(a, b)
    assert common is not None and common.area == pytest.approx(1.0 * 1.0)
    assert common.xmin == pytest.approx(1.0) and common.ymax == pytest.approx(0.5)
    assert clip(a, a).area == pytest.approx(a.area)


@pytest.mark.parametrize(
    ("mean", "cov", "match"),
    [
        ((0.0, 0.0), ((1.0, 0.5), (0.4, 1.0)), "symmetric"),
        ((0.0, 0.0), ((1.0, 2.0), (2.0, 1.0)), "positive semi-definite"),
        ((0.0, 0.0), ((math.nan, 0.0), (0.0, 1.0)), "cov must be finite"),
        ((0.0, 0.0), ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0)), r"shape \(2, 2\)"),
        ((0.0, math.inf), ((1.0, 0.0), (0.0, 1.0)), "mean must be finite"),
        ((0.0, 0.0, 0.0), ((1.0, 0.0), (0.0, 1.0)), r"mean must have shape"),
        (((0.0, 0.0),), np.ones((2, 2, 2)), "needs means of shape"),
    ],
)
def test_bad_input_names_the_parameter(mean, cov, match):
    with pytest.raises(InvalidParameterError, match=match):
        gaussian_mass(mean, cov, FOOT)


def test_too_many_polygons_in_a_union_is_refused():
    spread = [FOOT.transformed(float(k), 0.0, 0.0) for k in range(MAX_UNION + 1)]
    with pytest.raises(InvalidParameterError, match=f"at most {MAX_UNION}"):
        gaussian_union_mass((0.0, 0.0), np.eye(2), spread)
