"""Command-line interface. ``main`` turns every user error into one stderr line and exit 2.

User errors are the project's own (:class:`~pushrecovery.errors.PushRecoveryError`), click's
usage errors, files the system cannot open (``OSError``) and memory the machine does not have.
Any other exception is a bug of the library and keeps its traceback.
"""

from __future__ import annotations

import sys

__all__ = ["main"]


def main(argv: list[str] | None = None) -> None:
    """Run the ``pushrecovery`` command; never shows a traceback for bad input."""
    import click

    from pushrecovery.cli.app import cli
    from pushrecovery.errors import PushRecoveryError

    args = sys.argv[1:] if argv is None else argv
    try:
        code = cli.main(args=args, prog_name="pushrecovery", standalone_mode=False)
    except click.exceptions.NoArgsIsHelpError as exc:
        click.echo(exc.ctx.get_help() if exc.ctx else "", err=True)
        sys.exit(2)
    except click.UsageError as exc:
        _fail(exc.format_message())
    except click.ClickException as exc:  # e.g. a path that does not exist
        _fail(exc.format_message())
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


def _fail(message: str) -> None:
    line = " ".join(message.split())
    print(f"pushrecovery: error: {line}", file=sys.stderr)
    sys.exit(2)
