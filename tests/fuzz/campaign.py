"""``make fuzz``: thousands of hostile library calls, command lines and files, each counted.

Cases (``api.py``: library calls; ``cases.py``: command lines, mutated files, folders) run
in worker processes (``worker.py``), many per process; a worker that dies takes only its
current case with it (a *crash*, then a new worker goes on), one that does not answer within
``--timeout`` is killed (a *hang*). Each answer is checked as a user would
see it: exit status 0 or 2; on 2, exactly one stderr line ``pushrecovery: error: ...``; no
traceback, no Python warning, and no NaN or infinity in the output; a batch over a folder
keeps every good trial (else *lost*). One summary line, the
failures in ``OUT/failures.jsonl`` (with their input files kept), exit status 1 on any.

Usage: ``python tests/fuzz/campaign.py [--cases 10000] [--seed 0] [--timeout 60]``.
"""

from __future__ import annotations

import argparse
import collections
import json
import queue
import random
import re
import shutil
import subprocess
import sys
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))

import cases as fuzz_cases

ROOT = Path(__file__).resolve().parents[2]
#: A NaN or an infinity printed as a value: not the key "inf" (N = ∞ steps) of ``bounds``,
#: which is followed by a colon (JSON) or a value (the table).
NUMBER = re.compile(r"(?<![\w.\"])-?(nan|NaN|inf|Inf|Infinity)(?![\w\"])(?!\s+\[)")
KINDS = ("crash", "hang", "traceback", "nan", "multiline", "warning", "exit", "lost", "accepted")


class Worker:
    """A worker process and the thread that reads its answers."""

    def __init__(self, log: Path) -> None:
        self.log = log.open("a")
        self.proc = subprocess.Popen(
            [sys.executable, str(Path(__file__).parent / "worker.py")],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            stderr=self.log,
            text=True,
            cwd=ROOT,
        )
        self.lines: queue.Queue[str | None] = queue.Queue()
        threading.Thread(target=self._read, daemon=True).start()

    def _read(self) -> None:
        assert self.proc.stdout is not None
        for line in self.proc.stdout:
            self.lines.put(line)
        self.lines.put(None)

    def ask(self, case: dict, timeout: float) -> tuple[str, dict | int | None]:
        """Return ("answer", result), ("crash", returncode) or ("hang", None)."""
        assert self.proc.stdin is not None
        try:
            self.proc.stdin.write(json.dumps(case) + "\n")
            self.proc.stdin.flush()
        except BrokenPipeError:
            return "crash", self.proc.wait()
        deadline = time.monotonic() + timeout
        while True:
            try:
                line = self.lines.get(timeout=max(0.0, deadline - time.monotonic()))
            except queue.Empty:
                self.proc.kill()
                return "hang", None
            if line is None:
                return "crash", self.proc.wait()
            message = json.loads(line)
            if "started" not in message:
                return "answer", message

    def close(self) -> None:
        if self.proc.poll() is None:
            assert self.proc.stdin is not None
            self.proc.stdin.close()
            try:
                self.proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                self.proc.kill()


class _NonFinite(Exception):
    """A NaN or an infinity among a JSON output's numbers."""


def _refuse(constant: str) -> None:
    raise _NonFinite(constant)


def nonfinite_output(out: str) -> bool:
    """Whether ``out`` prints a NaN or an infinity as a number.

    JSON is parsed (a message quoting "inf m" in a string is text, not a number); other output
    is searched with :data:`NUMBER`.
    """
    try:
        json.loads(out, parse_constant=_refuse)
    except _NonFinite:
        return True
    except ValueError:  # not JSON: a table or a summary
        return bool(NUMBER.search(out))
    return False


def problems(result: dict) -> list[str]:
    """What a user would call broken in one answer."""
    found = []
    code, err, out = result["code"], result["stderr"], result["stdout"]
    if result["escaped"] or "Traceback" in err:
        found.append("traceback")
    if code not in (0, 2, 130) and not result["escaped"]:  # an escaped error: a traceback
        found.append("exit")
    if code == 2 and not (err.count("\n") == 1 and err.startswith("pushrecovery: error: ")):
        found.append("multiline")
    if result["warnings"] or "Warning" in err:
        found.append("warning")
    if code == 0 and nonfinite_output(out):
        found.append("nan")
    if code == 0 and result.get("accepted"):  # a library call given what it cannot take
        found.append("accepted")
    return found


def keeps_good_trials(folder: Path, expect: int) -> bool:
    """Whether a batch over a folder kept its good trials: at least ``expect`` analysed."""
    try:
        summary = json.loads((folder / "out" / "summary.json").read_text())
    except (OSError, ValueError):
        return False
    return int(summary.get("analysed", 0)) >= expect


