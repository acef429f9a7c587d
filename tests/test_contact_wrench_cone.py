"""The contact wrench cone of a sole against an exact program: an LP over its point contacts."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import linprog

from pushrecovery.control.wbc.foot_contact import contact_wrench_cone
from pushrecovery.errors import InvalidParameterError

MU = 0.7 / math.sqrt(2.0)
#: A box sole (heel 5 cm, toe 15 cm, 10 cm wide) and the G1's slightly tapered one [m].
SOLES = {
    "box": np.array([[-0.05, -0.05], [0.15, -0.05], [0.15, 0.05], [-0.05, 0.05]]),
    "g1": np.array([[-0.05, -0.025], [0.12, -0.0306], [0.12, 0.0306], [-0.05, 0.025]]),
    "pentagon": np.array([[-0.05, -0.04], [0.1, -0.05], [0.16, 0.0], [0.1, 0.05], [-0.05, 0.04]]),
}


def _generators(vertices: np.ndarray, mu: float) -> np.ndarray:
    """The wrenches (F, T) of unit pyramid edges at each vertex, as columns (6, 4k)."""
    columns = []
    for x, y in vertices:
        for fx, fy in ((mu, 0.0), (-mu, 0.0), (0.0, mu), (0.0, -mu)):
            force = np.array([fx, fy, 1.0])
            columns.append(np.concatenate([force, np.cross([x, y, 0.0], force)]))
    return np.array(columns).T


def _feasible(generators: np.ndarray, wrench: np.ndarray) -> bool:
    """Whether point forces in the pyramids sum to ``wrench`` (an LP: V λ = w, λ >= 0)."""
    found = linprog(np.zeros(generators.shape[1]), A_eq=generators, b_eq=wrench,
                    bounds=(0, None), method="highs")  # fmt: skip
    return found.status == 0


@pytest.mark.parametrize("name", sorted(SOLES))
def test_the_cone_holds_exactly_the_wrenches_point_contacts_can_give(name: str) -> None:
    vertices = SOLES[name]
    rows = contact_wrench_cone(vertices, MU)
    generators = _generators(vertices, MU)
    rng = np.random.default_rng(7)
    inside = outside = 0
    for _ in range(400):
        # Wrenches near the cone's boundary: F_z = 1, the rest spread around what it holds.
        wrench = np.array([*rng.normal(0.0, 0.2, 2), 1.0, *rng.normal(0.0, 0.04, 3)])
        margin = float((rows @ wrench).max())
        if abs(margin) < 1e-7:
            continue  # on a face: either answer is right
        assert (margin < 0.0) == _feasible(generators, wrench), wrench
        inside += margin < 0.0
        outside += margin > 0.0
    assert inside > 40 and outside > 40  # both sides were tried
    # Every generator lies in the cone; the zero wrench on its apex.
    assert (rows @ generators).max() < 1e-12
    assert np.abs(rows @ np.zeros(6)).max() == 0.0


def test_a_foot_loaded_on_its_toe_cannot_push_sideways_without_turning() -> None:
    # The coupling the independent bounds missed: all load on the toe edge (x = 0.15 m) and a
    # sideways force within the pyramid give a yaw moment x F_y about the ankle, which the toe
    # corners' friction (half-width 5 cm) cannot cancel: with T_z = 0 the floor cannot give it
    # (the foot turns on its toe), with T_z = x F_y it can.
    rows = contact_wrench_cone(SOLES["box"], MU)
    generators = _generators(SOLES["box"], MU)
    weight = 100.0
    on_toe = np.array([0.0, 0.0, weight, 0.0, -0.15 * weight, 0.0])
    assert (rows @ on_toe).max() == pytest.approx(0.0, abs=1e-9)  # on the CoP's face
    sideways = on_toe + np.array([0.0, 0.5 * MU * weight, 0.0, 0.0, 0.0, 0.0])
    assert (rows @ sideways).max() > 1e-3 and not _feasible(generators, sideways)
    turned = sideways + np.array([0.0, 0.0, 0.0, 0.0, 0.0, 0.15 * 0.5 * MU * weight])
    assert (rows @ turned).max() <= 1e-9 and _feasible(generators, turned)
    # The bounds the QP had before (|F_y| <= mu F_z, CoP on the sole, |T_z| <= mu r F_z) took it.
    assert abs(sideways[1]) <= MU * weight and sideways[5] == 0.0


@pytest.mark.parametrize(
    ("vertices", "mu"),
    [
        (np.zeros((2, 2)), MU),
        (np.array([[0.0, 0.0], [1.0, 0.0], [2.0, 0.0]]), MU),  # no area
        (SOLES["box"], 0.0),
        (SOLES["box"], math.nan),
        (np.array([[0.0, 0.0], [math.inf, 0.0], [0.0, 1.0]]), MU),
    ],
)
def test_bad_soles_are_refused(vertices: np.ndarray, mu: float) -> None:
    with pytest.raises(InvalidParameterError, match="vertices"):
        contact_wrench_cone(vertices, mu)
