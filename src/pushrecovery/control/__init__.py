"""Controllers behind one interface: ``reset(state)`` then ``compute(t, state) -> Command``.

The controllers are imported on first use (PEP 562), so that naming them
(:mod:`pushrecovery.control.registry`) loads no model.
"""

from __future__ import annotations

import importlib
from typing import Any

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

_WHERE = {
    "CONTROLLERS": "pushrecovery.control.base",
    "Command": "pushrecovery.control.base",
    "Controller": "pushrecovery.control.base",
    "make_controller": "pushrecovery.control.base",
    "AnkleCapturePoint": "pushrecovery.control.ankle",
    "AnklePD": "pushrecovery.control.ankle",
    "AnkleSaturated": "pushrecovery.control.ankle",
    "BangBang": "pushrecovery.control.bangbang",
    "MPCController": "pushrecovery.control.mpc",
    "RecoveryController": "pushrecovery.control.recovery",
    "PlaneRecoveryController": "pushrecovery.control.recovery.plane",
}


def __getattr__(name: str) -> Any:
    if name not in _WHERE:
        raise AttributeError(f"module 'pushrecovery.control' has no attribute {name!r}")
    return getattr(importlib.import_module(_WHERE[name]), name)
