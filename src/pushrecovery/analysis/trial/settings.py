"""Settings and results of a trial's analysis, and the body it assumes."""

from __future__ import annotations

import math
from collections.abc import Collection
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.recording import (
    LOADED,
    Recording,
)
from pushrecovery.arguments import bounded_float, finite_float, flag, require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError
from pushrecovery.extras import require
from pushrecovery.params import LIMITS, BodyParams

if TYPE_CHECKING:
    from pushrecovery.analysis.trial.summary import TrialSummary

__all__ = [
    "COP_AHEAD_OF_ANKLE",
    "PERSON_FIELDS",
    "PRESET_BODY",
    "XCOM_LENGTHS",
    "AnalysisSettings",
    "TrialAnalysis",
    "body_for",
]

FloatArray = NDArray[np.float64]

#: The pendulum lengths of the XCoM (``AnalysisSettings.xcom_length``).
XCOM_LENGTHS: tuple[str, ...] = ("com_height", "leg_length")

#: Assumed distance of the mean CoP ahead of the ankle in quiet standing when nothing in the
#: file locates the feet [m] (the gravity line falls a few cm in front of the ankle joint).
COP_AHEAD_OF_ANKLE = 0.05


@dataclass(frozen=True, slots=True)
class AnalysisSettings:
    """How a trial is processed; all SI.

    Parameters
    ----------
    cutoff : float
        Low-pass cutoff of the CoM and marker trajectories [Hz]; 0 for none. 6 Hz is the usual
        choice for whole-body kinematics (Winter).
    force_cutoff : float
        Low-pass cutoff of the force-plate signals [Hz]; 0 for none.
    max_gap : float
        Longest gap that is interpolated [s], >= 0; longer gaps are excluded.
    contact_height : float
        A foot supports while its lower marker is within this of its lowest [m], > 0.
    foot_width : float or None
        Foot width, for the medio-lateral base around the foot markers [m], > 0; None: the
        body's ``foot_width`` (:class:`~pushrecovery.params.BodyParams`).
    stance_width : float or None
        Ankle-to-ankle distance of the fixed feet assumed without foot data [m], >= 0; None:
        the body's ``stance_width``.
    ankle_ap, ankle_ml : float or None
        Lab position of the fixed feet (midpoint of the ankles) [m]; default from the mean
        CoP (ap: ``COP_AHEAD_OF_ANKLE`` behind it) or, without a CoP, the mean CoM.
    normalise : bool
        Add Hof's dimensionless columns (Hof 2008, J Biomech 41:1171): lengths over the leg
        length l (``BodyParams.leg_length``), velocities over sqrt(g l): ``*_norm``.
    xcom_length : {"com_height", "leg_length"}
        The pendulum length l of Hof's XCoM ξ = r + v/ω0, ω0 = sqrt(g/l) [1/s], in the 2-D
        margins (``xcom_*``, ``mos*``, ``ttb_xcom``): the body's CoM height (default, the
        paper's L) or its leg length (Hof, Gazendam & Sinke 2005). The per-axis margins of
        Eq. (4) and every verdict keep the body's ω = sqrt(g/L): they are its physics.
    com_noise : float or None
        Standard deviation of the CoM signal's errors at each sample [m] (independent, before
        the low-pass), >= 0: adds ``<axis>_risk``, the probability that the ankle does not
        suffice, P(ξ outside the base along the axis), with ξ's spread through the
        pipeline's own filter (:func:`~pushrecovery.analysis.signals.noise_gains`); None:
        no risk columns.
    com_height_sd : float or None
        Standard deviation of the body's CoM height [m], >= 0 (an anthropometric table's
        spread): the risk columns average over it (with or without ``com_noise``).
    """

    cutoff: float = 6.0
    force_cutoff: float = 10.0
    max_gap: float = 0.1
    contact_height: float = 0.02
    foot_width: float | None = None
    stance_width: float | None = None
    ankle_ap: float | None = None
    ankle_ml: float | None = None
    normalise: bool = False
    xcom_length: str = "com_height"
    com_noise: float | None = None
    com_height_sd: float | None = None

    def widths(self, params: BodyParams) -> tuple[float, float]:
        """Foot width and stance width [m]: these settings', else the body's."""
        return (
            params.foot_width if self.foot_width is None else self.foot_width,
            params.stance_width if self.stance_width is None else self.stance_width,
        )

    def __post_init__(self) -> None:
        for name in ("cutoff", "force_cutoff", "max_gap", "stance_width", "com_noise",
                     "com_height_sd"):  # fmt: skip
            value = getattr(self, name)
            if value is None and name in ("stance_width", "com_noise", "com_height_sd"):
                continue  # not given: the body's, none
            value = finite_float(name, value)
            if not value >= 0.0:
                raise InvalidParameterError(f"{name} must be a finite number >= 0, got {value}")
        flag("normalise", self.normalise)
        for name in ("contact_height", "foot_width"):
            value = getattr(self, name)
            if value is None and name == "foot_width":
                continue  # not given: the body's
            value = finite_float(name, value)
            if not value > 0.0:
                raise InvalidParameterError(f"{name} must be a finite number > 0, got {value}")
        for name in ("ankle_ap", "ankle_ml"):
            value = getattr(self, name)
            if value is not None:
                finite_float(name, value, "m")
        if not isinstance(self.xcom_length, str) or self.xcom_length not in XCOM_LENGTHS:
            raise InvalidParameterError(
                f"xcom_length must be one of {list(XCOM_LENGTHS)}, got {self.xcom_length!r}"
            )

    def xcom_omega(self, params: BodyParams) -> float:
        """Return ω0 = sqrt(g/l) of the XCoM [1/s], l as ``xcom_length`` says [m]."""
        length = params.com_height if self.xcom_length == "com_height" else params.leg_length
        return math.sqrt(params.gravity / length)


