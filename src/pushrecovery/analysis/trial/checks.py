"""A trial's data checked before its verdicts: what real labs record wrong (issues 18 and 34).

Verdicts assume a body standing on the base of support the analysis computed. Two things in the
data contradict that, and the frames where they do get no verdict (issue 18, item 5):

- **flight**: the total vertical force is below :data:`~pushrecovery.analysis.recording.LOADED`
  (:func:`~pushrecovery.analysis.events.flight_phases`): no foot carries the body;
- **CoP outside the base**: the measured CoP lies beyond the computed base along an axis by more
  than :data:`COP_TOLERANCE` (marker placement and plate calibration put a correct CoP within
  about a centimetre of the sole's edge). The CoP can only be where a foot presses, so the base
  is wrong in that frame (a missing foot, a wrong foot model or an invented assumption).

When the CoP contradicts the base in more than :data:`MAX_CONTRADICTED` of the loaded frames,
the base as a whole is rejected and the trial is not classified: no frame gets a verdict.

Issue 34 adds the faults of a lab's recording (docs/analysis.md, "Data checks", has the table
of checks, thresholds and reasons):

- **a heel or toe marker missing**: the base is unknown in that frame (``marker_gaps``; the
  frames get no verdict);
- **a plate under no foot** (:func:`plate_feet`): a loaded plate whose CoP lies under no
  foot's sole and whose load stays light is no foot's contact;
- **saturation and zero offset** of the force channels (:func:`channel_checks`): flags;
- **the forward axis against the feet** (:func:`check_forward`): a trial whose feet point
  elsewhere than the declared ap axis is refused.

:meth:`DataChecks.quality_rows` is the data-quality table, one row per check and target.
Over 400 lines on purpose: one concept, the checks of a trial's data.
"""

from __future__ import annotations

from dataclasses import asdict, dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.analysis.base_polygon import FootModel, foot_soles
from pushrecovery.analysis.events import flight_phases
from pushrecovery.analysis.recording import AXES, LOADED, Foot, Recording
from pushrecovery.analysis.signals import resample
from pushrecovery.arguments import positive_float, require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

__all__ = [
    "COP_TOLERANCE",
    "FORWARD_TOLERANCE",
    "MAX_CONTRADICTED",
    "PLATE_FOOT_TOLERANCE",
    "PLATE_LOAD_SHARE",
    "QUALITY_FIELDS",
    "SATURATION_SAMPLES",
    "ZERO_OFFSET",
    "ChannelCheck",
    "DataChecks",
    "PlateFeet",
    "channel_checks",
    "check_forward",
    "plate_feet",
]

FloatArray = NDArray[np.float64]
BoolArray = NDArray[np.bool_]

#: Columns of the data-quality table (:meth:`DataChecks.quality_rows`) and their types.
QUALITY_FIELDS: tuple[tuple[str, str], ...] = (
    ("check", "str"),
    ("target", "str"),
    ("flagged", "bool"),
    ("frames", "int | None"),
    ("value", "float | None"),
    ("threshold", "float"),
    ("unit", "str"),
)
#: The force components in body axes, in the recording's order.
AXES_3D = ("ap", "ml", "up")
#: How far the measured CoP may lie beyond the computed base before it contradicts it [m].
COP_TOLERANCE = 0.02
#: Share of the loaded frames beyond which a contradicted base is rejected for the trial.
MAX_CONTRADICTED = 0.2
#: How far a plate's CoP may lie outside a foot's sole (from its markers) and still be that
#: foot's contact [m]: Plug-in Gait's TOE marker sits on the 2nd metatarsal head with the toes'
#: tips 4-6 cm ahead of it, and a lightly loaded plate's CoP errs by up to about 1 cm.
PLATE_FOOT_TOLERANCE = 0.05
#: A plate whose peak vertical force exceeds this share of the body weight is a foot's
#: contact even with its CoP away from every sole (then the markers are off, not the load): a
#: foot bearing weight carries about half of it in double stance, all of it in single stance.
PLATE_LOAD_SHARE = 0.25

