"""The OpenGL context of offscreen rendering: ``MUJOCO_GL``, the renderer and its errors.

The backend is chosen as the package docstring (:mod:`pushrecovery.sim.mujoco.render`) says;
a failure to create the context is a :class:`~pushrecovery.errors.PushRecoveryError` naming
``MUJOCO_GL``.
"""

from __future__ import annotations

import importlib
import os
import sys
from types import ModuleType
from typing import TYPE_CHECKING

import numpy as np

from pushrecovery.errors import InvalidParameterError, ParameterTypeError, PushRecoveryError

if TYPE_CHECKING:
    import mujoco

__all__ = ["require_offscreen_gl"]


def _gl_name() -> str:
    return os.environ.get("MUJOCO_GL", "")


def _gl_error(exc: BaseException) -> PushRecoveryError:
    detail = (str(exc).strip().splitlines() or [""])[0] or type(exc).__name__
    if len(detail) > 120:
        detail = detail[:117] + "..."
    return PushRecoveryError(
        f"cannot render offscreen with MUJOCO_GL={_gl_name()!r} ({type(exc).__name__}: "
        f"{detail}); set MUJOCO_GL=egl (headless) or glfw (with a display)"
    )


def _mujoco_for_rendering() -> ModuleType:
    """Import ``mujoco`` with its OpenGL backend following ``MUJOCO_GL`` (egl by default)."""
    if sys.platform.startswith("linux"):
        os.environ.setdefault("MUJOCO_GL", "egl")
    try:
        import mujoco

        # The module the Renderer takes its GLContext class from (it looks the class up
        # there when a Renderer is created).
        renderer_module = sys.modules.get(getattr(mujoco.Renderer, "__module__", ""))
        gl_context = getattr(renderer_module, "gl_context", None)
        chosen = getattr(gl_context, "_MUJOCO_GL", None)
        if gl_context is not None and chosen is not None:
            if chosen != _gl_name().lower().strip():
                # mujoco was imported before MUJOCO_GL was set: select the backend again.
                importlib.reload(gl_context)
    except Exception as exc:  # an invalid MUJOCO_GL raises RuntimeError, a broken one others
        raise _gl_error(exc) from exc
    return mujoco


def _open_renderer(model: mujoco.MjModel, width: int, height: int) -> mujoco.Renderer:
    for name, value in (("width", width), ("height", height)):
        if isinstance(value, bool) or not isinstance(value, int | np.integer):
            raise ParameterTypeError(f"{name} must be a whole number [px], got {value!r:.40}")
    mj = _mujoco_for_rendering()
    buffer = (model.vis.global_.offwidth, model.vis.global_.offheight)
    if not (0 < width <= buffer[0] and 0 < height <= buffer[1]):
        raise InvalidParameterError(
            f"image size must be within the model's offscreen buffer {buffer[0]}x{buffer[1]} "
            f"px, got {width}x{height}"
        )
    try:
        return mj.Renderer(model, height=height, width=width)
    except Exception as exc:  # FatalError, ImportError, AttributeError, ... by backend
        raise _gl_error(exc) from exc


def require_offscreen_gl() -> None:
    """Check that offscreen rendering works (call it before a long run to fail early).

    Raises
    ------
    PushRecoveryError
        If no OpenGL context can be created; the message names ``MUJOCO_GL``.
    """
    mj = _mujoco_for_rendering()
    model = mj.MjModel.from_xml_string("<mujoco/>")
    _open_renderer(model, 8, 8).close()