@dataclass(frozen=True, slots=True)
class TrialAnalysis:
    """Result of :func:`analyze`: the per-frame table and the summary.

    ``columns`` are the per-frame columns of ``frames.parquet`` (docs/analysis.md: SI units,
    NaN where unknown, strategies as text, None where withheld); ``summary`` the trial's
    (a :class:`~pushrecovery.analysis.trial.summary.TrialSummary`; its ``to_dict()`` is
    ``summary.json``); ``base`` the base of support per frame in the plane (a
    :class:`~pushrecovery.analysis.base_polygon.BasePolygons`; None when not computed).
    """

    columns: dict[str, NDArray[Any]]
    summary: TrialSummary
    base: Any = None

    @property
    def time(self) -> FloatArray:
        """Frame times [s]."""
        return self.columns["time"]

    def to_arrow(self) -> Any:
        """Return the frames as a ``pyarrow.Table`` (NaN as null, as in ``frames.parquet``)."""
        require("analysis", "pyarrow", "to_arrow")
        import pyarrow as pa

        arrays = {}
        for name, values in self.columns.items():
            if values.dtype == object:
                arrays[name] = pa.array(list(values), type=pa.string())
            elif values.dtype.kind in "biu":
                arrays[name] = pa.array(values)
            else:
                arrays[name] = pa.array(values, mask=np.isnan(values))
        return pa.table(arrays)

    def to_pandas(self) -> Any:
        """Return the frames as a ``pandas.DataFrame`` (needs the ``tables`` extra: pandas)."""
        return pandas_table(self.to_arrow())


def pandas_table(table: Any) -> Any:
    """Return a pyarrow table as a pandas DataFrame, or say how to get pandas (the tables')."""
    require("tables", "pandas", "to_pandas")
    return table.to_pandas()


#: Where the body came from without --height and --sex.
PRESET_BODY = "preset (not scaled to the person: give --height and --sex)"
#: The fields a person's body (:func:`pushrecovery.anthropometry.person_params`) gives the
#: analysis, unless a flag, the subjects table or the file gives them.
PERSON_FIELDS = (
    "com_height",
    "leg_length",
    "heel",
    "toe",
    "foot_width",
    "flywheel_inertia",
    "flywheel_inertia_roll",
)


