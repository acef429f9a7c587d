"""Rows into Arrow tables and Arrow columns into numpy, without pyarrow's pandas integration.

``pyarrow.Table.from_pylist``, ``pyarrow.array`` and ``to_numpy`` import pandas (about 0.4 s,
a third of a small campaign's fixed cost) to look for pandas objects among the values. A
campaign's columns are four plain types (:data:`~.rows.COLUMNS`), so these functions build
the Arrow buffers from numpy arrays (and read them back) themselves; the values are the same
to the bit as ``from_pylist`` 's.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

from pushrecovery.arguments import require_type
from pushrecovery.errors import InvalidParameterError, ParameterTypeError

__all__ = ["column_array", "table_of_rows"]

#: Arrow's string type indexes its bytes with int32 offsets.
_MAX_STRING_BYTES = 2**31 - 1


def _array(values: Sequence[Any], arrow_type: Any, name: str) -> Any:
    """Return ``values`` (Python or numpy scalars, None for null) as an Arrow array."""
    import pyarrow as pa

    count = len(values)
    nulls = sum(1 for v in values if v is None) if None in values else 0
    validity = None
    if nulls:
        valid = np.fromiter((v is not None for v in values), dtype=np.bool_, count=count)
        validity = pa.py_buffer(np.packbits(valid, bitorder="little"))
    if pa.types.is_string(arrow_type):
        encoded = [b"" if v is None else str(v).encode() for v in values]
        lengths = np.fromiter((len(b) for b in encoded), dtype=np.int64, count=count)
        ends = np.cumsum(lengths)
        if count and int(ends[-1]) > _MAX_STRING_BYTES:
            raise InvalidParameterError(f"column {name} holds more than 2 GiB of text")
        offsets = np.zeros(count + 1, dtype=np.int32)
        offsets[1:] = ends
        buffers = [validity, pa.py_buffer(offsets), pa.py_buffer(b"".join(encoded))]
        return pa.Array.from_buffers(arrow_type, count, buffers, null_count=nulls)
    dtypes = {"bool": np.bool_, "double": np.float64, "int64": np.int64}
    dtype = dtypes.get(str(arrow_type))
    if dtype is None:
        raise InvalidParameterError(f"column {name} has type {arrow_type}, not a row column's")
    if nulls:  # a null's slot holds 0 (masked by the validity bitmap)
        values = [0 if v is None else v for v in values]
    data: np.ndarray = np.array(values, dtype=dtype) if count else np.zeros(0, dtype=dtype)
    if dtype is np.bool_:
        data = np.packbits(data, bitorder="little")
    return pa.Array.from_buffers(
        arrow_type, count, [validity, pa.py_buffer(data)], null_count=nulls
    )


def table_of_rows(rows: Sequence[Mapping[str, Any]], schema: Any) -> Any:
    """Return ``rows`` (mappings from column name to value) as a table with ``schema``.

    Parameters
    ----------
    rows : sequence of mapping
        One mapping per row; a column a row lacks is null.
    schema : pyarrow.Schema
        The columns (float64, int64, string or bool), as :func:`~.rows.row_schema` gives.

    Returns
    -------
    pyarrow.Table
        What ``pyarrow.Table.from_pylist(rows, schema=schema)`` gives.

    Raises
    ------
    InvalidParameterError
        Naming the column, for a type other than those four or more than 2 GiB of text.
    """
    if (
        isinstance(rows, str)
        or not isinstance(rows, Sequence)
        or not all(isinstance(r, Mapping) for r in rows)
    ):
        raise ParameterTypeError("rows must be a list of mappings (column to value)")
    import pyarrow as pa

    require_type("schema", schema, pa.Schema)
    keys = list(rows[0]) if rows else []
    if all(list(row) == keys for row in rows):  # one key order (a batch's rows): transpose
        found = dict(zip(keys, zip(*(row.values() for row in rows), strict=True), strict=True))
        nothing = (None,) * len(rows)
        values: list[Sequence[Any]] = [found.get(name, nothing) for name in schema.names]
    else:
        values = [[row.get(name) for row in rows] for name in schema.names]
    columns = [
        _array(column, field.type, field.name) for column, field in zip(values, schema, strict=True)
    ]
    return pa.Table.from_arrays(columns, schema=schema)


def _bits(buffer: Any, offset: int, count: int) -> np.ndarray:
    """Return ``count`` bits of an Arrow bitmap from bit ``offset`` as booleans."""
    raw = np.frombuffer(buffer, dtype=np.uint8)
    return np.unpackbits(raw, bitorder="little")[offset : offset + count].astype(np.bool_)


def _chunk_array(chunk: Any) -> np.ndarray:
    import pyarrow as pa

    kind, count, offset = chunk.type, len(chunk), chunk.offset
    if pa.types.is_string(kind) or pa.types.is_null(kind):
        return np.array(chunk.to_pylist(), dtype=object)
    validity, data = chunk.buffers()[:2]
    valid = None if validity is None or not chunk.null_count else _bits(validity, offset, count)
    if pa.types.is_boolean(kind):
        bits = _bits(data, offset, count)
        if valid is None:
            return bits
        found = bits.astype(object)
        found[~valid] = None
        return found
    if not (pa.types.is_float64(kind) or pa.types.is_int64(kind)):
        raise InvalidParameterError(f"a column of type {kind} is not a row column's")
    dtype = np.float64 if pa.types.is_float64(kind) else np.int64
    values = np.frombuffer(data, dtype=dtype, count=offset + count)[offset:].copy()
    if valid is None:
        return values
    values = values.astype(np.float64)  # as pyarrow's to_numpy: nulls are NaN
    values[~valid] = np.nan
    return values


def column_array(table: Any, name: str) -> np.ndarray:
    """Return column ``name`` of ``table`` as numpy, as ``to_numpy(zero_copy_only=False)``.

    float64 and int64 columns give their dtype (NaN for nulls, as float64), bool columns
    ``bool`` (objects with None for nulls), strings objects (None for nulls).

    Raises
    ------
    InvalidParameterError
        Naming ``name``: not a column of ``table``, or of a type no row column has.
    """
    if not hasattr(table, "column_names"):
        raise ParameterTypeError(f"table must be a pyarrow table, got {type(table).__name__}")
    require_type("name", name, str)
    if name not in table.column_names:
        raise InvalidParameterError(f"name must be a column of the table, got {name!r}")
    chunks = table.column(name).chunks
    if not chunks:
        return _chunk_array(table.column(name).combine_chunks())
    parts = [_chunk_array(chunk) for chunk in chunks]
    return parts[0] if len(parts) == 1 else np.concatenate(parts)
