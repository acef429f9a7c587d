"""Issue 16's reproducible examples: one-line errors, exit 2, no traceback, no crash, no hang.

The files are copies of ``../shared/fixtures/malformed``: two byte mutations of biomdp's
Kistler C3D files that made ezc3d end the process with SIGSEGV, and a TOML nested 3000
tables deep. The C3D examples run in a subprocess (a regression would otherwise take pytest
down with it); the timeout only guards against a hang.
"""

from __future__ import annotations

import os
import stat
import subprocess
import sys
import warnings
from pathlib import Path

import pytest

from conftest import AS_FROM_A_TERMINAL

DATA = Path(__file__).parent / "data"
HANG = 60.0  # [s] a guard, not a speed test: every case below returns within about a second


def _one_line_error(code: int, stderr: str, words: str) -> None:
    assert code == 2, stderr
    assert stderr.count("\n") == 1 and stderr.startswith("pushrecovery: error: "), stderr
    assert "Traceback" not in stderr and "Warning" not in stderr
    assert words in stderr


@pytest.mark.parametrize(
    ("name", "words"),
    [
        ("segfault-kistler-cop.c3d", "missing ANALOG:OFFSET"),
        ("segfault-kistler-dj-2plates.c3d", "parameter 'UNITS' with 171 dimensions"),
    ],
)
def test_c3d_files_that_crashed_ezc3d_are_refused(name: str, words: str, tmp_path: Path) -> None:
    run = subprocess.run(
        [sys.executable, "-m", "pushrecovery", "analyze", str(DATA / name), "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=HANG,
        env={**os.environ, "PYTHONWARNINGS": "default"},
    )
    _one_line_error(run.returncode, run.stderr, words)
    assert str(DATA / name) in run.stderr


@pytest.mark.parametrize(
    ("args", "words"),
    [
        (["bounds", "--gravity", "1e15", "--json"], "gravity must be in [0.1, 100] [m/s^2]"),
        (
            ["simulate", "--model", "flywheel", "--controller", "mpc", "--option", "horizon=3000"],
            "horizon must be an integer in [1, 200], got 3000",
        ),
        (
            [
                "critical-push",
                "--model",
                "pendulum",
                "--controller",
                "ankle-pd",
                "--kd",
                "0",
                "--duration",
                "9999",
            ],
            "duration must be in (0, 60] s",
        ),
        (["bounds", "--params", str(DATA / "deeply-nested.toml")], "nested too deeply"),
        (
            [
                "campaign",
                "--scheduler",
                "tcp://",
                "--out",
                "OUT",
                "--x0",
                "0",
                "0",
                "1",
                "--xdot",
                "0",
                "1",
                "0.5",
            ],
            "--scheduler must be an address such as tcp://HOST:PORT",
        ),
        (["step", "--v0", "1e300"], "v0 must satisfy |v0| < 10 sqrt(g L)"),
        (
            ["step", "--v0-range", "0.717", "2.67", "0.5", "--leg-length", "1e300"],
            "leg_length must be in [0.01, 10] [m]",
        ),
        (["simulate", "--xdot", "1e300"], "xdot must satisfy |xdot| < 10 sqrt(g L)"),
    ],
)
def test_the_issues_examples_are_one_line_errors(
    args: list[str], words: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from pushrecovery.cli import main

    args = [str(tmp_path / "out") if a == "OUT" else a for a in args]
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a numerical warning fails the case
        with pytest.raises(SystemExit) as exit_info:
            main(args)
    _one_line_error(int(exit_info.value.code or 0), capsys.readouterr().err, words)


def _cli_error(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str]:
    from pushrecovery.cli import main

    with pytest.raises(SystemExit) as exit_info:
        main(args)
    return int(exit_info.value.code or 0), capsys.readouterr().err


def test_a_fifo_is_refused_without_blocking(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    fifo = tmp_path / "params.toml"
    os.mkfifo(fifo)  # opening it for reading would block until a writer comes
    assert stat.S_ISFIFO(fifo.stat().st_mode)
    _one_line_error(*_cli_error(["bounds", "--params", str(fifo)], capsys), "not a regular file")


def test_a_parameter_file_over_64_kib_is_refused(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    big = tmp_path / "big.toml"
    big.write_text("# padding\n" * 7000 + "mass = 70.0\n")
    _one_line_error(*_cli_error(["bounds", "--params", str(big)], capsys), "larger than 64 KiB")


def test_a_c3d_file_that_crashes_ezc3d_costs_one_line_not_the_process(tmp_path: Path) -> None:
    """A mutation found by make fuzz (seed 3, case 830) that passes the structural checks.

    ezc3d ends its process with SIGSEGV on it; the helper process takes the crash.
    """
    from pushrecovery import InputFileError
    from pushrecovery.analysis.c3d import read_c3d

    path = DATA / "fuzz-segfault-kistler.c3d"
    with pytest.raises(InputFileError, match="the C3D reader crashed on this file"):
        read_c3d(path)
    # The next read gets a new helper.
    good = Path(__import__("biomdp").__file__).parent / "tests" / "datasets" / "kistler_COP.c3d"
    assert len(read_c3d(good).plates) == 1


def test_ctrl_c_stops_a_campaign_with_one_line_and_no_worker_traceback(tmp_path: Path) -> None:
    """SIGINT reaches the whole process group, as Ctrl-C does: only the parent reports it."""
    import signal
    import time

    out = tmp_path / "campaign"
    args = ["campaign", "--x0", "0", "0.1", "0.02", "--xdot", "-3", "3", "0.05"]
    process = subprocess.Popen(
        [
            sys.executable,
            *AS_FROM_A_TERMINAL,
            *args,
            "--out",
            str(out),
            "--no-plot",
            "--batch-size",
            "5",
            "--workers",
            "2",
        ],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
    )
    began = time.monotonic()
    while not (out / "batches").exists() and time.monotonic() - began < HANG:
        time.sleep(0.05)
    time.sleep(1.0)  # the workers are running pushes
    os.killpg(process.pid, signal.SIGINT)
    _, err = process.communicate(timeout=HANG)
    lines = [line for line in err.splitlines() if line.strip()]
    assert process.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err
    assert lines == [
        f"pushrecovery: interrupted; the finished batches are in {out}; rerun with --resume "
        "to complete the campaign"
    ]


def test_a_trial_without_a_valid_frame_plots_without_warnings(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """make fuzz (seed 0, case 463): an All-NaN median and empty legends warned."""
    from pushrecovery.cli import main

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SystemExit) as exit_info:
            main(["analyze", str(DATA / "fuzz-no-valid-frame-kistler.c3d"), "--out", str(tmp_path)])
    assert exit_info.value.code in (0, None), capsys.readouterr().err
    assert (tmp_path / "time_series.png").is_file()