def body_for(
    recording: Recording,
    *,
    mass: float | None,
    com_height: float | None,
    gravity: float,
    height: float | None = None,
    sex: str | None = None,
    keep: Collection[str] = (),
) -> tuple[dict[str, float], dict[str, str]]:
    """Subject mass and body: a flag, else the file, else the force plates; refused if none.

    Parameters
    ----------
    recording : Recording
        The trial.
    mass, com_height : float or None
        Values given as flags or by the subjects table [kg, m].
    gravity : float
        g [m/s^2], to weigh the subject on the force plates.
    height : float or None
        Stature [m], in [0.5, 2.5]: with ``sex``, the body's geometry and upper-body inertia
        come from de Leva's table (:func:`pushrecovery.anthropometry.person_params`).
    sex : {"female", "male"} or None
        The table's column; given together with ``height``.
    keep : collection of str
        Fields given otherwise (flags, the subjects table) that the person's body leaves alone.

    Returns
    -------
    (values, sources)
        ``mass``, ``com_height`` and (with ``height`` and ``sex``) the fields of
        :data:`PERSON_FIELDS` found (to override the preset with, see
        :func:`pushrecovery.presets.load_params`; a quantity nothing gives is left out), and
        where each came from: ``flag``, ``file``, ``force plates`` (mean vertical force / g
        while loaded), the anthropometric table, or ``preset``; with ``height`` and ``sex``,
        ``body``: the person's table (without, the body is the preset's: :data:`PRESET_BODY`).

    Raises
    ------
    InvalidParameterError
        No mass (neither given, in the file, nor weighed on its force plates): no body is
        guessed. ``height`` without ``sex`` or the reverse, or either out of its range; a
        mass, CoM height or gravity outside :data:`pushrecovery.params.LIMITS`.
    """
    require_type("recording", recording, Recording)
    if isinstance(keep, str | bytes) or not isinstance(keep, Collection):
        raise ParameterTypeError(f"keep must be a collection of field names, got {keep!r:.40}")
    mass = None if mass is None else bounded_float("mass", mass, *LIMITS["mass"])
    if com_height is not None:
        com_height = bounded_float("com_height", com_height, *LIMITS["com_height"])
    gravity = bounded_float("gravity", gravity, *LIMITS["gravity"])
    values: dict[str, float] = {}
    sources = {"mass": "preset", "com_height": "preset"}
    if mass is not None:
        values["mass"], sources["mass"] = mass, "flag"
    elif recording.mass is not None:
        values["mass"], sources["mass"] = recording.mass, "file"
    elif recording.force is not None and recording.force_time is not None:
        mass, source = _weighed(recording.force_time, recording.force[:, 2], gravity)
        if mass is not None:
            values["mass"], sources["mass"] = mass, source
    if "mass" not in values:
        raise InvalidParameterError(
            f"no body mass for {Path(recording.source).name or 'the trial'}: the file has none "
            "and no loaded force plate to weigh the subject on; give --mass KG (or a subjects "
            "table's mass)"
        )
    if com_height is not None:
        values["com_height"], sources["com_height"] = com_height, "flag"
    elif recording.com_height is not None:
        values["com_height"], sources["com_height"] = recording.com_height, "file"
    if height is None and sex is None:
        return values, sources
    if height is None or sex is None:
        raise InvalidParameterError(
            "height and sex go together (de Leva's table has one column per sex): give both "
            f"--height M and --sex female|male, got height={height}, sex={sex}"
        )
    from pushrecovery.anthropometry import person_params

    person = person_params(values["mass"], height, sex)
    for name in PERSON_FIELDS:
        if name not in values and name not in keep:
            values[name] = getattr(person.params, name)
            sources[name] = person.sources[name]
    sources["body"] = (
        f"{person.sources['model']}, stature {height:g} m; hip torque and range, stance and "
        "step timing: preset (not a person's)"
    )
    return values, sources


def _weighed(time: FloatArray, vertical: FloatArray, gravity: float) -> tuple[float | None, str]:
    """Mass from the plates: the quiet windows' mean vertical force / g, with its spread.

    Push-offs, landings and flights bias any mean over the loaded samples (84.0 kg against
    78.1 kg standing on biomdp's countermovement jump): only quiet windows weigh the subject
    (:func:`~pushrecovery.analysis.events.mass_from_quiet`). Without one, the mean over the
    loaded samples, said to be biased.
    """
    from pushrecovery.analysis.events import mass_from_quiet, quiet_windows

    finite = np.isfinite(vertical)
    if finite.sum() >= 2:
        windows = quiet_windows(time[finite], vertical[finite], gravity=gravity)
        if windows:
            found = mass_from_quiet(time[finite], vertical[finite], gravity, windows)
            spread = "" if found.spread is None else f", spread {found.spread:.2g} kg"
            return found.mass, (
                f"force plates (quiet windows: mean vertical force / g over {found.windows} "
                f"windows, {found.duration:.3g} s{spread})"
            )
    loaded = vertical[finite & (vertical > LOADED)]
    if not len(loaded):
        return None, ""
    return float(np.mean(loaded)) / gravity, (
        "force plates (mean vertical force / g while loaded: no quiet window, biased by any "
        "push-off or landing)"
    )
