"""The helper process of :mod:`.isolated`: ``python -m pushrecovery.analysis.c3d.server``.

Reads requests from stdin and answers on the original stdout; file descriptor 1 is pointed
at stderr first, so that nothing a C library prints can break the protocol.
"""

from __future__ import annotations

import importlib
import os
import sys

from pushrecovery.analysis.c3d.isolated import read_message, write_message


def serve() -> None:
    """Answer requests until stdin closes."""
    answers = os.fdopen(os.dup(sys.stdout.fileno()), "wb")
    os.dup2(sys.stderr.fileno(), sys.stdout.fileno())
    requests = sys.stdin.buffer
    while True:
        try:
            module, name, args = read_message(requests)
        except EOFError:
            return
        try:
            function = getattr(importlib.import_module(module), name)
            message = (True, function(*args))
        except Exception as exc:  # sent back and raised in the caller
            message = (False, exc)
        try:
            write_message(answers, message)
        except Exception as exc:  # an unpicklable result or error: say what it was
            write_message(answers, (False, RuntimeError(f"{type(exc).__name__}: {exc}")))


if __name__ == "__main__":
    serve()
