"""CSV histories (monitors, fracture degree, energy) and the JSON run summary.

CSV headers carry units, ``name [unit]`` (``time [s]``, ``m1:sxx [Pa]``, ``kinetic [J/m]``, ``D [-]``);
the in-memory column names (:attr:`CsvHistory.columns`) have none. :func:`read_csv` and
:func:`strip_unit` read such a file back by the bare names. Files are written atomically
(io/atomic.py). ``summary.json`` is strict JSON: a value that does not exist (NaN, ±inf) is ``null``.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from collections.abc import Callable
from pathlib import Path

import numpy as np

from .atomic import write_text_atomic

_UNIT = re.compile(r"\s*\[[^\[\]]*\]\s*$")

#: unit of each monitor quantity (the part after ``:`` of a monitors.csv column)
MONITOR_UNITS = {"ux": "m", "uy": "m", "vx": "m/s", "vy": "m/s", "speed": "m/s", "sxx": "Pa", "syy": "Pa",
                 "sxy": "Pa", "pressure": "Pa", "gas_pressure": "Pa"}


def strip_unit(name: str) -> str:
    """``'m1:sxx [Pa]'`` → ``'m1:sxx'``; a name without a trailing ``[unit]`` is returned unchanged."""
    return _UNIT.sub("", name).strip()


def monitor_unit(column: str) -> str:
    return MONITOR_UNITS.get(column.rsplit(":", 1)[-1], "-")


def read_csv(path: str | Path) -> dict[str, np.ndarray]:
    """A history CSV as {bare column name: values}; lines starting with ``#`` are skipped."""
    with open(path, newline="") as fh:
        rows = [r for r in csv.reader(fh) if r and not r[0].startswith("#")]
    head = [strip_unit(h) for h in rows[0]]
    data = np.array(rows[1:], float).reshape(-1, len(head))
    return {k: data[:, i] for i, k in enumerate(head)}


class CsvHistory:
    """Accumulates rows in memory and rewrites the file on ``flush`` (small, human-readable).

    ``unit`` gives the unit of a (non-time) column, written in the header as ``name [unit]``:
    a string for all columns, or a function of the column name.
    """

    def __init__(self, path: Path, columns: list[str], unit: str | Callable[[str], str] | None = None):
        self.path = Path(path)
        self.columns = ["time"] + list(columns)
        self.unit = unit
        self.rows: list[list[float]] = []

    def append(self, t: float, values) -> None:
        self.rows.append([t, *values])

    def header(self) -> list[str]:
        out = ["time [s]"]
        for c in self.columns[1:]:
            u = self.unit(c) if callable(self.unit) else self.unit
            out.append(f"{c} [{u}]" if u else c)
        return out

    def flush(self) -> None:
        buf = io.StringIO(newline="")
        w = csv.writer(buf)
        w.writerow(self.header())
        for r in self.rows:
            w.writerow([f"{v + 0.0 if isinstance(v, float) else v:.9g}" for v in r])   # no "-0" for a negative zero
        write_text_atomic(self.path, buf.getvalue())

    def column(self, name: str) -> list[float]:
        i = self.columns.index(strip_unit(name))
        return [r[i] for r in self.rows]


def json_safe(x):
    """``x`` with every non-finite float (NaN, ±inf) replaced by ``None``, recursively.

    Dicts, lists and tuples are walked; numpy scalars and arrays become Python numbers and lists.
    """
    if isinstance(x, dict):
        return {k: json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_safe(v) for v in x]
    if isinstance(x, np.ndarray):
        return json_safe(x.tolist())
    if isinstance(x, np.generic):
        x = x.item()
    if isinstance(x, float) and not math.isfinite(x):
        return None
    return x


def write_summary(path: Path, summary: dict) -> None:
    """Write ``summary`` as strict JSON (non-finite numbers as ``null``), atomically."""
    text = json.dumps(json_safe(summary), indent=2, sort_keys=False, allow_nan=False)
    write_text_atomic(path, text + "\n")


def write_table(path: str | Path, columns: list[tuple[str, np.ndarray]]) -> None:
    """A CSV of equal-length columns (header names with units, e.g. 'area [m^2]'), written atomically; booleans
    as 0/1."""
    buf = io.StringIO(newline="")
    w = csv.writer(buf)
    w.writerow([name for name, _ in columns])
    cols = [np.asarray(c) for _, c in columns]
    for i in range(len(cols[0]) if cols else 0):
        w.writerow([f"{int(c[i])}" if c.dtype.kind in "bi" else f"{float(c[i]) + 0.0:.9g}" for c in cols])
    write_text_atomic(Path(path), buf.getvalue())
