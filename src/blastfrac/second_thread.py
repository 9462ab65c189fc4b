"""Whether a coupled step uses its second CPU thread: chosen by timing the run's own steps, not assumed.

With ``simulation.threads = 2`` a coupled step can run its gas stages beside the rock's and split the rock's
per-item stages in two halves (``Simulation._concurrently``, ``CDEMSolver._in_halves``). Every item is computed
alike either way, so the results are the same to the bit; only the time differs. A hand-off to the other thread
costs ~0.1–0.3 ms on a 2-core VM (the other vCPU's wake-up and the GIL), so the second thread pays on a large
model (the shipped confined P0, 113,690 blocks: 1.5× faster) and costs on a small one (the demo, 7,918 blocks:
2.5 ms a step on one thread, 2.8–3.1 ms on two; benchmarks/RESULTS.md, stop 26).

:class:`SecondThread` therefore times the run's steps in trial windows, alternating one thread and two
(``WINDOW`` steps each, ``WINDOWS`` windows, starting with one thread: 16 steps of each), takes the mode whose
median step time is lower, holds it for ``RETUNE`` steps (the step's cost changes as the rock cracks) and then
tries again. A step's time is the wall time from its start to the next step's start, so the run loop's sampling
and output fall into it; the median keeps an occasional sampling step from deciding. A trial costs its 16 steps in
the slower mode: on the shipped P0 about 1 % of a run.
"""

from __future__ import annotations

import statistics
import time


class SecondThread:
    """The trial schedule and the choice; ``use(step)`` is called at the start of every step."""

    WINDOW = 8          #: steps in one trial window
    WINDOWS = 4         #: windows in one trial, alternating one thread / two
    RETUNE = 2000       #: steps between the end of a trial and the start of the next

    def __init__(self, clock=time.perf_counter):
        self._clock = clock
        self.parallel = True                 # the mode outside trials, once a trial has chosen it
        self._trial_start = 1                # the first step runs on one thread (it loads the kernels' modules)
        self._times: dict[bool, list[float]] = {False: [], True: []}
        self._last: tuple[float, bool, bool] | None = None      # (start time, mode, in a trial) of the last step
        self.steps = 0                       # steps run since the start (this process)
        self.steps_parallel = 0              # of them with the second thread
        self.trials: list[dict] = []         # each trial's first step, medians [s] and choice

    def _in_trial(self, step: int) -> bool:
        return self._trial_start <= step < self._trial_start + self.WINDOW * self.WINDOWS

    def use(self, step: int) -> bool:
        """True when step ``step`` is to use the second thread."""
        now = self._clock()
        first = self._last is None
        if first:
            self._trial_start = step + 1     # the first step of this process (0, or a restart's) runs on one thread
        elif self._last[2]:
            self._times[self._last[1]].append(now - self._last[0])
        end = self._trial_start + self.WINDOW * self.WINDOWS
        if step >= end and self._times[False] and self._times[True]:
            self._decide()
        if first:
            mode = False
        elif self._in_trial(step):
            mode = ((step - self._trial_start) // self.WINDOW) % 2 == 1
        else:
            mode = self.parallel
        self._last = (now, mode, self._in_trial(step))
        self.steps += 1
        self.steps_parallel += int(mode)
        return mode

    def _decide(self) -> None:
        one, two = statistics.median(self._times[False]), statistics.median(self._times[True])
        self.parallel = two < one
        self.trials.append({"first_step": self._trial_start, "one_thread_s": one, "two_threads_s": two,
                            "chose": 2 if self.parallel else 1})
        self._times = {False: [], True: []}
        self._trial_start += self.WINDOW * self.WINDOWS + self.RETUNE

    def report(self) -> dict:
        """summary.json → ``threads``: the steps run with the second thread and each trial's medians and choice."""
        return {"requested": 2, "steps": self.steps, "steps_with_second_thread": self.steps_parallel,
                "trials": self.trials}
