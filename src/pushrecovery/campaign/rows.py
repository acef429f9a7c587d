"""The columns of a campaign's rows, each family's Arrow schema, and the outcome of an error row.

A campaign writes one row per push (``OUT/pushes.parquet``). Its columns are a public contract:
``index``, one ``param_<name>`` per swept body parameter (in the order of the sweeps), then
:data:`COLUMNS` in this order. The planar models (every model but ``biped3d`` and ``g1``) and
the 3-D models write the same columns (the 3-D ones are null on the planar models); what
differs is what some of them mean, so each family has its own schema (:func:`row_schema`)
whose fields carry their unit and a one-line description as field metadata (``unit``,
``description``): a Parquet file explains its own columns,
``pyarrow.parquet.read_schema(path).field("x0").metadata``.

The rows themselves are ``dict`` s from column name to value, built on the workers by
:mod:`~pushrecovery.campaign.pushes` (planar) and
:mod:`~pushrecovery.campaign.pushes.humanoid` (3-D) and turned into a table by ``pyarrow``
with this schema.

Over 400 lines on purpose: the column table (each column's unit and description) is the
families' schema itself, and the verdict and physics columns are filled from it.
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, Literal, cast

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.params import UNITS
from pushrecovery.sim.physical_checks import PhysicalChecks
from pushrecovery.sim.result import Outcome
from pushrecovery.surfaces.strategy import STRATEGY_CODES, Strategy

if TYPE_CHECKING:
    from pushrecovery.campaign.spec import CampaignSpec, Push

__all__ = [
    "COLUMNS",
    "COLUMNS_3D",
    "COLUMNS_PHYSICS",
    "COLUMNS_UNCERTAIN",
    "ERROR_OUTCOME",
    "ERROR_OUTCOME_3D",
    "FAMILIES",
    "PARAM_UNITS",
    "Column",
    "Family",
    "columns",
    "physics_columns",
    "row_schema",
    "used_label",
    "verdict_columns",
]

Family = Literal["planar", "3d"]
#: The campaign families: the planar models', and the 3-D humanoids' (``biped3d``, ``g1``).
FAMILIES: tuple[Family, ...] = ("planar", "3d")


@dataclass(frozen=True, slots=True)
class Column:
    """One column of a campaign's rows.

    Attributes
    ----------
    name : str
        The column's name in the Parquet file.
    kind : str
        Its Arrow type: ``float64``, ``int64``, ``string`` or ``bool``.
    unit : str
        SI unit of its values (``-``: a count, a ratio or a label).
    description : str
        What it holds, in one line.
    """

    name: str
    kind: str
    unit: str
    description: str


_NULL_PLANAR = "null on the planar models"
_MUJOCO = "MuJoCo, every physics step"
_NULL_ANALYTIC = "null on the analytic models and in the compiled and rollout engines"
_NULL_CERTAIN = "null without the spec's state_sd or latency, in error rows and in 3-D"

#: The columns after ``index`` and the ``param_<name>`` ones, in order, as the planar models
#: read them (positions relative to the stance ankle).
_PLANAR: tuple[Column, ...] = (
    Column("x0", "float64", "m", "CoM position before the push, relative to the ankle"),
    Column("xdot", "float64", "m/s", "CoM velocity the push gives, J/m"),
    Column("impulse", "float64", "N s", "the push J at the CoM"),
    Column("predicted", "string", "-",
           "strategy the surfaces give for (x0, xdot): ankle, hip, step or fall"),
    Column("capture_point", "float64", "m", "x0 + xdot/omega"),
    Column("cop_margin", "float64", "m",
           "signed distance of the capture point inside the CoP region, Eq. (4)"),
    Column("cmp_margin", "float64", "m",
           "signed distance of the capture point inside the CMP region, corrected Eq. (15)"),
    Column("step_margin", "float64", "m",
           "signed distance of the capture point to the N-step regions (> 0: captured)"),
    Column("predicted_steps", "int64", "-",
           "steps the surfaces predict: 0 for ankle and hip, N for step, -1 for fall"),
    Column("predicted_recovers", "bool", "-",
           "the predicted strategy is within the controller's (ankle < hip < step)"),
    Column("outcome", "string", "-",
           "recovered, fell, undecided, slipped (at rest, a loaded foot slid), or error"),
    Column("used", "string", "-",
           "strategy the run used: ankle (CoP only), hip (hip torque), step, fall, error, or the "
           "outcome of a run neither recovered nor fallen (undecided, slipped)"),
    Column("steps", "int64", "-", "steps taken"),
    Column("peak_hip_torque", "float64", "N m", "largest |hip torque| applied"),
    Column("peak_ankle_torque", "float64", "N m",
           "m g max|CoP offset|: the ankle torque of the largest CoP offset (Eq. 1)"),
    Column("cop_min", "float64", "m", "smallest CoP commanded over the run"),
    Column("cop_max", "float64", "m", "largest CoP commanded over the run"),
    Column("time", "float64", "s", "simulated time to the outcome"),
    Column("stop_impacts", "int64", "-", "times the upper body hit its joint stop"),
    Column("error", "string", "-",
           "why the push has no outcome (diverged, too slow, its worker died); null otherwise"),
    Column("azimuth", "float64", "deg", f"push direction (3-D models); {_NULL_PLANAR}"),
    Column("fraction", "float64", "-", f"J / J*_ankle(azimuth) (3-D models); {_NULL_PLANAR}"),
    Column("ankle_critical", "float64", "N s",
           f"the ankle's predicted critical impulse (3-D models); {_NULL_PLANAR}"),
    Column("y0", "float64", "m", f"standing CoM's lateral ground point (3-D); {_NULL_PLANAR}"),
    Column("capture_point_y", "float64", "m", f"lateral capture point (3-D); {_NULL_PLANAR}"),
    Column("predicted_corrected", "string", "-",
           f"verdict for the push at the torso's height (3-D); {_NULL_PLANAR}"),
    Column("lift_offs", "int64", "-", f"steps begun (3-D); {_NULL_PLANAR}"),
    Column("peak_hip_motor_torque", "float64", "N m",
           f"largest hip motor command change (3-D); {_NULL_PLANAR}"),
    Column("max_torso_tilt", "float64", "rad", f"largest torso tilt (3-D); {_NULL_PLANAR}"),
    Column("peak_torque_ratio", "float64", "-",
           f"largest |motor command| / its limit (3-D); {_NULL_PLANAR}"),
    Column("failed_ticks", "int64", "-", f"ticks the QP did not solve (3-D); {_NULL_PLANAR}"),
    Column("foot_slip", "float64", "m",
           f"largest slip of a foot carrying >= 10% of m g ({_MUJOCO}); {_NULL_ANALYTIC}"),
    Column("peak_ground_force", "float64", "-",
           f"largest vertical floor force / (m g) in one physics step ({_MUJOCO}); "
           f"{_NULL_ANALYTIC}"),
    Column("max_penetration", "float64", "m",
           f"deepest floor contact ({_MUJOCO}); {_NULL_ANALYTIC}"),
    Column("friction_use", "float64", "-",
           f"largest |f_t| / (mu f_n) of a loaded floor contact, 1: sliding ({_MUJOCO}); "
           f"{_NULL_ANALYTIC}"),
    Column("joint_limit_steps", "int64", "-",
           f"physics steps with a joint on its range limit ({_MUJOCO}); {_NULL_ANALYTIC}"),
    Column("estimate_x", "float64", "m",
           f"the state estimate's x: x0 + a seeded error of SD state_sd[0]; {_NULL_CERTAIN}"),
    Column("estimate_xdot", "float64", "m/s",
           f"the state estimate's xdot: xdot + a seeded error of SD state_sd[1]; {_NULL_CERTAIN}"),
    Column("p_recovers", "float64", "-",
           "P(the controller's strategy suffices | estimate, state_sd, latency) "
           f"(docs/uncertainty.md); {_NULL_CERTAIN}"),
    Column("p_fall", "float64", "-",
           f"P(no strategy of the model captures | estimate, state_sd, latency); {_NULL_CERTAIN}"),
    Column("estimate_recovers", "bool", "-",
           "the certain verdict of the estimate after the latency is within the controller's "
           f"strategy; {_NULL_CERTAIN}"),
)  # fmt: skip

#: How the 3-D models read the columns whose meaning differs (the others read as planar).
_READ_3D: Mapping[str, tuple[str, str]] = {
    "x0": ("m", "standing CoM's ground point r0, x (the ankles' midpoint at 0)"),
    "xdot": ("m/s", "J/m, the CoM velocity the push gives along the azimuth"),
    "impulse": ("N s", "the push J at the torso, along the azimuth"),
    "predicted": ("-", "the ground plane's verdict for r0 and J/m along the azimuth"),
    "capture_point": ("m", "x of r0 + J/(m omega) (cos azimuth, sin azimuth)"),
    "cop_margin": ("m", "signed distance of the capture point inside the support polygon"),
    "cmp_margin": ("m", "signed distance of the capture point inside the CMP region"),
    "step_margin": ("m", "the plane's signed step margin (> 0: captured)"),
    "used": ("-", "step if a step landed, hip if m g |delta| passed 1 N m, else ankle; "
                  "fall, error, undecided, slipped"),
    "steps": ("-", "steps that landed"),
    "peak_hip_torque": ("N m", "the hip law's largest m g |delta|"),
    "peak_ankle_torque": ("N m", "NaN (the whole-body controller's CoP is not recorded)"),
    "cop_min": ("m", "NaN (the whole-body controller's CoP is not recorded)"),
    "cop_max": ("m", "NaN (the whole-body controller's CoP is not recorded)"),
    "time": ("s", "simulated time from the push's end to the outcome"),
    "stop_impacts": ("-", "0 (no joint stop in 3-D)"),
    "azimuth": ("deg", "push direction: 0 forward (+x), 90 left (+y)"),
    "fraction": ("-", "J / J*_ankle(azimuth)"),
    "ankle_critical": ("N s", "J*_ankle(azimuth) = m omega rho_P(r0, azimuth)"),
    "y0": ("m", "standing CoM's ground point r0, y"),
    "capture_point_y": ("m", "y of r0 + J/(m omega) (cos azimuth, sin azimuth)"),
    "predicted_corrected": ("-", "verdict for the push at the torso's height: velocity "
                                 "x (1 + d/z0)"),
    "lift_offs": ("-", "steps begun (landed or not)"),
    "peak_hip_motor_torque": ("N m", "largest |hip pitch or roll command - its value before|"),
    "max_torso_tilt": ("rad", "largest tilt of the upright body"),
    "peak_torque_ratio": ("-", "largest |motor command| / its limit (1: saturated)"),
    "failed_ticks": ("-", "ticks the QP (DAQP) did not solve (the last command held)"),
}  # fmt: skip

#: The fixed columns after the ``param_<name>`` ones, with their Arrow type names (both
#: families: the same names, types and order).
COLUMNS: tuple[tuple[str, str], ...] = tuple((c.name, c.kind) for c in _PLANAR)
#: The physical checks of a MuJoCo run (:class:`~pushrecovery.sim.physical_checks.PhysicalChecks`):
#: null (None) in the rows of runs that were not audited.
COLUMNS_PHYSICS: tuple[str, ...] = (
    "foot_slip", "peak_ground_force", "max_penetration", "friction_use", "joint_limit_steps",
)  # fmt: skip
#: A campaign's uncertain estimates (``state_sd``, ``latency``): null without them and in 3-D.
COLUMNS_UNCERTAIN: tuple[str, ...] = (
    "estimate_x", "estimate_xdot", "p_recovers", "p_fall", "estimate_recovers",
)  # fmt: skip
#: The columns of the 3-D models only: null (None) in the other models' rows.
COLUMNS_3D: tuple[str, ...] = tuple(
    name
    for name, _ in COLUMNS[[n for n, _ in COLUMNS].index("azimuth") :]
    if name not in COLUMNS_PHYSICS + COLUMNS_UNCERTAIN
)

#: The outcome columns of a push that raised, or whose worker died (both families).
ERROR_OUTCOME: Mapping[str, Any] = {
    "outcome": "error", "used": "error", "steps": 0, "peak_hip_torque": math.nan,
    "peak_ankle_torque": math.nan, "cop_min": math.nan, "cop_max": math.nan, "time": math.nan,
    "stop_impacts": 0,
}  # fmt: skip
#: What a 3-D error row adds to :data:`ERROR_OUTCOME`.
ERROR_OUTCOME_3D: Mapping[str, Any] = {
    "lift_offs": 0, "peak_hip_motor_torque": math.nan, "max_torso_tilt": math.nan,
    "peak_torque_ratio": math.nan, "failed_ticks": 0, "foot_slip": math.nan,
    "peak_ground_force": math.nan, "max_penetration": math.nan, "friction_use": math.nan,
    "joint_limit_steps": 0,
}  # fmt: skip

#: Units of the sweepable body parameters (``param_<name>`` columns; ``BodyParams``).
PARAM_UNITS: Mapping[str, str] = {k: v for k, v in UNITS.items() if k != "foot_polygon"}


def physics_columns(checks: PhysicalChecks | None) -> dict[str, Any]:
    """Return a row's :data:`COLUMNS_PHYSICS` for ``checks`` (None: a run not audited, nulls).

    ``peak_ground_force`` is in body weights (``PhysicalChecks.peak_force_ratio``).

    Raises
    ------
    ParameterTypeError
        If ``checks`` is neither PhysicalChecks nor None.
    """
    if checks is None:
        return dict.fromkeys(COLUMNS_PHYSICS)
    require_type("checks", checks, PhysicalChecks)
    return {
        "foot_slip": checks.foot_slip,
        "peak_ground_force": checks.peak_force_ratio,
        "max_penetration": checks.max_penetration,
        "friction_use": checks.friction_use,
        "joint_limit_steps": checks.joint_limit_steps,
    }


def used_label(outcome: Outcome, strategy: Strategy) -> str:
    """Return a row's ``used``: the strategy of a recovered run, ``fall``, or the outcome.

    A run that neither recovered nor fell (``undecided``: not at rest yet; ``slipped``: at
    rest, but a loaded foot slid) is labelled by its outcome: it is not a fall.
    """
    require_type("outcome", outcome, Outcome)
    require_type("strategy", strategy, Strategy)
    if outcome is Outcome.RECOVERED:
        return strategy.value
    return Strategy.FALL.value if outcome is Outcome.FELL else outcome.value


def _family(family: str) -> Family:
    if isinstance(family, str) and family in FAMILIES:
        return cast(Family, family)
    raise InvalidParameterError(f"family must be one of {list(FAMILIES)}, got {family!r}")


def columns(family: Family, sweeps: Sequence[str] = ()) -> tuple[Column, ...]:
    """Return every column of ``family``'s rows in order: index, the sweeps', :data:`COLUMNS`.

    Parameters
    ----------
    family : {"planar", "3d"}
        The campaign's family (``CampaignSpec.is_3d``).
    sweeps : sequence of str
        The swept ``BodyParams`` fields, in the campaign's order (``param_<name>`` columns).

    Raises
    ------
    InvalidParameterError
        Naming ``family`` or ``sweeps``: an unknown family, a parameter that cannot be swept.
    """
    require_type("family", family, str)
    if not isinstance(sweeps, list | tuple) or not all(isinstance(s, str) for s in sweeps):
        raise ParameterTypeError("sweeps must be a list of parameter names")
    return _columns(_family(family), tuple(sweeps))


@functools.lru_cache(maxsize=64)
def _columns(family: Family, sweeps: tuple[str, ...]) -> tuple[Column, ...]:
    unknown = [name for name in sweeps if name not in PARAM_UNITS]
    if unknown:
        raise InvalidParameterError(
            f"sweeps must be BodyParams fields ({sorted(PARAM_UNITS)}), got {unknown}"
        )
    fixed = _PLANAR
    if family == "3d":
        fixed = tuple(
            Column(c.name, c.kind, *_READ_3D[c.name]) if c.name in _READ_3D else c for c in _PLANAR
        )
    return (
        Column("index", "int64", "-", "push number in the campaign"),
        *(Column(f"param_{n}", "float64", PARAM_UNITS[n], f"swept body parameter {n}")
          for n in sweeps),
        *fixed,
    )  # fmt: skip


def verdict_columns(
    spec: CampaignSpec,
    push: Push,
    x0: float,
    strategy: Strategy,
    capture_point: float,
    margins: tuple[float, float, float],
    steps: int | None,
) -> dict[str, Any]:
    """Return the columns a row starts with, either family: the push and the surfaces' verdict.

    Parameters
    ----------
    spec : CampaignSpec
        The campaign (its sweeps and its controller's strategy).
    push : Push
        The push (``index``, ``param_<name>``, ``xdot``, ``impulse``).
    x0 : float
        The ``x0`` column [m].
    strategy : Strategy
        The predicted strategy.
    capture_point : float
        The ``capture_point`` column [m].
    margins : (float, float, float)
        ``cop_margin``, ``cmp_margin`` and ``step_margin`` [m], positive inside.
    steps : int or None
        Steps predicted (None: a fall, written -1).
    """
    from pushrecovery.campaign.spec import CampaignSpec, Push

    require_type("spec", spec, CampaignSpec)
    require_type("push", push, Push)
    require_type("strategy", strategy, Strategy)
    # STRATEGY_CODES escalates: a controller of one strategy recovers the lesser's pushes.
    reach = STRATEGY_CODES.index(Strategy(spec.strategy))
    row: dict[str, Any] = {
        f"param_{name}": value for name, value in zip(spec.sweeps, push.swept, strict=True)
    }
    row.update(
        index=push.index,
        x0=x0,
        xdot=push.xdot,
        impulse=push.impulse,
        predicted=strategy.value,
        capture_point=capture_point,
        cop_margin=margins[0],
        cmp_margin=margins[1],
        step_margin=margins[2],
        predicted_steps=-1 if steps is None else steps,
        predicted_recovers=STRATEGY_CODES.index(strategy) <= reach,
    )
    row.update(dict.fromkeys(COLUMNS_UNCERTAIN))  # filled by a campaign with state_sd
    return row


def row_schema(family: Family, sweeps: Sequence[str] = ()) -> Any:
    """Return the Arrow schema of ``family``'s rows; each field's metadata: unit, description.

    Parameters
    ----------
    family : {"planar", "3d"}
        The campaign's family.
    sweeps : sequence of str
        The swept ``BodyParams`` fields, in the campaign's order.

    Returns
    -------
    pyarrow.Schema
        The columns of :func:`columns`, with ``{"unit": ..., "description": ...}`` (UTF-8) as
        each field's metadata.

    Raises
    ------
    InvalidParameterError
        As :func:`columns`.
    """
    return _schema(_family(family), tuple(sweeps))


@functools.lru_cache(maxsize=64)
def _schema(family: Family, sweeps: tuple[str, ...]) -> Any:
    import pyarrow as pa

    types = {"float64": pa.float64(), "int64": pa.int64(), "string": pa.string(),
             "bool": pa.bool_()}  # fmt: skip
    return pa.schema(
        [
            pa.field(c.name, types[c.kind], metadata={"unit": c.unit, "description": c.description})
            for c in _columns(family, sweeps)
        ]
    )
