"""Which command runs which models: the planar commands and ``pushrecovery humanoid``.

The planar commands (``simulate``, ``critical-push``, ``validate``, ``campaign``) list only
the planar models and their options, the ``humanoid`` commands only the 3-D humanoids (biped3d,
g1) and theirs. A model or an option of the other family is refused in one line that names the
command that takes it (issue 31): :class:`ModelChoice` for ``--model``,
:func:`humanoid_only` for the humanoids' options, accepted by the planar commands without
being listed (``hidden``) so that an old command line learns where it moved, and
:func:`planar_only` the other way.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any, TypeVar

import click

from pushrecovery.sim.registry import MUJOCO_3D_MODELS

F = TypeVar("F", bound=Callable[..., Any])

__all__ = [
    "HUMANOID_MODELS",
    "ListedChoice",
    "ModelChoice",
    "humanoid_only",
    "planar_only",
    "refuse_humanoid_model",
]

#: The 3-D humanoids of ``pushrecovery humanoid`` (MuJoCo, the whole-body controller).
HUMANOID_MODELS: tuple[str, ...] = tuple(MUJOCO_3D_MODELS)


def refuse_humanoid_model(model: str, command: str) -> None:
    """Refuse a 3-D humanoid given to a planar command, naming ``pushrecovery humanoid``.

    Parameters
    ----------
    model : str
        The ``--model`` given.
    command : str
        The planar command's name (``simulate``, ``critical-push``, ``validate``).

    Raises
    ------
    InvalidParameterError
        If ``model`` is one of :data:`HUMANOID_MODELS`.
    """
    from pushrecovery.errors import InvalidParameterError

    if model in HUMANOID_MODELS:
        raise InvalidParameterError(
            f"--model {model} is a 3-D humanoid: use 'pushrecovery humanoid {command} "
            f"--model {model}'"
        )


class ListedChoice(click.Choice):
    """A choice whose help lists only the values that work; others pass on without a listing.

    An unlisted value is handed to the command as it is, which refuses it in its own words
    (``critical-push --model stepping-plane``: the critical push is sagittal): the help does
    not offer what the command refuses, and the refusal stays the command's.

    Parameters
    ----------
    choices : sequence of str
        The values listed in the help.
    unlisted : sequence of str, optional
        Values accepted without being listed.
    """

    def __init__(self, choices: tuple[str, ...], unlisted: tuple[str, ...] = ()) -> None:
        super().__init__(choices)
        self.unlisted = tuple(unlisted)

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """Return ``value`` if it is a choice or an unlisted value; else click's error."""
        if isinstance(value, str) and value in self.unlisted:
            return value
        return super().convert(value, param, ctx)


class ModelChoice(ListedChoice):
    """A ``--model`` choice that lists its family's models and points the others elsewhere.

    Parameters
    ----------
    choices : sequence of str
        The models the command runs (listed in its help).
    elsewhere : mapping of str to str
        Model -> the command line that runs it, after ``pushrecovery`` (``"humanoid simulate
        --model g1"``); refused in one line naming it, without being listed.
    family : str
        What the ``elsewhere`` models are, for the message (``"a 3-D humanoid"``).
    unlisted : sequence of str, optional
        Models of this family that the command refuses itself (:class:`ListedChoice`).
    files : bool
        Whether an MJCF file (a value ending in ``.xml``) is a model too (its path is
        returned; the command reads it).
    """

    def __init__(
        self,
        choices: tuple[str, ...],
        elsewhere: Mapping[str, str],
        family: str,
        unlisted: tuple[str, ...] = (),
        files: bool = False,
    ) -> None:
        super().__init__(choices, unlisted)
        self.elsewhere = dict(elsewhere)
        self.family = family
        self.files = files

    def convert(self, value: Any, param: click.Parameter | None, ctx: click.Context | None) -> Any:
        """Return ``value`` if it is a choice; refuse another family's model by its command."""
        if isinstance(value, str) and value in self.elsewhere:
            from pushrecovery.errors import InvalidParameterError

            raise InvalidParameterError(
                f"--model {value} is {self.family}: use 'pushrecovery {self.elsewhere[value]}'"
            )
        if self.files and isinstance(value, str) and value.lower().endswith(".xml"):
            return value
        return super().convert(value, param, ctx)


#: The humanoids' options that take no value.
_FLAGS = frozenset(("--stepping", "--quick", "--critical", "--no-critical"))


def humanoid_only(
    command: str, *flags: str, nargs: Mapping[str, int] | None = None
) -> Callable[[F], F]:
    """Return hidden options of a planar command that refuse the 3-D humanoids' ``flags``.

    Parameters
    ----------
    command : str
        The humanoid command that takes them (``simulate`` for ``pushrecovery humanoid
        simulate``).
    *flags : str
        The options (``--azimuth``); ``--stepping``, ``--quick``, ``--critical`` and
        ``--no-critical`` are flags, the others take one value, any text (refused before it is
        parsed).
    nargs : mapping of str to int, optional
        The options among ``flags`` that take several values (``{"--fraction": 3}``).

    Returns
    -------
    callable
        The click decorator: the options are not listed, not passed to the command, and one
        given is refused in one line naming ``pushrecovery humanoid COMMAND``.
    """
    message = "{flag} is an option of the 3-D humanoids (biped3d, g1): use "
    return _refused(command, flags, nargs, message + "'pushrecovery humanoid {command} {shown}'")


def planar_only(
    command: str, *flags: str, nargs: Mapping[str, int] | None = None
) -> Callable[[F], F]:
    """Return hidden options of a humanoid command that refuse the planar models' ``flags``.

    As :func:`humanoid_only`, ``command`` the humanoid command itself and ``flags`` the planar
    options (``--xdot``; ``nargs``: ``{"--x0": 3}``), each taking any text: one given is
    refused in one line pointing to ``pushrecovery humanoid COMMAND --help``.
    """
    message = "{flag} is an option of the planar models, not of the 3-D humanoids: see "
    return _refused(command, flags, nargs, message + "'pushrecovery humanoid {command} --help'")


def _refused(
    command: str, flags: tuple[str, ...], nargs: Mapping[str, int] | None, message: str
) -> Callable[[F], F]:
    """Add the hidden ``flags``: one given raises ``message`` filled in (``{shown}``: as given)."""
    counts = nargs or {}

    def refuse(ctx: click.Context, param: click.Parameter, value: Any) -> Any:
        if value is None or value is False:
            return value
        from pushrecovery.errors import InvalidParameterError

        flag = param.opts[0]
        given = " ".join(value) if isinstance(value, tuple) else value
        shown = flag if flag in _FLAGS else f"{flag} {given}"
        raise InvalidParameterError(message.format(flag=flag, command=command, shown=shown))

    def apply(func: F) -> F:
        for flag in reversed(flags):
            func = click.option(
                flag,
                is_flag=flag in _FLAGS,
                default=False if flag in _FLAGS else None,
                type=None if flag in _FLAGS else str,
                nargs=counts.get(flag, 1),
                hidden=True,
                expose_value=False,
                callback=refuse,
            )(func)
        return func

    return apply
