"""Controllers behind one interface: ``reset(state)`` then ``compute(t, state) -> Command``."""

from pushrecovery.control.ankle import AnkleCapturePoint, AnklePD, AnkleSaturated
from pushrecovery.control.bangbang import BangBang
from pushrecovery.control.base import CONTROLLERS, Command, Controller, make_controller
from pushrecovery.control.mpc import MPCController
from pushrecovery.control.recovery import RecoveryController

__all__ = [
    "CONTROLLERS",
    "AnkleCapturePoint",
    "AnklePD",
    "AnkleSaturated",
    "BangBang",
    "Command",
    "Controller",
    "MPCController",
    "RecoveryController",
    "make_controller",
]
