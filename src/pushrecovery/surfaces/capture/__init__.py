"""Capture regions and plans on the ground plane, and the linear programs that check them.

:mod:`~pushrecovery.surfaces.capture.region` (the N-step foothold regions and their
terms), :mod:`~pushrecovery.surfaces.capture.plan` (the plans and their loads) and
:mod:`~pushrecovery.surfaces.capture.lp` (exact LPs, the tests' reference).
"""
