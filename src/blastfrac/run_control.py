"""Run control around the step loop: stop signals, checkpoint naming and restart keys, clearing an earlier
run's outputs, and the progress bar (used by simulation.Simulation.run)."""

from __future__ import annotations

import sys
from pathlib import Path

CHECKPOINT_NAME = "checkpoint.npz"


class RunInterrupted(RuntimeError):
    """SIGINT or SIGTERM stopped the run after a whole step; checkpoint, CSVs and summary.json are written.
    ``signum`` is the signal, ``exit_code`` 128 + signum (130, 143)."""

    def __init__(self, signum: int, out_dir: Path):
        super().__init__(f"interrupted by signal {signum}; the run can continue with "
                         f"blastfrac run --restart {out_dir}")
        self.signum, self.exit_code, self.out_dir = signum, 128 + signum, out_dir


#: files a run writes that a later run into the same directory must not leave behind (stale frames)
_RUN_OUTPUTS = ("rock_[0-9][0-9][0-9][0-9].vtu", "gas_[0-9][0-9][0-9][0-9].vtu", "rock.pvd", "gas.pvd",
                CHECKPOINT_NAME, "summary.json", "monitors.csv", "energy.csv", "fracture_degree.csv",
                "borehole_pressure.csv", "fragments.csv", "ppv_profile.csv")


def clear_previous_outputs(out_dir: Path) -> int:
    """Remove the frames, histories, summary and checkpoint of an earlier run in ``out_dir`` (only blastfrac's own
    file names; anything else stays); returns the number of files removed, and says so on stderr."""
    n = 0
    for pattern in _RUN_OUTPUTS:
        for f in Path(out_dir).glob(pattern):
            if f.is_file():
                f.unlink()
                n += 1
    if n:
        print(f"note: removed {n} output files of an earlier run in {out_dir} (frames, histories, summary)",
              file=sys.stderr, flush=True)
    return n


def _install_stop_handlers(sim) -> dict:
    """SIGINT/SIGTERM set ``sim._stop_signal``; the loop stops after the current step (main thread only)."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        return {}

    def handler(signum, frame):
        if sim._stop_signal is not None:           # a second signal: stop at once
            raise KeyboardInterrupt
        sim._stop_signal = signum

    old = {}
    for sig in (signal.SIGINT, signal.SIGTERM):
        old[sig] = signal.signal(sig, handler)
    return old


def _restore_handlers(old: dict) -> None:
    import signal

    for sig, h in old.items():
        signal.signal(sig, h)


def _restart_key(resolved: dict) -> str:
    """The resolved scenario without what a restart may change (end time, step limit, progress, device, threads,
    graph, output). The thread count and the graphs change no result (tests/unit/test_threads.py,
    test_coupled_graph.py; the restart test resumes a two-thread run on one, test_coupled_graph.py a run through the
    launches with its coupled steps captured)."""
    import json

    d = {k: v for k, v in resolved.items() if k != "output"}
    d["simulation"] = {k: v for k, v in d.get("simulation", {}).items()
                       if k not in ("end_time", "max_steps", "progress", "device", "threads", "graph")}
    return json.dumps(d, sort_keys=True, default=str)


class _NoProgress:
    def __enter__(self):
        return None

    def __exit__(self, *a):
        return False


def _progress(show: bool):
    if not show:
        return _NoProgress()
    from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn, TimeRemainingColumn

    return Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.completed}/{task.total} steps"),
                    TimeElapsedColumn(), TimeRemainingColumn(), transient=False)
