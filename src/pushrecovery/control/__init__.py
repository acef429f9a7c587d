"""Controllers behind one interface: ``reset(state)`` then ``compute(t, state) -> Command``."""

from pushrecovery.control.ankle import AnklePD, AnkleSaturated
from pushrecovery.control.base import CONTROLLERS, Command, Controller, make_controller

__all__ = ["CONTROLLERS", "AnklePD", "AnkleSaturated", "Command", "Controller", "make_controller"]