#: Consecutive identical samples at a force channel's largest or smallest value that make a
#: flat top, the mark of a clipped (saturated) amplifier or converter: a real peak sampled with
#: converter noise repeats its exact extreme for 1-2 samples (biomdp's Kistler and Vicon plate
#: files: at most 2), a clipped one for as long as the true force stays beyond the range.
SATURATION_SAMPLES = 5
#: Largest mean force a channel may read while its plate is unloaded [N]: a quarter of
#: :data:`~pushrecovery.analysis.recording.LOADED`; 5 N moves the CoP of half a 70 kg body
#: 20 cm from the plate's centre by 3 mm.
ZERO_OFFSET = 5.0
#: Fewest unloaded seconds that give a channel's zero offset (else it is not checked).
MIN_UNLOADED = 0.1
#: Largest angle between the feet's heel -> toe direction and the declared forward axis [deg]:
#: feet turn out some 5-15 degrees each, symmetrically (their mean points forward); beyond 45
#: degrees the declared axis is nearer another lab axis than the feet's forward.
FORWARD_TOLERANCE = 45.0


def check_forward(feet: tuple[Foot, ...]) -> float | None:
    """Return the angle of the feet's forward from the declared ap axis [deg], + to the left.

    The feet's forward is the sum over feet of each foot's mean unit heel -> toe direction
    on the floor (the frames where both markers are present). None without foot markers.

    Raises
    ------
    InvalidParameterError
        If the angle exceeds :data:`FORWARD_TOLERANCE` in size: the file's forward is another
        axis than the one declared (``ap_axis``, ``--ap-axis``).
    """
    if not (isinstance(feet, tuple | list) and all(isinstance(f, Foot) for f in feet)):
        raise ParameterTypeError(
            f"feet must be a tuple of Foot (a recording's feet), got {type(feet).__name__}"
        )
    total = np.zeros(2)
    for foot in feet:
        d = foot.toe[:, :2] - foot.heel[:, :2]
        length = np.hypot(d[:, 0], d[:, 1])
        known = np.isfinite(length) & (length > 0.0)
        if known.any():
            mean = np.mean(d[known] / length[known, None], axis=0)
            total += mean / max(float(np.hypot(*mean)), 1e-12)
    if not total.any():
        return None
    angle = float(np.degrees(np.arctan2(total[1], total[0])))
    if abs(angle) > FORWARD_TOLERANCE:
        side = "left" if angle > 0 else "right"
        raise InvalidParameterError(
            f"the feet point {abs(angle):.0f} degrees to the {side} of the declared forward "
            f"axis (heel -> toe markers; more than {FORWARD_TOLERANCE:g} degrees): the file's "
            "forward is another lab axis; give it with --ap-axis (ap_axis)"
        )
    return angle


@dataclass(frozen=True, slots=True)
class ChannelCheck:
    """Saturation and zero offset of one force channel (:func:`channel_checks`).

    Attributes
    ----------
    channel : str
        ``plate k vertical`` (per plate, files with several), or ``force ap``, ``force ml``,
        ``force up``: the total ground reaction force (with one plate: that plate's channels
        in body axes).
    flat_samples : int
        Longest run of identical consecutive samples at the channel's largest or smallest
        value, counted when that value is at least :data:`~pushrecovery.analysis.recording.LOADED`
        in size (a flat zero is an unloaded plate, not a clipped one) and the channel spans at
        least ``LOADED`` (a constant channel is no clipped peak); else 0.
    saturated : bool
        ``flat_samples`` >= :data:`SATURATION_SAMPLES`.
    offset : float or None
        Mean of the channel while its plate is unloaded (vertical force below ``LOADED``) [N];
        None with fewer than :data:`MIN_UNLOADED` s unloaded.
    offset_flag : bool
        ``|offset|`` > :data:`ZERO_OFFSET`.
    """

    channel: str
    flat_samples: int
    saturated: bool
    offset: float | None
    offset_flag: bool


def channel_checks(recording: Recording) -> tuple[ChannelCheck, ...]:
    """Check the force channels of ``recording`` for saturation and zero offset.

    The channels the recording keeps: the total force's three components, and each plate's
    vertical force when there are several plates (module docstring of
    :class:`ChannelCheck`); none without force plates.
    """
    require_type("recording", recording, Recording)
    if recording.force is None or recording.force_time is None:
        return ()
    time = recording.force_time
    period = float(time[-1] - time[0]) / max(len(time) - 1, 1)
    fewest = max(1, int(np.ceil(MIN_UNLOADED / period))) if period > 0 else 1
    total = recording.force
    channels = [(f"force {name}", total[:, i], total[:, 2]) for i, name in enumerate(AXES_3D)]
    if len(recording.plates) > 1:
        channels += [
            (f"plate {k + 1} vertical", vertical, vertical)
            for k, (vertical, _) in enumerate(recording.plates)
        ]
    return tuple(_channel(name, x, v, fewest) for name, x, v in channels)


