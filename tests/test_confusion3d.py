"""The confusion matrix of predicted against used strategy on the 3-D bodies (issue 19 item 5).

The counting and the causes are checked on hand-made rows (no physics); the predicted strategy
against hand-computed thresholds for the paper preset's rectangle feet (heel −0.05, toe 0.15,
width 0.10 m, ankles 0.20 m apart; m = 72 kg, L = 1 m), the standing CoM 1 cm ahead of the
ankles as on the biped3d.
"""

import math

import numpy as np
import pyarrow.parquet as pq
import pytest

from pushrecovery import load_params
from pushrecovery.campaign.spec.humanoid import critical_impulse, predict_push
from pushrecovery.errors import InvalidParameterError
from pushrecovery.experiments.confusion3d import (
    CAUSES,
    FAILED_TICKS,
    LABELS,
    ConfusionPush,
    classify_cause,
    confusion_counts,
    confusion_from_rows,
)
from pushrecovery.surfaces.cmp import cmp_offset, cmp_offset_roll

ORIGIN = (0.01, 0.0)  # the standing CoM's ground point [m]
#: Just inside / just outside a threshold [-]: far from rounding, near the edge.
NEAR = 0.01


def row(predicted, used, *, corrected=None, outcome="recovered", lift_offs=0, ratio=0.5,
        failed=0, azimuth=0.0, fraction=1.0):  # fmt: skip
    return {
        "azimuth": azimuth,
        "fraction": fraction,
        "impulse": 10.0 * fraction,
        "predicted": predicted,
        "predicted_corrected": corrected or predicted,
        "used": used,
        "outcome": outcome,
        "steps": 1 if used == "step" else 0,
        "lift_offs": lift_offs,
        "peak_torque_ratio": ratio,
        "failed_ticks": failed,
        "index": 0,  # other campaign columns are ignored
    }


def test_counts_by_hand():
    predicted = ["ankle", "ankle", "hip", "step", "step", "fall"]
    used = ["ankle", "hip", "hip", "fall", "step", "step"]
    counts = confusion_counts(predicted, used)
    expected = np.zeros((4, 4), dtype=int)
    for p, u in (("ankle", "ankle"), ("ankle", "hip"), ("hip", "hip"), ("step", "fall"),
                 ("step", "step"), ("fall", "step")):  # fmt: skip
        expected[LABELS.index(p), LABELS.index(u)] += 1
    assert counts.tolist() == expected.tolist()
    assert counts.sum() == 6 and np.trace(counts) == 3


def test_rows_to_matrix_causes_and_accuracy():
    rows = [
        row("ankle", "ankle"),  # agree
        row("ankle", "hip", corrected="hip"),  # the push's height
        row("hip", "ankle"),  # a lesser strategy sufficed
        row("hip", "step"),  # the hip law fell short, a step saved it
        row("step", "fall", outcome="fell", lift_offs=1),  # stepped, fell
        row("step", "fall", outcome="fell"),  # never lifted a foot
        row("ankle", "ankle", outcome="undecided"),  # still moving: used = undecided
        row("hip", "fall", outcome="fell", ratio=1.0, failed=FAILED_TICKS),  # saturated
        row("step", "fall", outcome="fell", lift_offs=1, ratio=1.0, failed=FAILED_TICKS - 1),
        row("ankle", "ankle", outcome="error"),  # no outcome: left out
        row("step", "step", outcome="slipped"),  # at rest on feet that slid: used = slipped
    ]
    result = confusion_from_rows(rows, "biped3d")
    assert len(result.pushes) == 10 and result.errors == 1
    assert [p.cause for p in result.pushes] == [
        "agree", "torso lever", "lesser sufficed", "hip shortfall", "step failed", "no step",
        "undecided", "saturation", "step failed", "slipped",
    ]  # fmt: skip
    assert result.pushes[6].used == "undecided" and result.pushes[9].used == "slipped"
    counts = result.counts
    assert counts.sum() == 8  # the runs that recovered or fell
    assert counts[LABELS.index("ankle"), LABELS.index("fall")] == 0
    assert counts[LABELS.index("step"), LABELS.index("fall")] == 3
    assert result.apart() == {"undecided": [1, 0, 0, 0], "slipped": [0, 0, 1, 0]}
    # The undecided run is left out; the slipped one did not recover: it disagrees.
    assert result.judged == 9
    assert result.accuracy == pytest.approx(1 / 9)
    # against the corrected verdict the second row agrees as well
    assert result.accuracy_corrected == pytest.approx(2 / 9)
    causes = result.causes()
    assert set(causes) == set(CAUSES) and sum(causes.values()) == 10 and causes["agree"] == 1


