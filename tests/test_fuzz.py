"""``make fuzz`` at small N with a fixed seed (issue 38): library calls and command lines.

The campaign (``tests/fuzz/campaign.py``) draws 200 cases from seed 0: four in five are calls
of the public functions and classes of every floor (``tests/fuzz/api.py``), the rest command
lines, mutated files and folders of trials. Every case
must end in a result or one named line: no crash, hang, traceback, NaN for finite inputs,
multi-line error, warning or good trial lost. ``make fuzz`` runs 10,000 cases of every floor.
"""

import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_a_small_fixed_seed_campaign_finds_nothing(tmp_path):
    done = subprocess.run(
        [sys.executable, str(ROOT / "tests" / "fuzz" / "campaign.py"), "--cases", "200",
         "--seed", "0", "--api", "0.8", "--timeout", "60", "--workers", "1",
         "--out", str(tmp_path / "fuzz")],
        capture_output=True, text=True, cwd=ROOT, check=False,
    )  # fmt: skip
    failures = tmp_path / "fuzz" / "failures.jsonl"
    found = failures.read_text()[:3000] if failures.exists() else ""
    assert done.returncode == 0, done.stdout + done.stderr[-2000:] + found
    assert "0 crash, 0 hang, 0 traceback, 0 nan, 0 multiline, 0 warning, 0 exit" in done.stdout