def _channel(name: str, values: FloatArray, vertical: FloatArray, fewest: int) -> ChannelCheck:
    """One channel's :class:`ChannelCheck`; ``vertical`` is its plate's vertical force."""
    finite = values[np.isfinite(values)]
    flat = 0
    if len(finite) and float(finite.max() - finite.min()) >= LOADED:
        for extreme in {float(finite.max()), float(finite.min())}:
            if abs(extreme) >= LOADED:
                flat = max(flat, _longest_run(values == extreme))
    with np.errstate(invalid="ignore"):
        unloaded = (vertical < LOADED) & np.isfinite(values)
    offset = float(np.mean(values[unloaded])) if unloaded.sum() >= fewest else None
    flagged = offset is not None and abs(offset) > ZERO_OFFSET
    return ChannelCheck(name, flat, flat >= SATURATION_SAMPLES, offset, flagged)


def _longest_run(flags: BoolArray) -> int:
    """Longest run of True in ``flags``."""
    if not flags.any():
        return 0
    edges = np.diff(np.concatenate([[0], flags.astype(np.int8), [0]]))
    return int((np.flatnonzero(edges == -1) - np.flatnonzero(edges == 1)).max())


@dataclass(frozen=True, slots=True)
class PlateFeet:
    """Which foot stands on each force plate (:func:`plate_feet`).

    Attributes
    ----------
    owners : dict of int to str
        Plate index -> the foot whose contact it is (``plate k`` without foot markers, or when
        two plates would go to one foot); stray plates are not in it.
    distance : dict of int to float
        Plate index -> median distance of its loaded CoP to the nearest foot's sole [m]
        (0 inside), NaN without foot markers.
    peak : dict of int to float
        Plate index -> its largest vertical force [N].
    stray : tuple of int
        Plates loaded with their CoP under no foot (beyond :data:`PLATE_FOOT_TOLERANCE`) and
        never beyond :data:`PLATE_LOAD_SHARE` of the body weight: no foot's contact, no foot
        events, left out of the combined CoP.
    """

    owners: dict[int, str]
    distance: dict[int, float]
    peak: dict[int, float]
    stray: tuple[int, ...]

    def to_dict(self) -> dict[str, Any]:
        """Return the summary's ``checks`` entries of the plates (plates named from 1)."""
        return {
            "plate_foot_tolerance": PLATE_FOOT_TOLERANCE,
            "plate_load_share": PLATE_LOAD_SHARE,
            "plate_feet": {f"plate {k + 1}": name for k, name in self.owners.items()},
            "plate_foot_distance": {f"plate {k + 1}": v for k, v in self.distance.items()},
            "stray_plates": [f"plate {k + 1}" for k in self.stray],
        }


def plate_feet(recording: Recording, foot_width: float, weight: float) -> PlateFeet:
    """Return the foot standing on each force plate of ``recording`` (multi-plate C3D files).

    A plate is a foot's contact when its CoP, at the samples it is loaded, lies within
    :data:`PLATE_FOOT_TOLERANCE` of that foot's sole (median distance over those samples; the
    sole is :func:`~pushrecovery.analysis.base_polygon.foot_soles` of the foot's markers at
    the plate's samples, ``foot_width`` [m] wide): the nearest such foot. A plate whose CoP
    lies under no foot is still the nearest foot's when its peak vertical force exceeds
    :data:`PLATE_LOAD_SHARE` of ``weight`` [N]; else it is **stray** (issue 34: a plate 17-23
    cm from a foot loaded to 66 N for 80 ms made that foot's contact and foot-off). Without
    foot markers every loaded plate keeps its name (``plate k``). Two plates that would go
    to one foot keep their names.
    """
    require_type("recording", recording, Recording)
    foot_width = positive_float("foot_width", foot_width, "m")
    weight = positive_float("weight", weight, "N")
    owners: dict[int, str] = {}
    distance: dict[int, float] = {}
    peak: dict[int, float] = {}
    stray: list[int] = []
    if recording.force_time is None or not recording.plates:
        return PlateFeet(owners, distance, peak, ())
    model = FootModel(width=foot_width)
    soles = {
        foot.name: foot_soles(
            Foot(
                foot.name,
                *(
                    resample(recording.time, getattr(foot, part), recording.force_time)
                    for part in ("heel", "toe", "ankle")
                ),
            ),
            model,
        )
        for foot in recording.feet
    }
    for k, (vertical, cop) in enumerate(recording.plates):
        loaded = np.isfinite(cop).all(axis=1)
        if not loaded.any():
            continue
        peak[k] = float(np.nanmax(vertical))
        owners[k] = f"plate {k + 1}"
        distances = {
            name: _median_distance(cop[loaded], sole[loaded]) for name, sole in soles.items()
        }
        known = {name: d for name, d in distances.items() if np.isfinite(d)}
        distance[k] = min(known.values()) if known else float("nan")
        if not known:
            continue
        nearest = min(known, key=lambda name: known[name])
        if known[nearest] <= PLATE_FOOT_TOLERANCE or peak[k] > PLATE_LOAD_SHARE * weight:
            owners[k] = nearest
        else:
            del owners[k]
            stray.append(k)
    if len(set(owners.values())) != len(owners):  # two plates under one foot: by plate
        owners = {k: f"plate {k + 1}" for k in owners}
    return PlateFeet(owners, distance, peak, tuple(stray))


