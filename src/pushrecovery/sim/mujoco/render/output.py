"""Filmstrips and animations of rendered frames (PIL), with times, labels and a legend."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import NDArray

from pushrecovery.arguments import bounded_float, finite_array, input_path, require_type
from pushrecovery.control.wbc.bodies import check_model
from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError

if TYPE_CHECKING:
    import mujoco
    from PIL import Image as PILImage
from pushrecovery.sim.mujoco.render.frames import FrameLike, _as_frames, select_times, subsample
from pushrecovery.sim.mujoco.render.scene import LEGEND, check_size, fit_view, render_frames

__all__ = [
    "HOLD_LAST",
    "output_paths",
    "render_run",
    "write_animation",
    "write_filmstrip",
]


#: How long the last GIF frame is held before the animation loops [s].
HOLD_LAST = 1.0
# Heights of a filmstrip's label, legend and title strips and the gap between panels [px].
_LABEL_HEIGHT, _LEGEND_HEIGHT, _TITLE_HEIGHT, _GAP = 20, 22, 22, 4


#: Largest time an image may carry [s] (its label and GIF delay; a run lasts at most 60 s).
_MAX_TIME = 1e6


# --- images ----------------------------------------------------------------------------------
def _font(size: int) -> Any:
    from PIL import ImageFont

    try:
        return ImageFont.load_default(size=size)
    except (TypeError, OSError, ImportError):  # old Pillow or no FreeType: bitmap font
        return ImageFont.load_default()


def _rgb(rgba: tuple[float, float, float, float]) -> tuple[int, int, int]:
    return (round(255 * rgba[0]), round(255 * rgba[1]), round(255 * rgba[2]))


#: A legend: (label, RGBA colour) per marker.
Legend = Sequence[tuple[str, tuple[float, float, float, float]]]


def _draw_legend(
    draw: Any, x: int, y: int, height: int, font: Any, legend: Legend = LEGEND
) -> None:
    """Coloured dots and names of the markers, starting at (x, y) in a strip of ``height``."""
    r = max(3, height // 4)
    cy = y + height // 2
    for name, rgba in legend:
        draw.ellipse((x, cy - r, x + 2 * r, cy + r), fill=_rgb(rgba))
        x += 2 * r + 4
        draw.text((x, cy), name, fill=(0, 0, 0), font=font, anchor="lm")
        x += int(draw.textlength(name, font=font)) + 12


def _checked_inputs(
    images: Sequence[NDArray[np.uint8]], times: Sequence[float], legend: object
) -> NDArray[np.float64]:
    """Return the images' times [s] after checking images, times and legend, or raise.

    Images: uint8 RGB arrays of one shape, a time each; the legend: (name, RGBA) entries.
    """
    if isinstance(images, str | bytes) or not (
        isinstance(images, Sequence) or (isinstance(images, np.ndarray) and images.ndim == 4)
    ):
        raise ParameterTypeError(f"images must be a sequence of RGB arrays, got {images!r:.40}")
    stamps = finite_array("times", times, bound=_MAX_TIME, unit="s").reshape(-1)
    if len(images) == 0 or len(images) != stamps.size:
        raise InvalidParameterError(
            f"need as many times as images (>= 1), got {stamps.size} and {len(images)}"
        )
    first = images[0]
    shape = np.shape(first) if isinstance(first, np.ndarray) else ()
    if (
        len(shape) != 3
        or shape[2] != 3
        or any(not isinstance(im, np.ndarray) or im.dtype != np.uint8 for im in images)
        or any(np.shape(im) != shape for im in images)
    ):
        raise InvalidParameterError(
            "images must be uint8 RGB arrays of one shape (height, width, 3)"
        )
    if (
        isinstance(legend, str | bytes)
        or not isinstance(legend, Sequence)
        or not all(
            isinstance(entry, tuple | list)
            and len(entry) == 2
            and isinstance(entry[0], str)
            and np.shape(entry[1]) == (4,)
            for entry in legend
        )
    ):
        raise InvalidParameterError("legend must be (name, (r, g, b, a)) pairs, colours in [0, 1]")
    for _, rgba in legend:
        bounded_float("a legend colour", min(rgba), 0.0, 1.0)
        bounded_float("a legend colour", max(rgba), 0.0, 1.0)
    return stamps


def _save(image: PILImage.Image, path: Path, **options: Any) -> Path:
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        image.save(path, **options)
    except OSError as exc:
        raise PushRecoveryError(f"cannot write {str(path)[:200]}: {exc.strerror or exc}") from exc
    except ValueError as exc:  # a NUL in the name, a suffix PIL does not know
        raise InvalidParameterError(f"cannot write {str(path)[:200]!r}: {exc}") from None
    return path


def write_filmstrip(
    images: Sequence[NDArray[np.uint8]],
    times: Sequence[float],
    path: Path,
    *,
    title: str | None = None,
    legend: Legend = LEGEND,
) -> Path:
    """Write the images side by side, each labelled ``t = ... s``, with a legend, as a PNG.

    Parameters
    ----------
    images : Sequence[NDArray[np.uint8]]
        RGB images of one shape ``(height, width, 3)``.
    times : Sequence[float]
        Time of each image [s].
    path : Path
        Output file (PNG, 256-colour palette to keep it small); parents are created.
    title : str or None
        Optional line of text above the panels.
    legend : sequence of (str, RGBA)
        The markers' names and colours (default the side view's CoM, capture point, CoP).

    Returns
    -------
    Path
        ``path``.
    """
    from PIL import Image, ImageDraw

    times = list(_checked_inputs(images, times, legend))
    path = input_path("path", path)
    require_type("title", title, (str, type(None)))
    h, w = np.shape(images[0])[:2]
    n = len(images)
    top = _TITLE_HEIGHT if title else 0
    canvas = Image.new(
        "RGB", (n * w + (n + 1) * _GAP, top + _LABEL_HEIGHT + h + _LEGEND_HEIGHT + _GAP), "white"
    )
    draw = ImageDraw.Draw(canvas)
    font = _font(13)
    if title:
        draw.text((_GAP, top // 2), title, fill=(0, 0, 0), font=_font(15), anchor="lm")
    for k, (image, t) in enumerate(zip(images, times, strict=True)):
        x = _GAP + k * (w + _GAP)
        label = f"t = {t:.2f} s"
        draw.text(
            (x + w // 2, top + _LABEL_HEIGHT // 2), label, fill=(0, 0, 0), font=font, anchor="mm"
        )
        canvas.paste(Image.fromarray(np.asarray(image, dtype=np.uint8)), (x, top + _LABEL_HEIGHT))
    _draw_legend(draw, _GAP, top + _LABEL_HEIGHT + h, _LEGEND_HEIGHT, font, legend)
    paletted = canvas.quantize(colors=256, dither=Image.Dither.NONE)
    return _save(paletted, path, optimize=True)


def write_animation(
    images: Sequence[NDArray[np.uint8]],
    times: Sequence[float],
    path: Path,
    *,
    legend: Legend = LEGEND,
) -> Path:
    """Write the images as a looping GIF played in real time, with time label and legend.

    Parameters
    ----------
    images, times, legend
        As :func:`write_filmstrip`'s, the times [s] non-decreasing: frame delays follow them
        (rounded to the GIF's 10 ms unit without drift); the last frame is held ``HOLD_LAST`` s.
    path : Path
        Output file (GIF); parents are created.

    Returns
    -------
    Path
        ``path``.
    """
    from PIL import Image, ImageDraw

    t = _checked_inputs(images, times, legend)
    path = input_path("path", path)
    if np.any(np.diff(t) < 0.0):
        raise InvalidParameterError("times must be non-decreasing")
    ticks = np.round((t - t[0]) * 100.0).astype(int)  # centiseconds, rounded without drift
    delays = [max(10, int(10 * d)) for d in np.diff(ticks)] + [round(1000 * HOLD_LAST)]
    h, w = np.shape(images[0])[:2]
    font = _font(12)
    frames = []
    for image, time in zip(images, t, strict=True):
        canvas = Image.new("RGB", (w, h + _LEGEND_HEIGHT), "white")
        canvas.paste(Image.fromarray(np.asarray(image, dtype=np.uint8)), (0, 0))
        draw = ImageDraw.Draw(canvas)
        _draw_legend(draw, _GAP, h, _LEGEND_HEIGHT, font, legend)
        draw.text(
            (w - _GAP, h + _LEGEND_HEIGHT // 2),
            f"t = {time:.2f} s",
            fill=(0, 0, 0),
            font=font,
            anchor="rm",
        )
        frames.append(canvas)
    # One palette for all frames, so the static background stays identical between frames
    # and the GIF stores only the changed rectangle of each frame.
    palette = frames[0].quantize(colors=128, dither=Image.Dither.NONE)
    paletted = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
    return _save(
        paletted[0],
        path,
        save_all=True,
        append_images=paletted[1:],
        duration=delays,
        loop=0,
        optimize=False,
    )


# --- all together --------------------------------------------------------------------------
def output_paths(path: Path) -> tuple[Path, Path]:
    """Filmstrip and animation paths for ``--render FILE``: ``FILE.png`` and ``FILE.gif``.

    A ``.png`` or ``.gif`` suffix of ``path`` is replaced, any other suffix is kept
    (``run.v2`` gives ``run.v2.png``).
    """
    path = input_path("path", path)
    if not path.name or path.name == "..":
        raise InvalidParameterError(f"path must name a file, got {str(path)[:200]!r}")
    base = path.with_suffix("") if path.suffix.lower() in (".png", ".gif") else path
    return base.with_name(base.name + ".png"), base.with_name(base.name + ".gif")


def render_run(
    model: mujoco.MjModel,
    frames: Sequence[FrameLike],
    path: Path,
    *,
    panels: int = 7,
    panel_size: tuple[int, int] = (180, 240),
    fps: float = 25.0,
    size: tuple[int, int] = (320, 240),
    title: str | None = None,
) -> tuple[Path, Path]:
    """Write the filmstrip PNG and the animated GIF of a recorded run.

    Parameters
    ----------
    model : mujoco.MjModel
        The model the frames were recorded with.
    frames : Sequence[FrameLike]
        Recorded frames, times non-decreasing (any rate, e.g. every step at 1 kHz).
    path : Path
        ``FILE``, ``FILE.png`` or ``FILE.gif``: both ``FILE.png`` and ``FILE.gif`` are written
        (see :func:`output_paths`).
    panels : int
        Number of filmstrip panels, evenly spaced in time from the first to the last frame.
    panel_size : tuple[int, int]
        Filmstrip panel (width, height) [px].
    fps : float
        GIF frame rate [1/s], in (0, 50] (browsers slow down faster GIFs); the recorded frames
        are subsampled to it (25 fps is exact in the GIF's 10 ms delay unit).
    size : tuple[int, int]
        GIF frame (width, height) [px] (a legend strip is added below).
    title : str or None
        Optional title line of the filmstrip.

    Returns
    -------
    tuple[Path, Path]
        Paths of the PNG filmstrip and of the GIF.

    Raises
    ------
    PushRecoveryError
        If offscreen OpenGL is unavailable (message names ``MUJOCO_GL``) or a file cannot be
        written; :class:`~pushrecovery.errors.InvalidParameterError` on bad arguments.
    """
    check_model(model)
    fps = bounded_float("fps", fps, 0.0, 50.0, "1/s")
    if fps == 0.0:
        raise InvalidParameterError("fps must be in (0, 50] 1/s, got 0")
    panel_size, size = check_size("panel_size", panel_size), check_size("size", size)
    require_type("title", title, (str, type(None)))
    png, gif = output_paths(path)
    frames = _as_frames(frames)
    strip = select_times(frames, panels)
    strip_images = render_frames(
        model,
        strip,
        width=panel_size[0],
        height=panel_size[1],
        view=fit_view(model, frames, panel_size[0] / panel_size[1]),
    )
    write_filmstrip(strip_images, [f.time for f in strip], png, title=title)
    movie = subsample(frames, fps)
    movie_images = render_frames(
        model, movie, width=size[0], height=size[1], view=fit_view(model, frames, size[0] / size[1])
    )
    write_animation(movie_images, [f.time for f in movie], gif)
    return png, gif
