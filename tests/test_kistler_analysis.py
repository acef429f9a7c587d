"""The real Kistler quiet-standing trial shipped by biomdp, analysed end to end."""

import json
import pathlib

import biomdp
import numpy as np

from pushrecovery.cli import main

KISTLER = pathlib.Path(biomdp.__file__).parent / "tests" / "datasets" / "kistler_COP.c3d"


def test_quiet_standing_needs_the_ankle_throughout(tmp_path, capsys):
    main_args = ["analyze", str(KISTLER), "--out", str(tmp_path / "k"), "--json", "--no-plot"]
    try:
        main(main_args)
    except SystemExit as exc:
        assert exc.code == 0
    summary = json.loads(capsys.readouterr().out)
    # Force plates only: the mass is the mean vertical force / g (the vendor's export gives a
    # body weight of 667.6 N), the CoM comes from zero-point integration.
    assert summary["body"]["mass_source"].startswith("force plates")
    assert abs(summary["body"]["mass"] * 9.81 - 667.6) < 2.0
    assert summary["com_source"].startswith("zero-point")
    assert summary["frames"] == 10000 and summary["valid_frames"] > 9000
    # Every analysed frame, in both directions, needs the ankle only.
    for axis in ("ap", "ml"):
        times = summary["directions"][axis]["time_in_strategy"]
        assert times["hip"] == times["step"] == times["fall"] == 0.0
        assert summary["directions"][axis]["min_margin"]["cop"]["value"] > 0.02
    assert summary["strategy"]["time_in_strategy"]["ankle"] == summary["valid_frames"] / 1000.0
    assert summary["step_events"] == []
    # Quiet standing: the CoP sways about the CoM, wider than it (the CoP drives the CoM).
    import pyarrow.parquet as pq

    frames = pq.read_table(tmp_path / "k" / "frames.parquet").to_pydict()
    for axis in ("ap", "ml"):
        com = np.array(frames[f"{axis}_com"], dtype=float)
        cop = np.array(frames[f"{axis}_cop"], dtype=float)
        both = np.isfinite(com) & np.isfinite(cop)
        assert abs(np.mean(com[both]) - np.mean(cop[both])) < 0.002
        assert 0.2 < np.std(com[both]) / np.std(cop[both]) < 1.0