def _median_distance(points: FloatArray, soles: FloatArray) -> float:
    """Return the median distance of ``points`` (m, 2) to the rectangles ``soles`` [m].

    ``soles`` (m, 4, 2): corners back-right, front-right, front-left, back-left (those of
    :func:`~pushrecovery.analysis.base_polygon.foot_soles`); 0 inside, NaN if unknown.
    """
    origin = soles[:, 0]
    along = soles[:, 1] - origin
    across = soles[:, 3] - origin
    length = np.linalg.norm(along, axis=1)
    width = np.linalg.norm(across, axis=1)
    d = points - origin
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.einsum("ij,ij->i", d, along) / length
        t = np.einsum("ij,ij->i", d, across) / width
    ds = np.maximum(0.0, np.maximum(-s, s - length))
    dt = np.maximum(0.0, np.maximum(-t, t - width))
    gap = np.hypot(ds, dt)
    return float(np.median(gap[np.isfinite(gap)])) if np.isfinite(gap).any() else float("nan")


@dataclass(frozen=True, slots=True, eq=False)
class DataChecks:
    """What the checks found, per frame of the analysis.

    Attributes
    ----------
    flights : tuple of (start, end)
        Flight phases [s] (at the force plates' rate).
    flight : ndarray of bool
        Frames inside a flight phase.
    cop_outside : dict of str to ndarray of bool
        Per axis, frames whose CoP lies beyond the base by more than ``tolerance``.
    loaded_frames : int
        Frames with a measured CoP (a loaded plate).
    tolerance : float
        :data:`COP_TOLERANCE` [m].
    base_rejected : bool
        The CoP contradicts the base in more than :data:`MAX_CONTRADICTED` of the loaded
        frames: the trial is not classified.
    marker_gaps : dict of str to ndarray of bool
        Per base marker (``"left heel"``, ...), the frames it is missing in: the base is
        unknown there (never filled: a spline through the gap would invent its edge).
    plates : PlateFeet
        Which foot stands on each force plate, and the stray plates.
    channels : tuple of ChannelCheck
        Saturation and zero offset of each force channel the recording keeps.
    forward_angle : float or None
        Angle of the feet's heel -> toe direction from the ap axis [deg] (:func:`check_forward`),
        None without foot markers.
    """

    flights: tuple[tuple[float, float], ...]
    flight: BoolArray
    cop_outside: dict[str, BoolArray]
    loaded_frames: int
    tolerance: float
    base_rejected: bool
    marker_gaps: dict[str, BoolArray] = field(default_factory=dict)
    plates: PlateFeet = field(default_factory=lambda: PlateFeet({}, {}, {}, ()))
    channels: tuple[ChannelCheck, ...] = ()
    forward_angle: float | None = None

    @property
    def marker_gap(self) -> BoolArray:
        """Frames in which a base marker (a heel or toe marker) is missing."""
        missing = np.zeros_like(self.flight)
        for frames in self.marker_gaps.values():
            missing |= frames
        return missing

    @property
    def contradicted(self) -> BoolArray:
        """Frames whose CoP lies beyond the base along either axis."""
        return self.cop_outside[AXES[0]] | self.cop_outside[AXES[1]]

    @property
    def withheld(self) -> BoolArray:
        """Frames that get no verdict: all of them if the base is rejected."""
        if self.base_rejected:
            return np.ones_like(self.flight)
        return self.flight | self.contradicted | self.marker_gap

    def reasons(self) -> dict[str, int]:
        """Frames withheld, per reason (a frame may have both)."""
        reasons = {
            "flight (vertical force below 20 N)": int(self.flight.sum()),
            f"CoP beyond the computed base by more than {self.tolerance * 100:g} cm": int(
                self.contradicted.sum()
            ),
            "a heel or toe marker missing (base unknown)": int(self.marker_gap.sum()),
        }
        if self.base_rejected:
            reasons["base of support contradicted by the CoP: trial not classified"] = len(
                self.flight
            )
        return {key: value for key, value in reasons.items() if value}

    def quality_rows(self) -> list[dict[str, Any]]:
        """Return the data-quality table: one row per check and what it checked.

        Columns (:data:`QUALITY_FIELDS`): ``check`` (``flight``, ``cop_outside_base``,
        ``base_rejected``, ``marker_gap``, ``plate_under_no_foot``, ``saturation``,
        ``zero_offset``, ``forward_axis``), ``target`` (the trial, an axis, a marker, a plate
        or a force channel), ``flagged``, ``frames`` (frames concerned, where it counts
        frames), ``value`` (the measure compared with the threshold: a share, a distance [m],
        a run of samples, a force [N], an angle [deg]), ``threshold`` and its ``unit``
        (docs/analysis.md, "Data checks").
        """
        rows = [_row("flight", "trial", int(self.flight.sum()), None, LOADED, "N")]
        for axis, frames in self.cop_outside.items():
            rows.append(
                _row("cop_outside_base", axis, int(frames.sum()), None, self.tolerance, "m")
            )
        share = self.contradicted.sum() / self.loaded_frames if self.loaded_frames else None
        rows.append(
            _row("base_rejected", "trial", int(self.contradicted.sum()), share,
                 MAX_CONTRADICTED, "share", flagged=self.base_rejected)
        )  # fmt: skip
        gaps = {name: int(frames.sum()) for name, frames in self.marker_gaps.items()}
        for name, count in (gaps or {"heel and toe markers": 0}).items():
            rows.append(_row("marker_gap", name, count, None, 0.0, "frames"))
        for k, distance in self.plates.distance.items():
            rows.append(
                _row("plate_under_no_foot", f"plate {k + 1}", None, distance,
                     PLATE_FOOT_TOLERANCE, "m", flagged=k in self.plates.stray)
            )  # fmt: skip
        for channel in self.channels:
            rows.append(
                _row("saturation", channel.channel, None, float(channel.flat_samples),
                     SATURATION_SAMPLES, "samples", flagged=channel.saturated)
            )  # fmt: skip
            rows.append(
                _row("zero_offset", channel.channel, None, channel.offset, ZERO_OFFSET, "N",
                     flagged=channel.offset_flag)
            )  # fmt: skip
        if self.forward_angle is not None:
            rows.append(
                _row("forward_axis", "feet", None, self.forward_angle, FORWARD_TOLERANCE, "deg",
                     flagged=False)
            )  # fmt: skip
        return rows

    def row_flags(self) -> dict[str, Any]:
        """Return the trial row's columns of the newer checks (docs/analysis.md).

        ``excluded_frames_markers`` (int), ``marker_gap_frames`` (``"left heel=30; left
        toe=10"``), ``stray_plates``, ``saturated_channels``, ``zero_offset_channels`` (names
        joined by ``"; "``, empty when none) and ``forward_angle`` [deg] (None without feet).
        """
        return {
            "excluded_frames_markers": int(self.marker_gap.sum()),
            "marker_gap_frames": "; ".join(
                f"{name}={int(v.sum())}" for name, v in self.marker_gaps.items()
            ),
            "stray_plates": "; ".join(f"plate {k + 1}" for k in self.plates.stray),
            "saturated_channels": "; ".join(c.channel for c in self.channels if c.saturated),
            "zero_offset_channels": "; ".join(c.channel for c in self.channels if c.offset_flag),
            "forward_angle": self.forward_angle,
        }

    def to_dict(self) -> dict[str, Any]:
        """Return the summary's ``checks``."""
        return {
            "flight_phases": [{"start": a, "end": b, "duration": b - a} for a, b in self.flights],
            "flight_frames": int(self.flight.sum()),
            "cop_tolerance": self.tolerance,
            "loaded_frames": self.loaded_frames,
            "cop_outside_base_frames": {axis: int(v.sum()) for axis, v in self.cop_outside.items()},
            "base_rejected": self.base_rejected,
            "max_contradicted_share": MAX_CONTRADICTED,
            "excluded_frames_markers": int(self.marker_gap.sum()),
            "marker_gap_frames": {name: int(v.sum()) for name, v in self.marker_gaps.items()},
            **self.plates.to_dict(),
            "saturation_samples": SATURATION_SAMPLES,
            "zero_offset_threshold": ZERO_OFFSET,
            "saturated_channels": [c.channel for c in self.channels if c.saturated],
            "zero_offset_channels": [c.channel for c in self.channels if c.offset_flag],
            "channels": [asdict(c) for c in self.channels],
            "forward_angle": self.forward_angle,
            "forward_tolerance": FORWARD_TOLERANCE,
        }


