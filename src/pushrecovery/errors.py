"""The project's exception tree.

Every error raised on bad user input derives from :class:`PushRecoveryError`; errors about
values also derive from :class:`ValueError`, so ``except ValueError`` keeps working. Anything
else (a plain ``ValueError``, ``TypeError``, ``RuntimeError``...) escaping the library is a bug
in it, and the CLI shows it as one, with its traceback.
"""

from __future__ import annotations

__all__ = [
    "InputFileError",
    "InvalidParameterError",
    "ParameterTypeError",
    "PushRecoveryError",
    "SimulationDiverged",
    "SimulationTimeout",
]


class PushRecoveryError(Exception):
    """Base class of every error pushrecovery raises on purpose.

    Its message is one line (the CLI prints it as one): a message that quotes a value whose
    form spans lines (a numpy array's repr) has its line breaks folded into spaces.
    """

    def __init__(self, *args: object, **kwargs: object) -> None:
        if len(args) == 1 and isinstance(args[0], str) and "\n" in args[0]:
            args = (" ".join(args[0].split()),)
        super().__init__(*args, **kwargs)  # ModuleNotFoundError's name= (MissingExtraError)


class InvalidParameterError(PushRecoveryError, ValueError):
    """A parameter or argument is outside its allowed range.

    The message names the parameter, the value received and the allowed range.
    """


class ParameterTypeError(PushRecoveryError, TypeError):
    """An argument has the wrong type (a number where a mapping belongs, ...).

    The message names the parameter, the type expected and the type received.
    """


class InputFileError(PushRecoveryError, ValueError):
    """A file given by the user is missing, unreadable or malformed."""


class SimulationDiverged(PushRecoveryError, RuntimeError):
    """The physics engine became unstable: the push or the state is beyond what it simulates."""


class SimulationTimeout(PushRecoveryError, RuntimeError):
    """A run took longer than its wall-time limit (``simulate(..., wall_limit=...)``)."""
