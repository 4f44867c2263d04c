"""Read the tables that `rubber-atlas trajectory` and `rubber-atlas diagram --out` write.

Both formats hold the same columns: CSV (comment lines `# key: value`, a header, rows) and
HDF5 (one 1-D dataset per column with `units` and `long_name`, string attributes on the root).
"""
from __future__ import annotations

import json
from pathlib import Path

import numpy as np


def read_table(path: str | Path) -> tuple[dict[str, np.ndarray], dict[str, str]]:
    """Return (columns, attributes) of a CSV or HDF5 table written by rubber-atlas."""
    path = Path(path)
    if path.suffix.lower() == ".csv":
        attrs: dict[str, str] = {}
        with path.open() as f:
            lines = f.read().splitlines()
        body = []
        for line in lines:
            if line.startswith("# "):
                key, _, value = line[2:].partition(": ")
                attrs[key] = value
            else:
                body.append(line)
        header = body[0].split(",")
        data = np.array([[float(x) for x in row.split(",")] for row in body[1:]], dtype=float)
        data = data.reshape(-1, len(header))
        return {name: data[:, i] for i, name in enumerate(header)}, attrs
    import h5py

    with h5py.File(path, "r") as f:
        columns = {name: f[name][()] for name in f.keys()}
        attrs = {k: (v.decode() if isinstance(v, bytes) else str(v)) for k, v in f.attrs.items()}
    return columns, attrs


def critical_set(path: str | Path) -> dict:
    """The JSON summary of the critical set stored with a diagram file."""
    _, attrs = read_table(path)
    return json.loads(attrs["critical_set_json"])
