"""Warp initialisation and device resolution shared by every solver.

Warp is initialised lazily and quietly the first time a solver needs it, so that
importing :mod:`blastfrac` (for example to validate a scenario) stays cheap.
"""

from __future__ import annotations

import ctypes
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
    # blastfrac differentiates no kernel, so each of its kernel modules sets enable_backward = False for itself (a
    # cold kernel cache then compiles the demo's first run in 12 s instead of 37 s; the forward code is the same to
    # the bit); Warp's global default stays as it is for any kernels of the caller's own
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


def kernel_module_names() -> list[str]:
    """Names of blastfrac's Warp modules that hold kernels, after importing every submodule (what a GPU compiles:
    tests/unit/test_cuda_compile.py, benchmarks/gpu_pack.py)."""
    import importlib
    import pkgutil

    from warp._src.context import user_modules

    import blastfrac

    init_warp()
    for info in pkgutil.walk_packages(blastfrac.__path__, "blastfrac."):
        if not info.name.endswith("__main__"):
            importlib.import_module(info.name)
    return sorted(name for name, m in user_modules.items() if name.startswith("blastfrac.") and m.kernels)


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
    calls).

    On a CPU a replay calls the kernel's entry point itself with an argument record built once (``_CpuReplay``):
    Warp's own replay builds a new ctypes record of every argument at each call (~5–10 µs for the 20–30 arguments
    of a contact or MPM launch, most of a small model's step). An argument set again is copied into the record, and
    its struct arguments are copied in at each call (a struct's fields can change between calls), so it runs on
    exactly what Warp's replay would; under a CPU graph capture the replay goes through Warp."""

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
            self._replay(rec)
            return
        if rec is not None and len(rec[1]) == len(params):
            cmd, last = rec[0], rec[1]
            for i, a in enumerate(params):
                if isinstance(a, wp.array):
                    if a is not last[i]:
                        break                        # another array: record again
                elif hasattr(a, "_cls"):             # a struct: another object is packed again
                    if a is not last[i]:
                        cmd.set_param_at_index(i, a)     # (the CPU record copies structs in at each call)
                        last[i] = a
                elif a is not last[i] and a != last[i]:
                    cmd.set_param_at_index(i, a)
                    last[i] = a
                    if rec[3] is not None:
                        rec[3].set(cmd, i)
            else:
                if dim != rec[2]:
                    cmd.set_dim(dim)
                    rec[2] = dim
                self._replay(rec)
                return
        with _RECORD_LOCK:                           # a first launch loads the kernel's module: one thread at a time
            cmd = wp.launch(kernel, dim=dim, inputs=params, device=device, record_cmd=True)
        self._cmds[(kernel, key)] = [cmd, params, dim, _CpuReplay.of(cmd)]
        self.records += 1
        cmd.launch()

    def _replay(self, rec) -> None:
        cpu = rec[3]
        if cpu is None or _apic_capture(rec[0].device) is not None:     # a graph capture records it
            rec[0].launch()
        else:
            cpu.run(rec[0])
        self.replays += 1


try:                                             # Warp's internals the CPU replay needs (Warp 1.19)
    from warp._src.codegen import Struct as _Struct
    from warp._src.context import _get_apic_capture_for_device as _apic_capture
except ImportError:                              # another Warp: every replay goes through Warp's own
    _Struct = _apic_capture = None


class _CpuReplay:
    """A recorded CPU launch's argument record, built once (Launcher): what Warp's replay (``invoke``) builds anew
    at every call, the same fields from the same packed arguments, and the kernel's entry point. Its struct fields
    are copied in again at each call."""

    __slots__ = ("forward", "args", "ref", "structs", "names")

    @classmethod
    def of(cls, cmd):
        """The replay record of a recorded launch ``cmd``, or None where Warp's own replay must run it (a GPU, the
        adjoint, a kernel with thread blocks)."""
        if _apic_capture is None or not cmd.device.is_cpu or cmd.adjoint or cmd.block_dim > 1:
            return None
        args = cmd.kernel.adj.args
        packed = cmd.params[1: 1 + len(args)]
        fields = [(a.label, type(p)) for a, p in zip(args, packed)]
        rec = cls()
        rec.args = type("ArgsStruct", (ctypes.Structure,), {"_fields_": fields})()
        for (name, _), p in zip(fields, packed):
            setattr(rec.args, name, p)
        rec.ref = ctypes.byref(rec.args)
        rec.forward = cmd.hooks.forward
        rec.structs = [(a.label, 1 + i) for i, a in enumerate(args) if isinstance(a.type, _Struct)]
        rec.names = [a.label for a in args]
        return rec

    def set(self, cmd, index: int) -> None:
        """Argument ``index`` was set again (Launch.set_param_at_index): copy its packed value into the record."""
        setattr(self.args, self.names[index], cmd.params[1 + index])

    def run(self, cmd) -> None:
        params = cmd.params
        for name, i in self.structs:
            setattr(self.args, name, params[i])
        self.forward(ctypes.byref(params[0]), self.ref)