def _row(
    check: str,
    target: str,
    frames: int | None,
    value: float | None,
    threshold: float,
    unit: str,
    *,
    flagged: bool | None = None,
) -> dict[str, Any]:
    """One row of the data-quality table; flagged, unless given, when it counts frames."""
    return {
        "check": check,
        "target": target,
        "flagged": bool(frames) if flagged is None else bool(flagged),
        "frames": frames,
        "value": value,
        "threshold": float(threshold),
        "unit": unit,
    }


def check_frames(
    time: FloatArray,
    force_time: FloatArray | None,
    force: FloatArray | None,
    cop: FloatArray | None,
    lower: dict[str, FloatArray],
    upper: dict[str, FloatArray],
    marker_gaps: dict[str, BoolArray] | None = None,
    plates: PlateFeet | None = None,
    channels: tuple[ChannelCheck, ...] = (),
    forward_angle: float | None = None,
) -> DataChecks:
    """Check the frames at ``time`` [s] (module docstring); the pipeline's, unchecked.

    ``force`` is the ground reaction force (m, 3) [N] at ``force_time`` [s] (None without
    plates), ``cop`` the CoP (n, 2) [m] at the frames (NaN where unloaded), ``lower`` and
    ``upper`` the base per axis at the frames [m], ``marker_gaps`` per base marker the frames
    it is missing in, ``plates`` the plates' feet (:func:`plate_feet`), ``channels`` the
    force channels' checks (:func:`channel_checks`), ``forward_angle`` that of
    :func:`check_forward`.
    """
    n = len(time)
    flight = np.zeros(n, dtype=bool)
    flights: tuple[tuple[float, float], ...] = ()
    if force is not None and force_time is not None and np.isfinite(force[:, 2]).any():
        vertical = np.where(np.isfinite(force[:, 2]), force[:, 2], LOADED)  # gaps: not flight
        found = flight_phases(force_time, vertical)
        flights = found.intervals
        for start, end in flights:
            flight |= (time >= start - 1e-9) & (time <= end + 1e-9)
    outside = {axis: np.zeros(n, dtype=bool) for axis in AXES}
    loaded = 0
    if cop is not None:
        for i, axis in enumerate(AXES):
            with np.errstate(invalid="ignore"):
                outside[axis] = (cop[:, i] < lower[axis] - COP_TOLERANCE) | (
                    cop[:, i] > upper[axis] + COP_TOLERANCE
                )
        measured = np.isfinite(cop).all(axis=1) & ~flight
        loaded = int(measured.sum())
        for axis in AXES:
            outside[axis] &= measured
    contradicted = outside[AXES[0]] | outside[AXES[1]]
    rejected = loaded > 0 and contradicted.sum() > MAX_CONTRADICTED * loaded
    gaps = {name: frames for name, frames in (marker_gaps or {}).items() if frames.any()}
    owners = PlateFeet({}, {}, {}, ()) if plates is None else plates
    return DataChecks(
        flights,
        flight,
        outside,
        loaded,
        COP_TOLERANCE,
        bool(rejected),
        marker_gaps=gaps,
        plates=owners,
        channels=channels,
        forward_angle=forward_angle,
    )
