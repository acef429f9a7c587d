"""pushrecovery: decision surfaces and controllers for humanoid push recovery.

Implements and verifies the models of Stephens, "Humanoid Push Recovery" [Stephens07]:
CoP (ankle) balancing, CMP (hip) balancing and stepping. Importing the package is cheap; the
plotting and CLI layers import their heavy dependencies lazily.

References
----------
.. [Stephens07] B. Stephens, "Humanoid Push Recovery", IEEE-RAS Humanoids, 2007.
"""

from pushrecovery.errors import InputFileError, InvalidParameterError, PushRecoveryError
from pushrecovery.params import PRESETS, BodyParams, load_params

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
