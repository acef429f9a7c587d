"""Recorded frames of a run: converting, selecting and subsampling them in time."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike, NDArray

from pushrecovery.arguments import (
    bounded_float,
    finite_array,
    finite_float,
    finite_vector,
    float_array,
    whole_number,
)
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

__all__ = ["MAX_FPS", "MAX_FRAMES", "Frame", "FrameLike", "select_times", "subsample"]

#: Most frames a selection asks for: a minute of video at 1 kHz.
MAX_FRAMES = 60_000
#: Highest frame rate a subsampling takes [1/s]: ten times the plants' 1 kHz recording.
MAX_FPS = 1e4


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
    """Return ``frames`` as :class:`Frame` objects, or raise naming what is wrong."""
    if isinstance(frames, str | bytes) or not isinstance(frames, Sequence):
        raise ParameterTypeError(
            f"frames must be a sequence of frames, got {type(frames).__name__}"
        )
    if len(frames) == 0:
        raise InvalidParameterError("frames must not be empty")
    out = []
    for f in frames:
        if isinstance(f, Frame):
            out.append(f)
            continue
        if not isinstance(f, tuple | list) or len(f) != 5:
            raise InvalidParameterError(
                "a frame must be a Frame or a tuple (time, qpos, com, capture_point, cop)"
            )
        t, qpos, com, capture_point, cop = f
        xz = finite_vector("a frame's com", com, 2, unit="m")
        out.append(
            Frame(
                finite_float("a frame's time", t, "s"),
                finite_array("a frame's qpos", qpos),
                (float(xz[0]), float(xz[1])),
                float(float_array("a frame's capture_point", capture_point)),
                float(float_array("a frame's cop", cop)),
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
        Target frame rate [1/s], in (0, :data:`MAX_FPS`].

    Returns
    -------
    list[int]
        Increasing indices, at most about ``duration * fps + 1`` of them.
    """
    fps = _checked_fps(fps)
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


def _checked_fps(fps: object) -> float:
    """Return a frame rate in (0, MAX_FPS] [1/s] (a grid finer than the recording's is no use)."""
    fps = bounded_float("fps", fps, 0.0, MAX_FPS, "1/s")
    if fps == 0.0:
        raise InvalidParameterError("fps must be > 0 1/s, got 0")
    return fps


def _checked_times(times: ArrayLike) -> NDArray[np.float64]:
    t = float_array("times", times).reshape(-1)
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
        Target frame rate [1/s], in (0, :data:`MAX_FPS`].

    Returns
    -------
    list[Frame]
        At most about ``duration * fps + 1`` frames.
    """
    fps = _checked_fps(fps)
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
