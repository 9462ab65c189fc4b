"""A step does not depend on the order in which a launch's threads run (issue 14 item 6, readiness for a GPU).

Warp runs a CPU launch's threads one after another, thread 0 first, so a kernel whose threads read what other
threads of the same launch write (an order dependence, a race on a GPU) gives the same answer on every CPU run and
shows nothing. Here the same steps are taken twice from one cracked state with gas in the cracks: once as Warp
compiles them, once in a child process whose CPU kernels run their threads in reverse order (Warp's CPU task loop
rewritten before anything compiles, in a kernel cache of its own). Without an order dependence the two differ only
by the round-off of sums made in the other order: no spring breaks or drops differently, no crack cell wets
differently, and no float array moves by more than round-off over the steps.

The gas–rock coupler's listed elements, which its threads append in the order they arrive, must come out in the
same order too (it sorts them by element). Block contact runs in the form a GPU runs (``BlockContact._cpu = False``: one thread per listed node or vertex, its
lists filled by atomic appends), which a CPU otherwise runs as one thread over each list in node order; run in order
on a CPU the two forms give the same bits. The child first runs a kernel whose threads do read their neighbour's
write, to show that the reversal took effect. A spring or cell that sits on a threshold could in principle flip
under round-off; none does in these steps.
"""

import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest

from blastfrac.run_control import CHECKPOINT_NAME
from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

HERE = Path(__file__).resolve().parent
if str(HERE.parent / "unit") not in sys.path:
    sys.path.insert(0, str(HERE.parent / "unit"))      # test_coupled_graph's scenario and state
START, STEPS = 600, 30                 # the cracked state's step (~1,000 springs broken, gas in the cracks), and steps

CHILD = textwrap.dedent('''
    import sys
    import numpy as np
    import warp as wp
    import warp._src.codegen as codegen

    loop = "for (size_t task_index = 0; task_index < dim->size; ++task_index)"
    if loop not in codegen.cpu_module_template_forward:
        sys.exit(3)                                         # Warp's CPU task loop changed: nothing to reverse
    codegen.cpu_module_template_forward = codegen.cpu_module_template_forward.replace(
        loop, "for (size_t task_index = dim->size; task_index-- > 0;)")
    wp.config.kernel_cache_dir = sys.argv[1]

    @wp.kernel
    def chain(out: wp.array(dtype=int)):
        i = wp.tid()
        if i == 0:
            out[0] = 1
        else:
            out[i] = out[i - 1] + 1                         # reads the previous thread's write

    out = wp.zeros(8, dtype=int, device="cpu")
    wp.launch(chain, dim=8, inputs=[out], device="cpu")
    reversed_ = out.numpy().tolist() == [1] * 8             # in order: 1, 2, ..., 8

    sys.path[:0] = [sys.argv[2]]
    from test_thread_order import run_from
    np.savez(sys.argv[3], reversed_=reversed_, **run_from(sys.argv[4], sys.argv[5]))
''')


def _scenario() -> dict:
    from test_coupled_graph import _scenario as coupled

    sc = coupled("off", crack_gas=True)
    sc["simulation"]["end_time"] = 1.0                      # the steps count, not the time
    return sc


def run_from(checkpoint_dir: str, out_dir: str) -> dict:
    """STEPS steps from the checkpoint in checkpoint_dir, in out_dir; the state arrays after them."""
    import shutil

    from test_coupled_graph import _state

    shutil.copytree(checkpoint_dir, out_dir)
    sim = Simulation(scenario_from_dict(_scenario()), out_dir=out_dir, max_steps=START + STEPS)
    sim.cdem.contact._cpu = False          # block contact's GPU form: one thread per listed item, lists by atomics
    sim.run(progress=False, restart=Path(out_dir) / CHECKPOINT_NAME)
    assert sim.steps == START + STEPS
    out = _state(sim)
    cp, E = sim.coupler, sim.model.element_count
    n = cp.cls_count.numpy()
    # the coupler's listed elements by class, as its last rebuild left them (appended by one thread each)
    out["coupler_list"] = np.concatenate([cp.cls_elems.numpy()[c * E: c * E + n[c]] for c in (0, 1)])
    return out


def test_a_step_does_not_depend_on_the_order_of_threads(tmp_path):
    sc = _scenario()
    sc["output"]["checkpoint_interval"] = 1e-9              # a checkpoint where the run stops
    start = Simulation(scenario_from_dict(sc), out_dir=tmp_path / "start", max_steps=START)
    start.run(progress=False)
    assert int(np.count_nonzero(start.state.pair_mode.numpy())) > 500
    assert start.crack_gas.gas.mass.numpy().sum() > 0
    ref = run_from(str(tmp_path / "start"), str(tmp_path / "in_order"))
    script = tmp_path / "reversed_threads.py"              # (Warp reads a kernel's source from its file)
    script.write_text(CHILD)
    child = subprocess.run([sys.executable, str(script), str(tmp_path / "cache"), str(HERE),
                            str(tmp_path / "reversed.npz"), str(tmp_path / "start"), str(tmp_path / "reversed")],
                           check=False, capture_output=True, text=True, timeout=900)
    if child.returncode == 3:
        pytest.skip("Warp's CPU task loop is not the one this test rewrites (warp._src.codegen changed)")
    assert child.returncode == 0, child.stderr[-3000:]
    rev = dict(np.load(tmp_path / "reversed.npz"))
    assert bool(rev.pop("reversed_")), "the child's threads did not run in reverse order"
    rows = []
    for name, a in ref.items():
        b = rev[name]
        if a.dtype.kind in "iub":
            rows.append((name, int(np.count_nonzero(a != b)), None))
            assert np.array_equal(a, b), name                # the same springs broken and dropped, cells wetted
        else:
            scale = max(float(np.abs(a).max()), 1e-300)
            d = float(np.abs(a - b).max()) / scale
            rows.append((name, None, d))
            assert d < 1e-9, (name, d)                       # round-off of sums in another order (1e-17–6e-13 seen)
    changed = sum(1 for _, _, d in rows if d)
    print("\n  reversed against in-order threads after", STEPS, "steps:",
          ", ".join(f"{n} {d:.1e}" for n, _, d in rows if d), f"({changed} float arrays moved by round-off)")
    assert changed > 3                                       # the sums did run in another order
