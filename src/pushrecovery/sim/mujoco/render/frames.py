"""Recorded frames of a run: converting, selecting and subsampling them in time."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import whole_number
from pushrecovery.errors import InvalidParameterError

__all__ = [
    "MAX_FRAMES",
    "Frame",
    "FrameLike",
    "nearest_indices",
    "select_indices",
    "select_times",
    "subsample",
    "subsample_indices",
]

#: Most frames a selection asks for: a minute of video at 1 kHz.
MAX_FRAMES = 60_000


@dataclass(frozen=True, eq=False)
class Frame:
    """One recorded instant of a run.

    Attributes
    ----------
    time : float
        Simulation time [s].
    qpos : NDArray[np.float64]
        Copy of ``data.qpos`` (shape ``(model.nq,)``), in MuJoCo's units: [m] for slide and
        free-joint positions, [-] for the free joint's unit quaternion, [rad] for hinges.
    com : tuple[float, float]
        CoM position (x, z) in world coordinates [m].
    capture_point : float
        Capture point x on the floor [m] (drawn at z = 0; not drawn if not finite).
    cop : float
        CoP x on the floor [m]; NaN when the foot is off the floor (then not drawn).
    """

    time: float
    qpos: NDArray[np.float64]
    com: tuple[float, float]
    capture_point: float
    cop: float


#: A :class:`Frame` or a tuple of its fields in order (time, qpos, com, capture_point, cop),
#: as the plants record them (``MujocoPlant.frames``).
FrameLike = Frame | tuple[float, NDArray[np.float64], tuple[float, float], float, float]


def _as_frames(frames: Sequence[FrameLike]) -> list[Frame]:
    if len(frames) == 0:
        raise InvalidParameterError("frames must not be empty")
    out = []
    for f in frames:
        if isinstance(f, Frame):
            out.append(f)
        else:
            if len(f) != 5:
                raise InvalidParameterError(
                    "a frame must be a Frame or a tuple (time, qpos, com, capture_point, cop)"
                )
            t, qpos, com, capture_point, cop = f
            out.append(
                Frame(
                    float(t),
                    np.asarray(qpos, dtype=float),
                    (float(com[0]), float(com[1])),
                    float(capture_point),
                    float(cop),
                )
            )
    return out


# --- frames and camera ---------------------------------------------------------------------
def nearest_indices(times: NDArray[np.float64], targets: NDArray[np.float64]) -> list[int]:
    """Return the indices of the times nearest to the targets, without repeats, in order.

    Parameters
    ----------
    times : ndarray
        Frame times [s], non-decreasing, at least one.
    targets : ndarray
        The times wanted [s], increasing.
    """
    if len(times) == 1:
        return [0]
    right = np.clip(np.searchsorted(times, targets), 1, len(times) - 1)
    left = right - 1
    idx = np.where(np.abs(times[left] - targets) <= np.abs(times[right] - targets), left, right)
    return [int(i) for i in np.unique(idx)]


def subsample_indices(times: ArrayLike, fps: float) -> list[int]:
    """Return the indices of the times nearest to a grid of ``fps`` per second (ends kept).

    Parameters
    ----------
    times : Sequence[float]
        Frame times [s], finite and non-decreasing (any frames: 2-D or 3-D).
    fps : float
        Target frame rate [1/s], > 0.

    Returns
    -------
    list[int]
        Increasing indices, at most about ``duration * fps + 1`` of them.
    """
    if not (math.isfinite(fps) and fps > 0.0):
        raise InvalidParameterError(f"fps must be > 0 1/s, got {fps:g}")
    t = _checked_times(times)
    count = math.floor((t[-1] - t[0]) * fps + 1e-9) + 1
    return nearest_indices(t, np.append(t[0] + np.arange(count) / fps, t[-1]))


def select_indices(times: ArrayLike, count: int) -> list[int]:
    """Return the indices of the times nearest to ``count`` evenly spaced times.

    Parameters
    ----------
    times : Sequence[float]
        Frame times [s], finite and non-decreasing.
    count : int
        Number of frames wanted, in [1, :data:`MAX_FRAMES`] (fewer are returned if there are
        fewer distinct ones).

    Returns
    -------
    list[int]
        Increasing indices.
    """
    count = whole_number("count", count, 1, MAX_FRAMES)
    t = _checked_times(times)
    return nearest_indices(t, np.linspace(t[0], t[-1], min(count, len(t))))


def _checked_times(times: ArrayLike) -> NDArray[np.float64]:
    t = np.asarray(times, dtype=float).reshape(-1)
    if t.size == 0:
        raise InvalidParameterError("frames must not be empty")
    if not np.all(np.isfinite(t)) or np.any(np.diff(t) < 0.0):
        raise InvalidParameterError("frame times must be finite and non-decreasing")
    return t


def subsample(frames: Sequence[FrameLike], fps: float) -> list[Frame]:
    """Frames nearest to a regular grid of ``fps`` frames per second (first and last kept).

    Parameters
    ----------
    frames : Sequence[FrameLike]
        Recorded frames, times non-decreasing (e.g. recorded at 1 kHz).
    fps : float
        Target frame rate [1/s], > 0.

    Returns
    -------
    list[Frame]
        At most about ``duration * fps + 1`` frames.
    """
    if not (math.isfinite(fps) and fps > 0.0):
        raise InvalidParameterError(f"fps must be > 0 1/s, got {fps:g}")
    frames = _as_frames(frames)
    return [frames[i] for i in subsample_indices([f.time for f in frames], fps)]


def select_times(frames: Sequence[FrameLike], count: int) -> list[Frame]:
    """``count`` frames evenly spaced in time, from the first to the last.

    Parameters
    ----------
    frames : Sequence[FrameLike]
        Recorded frames, times non-decreasing.
    count : int
        Number of frames wanted, >= 1 (fewer are returned if there are fewer distinct ones).

    Returns
    -------
    list[Frame]
        The frames nearest to ``count`` evenly spaced times.
    """
    frames = _as_frames(frames)
    return [frames[i] for i in select_indices([f.time for f in frames], count)]
