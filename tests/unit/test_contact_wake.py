"""Block contact's wakes (contact_fan.wake_block, node_woken): a block's woken state within a pass is that of the
pass's start, whichever node of the pass wrote a wake first, so that the pass can run in any order or in two parts.

Expected states from the definition: at step s a block is woken when its last wake before s lies in
[s − near_window, s); a wake written at step s counts from step s + 1 on.
"""

import numpy as np
import warp as wp

from blastfrac._warp import init_warp
from blastfrac.cdem.contact_fan import node_woken, wake_block

W = 20                                     # near_window [steps]


@wp.kernel
def _pass(elem_near: wp.array(dtype=wp.int32), order: wp.array(dtype=wp.int32), wakes: wp.array(dtype=wp.int32),
          step: wp.int32, window: wp.int32, before: wp.array(dtype=wp.int32), after: wp.array(dtype=wp.int32)):
    """One thread: for each block in ``order``, read its woken state, wake it if wakes[k] = 1, read it again."""
    for k in range(order.shape[0]):
        e = order[k]
        before[k] = wp.where(node_woken(e, elem_near, step, window), 1, 0)
        if wakes[k] != 0:
            wake_block(e, elem_near, step, window)
        after[k] = wp.where(node_woken(e, elem_near, step, window), 1, 0)


def _run(last_wake: np.ndarray, order, wakes, step: int):
    init_warp()
    near = wp.array(last_wake.astype(np.int32), dtype=wp.int32, device="cpu")
    n = len(order)
    before, after = (wp.zeros(n, dtype=wp.int32, device="cpu") for _ in range(2))
    wp.launch(_pass, 1, inputs=[near, wp.array(np.asarray(order, np.int32), dtype=wp.int32, device="cpu"),
                                wp.array(np.asarray(wakes, np.int32), dtype=wp.int32, device="cpu"), step, W,
                                before, after], device="cpu")
    return near, before.numpy(), after.numpy()


def test_a_wake_does_not_change_the_woken_state_within_its_pass():
    s = 1000
    # block 0 woken 3 steps ago (woken now), block 1 woken W + 1 steps ago (expired), block 2 never
    last = np.array([s - 3, s - W - 1, -(1 << 30)])
    woken_at_start = np.array([1, 0, 0])
    # each block is woken by the first node that meets it and read by later ones, in two different orders
    for order in ([0, 1, 2, 0, 1, 2], [2, 1, 0, 2, 1, 0]):
        wakes = [1, 1, 1, 0, 0, 0]
        near, before, after = _run(last, order, wakes, s)
        expect = woken_at_start[order]
        assert np.array_equal(before, expect) and np.array_equal(after, expect), (order, before, after)
        # the next steps see the wake of step s: woken for s + 1 … s + W, not at s + W + 1
        for step, want in ((s + 1, 1), (s + W, 1), (s + W + 1, 0)):
            _, b, _ = _run(near.numpy(), [0, 1, 2], [0, 0, 0], step)
            assert np.array_equal(b, [want] * 3), (step, b)


def test_a_second_wake_in_one_pass_keeps_the_first():
    s = 50
    last = np.array([s - 5, -(1 << 30)])
    near, before, after = _run(last, [0, 0, 1, 1], [1, 1, 1, 1], s)
    assert np.array_equal(before, [1, 1, 0, 0]) and np.array_equal(after, [1, 1, 0, 0])
    # a block woken now reads as woken from the next step on, whatever it was before
    _, b, _ = _run(near.numpy(), [0, 1], [0, 0], s + 1)
    assert np.array_equal(b, [1, 1])
