"""Rows into Arrow and columns back to numpy without pyarrow's pandas path (campaign/arrow.py)."""

from __future__ import annotations

import io
import math
import subprocess
import sys

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import pytest

from pushrecovery import InvalidParameterError
from pushrecovery.campaign.arrow import column_array, table_of_rows

SCHEMA = pa.schema(
    [("f", pa.float64()), ("i", pa.int64()), ("s", pa.string()), ("b", pa.bool_()),
     ("fn", pa.float64()), ("in", pa.int64()), ("sn", pa.string()), ("bn", pa.bool_())]
)  # fmt: skip
ROWS = [
    {"f": 0.1, "i": 3, "s": "ankle", "b": True, "fn": None, "in": None, "sn": None,
     "bn": None},
    {"f": math.nan, "i": -1, "s": "", "b": False, "fn": -0.0, "in": 2**62, "sn": "ψ 30 °",
     "bn": False},
    {"f": np.float64(1e-300), "i": np.int64(7), "s": "the physics diverged: x", "b": np.True_,
     "fn": math.inf, "in": 0, "sn": "", "bn": True},
    {"f": -2.5, "i": 0, "s": "fell", "b": True},  # the null columns left out
]  # fmt: skip


def _parquet(table: pa.Table) -> bytes:
    sink = io.BytesIO()
    pq.write_table(table, sink)
    return sink.getvalue()


@pytest.mark.parametrize("rows", [ROWS, ROWS[:3], ROWS[3:]])  # mixed keys; one key order
@pytest.mark.parametrize("extra", [False, True])  # a column no row has: all null
def test_rows_become_the_table_from_pylist_gives(rows: list, extra: bool) -> None:
    schema = SCHEMA.append(pa.field("z", pa.int64(), metadata={"unit": "-"})) if extra else SCHEMA
    ours = table_of_rows(rows, schema)
    theirs = pa.Table.from_pylist(rows, schema=schema)
    assert ours.schema.equals(theirs.schema, check_metadata=True)
    assert repr(ours.to_pylist()) == repr(theirs.to_pylist())  # NaN, -0.0 and None included
    assert [c.null_count for c in ours.columns] == [c.null_count for c in theirs.columns]
    assert _parquet(ours) == _parquet(theirs)
    assert table_of_rows([], schema).num_rows == 0


def test_columns_come_back_as_to_numpy_gives() -> None:
    table = pa.Table.from_pylist(ROWS, schema=SCHEMA)
    for t in (table, table.slice(1, 2), pa.concat_tables([table.slice(0, 1), table.slice(1)])):
        for name in SCHEMA.names:
            ours, theirs = column_array(t, name), t.column(name).to_numpy(zero_copy_only=False)
            assert ours.dtype == theirs.dtype, name
            assert repr(ours.tolist()) == repr(theirs.tolist()), name


def test_neither_way_imports_pandas() -> None:
    code = (
        "import sys, pyarrow as pa\n"
        "from pushrecovery.campaign.arrow import column_array, table_of_rows\n"
        "from pushrecovery.campaign.rows import row_schema\n"
        "t = table_of_rows([{'x0': 0.1, 'outcome': 'fell', 'predicted_recovers': True}],"
        " row_schema('planar'))\n"
        "[column_array(t, n) for n in t.column_names]\n"
        "sys.exit('pandas' in sys.modules)\n"
    )
    assert subprocess.run([sys.executable, "-c", code], check=False).returncode == 0


def test_bad_columns_are_refused_by_name() -> None:
    with pytest.raises(InvalidParameterError, match="column d has type"):
        table_of_rows([{"d": 1.0}], pa.schema([("d", pa.float32())]))
    table = pa.table({"d": pa.array([1.0], pa.float32())})
    with pytest.raises(InvalidParameterError, match="type float"):
        column_array(table, "d")
    with pytest.raises(InvalidParameterError, match="name must be a column"):
        column_array(table, "x0")
