"""Warp initialisation and device resolution shared by every solver.

Warp is initialised lazily and quietly the first time a solver needs it, so that
importing :mod:`blastfrac` (for example to validate a scenario) stays cheap.
"""

from __future__ import annotations

import functools
import os
import re
import sys
import threading

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


#: recording a launch may load its module, which Warp does not guard against two threads (it crashed the process)
_RECORD_LOCK = threading.Lock()


class Launcher:
    """``wp.launch`` through recorded launches (``wp.launch(..., record_cmd=True)``), one per kernel and call site.

    Packing a launch's arguments costs Warp ~1.5 µs per argument in Python at every call (a 29-argument launch:
    50 µs, against 7 µs to replay it); a replay only sets the scalar arguments that changed and the launch size.
    Called like ``wp.launch(kernel, dim, inputs=..., outputs=..., device=...)``; ``key`` tells apart two call
    sites of one kernel with different arrays (each keeps its own record). A launch is recorded again whenever one
    of its arrays is another object than at the last call (another State, a reallocated array), and a struct
    argument that is another object is packed again. The same struct object is not: Warp packs a struct as a
    reference to the instance's own ctypes record (``StructInstance._ctype``), which its field assignments update
    and every launch reads, so a replay sees fields set since (tests/unit/test_launcher.py checks this against
    plain launches, so a Warp release that copied the record instead would fail there, not silently). A replay
    thus always runs on what it is given; the same arguments give the same launch, bit for bit.
    ``records`` counts the recordings (a count that keeps growing means a call site alternates between arrays
    and needs a key), ``replays`` the launches replayed (benchmarks count them beside the plain ``wp.launch``
    calls)."""

    def __init__(self):
        self.records = 0
        self.replays = 0
        self._cmds: dict = {}

    def __call__(self, kernel, dim, inputs=(), outputs=(), device=None, key=None) -> None:
        params = [*inputs, *(outputs or ())]
        if dim == 0:
            return                                   # wp.launch does nothing for an empty launch either
        rec = self._cmds.get((kernel, key))
        if rec is not None and params == rec[1]:
            # the common case, nothing changed (arrays and structs compare by identity, scalars by value)
            if dim != rec[2]:
                rec[0].set_dim(dim)
                rec[2] = dim
            rec[0].launch()
            self.replays += 1
            return
        if rec is not None and len(rec[1]) == len(params):
            cmd, last = rec[0], rec[1]
            for i, a in enumerate(params):
                if isinstance(a, wp.array):
                    if a is not last[i]:
                        break                        # another array: record again
                elif hasattr(a, "_cls"):             # a struct: another object is packed again
                    if a is not last[i]:
                        cmd.set_param_at_index(i, a)
                        last[i] = a
                elif a is not last[i] and a != last[i]:
                    cmd.set_param_at_index(i, a)
                    last[i] = a
            else:
                if dim != rec[2]:
                    cmd.set_dim(dim)
                    rec[2] = dim
                cmd.launch()
                self.replays += 1
                return
        with _RECORD_LOCK:                           # a first launch loads the kernel's module: one thread at a time
            cmd = wp.launch(kernel, dim=dim, inputs=params, device=device, record_cmd=True)
        self._cmds[(kernel, key)] = [cmd, params, dim]
        self.records += 1
        cmd.launch()
