"""The steps of a batch of measured trials: one row per step (``steps.parquet``, ``steps.csv``).

A step is a foot's foot-off and its next foot-contact
(:func:`~pushrecovery.analysis.steps_measured.measured_steps`). Its row holds the timing and
the foot's displacement, Hof's margins of stability at the contact, the verdicts of the frame
at its foot-off (the strategy and the steps the state needed: the N-step verdict before the
step), the step the surfaces recommend there with its capture range (Eqs. 21–22 with the
body's feet, docs/steps.md) and the taken step's margin inside it, and the landing against the
2-D one-step capture region. Columns are SI; each field of the Parquet schema carries its unit
and a description as metadata (:func:`step_schema`). A contract: columns are added, never
renamed or dropped.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field, fields
from typing import TYPE_CHECKING, Any

from pushrecovery.arguments import require_type
from pushrecovery.campaign.trials.rows import check_job, subject_name

if TYPE_CHECKING:
    from pushrecovery.analysis.trial import TrialSummary

__all__ = ["STEP_FIELDS", "StepRow", "step_schema", "trial_steps"]


def _col(unit: str, description: str) -> Any:
    """Return a nullable column with its unit and description (the Parquet field's metadata)."""
    return field(default=None, metadata={"unit": unit, "description": description})


@dataclass(frozen=True, slots=True)
class StepRow:
    """One measured step of a trial; see each field's ``description`` (:func:`step_schema`).

    ``ap`` is forward (+), ``ml`` the subject's left (+); verdicts ``..._ap``/``..._ml`` are
    the axis' own. Margins are + inside (stable side); null where unknown.
    """

    trial: str = field(metadata={"unit": "", "description": "trial (path below the root)"})
    subject: str = field(metadata={"unit": "", "description": "the trial's subject"})
    step: int = field(metadata={"unit": "", "description": "the step's order in the trial, from 1"})
    foot: str = field(metadata={"unit": "", "description": "the stepping foot"})
    foot_off: float = field(metadata={"unit": "s", "description": "foot-off"})
    foot_contact: float = field(metadata={"unit": "s", "description": "foot-contact"})
    onset: float | None = _col("s", "perturbation onset of the trial")
    latency: float | None = _col("s", "foot-off minus the onset")
    duration: float | None = _col("s", "swing time: foot-contact minus foot-off")
    length: float | None = _col("m", "the foot's displacement along ap (forward +)")
    width: float | None = _col("m", "the foot's displacement along ml (left +)")
    start_ap: float | None = _col("m", "the foot (heel-toe midpoint) before the step, ap")
    start_ml: float | None = _col("m", "the foot (heel-toe midpoint) before the step, ml")
    end_ap: float | None = _col("m", "the foot (heel-toe midpoint) after the step, ap")
    end_ml: float | None = _col("m", "the foot (heel-toe midpoint) after the step, ml")
    mos_ap_contact: float | None = _col(
        "m", "Hof's MoS toward the motion along ap at foot-contact (frames' mos_ap)"
    )
    mos_ml_contact: float | None = _col(
        "m", "Hof's MoS toward the motion along ml at foot-contact (frames' mos_ml)"
    )
    mos_ap_off: float | None = _col("m", "Hof's MoS toward the motion along ap at foot-off")
    mos_ml_off: float | None = _col("m", "Hof's MoS toward the motion along ml at foot-off")
    cop_margin_ap_contact: float | None = _col(
        "m", "capture point's margin in the CoP region along ap at foot-contact (Eq. 4)"
    )
    cop_margin_ml_contact: float | None = _col(
        "m", "capture point's margin in the CoP region along ml at foot-contact (Eq. 4)"
    )
    strategy_ap: str | None = _col("", "strategy the foot-off frame needed along ap")
    strategy_ml: str | None = _col("", "strategy the foot-off frame needed along ml")
    steps_needed_ap: int | None = _col(
        "", "steps the foot-off frame needed along ap (0 ankle/hip, -1 fall): N-step verdict"
    )
    steps_needed_ml: int | None = _col(
        "", "steps the foot-off frame needed along ml (0 ankle/hip, -1 fall): N-step verdict"
    )
    step_region_margin_ap: float | None = _col(
        "m", "capture point's margin in the region of max_steps steps along ap at foot-off"
    )
    step_region_margin_ml: float | None = _col(
        "m", "capture point's margin in the region of max_steps steps along ml at foot-off"
    )
    recommended_ap: float | None = _col(
        "m", "first step the surfaces recommend at foot-off along ap (Eq. 21), signed"
    )
    recommended_ml: float | None = _col(
        "m", "first step the surfaces recommend at foot-off along ml (Eq. 21), signed"
    )
    step_min_ap: float | None = _col("m", "shortest first step that captures, ap (unsigned)")
    step_max_ap: float | None = _col("m", "longest first step that captures, ap (unsigned)")
    step_min_ml: float | None = _col("m", "shortest first step that captures, ml (unsigned)")
    step_max_ml: float | None = _col("m", "longest first step that captures, ml (unsigned)")
    step_margin_ap: float | None = _col(
        "m", "taken step's margin in [step_min_ap, step_max_ap] toward the recommended step"
    )
    step_margin_ml: float | None = _col(
        "m", "taken step's margin in [step_min_ml, step_max_ml] toward the recommended step"
    )
    capture_region_margin: float | None = _col(
        "m", "landing ankle's signed distance to the 2-D one-step capture region at foot-off"
    )
    in_capture_region: bool | None = _col("", "the landing ankle lies in that region")
    risk_ap_off: float | None = _col(
        "", "P(the ankle does not suffice) along ap at foot-off under com_noise (else null)"
    )
    risk_ml_off: float | None = _col(
        "", "P(the ankle does not suffice) along ml at foot-off under com_noise (else null)"
    )


#: Column names and their Python types, in order.
STEP_FIELDS: tuple[tuple[str, str], ...] = tuple((f.name, str(f.type)) for f in fields(StepRow))


@functools.cache
def step_schema() -> Any:
    """Return the Arrow schema of the steps table; each field's metadata: unit, description."""
    import pyarrow as pa

    types = {"str": pa.string(), "int": pa.int64(), "float": pa.float64(), "bool": pa.bool_()}
    return pa.schema(
        [
            pa.field(
                f.name,
                types[str(f.type).split("|")[0].strip()],
                nullable=True,
                metadata={"unit": f.metadata["unit"], "description": f.metadata["description"]},
            )
            for f in fields(StepRow)
        ]
    )


def trial_steps(job: Any, summary: TrialSummary) -> list[StepRow]:
    """Return the measured steps of an analysed trial, in time order (:class:`StepRow`)."""
    from pushrecovery.analysis.trial import TrialSummary

    check_job(job)
    require_type("summary", summary, TrialSummary)
    subject = subject_name(job)
    rows = []
    for k, taken in enumerate(summary.events.measured_steps, start=1):
        step = taken.step
        off, contact = taken.at_foot_off.axes, taken.at_foot_contact.axes
        ap, ml = taken.against_recommended["ap"], taken.against_recommended["ml"]
        region = taken.capture_region
        rows.append(
            StepRow(
                trial=job.name,
                subject=subject,
                step=k,
                foot=step.foot,
                foot_off=step.off_time,
                foot_contact=step.contact_time,
                onset=summary.events.onset.time,
                latency=step.latency,
                duration=step.duration,
                **{name: _finite(getattr(step, name)) for name in _POSITIONS},
                mos_ap_contact=contact["ap"].mos,
                mos_ml_contact=contact["ml"].mos,
                mos_ap_off=off["ap"].mos,
                mos_ml_off=off["ml"].mos,
                cop_margin_ap_contact=contact["ap"].cop_margin,
                cop_margin_ml_contact=contact["ml"].cop_margin,
                strategy_ap=off["ap"].strategy,
                strategy_ml=off["ml"].strategy,
                steps_needed_ap=off["ap"].steps,
                steps_needed_ml=off["ml"].steps,
                step_region_margin_ap=off["ap"].step_margin,
                step_region_margin_ml=off["ml"].step_margin,
                recommended_ap=ap.recommended,
                recommended_ml=ml.recommended,
                step_min_ap=ap.shortest,
                step_max_ap=ap.longest,
                step_min_ml=ml.shortest,
                step_max_ml=ml.longest,
                step_margin_ap=ap.margin,
                step_margin_ml=ml.margin,
                capture_region_margin=None if region is None else region.margin,
                in_capture_region=None if region is None else region.within,
                risk_ap_off=off["ap"].risk,
                risk_ml_off=off["ml"].risk,
            )
        )
    return rows


_POSITIONS = ("length", "width", "start_ap", "start_ml", "end_ap", "end_ml")


def _finite(value: float) -> float | None:
    return value if value == value else None  # NaN (a foot's markers missing) as null
