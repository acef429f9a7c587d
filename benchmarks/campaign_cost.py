"""The fixed cost of a small campaign run in-process, against the bare import, in the same run.

``pushrecovery campaign ... --workers 1 --no-plot --json`` of a handful of pushes (3) for
three pairs: ``pendulum`` + ``ankle-saturated`` (the one-push loop), ``pendulum`` +
``ankle-pd`` (a compiled pair; a campaign this small runs the one-push loop) and ``stepping``
+ ``recovery`` (the compiled loop, the MPC and numba's kernels), against
``python -c "import pushrecovery"``. Each of :data:`REPEAT` rounds runs the import and then
each campaign once, one after the other, so that a busy machine slows both alike; the fixed
cost of a round is its campaign's wall time minus its import's. Reported: the median and the
largest of the rounds (never the best), wall and CPU time (user + system of the child).
Target: median fixed cost <= 1.5 s.
"""

from __future__ import annotations

import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPEAT = 7
TARGET = 1.5  # [s] above the bare import
CASES = {
    "pendulum + ankle-saturated": ["--model", "pendulum", "--controller", "ankle-saturated"],
    "pendulum + ankle-pd": ["--model", "pendulum", "--controller", "ankle-pd"],
    "stepping + recovery": ["--model", "stepping", "--controller", "recovery"],
}
PUSHES = ["--x0", "0", "0.05", "0.05", "--xdot", "0.2", "0.4", "0.2"]  # 2 x 2 = 4 pushes


def _timed(command: list[str]) -> tuple[float, float]:
    """Return the wall and CPU time [s] of running ``command`` to its end."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def main() -> int:
    exe = str(Path(sys.executable).with_name("pushrecovery"))
    root = Path(tempfile.mkdtemp(prefix="pushrecovery-cost-"))
    fixed: dict[str, list[tuple[float, float]]] = {name: [] for name in CASES}
    imports: list[tuple[float, float]] = []
    try:
        for k in range(REPEAT):
            bare = _timed([sys.executable, "-c", "import pushrecovery"])
            imports.append(bare)
            for name, args in CASES.items():
                out = root / f"{k}-{name.split()[0]}-{name.split()[-1]}"
                command = [exe, "campaign", *args, *PUSHES, "--workers", "1", "--no-plot"]
                wall, cpu = _timed([*command, "--json", "--out", str(out)])
                fixed[name].append((wall - bare[0], cpu - bare[1]))
                shutil.rmtree(out, ignore_errors=True)
    finally:
        shutil.rmtree(root, ignore_errors=True)
    walls = [w for w, _ in imports]
    print(
        f"campaign fixed cost ({REPEAT} rounds, 4 pushes, --workers 1 in-process, --no-plot): "
        f"bare import median {statistics.median(walls) * 1e3:.0f} ms, max {max(walls) * 1e3:.0f} ms"
    )
    failed = False
    for name, pairs in fixed.items():
        wall = [w for w, _ in pairs]
        cpu = [c for _, c in pairs]
        median = statistics.median(wall)
        ratio = statistics.median(
            (w + b[0]) / b[0] for (w, _), b in zip(pairs, imports, strict=True)
        )
        failed = failed or median > TARGET
        print(
            f"  {name}: + {median:.2f} s wall (max {max(wall):.2f} s; {ratio:.0f}x the "
            f"import), + {statistics.median(cpu):.2f} s CPU (max {max(cpu):.2f} s); "
            f"target <= {TARGET:g} s: {'met' if median <= TARGET else 'MISSED'}"
        )
    return int(failed)


if __name__ == "__main__":
    sys.exit(main())
