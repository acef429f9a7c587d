"""Offscreen rendering of a MuJoCo run: a filmstrip PNG and an animated GIF.

A plant records :class:`Frame` objects during a run (time, ``qpos`` and the overlay points in
the sagittal plane); :func:`render_run` replays them and writes ``FILE.png`` (a row of panels
evenly spaced in time, each labelled with its time) and ``FILE.gif`` (the run in real time).
The side camera looks at the plane y = 0 with x (forward) from left to right and z up. The
overlays are drawn as small spheres: CoM red, capture point blue, CoP green (on the floor).

OpenGL backend
--------------
MuJoCo picks its OpenGL backend from the environment variable ``MUJOCO_GL`` when
``mujoco`` is imported (module ``mujoco.rendering.classic.gl_context``), and creates the
context when a ``mujoco.Renderer`` is created. Before creating a renderer this module sets
``MUJOCO_GL=egl`` on Linux if the user has not set it (headless, works without a display;
``osmesa`` does not work everywhere). If ``mujoco`` was already imported with another value,
the backend selection module is re-executed (``importlib.reload``) so that the renderer follows
the current ``MUJOCO_GL``; nothing is changed when the user set ``MUJOCO_GL``. Nothing happens
at import of this module, so a missing OpenGL library can never break ``import mujoco``
for the physics. Any failure to create the OpenGL context is reported as a
:class:`~pushrecovery.errors.PushRecoveryError` naming ``MUJOCO_GL``.
"""

from pushrecovery.sim.mujoco.render.frames import Frame, FrameLike, select_times, subsample
from pushrecovery.sim.mujoco.render.gl import require_offscreen_gl
from pushrecovery.sim.mujoco.render.output import (
    output_paths,
    render_run,
    write_animation,
    write_filmstrip,
)
from pushrecovery.sim.mujoco.render.scene import View, fit_view, render_frames

__all__ = [
    "Frame",
    "FrameLike",
    "View",
    "fit_view",
    "output_paths",
    "render_frames",
    "render_run",
    "require_offscreen_gl",
    "select_times",
    "subsample",
    "write_animation",
    "write_filmstrip",
]
