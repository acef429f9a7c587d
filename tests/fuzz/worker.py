"""One fuzzing worker: runs cases from stdin in this process, one JSON line out per case.

Protocol (``campaign.py``): a line ``{"id": ..., "args": [...]}`` (a command line) or
``{"id": ..., "api": name, "seed": int}`` (a library call, ``api.py``) in; ``{"id": ...,
"code": int, "stdout": str, "stderr": str, "warnings": [str], "escaped": str | null}`` out,
after the line ``{"started": id}`` that tells the parent which case a crash belongs to.
``escaped`` is an exception that left ``pushrecovery.cli.main`` (a traceback for the user).
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import resource
import sys
import traceback
import warnings
from pathlib import Path

#: Address space of a worker [bytes]: MuJoCo, numba and the report fit well within.
MEMORY_LIMIT = 8 << 30


def run(args: list[str]) -> dict[str, object]:
    """Run ``pushrecovery ARGS`` in this process and return what a user would see."""
    from pushrecovery.cli import main

    out, err = io.StringIO(), io.StringIO()
    code, escaped = 0, None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                main(args)
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            except BaseException as exc:  # a traceback the user would see
                code = 1
                escaped = "".join(traceback.format_exception_only(type(exc), exc)).strip()
                escaped += " | " + traceback.format_tb(exc.__traceback__)[-1].strip()[:300]
    return {
        "code": code,
        "stdout": out.getvalue()[:200_000],  # whole, for the JSON check
        "stderr": err.getvalue()[-4000:],
        "warnings": [f"{w.category.__name__}: {w.message}"[:300] for w in caught],
        "escaped": escaped,
    }


def serve() -> None:
    """Answer cases from stdin until it closes."""
    os.environ.setdefault("MPLBACKEND", "Agg")
    # A memory bomb (an argument asking for billions of samples) raises MemoryError here,
    # a traceback counted against its case, instead of taking the machine's memory.
    _, hard = resource.getrlimit(resource.RLIMIT_AS)
    resource.setrlimit(resource.RLIMIT_AS, (MEMORY_LIMIT, hard))
    # Every case's relative paths land in the case folder the parent names.
    home = os.getcwd()
    for line in sys.stdin:
        case = json.loads(line)
        sys.__stdout__.write(json.dumps({"started": case["id"]}) + "\n")
        sys.__stdout__.flush()
        folder = case.get("cwd", home)
        os.makedirs(folder, exist_ok=True)
        os.chdir(folder)
        if "api" in case:
            import api

            result = api.call(case["api"], case["seed"], Path(folder))
        else:
            result = run(case["args"])
        os.chdir(home)
        sys.__stdout__.write(json.dumps({"id": case["id"], **result}) + "\n")
        sys.__stdout__.flush()


if __name__ == "__main__":
    serve()
