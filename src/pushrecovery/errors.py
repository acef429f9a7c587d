"""The project's exception tree.

Every error raised on bad user input derives from :class:`PushRecoveryError`; errors about
values also derive from :class:`ValueError`, so ``except ValueError`` keeps working.
"""

from __future__ import annotations

__all__ = ["InputFileError", "InvalidParameterError", "PushRecoveryError"]


class PushRecoveryError(Exception):
    """Base class of every error pushrecovery raises on purpose."""


class InvalidParameterError(PushRecoveryError, ValueError):
    """A parameter or argument is outside its allowed range.

    The message names the parameter, the value received and the allowed range.
    """


class InputFileError(PushRecoveryError, ValueError):
    """A file given by the user is missing, unreadable or malformed."""
