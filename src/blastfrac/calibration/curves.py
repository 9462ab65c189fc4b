"""Reading a laboratory curve: first peak (strength), elastic moduli, plane-strain conversion.

All NumPy; stresses in Pa, strains dimensionless (compression positive in the curves).
"""

from __future__ import annotations

import numpy as np


def first_peak(load: np.ndarray, drop: float = 0.02, start: int = 0) -> int:
    """Index of the first peak: the running maximum at the first sample that falls more than
    ``drop`` (relative) below it. Later re-hardening of a crushed specimen (blocks wedging after
    failure) is not strength. Returns the global maximum when the load never drops. Samples
    before ``start`` (the platen speed ramp, where small loads oscillate) are not searched.
    """
    load = np.asarray(load, float)
    start = min(max(start, 0), len(load) - 1)
    if len(load) == 0:
        raise ValueError("empty curve")
    tail = load[start:]
    run = np.maximum.accumulate(tail)
    fall = np.flatnonzero((run > 0) & (tail < (1.0 - drop) * run))
    end = fall[0] if len(fall) else len(tail)
    return start + int(np.argmax(tail[:end]))


def elastic_window(stress: np.ndarray, peak_index: int, lo: float = 0.1, hi: float = 0.4,
                   start: int = 0) -> np.ndarray:
    """Indices of the pre-peak samples at or after ``start`` (end of the speed ramp) with
    lo·peak ≤ σ ≤ hi·peak, the linear part of the curve; all samples from ``start`` to the peak
    when fewer than 3 qualify (a purely elastic run)."""
    s = np.asarray(stress, float)[: peak_index + 1]
    peak = s[-1]
    idx = np.arange(len(s))
    win = np.flatnonzero((s >= lo * peak) & (s <= hi * peak) & (idx >= start))
    return win if len(win) >= 3 else idx[start:]


def slope(x: np.ndarray, y: np.ndarray) -> float:
    """Least-squares slope dy/dx."""
    if len(x) < 2:
        return float("nan")
    return float(np.polyfit(np.asarray(x, float), np.asarray(y, float), 1)[0])


def plane_strain_to_3d(Ep: float, nup: float) -> tuple[float, float]:
    """(E, ν) of the 3D material whose plane-strain moduli are E' = E/(1−ν²), ν' = ν/(1−ν)."""
    nu = nup / (1.0 + nup)
    return Ep * (1.0 - nu * nu), nu


def three_d_to_plane_strain(E: float, nu: float) -> tuple[float, float]:
    """(E', ν') = (E/(1−ν²), ν/(1−ν))."""
    return E / (1.0 - nu * nu), nu / (1.0 - nu)
