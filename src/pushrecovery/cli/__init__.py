"""Command-line interface. ``main`` turns every user error into one stderr line and exit 2.

User errors are the project's own (:class:`~pushrecovery.errors.PushRecoveryError`), click's
usage errors, files the system cannot open (``OSError``), memory the machine does not have and
an optional dependency that is not installed (:mod:`pushrecovery.extras`: the line names the
extra to install). Any other exception is a bug of the library and keeps its traceback.
"""

from __future__ import annotations

import sys

__all__ = ["main"]

#: Commands that answer for one state and exit: run from a command line of their own (``argv``
#: None), their kernels run as plain Python, which is faster than loading numba
#: (:mod:`pushrecovery.kernels.jit`).
ONE_STATE_COMMANDS = frozenset({"classify", "capture-region"})


def main(argv: list[str] | None = None) -> None:
    """Run the ``pushrecovery`` command; never shows a traceback for bad input."""
    import click

    from pushrecovery.cli.app import cli
    from pushrecovery.errors import PushRecoveryError

    args = sys.argv[1:] if argv is None else argv
    if argv is None and args[:1] and args[0] in ONE_STATE_COMMANDS:
        from pushrecovery.kernels.jit import run_as_python

        run_as_python()
    try:
        code = cli.main(args=args, prog_name="pushrecovery", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:
        click.echo(exc.ctx.get_help() if exc.ctx else "", err=True)
        sys.exit(2)
    except click.UsageError as exc:
        _fail(exc.format_message())
    except click.ClickException as exc:  # e.g. a path that does not exist
        _fail(exc.format_message())
    except ModuleNotFoundError as exc:  # MissingExtraError, or an extra's module unchecked
        _fail(str(_missing_extra(exc, args)))
    except PushRecoveryError as exc:
        _fail(str(exc))
    except OSError as exc:  # a file or a device the system refuses
        _fail(f"{type(exc).__name__}: {exc}")
    except MemoryError:
        _fail("not enough memory for this request: ask for fewer states, pushes or frames")
    except click.Abort:  # Ctrl-C (click has ended the terminal's "^C" line)
        print("pushrecovery: interrupted", file=sys.stderr)
        sys.exit(130)
    sys.exit(code if isinstance(code, int) else 0)


def _missing_extra(exc: ModuleNotFoundError, args: list[str]) -> ModuleNotFoundError:
    """Return the error naming the extra to install for the command line ``args``.

    The command's own extras (:data:`.app.COMMAND_EXTRAS`) first, so that one install makes
    it run; else the library's :class:`~pushrecovery.extras.MissingExtraError`; else the
    extra that brings the missing module. A module no extra brings is a bug: re-raised.
    """
    from pushrecovery.cli.app import COMMAND_EXTRAS, COMMANDS
    from pushrecovery.extras import MissingExtraError, extra_of, missing, require_extra

    words = [*args[:1]] if args[:1] and args[0] in COMMANDS else []
    if words == ["humanoid"] and args[1:2] and not args[1].startswith("-"):
        words.append(args[1])
    command = "'" + " ".join(["pushrecovery", *words]) + "'"
    own = COMMAND_EXTRAS.get(words[0] if words else "", ())
    for extra in own:
        try:
            require_extra(extra, command)
        except MissingExtraError as first:
            return first
    if isinstance(exc, MissingExtraError):
        return exc
    named = extra_of(exc.name or "", own)
    if named is None:  # not an optional dependency: a bug, with its traceback
        raise exc
    return missing(named, exc.name or "", command)


def _fail(message: str) -> None:
    line = " ".join(message.split())
    print(f"pushrecovery: error: {line}", file=sys.stderr)
    sys.exit(2)
