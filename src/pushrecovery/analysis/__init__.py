"""Measured balance data (CSV, C3D) -> per-frame capture point, margins, strategy and step.

``readers`` turns a file into a :class:`~.recording.Recording` (body axes, SI), ``trial``
analyses it with the surfaces of :mod:`pushrecovery.surfaces`; ``c3d`` reads and writes C3D
files (markers and force plates) with ezc3d.
"""