def test_write_tables(tmp_path):
    result = confusion_from_rows([row("ankle", "ankle"), row("hip", "step")], "biped3d")
    parquet, csv = result.write(tmp_path / "confusion")
    table = pq.read_table(parquet)
    assert table.num_rows == 2 and table.column("cause").to_pylist() == ["agree", "hip shortfall"]
    assert csv.read_text().splitlines()[0].startswith('"azimuth"')
    assert "| ankle | 1 | 0 | 0 | 0 | 0 | 0 |" in result.to_markdown()
    assert "| predicted \\ used | ankle | hip | step | fall | undecided | slipped |" in (
        result.to_markdown()
    )


def test_figure_annotates_the_counts():
    from pushrecovery.plots.confusion3d import confusion3d_figure

    rows = [row("ankle", "ankle", azimuth=a) for a in (0.0, 90.0)] + [row("hip", "step")]
    rows.append(row("hip", "hip", outcome="undecided"))
    fig = confusion3d_figure(confusion_from_rows(rows, "biped3d"))
    matrix = fig.axes[0]
    texts = [t.get_text() for t in matrix.texts]
    # 4 rows x (4 used + undecided + slipped), row by row.
    assert len(texts) == 24 and texts[0] == "2" and texts[LABELS.index("hip") * 6 + 2] == "1"
    assert texts[LABELS.index("hip") * 6 + 4] == "1"  # the undecided column


@pytest.mark.parametrize(
    ("bad", "name"),
    [({"predicted": "jump"}, "predicted"), ({"used": None}, "missing used")],
)
def test_bad_rows(bad, name):
    with pytest.raises(InvalidParameterError, match=name):
        confusion_from_rows([{**row("ankle", "ankle"), **bad}], "biped3d")


def test_bad_counts():
    with pytest.raises(InvalidParameterError, match="same length"):
        confusion_counts(["ankle"], [])
    with pytest.raises(InvalidParameterError, match="labels"):
        confusion_counts(["ankle"], ["run"])
    with pytest.raises(InvalidParameterError, match="used"):
        ConfusionPush(0.0, 1.0, 1.0, "ankle", "ankle", "crawl", "recovered", 0, 0, 0.0, 0)


def test_cause_order_prefers_the_lever_to_the_shortfall():
    # corrected verdict hip, used hip: the lever explains it even though the plain one is ankle
    push = ConfusionPush(0.0, 1.1, 11.0, "ankle", "hip", "hip", "recovered", 0, 0, 0.4, 0)
    assert classify_cause(push) == "torso lever"


# --- the predicted strategy against a hand computation --------------------------------------


@pytest.fixture(scope="module")
def params():
    return load_params()


def test_ankle_critical_impulse_by_hand(params):
    m, w = 72.0, math.sqrt(9.81 / 1.0)
    assert critical_impulse(params, ORIGIN, 0.0) == pytest.approx(m * w * (0.15 - 0.01))
    assert critical_impulse(params, ORIGIN, 90.0) == pytest.approx(m * w * (0.10 + 0.05))
    assert critical_impulse(params, ORIGIN, 0.0, "hip") == pytest.approx(
        m * w * (0.15 + cmp_offset(params) - 0.01)
    )


@pytest.mark.parametrize(
    ("azimuth", "ankle_edge", "hip_width"),
    [(0.0, 0.15 - 0.01, "pitch"), (90.0, 0.10 + 0.05, "roll")],
)
def test_predicted_strategy_by_hand(params, azimuth, ankle_edge, hip_width):
    # ξ = r0 + J/(m ω) u: ankle while ξ is inside the feet's hull, hip while inside it grown by
    # the hip's CMP offset along that axis, step beyond (one step captures these).
    m, w = 72.0, math.sqrt(9.81 / 1.0)
    a = cmp_offset(params) if hip_width == "pitch" else cmp_offset_roll(params)
    ankle, hip = m * w * ankle_edge, m * w * (ankle_edge + a)
    cases = [((1 - NEAR) * ankle, "ankle"), ((1 + NEAR) * ankle, "hip"),
             ((1 - NEAR) * hip, "hip"), ((1 + NEAR) * hip, "step")]  # fmt: skip
    for impulse, expected in cases:
        found, corrected = predict_push(params, ORIGIN, impulse, azimuth)
        assert found.strategy.value == expected, (impulse, expected)
        assert corrected == expected  # no lever: the same verdict
    # the push 20 % above the CoM's height (d/z0 = 0.2): the ankle's limit / 1.2
    _, corrected = predict_push(params, ORIGIN, (1 + NEAR) * ankle / 1.2, azimuth, 0.2)
    assert corrected == "hip"
    found, corrected = predict_push(params, ORIGIN, (1 - NEAR) * ankle / 1.2, azimuth, 0.2)
    assert found.strategy.value == corrected == "ankle"


def test_predict_push_bad_lever(params):
    with pytest.raises(InvalidParameterError, match="lever_ratio"):
        predict_push(params, ORIGIN, 1.0, 0.0, -0.1)
