"""CSV histories (monitors, fracture degree, energy) and the JSON run summary."""

from __future__ import annotations

import csv
import json
from pathlib import Path


class CsvHistory:
    """Accumulates rows in memory and rewrites the file on ``flush`` (small, human-readable)."""

    def __init__(self, path: Path, columns: list[str]):
        self.path = Path(path)
        self.columns = ["time"] + list(columns)
        self.rows: list[list[float]] = []

    def append(self, t: float, values) -> None:
        self.rows.append([t, *values])

    def flush(self) -> None:
        with self.path.open("w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(self.columns)
            for r in self.rows:
                w.writerow([f"{v:.9g}" for v in r])

    def column(self, name: str) -> list[float]:
        i = self.columns.index(name)
        return [r[i] for r in self.rows]


def write_summary(path: Path, summary: dict) -> None:
    Path(path).write_text(json.dumps(summary, indent=2, sort_keys=False) + "\n")