def generate(
    rng: random.Random,
    folder: Path,
    index: int,
    sources: list[Path],
    callables: list[str],
    api_share: float = 0.4,
) -> fuzz_cases.Case:
    draw = rng.random()
    if draw < api_share:  # a library call: the callable's name and the seed of its arguments
        name = rng.choice(callables)
        return fuzz_cases.Case(f"api:{name.split('.')[1]}", [name, str(rng.randrange(2**31))])
    draw = (draw - api_share) / (1.0 - api_share) if api_share < 1.0 else 0.0
    if draw < 0.45:
        return fuzz_cases.command_case(rng, folder)
    if draw < 0.6:
        return fuzz_cases.c3d_case(rng, folder, index, sources)
    if draw < 0.72:
        return fuzz_cases.csv_case(rng, folder, index)
    if draw < 0.84:
        return fuzz_cases.toml_case(rng, folder, index)
    if draw < 0.92:
        return fuzz_cases.mjcf_case(rng, folder, index)
    return fuzz_cases.folder_case(rng, folder, index)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=10_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--timeout", type=float, default=60.0, help="hang limit per case [s]")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--api", type=float, default=0.4, help="share of library calls")
    parser.add_argument("--only", default="", help="library calls of these prefixes (a,b,...)")
    parser.add_argument("--out", type=Path, default=ROOT / "out" / "fuzz")
    options = parser.parse_args()

    import api as fuzz_api
    import biomdp

    callables = sorted(fuzz_api.public())
    if options.only:
        callables = [n for n in callables if n.startswith(tuple(options.only.split(",")))]

    sources = sorted((Path(biomdp.__file__).parent / "tests" / "datasets").glob("*.c3d"))
    options.out = options.out.resolve()
    shutil.rmtree(options.out, ignore_errors=True)
    work, kept = options.out / "work", options.out / "inputs"
    work.mkdir(parents=True)
    kept.mkdir()
    todo: queue.Queue[int] = queue.Queue()
    for index in range(options.cases):
        todo.put(index)
    counts: collections.Counter[str] = collections.Counter()
    kinds: collections.Counter[str] = collections.Counter()
    slowest = [0.0, ""]
    failures = (options.out / "failures.jsonl").open("w")
    lock = threading.Lock()
    start = time.monotonic()

    def serve() -> None:
        log = options.out / f"worker-{threading.get_ident()}.log"
        worker = Worker(log)
        while True:
            try:
                index = todo.get_nowait()
            except queue.Empty:
                break
            # Each case from its own seed: the same cases whatever the threads' timing.
            folder = work / f"{index}"
            folder.mkdir()
            case = generate(
                random.Random(options.seed * 1_000_003 + index),
                folder,
                index,
                sources,
                callables,
                options.api,
            )
            began = time.monotonic()
            request: dict = {"id": index, "args": case.args, "cwd": str(folder)}
            if case.kind.startswith("api:"):
                request = {"id": index, "api": case.args[0], "seed": int(case.args[1]),
                           "cwd": str(folder)}  # fmt: skip
            status, answer = worker.ask(request, options.timeout)
            spent = time.monotonic() - began
            found = (
                problems(answer) if status == "answer" and isinstance(answer, dict) else [status]
            )
            if case.expect is not None and not found and not keeps_good_trials(folder, case.expect):
                found.append("lost")
            if case.invalid and not found and answer.get("code") == 0:
                found.append("accepted")  # e.g. --duration nan ran
            if status != "answer":
                worker.close()
                worker = Worker(log)
            with lock:
                kinds[case.kind] += 1
                if spent > slowest[0]:
                    slowest[:] = [spent, " ".join(case.args)[:120]]
                for kind in found:
                    counts[kind] += 1
                if found:
                    for arg in case.args:
                        if arg.startswith(str(folder)) and Path(arg).is_file():
                            shutil.copy(arg, kept / f"{index}-{Path(arg).name}")
                    record = {"id": index, "problems": found, "args": case.args}
                    if isinstance(answer, dict):
                        record.update(answer)
                    else:
                        record["returncode"] = answer
                    failures.write(json.dumps(record) + "\n")
                    failures.flush()
            shutil.rmtree(folder, ignore_errors=True)  # the case's files and outputs
        worker.close()

    broken: list[str] = []  # the campaign's own errors: a fuzzer that stops early fails

    def guarded() -> None:
        try:
            serve()
        except Exception as exc:
            broken.append(f"{type(exc).__name__}: {exc}")

    threads = [threading.Thread(target=guarded) for _ in range(options.workers)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    failures.close()
    shutil.rmtree(work, ignore_errors=True)
    total = sum(kinds.values())
    classes = ", ".join(f"{k} {v}" for k, v in sorted(kinds.items()))
    bad = sum(counts.values())
    print(
        f"fuzz: {total} cases in {time.monotonic() - start:.0f} s "
        f"(seed {options.seed}; {classes}): "
        + ", ".join(f"{counts[k]} {k}" for k in KINDS)
        + f"; slowest {slowest[0]:.1f} s ({slowest[1]})"
        + (f"; details in {options.out / 'failures.jsonl'}" if bad else "")
    )
    if broken or total != options.cases:
        print(f"fuzz: the campaign itself failed ({total} of {options.cases} cases): {broken}")
        return 2
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
