"""Run ezc3d where its crash or hang cannot take the caller down: a helper process.

ezc3d is C++ and trusts the file. The Python walk of the parameter section
(:mod:`.structure`) refuses what we know crashes it, but ``make fuzz`` still finds byte
mutations on which it ends the process with SIGSEGV or reads for a minute before giving up
(docs/reliability.md). So files are parsed by a helper process, ``python -m
pushrecovery.analysis.c3d.server``, started on the first read and kept for the next ones
(its imports are paid once). A helper that dies takes only the current file with it; one
that overruns its time is killed; the next read starts a new one. A fresh interpreter, not
``multiprocessing``: no fork of a multi-threaded caller, and a user's script without an
``if __name__ == "__main__"`` guard is not run again in the child.

POSIX only (``select`` on the helper's pipe), as the rest of the project's tooling.

Protocol: 8-byte big-endian length, then a pickle; requests ``(module, function, args)``,
answers ``(ok, value)`` (the value, or the exception the function raised).
"""

from __future__ import annotations

import atexit
import os
import pickle
import select
import subprocess
import sys
import threading
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any, TypeVar

from pushrecovery.arguments import require_type
from pushrecovery.errors import InputFileError, ParameterTypeError

__all__ = ["READ_SECONDS_PER_MB", "READ_TIMEOUT", "read_message", "run_isolated", "write_message"]

T = TypeVar("T")

#: Shortest time a file may take to parse [s], and the allowance per MB above it: the
#: largest real trial we read (a 3 MB Vicon file) takes 0.5 s.
READ_TIMEOUT = 10.0
READ_SECONDS_PER_MB = 2.0


def write_message(stream: IO[bytes], message: Any) -> None:
    """Write one length-prefixed pickle."""
    if not callable(getattr(stream, "write", None)):
        raise ParameterTypeError(f"stream must be a binary stream, got {type(stream).__name__}")
    data = pickle.dumps(message, protocol=pickle.HIGHEST_PROTOCOL)
    stream.write(len(data).to_bytes(8, "big") + data)
    stream.flush()


def read_message(stream: IO[bytes]) -> Any:
    """Read one length-prefixed pickle (EOFError at the end of the stream)."""
    if not callable(getattr(stream, "read", None)):
        raise ParameterTypeError(f"stream must be a binary stream, got {type(stream).__name__}")
    head = stream.read(8)
    if len(head) < 8:
        raise EOFError
    data = stream.read(int.from_bytes(head, "big"))
    return pickle.loads(data)


class _Helper:
    """The helper process, started on demand; one request at a time."""

    def __init__(self) -> None:
        self.lock = threading.Lock()
        self.process: subprocess.Popen[bytes] | None = None

    def start(self) -> subprocess.Popen[bytes]:
        if self.process is None or self.process.poll() is not None:
            # The helper imports this very package, even one put on sys.path at run time.
            root = str(Path(__file__).resolve().parents[3])
            paths = [root, *filter(None, os.environ.get("PYTHONPATH", "").split(os.pathsep))]
            self.process = subprocess.Popen(
                [sys.executable, "-m", "pushrecovery.analysis.c3d.server"],
                stdin=subprocess.PIPE,
                stdout=subprocess.PIPE,
                stderr=subprocess.DEVNULL,  # ezc3d's own messages: the user gets one line
                env={**os.environ, "PYTHONPATH": os.pathsep.join(paths)},
            )
        return self.process

    def stop(self) -> None:
        process, self.process = self.process, None
        if process is None:
            return
        if process.poll() is None:
            process.kill()
            process.wait()
        for stream in (process.stdin, process.stdout):
            if stream is not None:
                stream.close()

    def ask(self, request: Any, timeout: float) -> tuple[str, Any]:
        """Return ("answer", message), ("crash", exit code) or ("timeout", None)."""
        with self.lock:
            process = self.start()
            assert process.stdin is not None and process.stdout is not None
            try:
                write_message(process.stdin, request)
            except BrokenPipeError:
                code = process.wait()
                self.stop()
                return "crash", code
            ready, _, _ = select.select([process.stdout], [], [], timeout)
            if not ready:
                self.stop()
                return "timeout", None
            try:
                return "answer", read_message(process.stdout)
            except EOFError:
                code = process.wait()
                self.stop()
                return "crash", code


_HELPER = _Helper()
atexit.register(_HELPER.stop)


def run_isolated(function: Callable[..., T], args: tuple[Any, ...], file: Path) -> T:
    """Return ``function(*args)`` computed by the helper process while it reads ``file``.

    Parameters
    ----------
    function : callable
        A module-level function (the helper imports it by module and name).
    args : tuple
        Its arguments (pickled).
    file : Path
        The file being read: named in the errors; its size sets the time allowed,
        :data:`READ_TIMEOUT` + :data:`READ_SECONDS_PER_MB` per MB.

    Raises
    ------
    InputFileError
        If the helper dies on the file (a crash of the C3D reader) or does not finish in time;
        the function's own errors are raised as they are.
    """
    if not callable(function) or not isinstance(args, tuple):
        raise ParameterTypeError("function must be callable and args a tuple")
    require_type("file", file, Path)
    timeout = READ_TIMEOUT + READ_SECONDS_PER_MB * os.path.getsize(file) / 1e6
    status, answer = _HELPER.ask((function.__module__, function.__qualname__, args), timeout)
    if status == "timeout":
        raise InputFileError(
            f"{file}: the C3D reader did not finish within {timeout:.0f} s (a malformed file)"
        )
    if status == "crash":
        raise InputFileError(
            f"{file}: the C3D reader crashed on this file (exit {answer}: a malformed file)"
        )
    ok, value = answer
    if not ok:
        raise value
    return value
