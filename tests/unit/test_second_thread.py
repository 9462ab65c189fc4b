"""The second thread's choice (blastfrac.second_thread): trial windows alternate one thread and two, the faster
median wins, the choice is tried again after RETUNE steps, and a run with simulation.threads = 2 reports it."""

from blastfrac.second_thread import SecondThread


class FakeClock:
    """A clock the test advances by the time each mode's step takes."""

    def __init__(self):
        self.t = 0.0

    def __call__(self):
        return self.t


def _run(sel: SecondThread, clock: FakeClock, steps: int, cost, first: int = 0) -> list[bool]:
    modes = []
    for k in range(first, first + steps):
        m = sel.use(k)
        modes.append(m)
        clock.t += cost(k, m)
    return modes


def test_trial_alternates_windows_and_picks_the_faster_mode():
    for faster in (False, True):
        clock = FakeClock()
        sel = SecondThread(clock)
        W, N = sel.WINDOW, sel.WINDOWS
        cost = lambda k, m: 1.0 if m == faster else 2.0          # noqa: E731
        modes = _run(sel, clock, 1 + W * N + 100, cost)
        assert modes[0] is False                                   # the first step loads the modules: one thread
        trial = modes[1:1 + W * N]
        expected = [((k // W) % 2 == 1) for k in range(W * N)]    # one thread first, then two, ...
        assert trial == expected
        assert all(m == faster for m in modes[1 + W * N:])         # held after the trial
        assert sel.trials[0]["chose"] == (2 if faster else 1)
        assert sel.trials[0]["one_thread_s"] == (1.0 if not faster else 2.0)


def test_an_occasional_slow_step_does_not_decide():
    clock = FakeClock()
    sel = SecondThread(clock)
    # two threads are faster, but every 8th step (sampling, output) takes 50x longer whatever the mode
    cost = lambda k, m: (50.0 if k % 8 == 3 else 1.0) * (0.8 if m else 1.0)   # noqa: E731
    _run(sel, clock, 1 + sel.WINDOW * sel.WINDOWS + 1, cost)
    assert sel.trials and sel.trials[0]["chose"] == 2


def test_the_choice_is_tried_again_when_the_step_changes():
    clock = FakeClock()
    sel = SecondThread(clock)
    sel.RETUNE = 50
    span = sel.WINDOW * sel.WINDOWS
    # two threads pay on the intact rock of the first steps and cost once it has cracked (step ≥ 200)
    cost = lambda k, m: (1.0 if m else 1.5) if k < 200 else (2.0 if m else 1.0)   # noqa: E731
    modes = _run(sel, clock, 560, cost)            # ends between two trials (one starts at 575 with WINDOWS = 4)
    assert sel.trials[0]["chose"] == 2 and sel.trials[-1]["chose"] == 1
    assert modes[1 + span] is True and modes[-1] is False
    assert sel.steps == 560 and 0 < sel.steps_parallel < 560


def test_a_restart_starts_on_one_thread_and_trials_again():
    clock = FakeClock()
    sel = SecondThread(clock)
    cost = lambda k, m: 1.0 if m else 3.0                         # noqa: E731
    modes = _run(sel, clock, 1 + sel.WINDOW * sel.WINDOWS + 5, cost, first=5000)
    assert modes[0] is False and sel.trials and sel.trials[0]["first_step"] == 5001 and modes[-1] is True
