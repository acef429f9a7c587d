"""Write an analysed trial: the frames, the data-quality table and ``summary.json``."""

from __future__ import annotations

import json
import math
import os
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from pushrecovery.arguments import output_folder, require_type
from pushrecovery.extras import require

if TYPE_CHECKING:  # the trial's summary serialises itself with json_safe
    from pushrecovery.analysis.trial import TrialAnalysis

__all__ = ["FRAME_FILES", "QUALITY_FILES", "SUMMARY_FILE", "json_safe", "write_analysis"]

#: Per-frame tables written into the output directory.
FRAME_FILES = ("frames.parquet", "frames.csv")
#: The data-quality table written into the output directory (docs/analysis.md, "Data checks").
QUALITY_FILES = ("quality.parquet", "quality.csv")
#: The summary written into the output directory.
SUMMARY_FILE = "summary.json"


def json_safe(value: Any) -> Any:
    """Plain Python values, non-finite floats as None (JSON has no NaN or infinity)."""
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {key: json_safe(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [json_safe(item) for item in value]
    return value


def write_analysis(analysis: TrialAnalysis, out_dir: str | Path) -> dict[str, Path]:
    """Write the frames and the data-quality table (Parquet and CSV) and the summary (JSON).

    Columns of the frame tables are those of :attr:`TrialAnalysis.columns` (docs/analysis.md):
    lengths in m, velocities in m/s, times in s; missing values are empty in the CSV and null
    in Parquet; a time to leave of +inf (never) is written as ``inf``. The data-quality table
    has one row per check and what it checked
    (:meth:`~pushrecovery.analysis.trial.checks.DataChecks.quality_rows`).

    Returns
    -------
    dict
        ``frames_parquet``, ``frames_csv``, ``quality_parquet``, ``quality_csv`` and
        ``summary`` paths.
    """
    require("analysis", "pyarrow", "writing an analysis")
    import pyarrow as pa
    import pyarrow.csv as pacsv
    import pyarrow.parquet as pq

    from pushrecovery.analysis.trial import TrialAnalysis

    require_type("analysis", analysis, TrialAnalysis)
    out = output_folder("out_dir", out_dir)
    table = analysis.to_arrow()
    paths = {
        "frames_parquet": out / FRAME_FILES[0],
        "frames_csv": out / FRAME_FILES[1],
        "summary": out / SUMMARY_FILE,
    }
    # Dictionary pages for the text columns only: the numbers' dictionaries cost more than half
    # the write (10,000 frames: 22 -> 9 ms) and make the file larger; the values are the same.
    text = [f.name for f in table.schema if pa.types.is_string(f.type)]
    _atomic(paths["frames_parquet"], lambda p: pq.write_table(table, p, use_dictionary=text))
    _atomic(paths["frames_csv"], lambda p: pacsv.write_csv(table, p))
    quality = _quality_table(analysis)
    paths["quality_parquet"] = out / QUALITY_FILES[0]
    paths["quality_csv"] = out / QUALITY_FILES[1]
    _atomic(paths["quality_parquet"], lambda p: pq.write_table(quality, p))
    _atomic(paths["quality_csv"], lambda p: pacsv.write_csv(quality, p))
    summary = json.dumps(analysis.summary.to_dict(), indent=2, allow_nan=False)
    _atomic(paths["summary"], lambda p: p.write_text(summary + "\n"))
    return paths


def _quality_table(analysis: TrialAnalysis) -> Any:
    """Return the data-quality rows as a typed Arrow table (QUALITY_FIELDS)."""
    import pyarrow as pa

    from pushrecovery.analysis.trial.checks import QUALITY_FIELDS

    types = {"str": pa.string(), "int": pa.int64(), "float": pa.float64(), "bool": pa.bool_()}
    schema = pa.schema([(name, types[kind.split(" ")[0]]) for name, kind in QUALITY_FIELDS])
    rows = json_safe(analysis.summary.checks.quality_rows())
    return pa.Table.from_pylist(rows, schema=schema)


def _atomic(path: Path, write: Any) -> None:
    """Write through a temporary file, so a reader never sees half a file."""
    temporary = path.with_name(f".{path.name}.tmp")
    write(temporary)
    os.replace(temporary, path)
