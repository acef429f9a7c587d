"""pushrecovery: decision surfaces and controllers for humanoid push recovery.

Implements and verifies the models of Stephens, "Humanoid Push Recovery" [Stephens07]:
CoP (ankle) balancing, CMP (hip) balancing and stepping. Importing the package is cheap (the
parameters and numpy load on first use, PEP 562); the plotting and CLI layers import their
heavy dependencies lazily. ``pip install pushrecovery`` is the core (models, surfaces, monitor,
controllers, analytic simulation); MuJoCo, campaigns, trial analysis, figures and the report
are extras, and a feature missing one says which (:mod:`pushrecovery.extras`).

References
----------
.. [Stephens07] B. Stephens, "Humanoid Push Recovery", IEEE-RAS Humanoids, 2007.
"""

from __future__ import annotations

from typing import Any

from pushrecovery.errors import InputFileError, InvalidParameterError, PushRecoveryError

__version__ = "0.1.0"

__all__ = [
    "PRESETS",
    "BodyParams",
    "InputFileError",
    "InvalidParameterError",
    "PushRecoveryError",
    "__version__",
    "load_params",
]


def __getattr__(name: str) -> Any:
    if name == "BodyParams":
        from pushrecovery.params import BodyParams

        return BodyParams
    if name in ("PRESETS", "load_params"):
        from pushrecovery import presets

        return getattr(presets, name)
    raise AttributeError(f"module 'pushrecovery' has no attribute {name!r}")
