"""Warp initialisation and device resolution shared by every solver.

Warp is initialised lazily and quietly the first time a solver needs it, so that
importing :mod:`blastfrac` (for example to validate a scenario) stays cheap.
"""

from __future__ import annotations

import functools
import os
import re
import sys

import warp as wp

F64 = wp.float64

#: the device names a scenario or ``--device`` may give: cpu, cuda, cuda:N (N >= 0)
DEVICE_PATTERN = re.compile(r"^(cpu|cuda(?::([0-9]+))?)$")


@functools.cache
def init_warp() -> None:
    """Initialise Warp once, without its start-up banner."""
    wp.config.log_level = wp.LOG_WARNING
    # Warp's native layer prints a warning on machines without a CUDA driver; CPU runs are the
    # normal case here, so hide that one message by muting file descriptor 2 during init.
    sys.stderr.flush()
    saved = os.dup(2)
    try:
        with open(os.devnull, "w") as null:
            os.dup2(null.fileno(), 2)
            wp.init()
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def resolve_device(name: str | None) -> str:
    """Return a Warp device string for ``name`` ("cpu", "cuda", "cuda:0", None → cpu).

    Raises ``ValueError`` with a user-facing message when a CUDA device is asked for
    but none is available.
    """
    init_warp()
    if name is None or name == "cpu":
        return "cpu"
    m = DEVICE_PATTERN.match(name)
    if m is None:
        raise ValueError(f"unknown device '{name}': expected 'cpu', 'cuda' or 'cuda:N' with N >= 0")
    if not wp.is_cuda_available():
        raise ValueError(f"device '{name}' requested but no CUDA device is available; use device='cpu'")
    if m.group(2) is not None:
        count = wp.get_cuda_device_count()
        if int(m.group(2)) >= count:
            raise ValueError(f"device '{name}' requested but this machine has {count} CUDA device(s) "
                             f"(cuda:0..cuda:{count - 1})")
        return f"cuda:{int(m.group(2))}"
    return "cuda:0"
