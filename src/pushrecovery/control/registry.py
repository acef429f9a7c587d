"""The built-in controllers by name: import strings, loaded on demand.

Listing them costs nothing (the CLI's choices, ``pushrecovery --help``);
:func:`~pushrecovery.control.base.make_controller` imports a controller's module when one is
built. Controllers registered with :func:`~pushrecovery.control.base.register` (a user's own)
are found there as well.
"""

from __future__ import annotations

__all__ = ["CONTROLLER_NAMES", "CONTROLLER_PATHS"]

#: Controller name -> "module:Class".
CONTROLLER_PATHS: dict[str, str] = {
    "ankle-saturated": "pushrecovery.control.ankle:AnkleSaturated",
    "ankle-pd": "pushrecovery.control.ankle:AnklePD",
    "ankle-capture-point": "pushrecovery.control.ankle:AnkleCapturePoint",
    "bang-bang": "pushrecovery.control.bangbang:BangBang",
    "mpc": "pushrecovery.control.mpc.controller:MPCController",
    "recovery": "pushrecovery.control.recovery:RecoveryController",
    "recovery-plane": "pushrecovery.control.recovery.plane:PlaneRecoveryController",
}
#: The built-in controllers' names.
CONTROLLER_NAMES = tuple(CONTROLLER_PATHS)
