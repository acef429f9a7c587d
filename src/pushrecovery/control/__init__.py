"""Controllers behind one interface: ``reset(state)`` then ``compute(t, state) -> Command``."""

from pushrecovery.control.ankle import AnkleCapturePoint, AnklePD, AnkleSaturated
from pushrecovery.control.bangbang import BangBang
from pushrecovery.control.base import CONTROLLERS, Command, Controller, make_controller
from pushrecovery.control.mpc import MPCController
from pushrecovery.control.recovery import RecoveryController
from pushrecovery.control.recovery_plane import PlaneRecoveryController

__all__ = [
    "CONTROLLERS",
    "AnkleCapturePoint",
    "AnklePD",
    "AnkleSaturated",
    "BangBang",
    "Command",
    "Controller",
    "MPCController",
    "PlaneRecoveryController",
    "RecoveryController",
    "make_controller",
]
