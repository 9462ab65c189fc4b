"""The captured coupled step (coupled_graph.CoupledGraphs, issue 14 item 1): a CPU graph replays what the
launches do.

A coupled blast (MPM products expanding from a decoupled charge into its borehole, particle–edge contact, springs that break, block contact, an MPM box
that grows) stepped twice from the same start: once with every step through the launches (simulation.graph =
'off'), once with the coupled steps replayed from captured graphs (simulation.graph = 'on'; on a GPU the same path
captures CUDA graphs). Inside a graph nothing is read back: the coupler's list length, largest reach and empty-list
branch stay on the device, the burn reads the time from a device clock. Every state array of the rock and the gas,
the contact books and the energy terms must agree to the last bit, and the graphs must have carried the steps
through Δt changes, list rebuilds, box renewals and fracture.
"""

import numpy as np
import pytest

from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation

ROCK = ("x", "v", "f", "sigma", "pair_F", "pair_mode", "pair_dropped", "pair_tbreak", "pair_inelastic", "pair_damp",
        "elem_damp", "energy_acc")
GAS = ("x", "v", "v_pic", "ie", "p", "burn", "vol", "f_ext_p")


def _scenario(graph: str, crack_gas: bool = False) -> dict:
    r_b, h = 0.003, 0.00075
    return {
        "crack_gas": {"enabled": crack_gas},
        "title": "coupled graph", "simulation": {"end_time": 6e-6, "progress": False, "threads": 1, "graph": graph,
                                                # the rock's step below the gas's over most of the run, so that Δt
                                                # holds long enough for graphs to carry most steps
                                                "dt_safety": 0.6},
        "output": {"paraview": False, "figures": False},
        "rock": {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2, "tensile_strength": 10e6,
                 "cohesion": 40e6, "friction_angle": 40.0, "residual_friction_angle": 30.0,
                 "spring_damping": 0.15},
        "geometry": {"domain": {"type": "rectangle", "width": 0.04, "height": 0.04}, "mesh_size": 5 * h,
                     "mesh_size_near": h, "refinement_distance": 0.012,
                     "boreholes": [{"center": [0.0, 0.0], "radius": r_b}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "explosive": {"name": "emulsion", "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": 0.6 * r_b}],
                      "grid": {"cell_size": h / 3, "points_per_cell": 2, "bounds": [[-0.012, -0.012], [0.012, 0.012]]}},
    }


def _state(sim) -> dict:
    out = {k: getattr(sim.state, k).numpy().copy() for k in ROCK}
    out.update({"gas_" + k: getattr(sim.gas, k).numpy().copy() for k in GAS})
    out["ppv"] = sim.ppv.values().copy()
    out["coupler_acc"] = sim.coupler.acc.numpy().copy()
    out["contact_loss"] = sim.cdem.contact.loss_acc.numpy().copy()
    if sim.crack_gas is not None:
        g = sim.crack_gas.gas
        out.update(crack_mass=g.mass.numpy().copy(), crack_energy=g.energy.numpy().copy(),
                   crack_wet=g.wet.numpy().copy(), crack_paths=sim.crack_gas.links.count.numpy().copy())
    return out


@pytest.mark.parametrize("crack_gas, two_hashes", [(False, False), (True, False), (False, True)],
                         ids=["particles", "crack_gas", "two_hashes"])
def test_captured_coupled_steps_are_bit_identical(tmp_path, monkeypatch, crack_gas, two_hashes):
    """With crack gas the network's rebuilds, flows, mouths and hand-overs to the particles run inside the graph
    too (its counts on the device, its branches through wp.capture_if). With ``two_hashes`` the coupler's split is
    lowered (CELL_REACH), so that its listed elements fall in two size classes with a hash each, as a coarse far
    mesh's cracked blocks do in the demo; this small case keeps one class otherwise."""
    if two_hashes:
        import blastfrac.coupling.coupler as coupler

        monkeypatch.setattr(coupler, "CELL_REACH", 0.5)
    ref, cap = (Simulation(scenario_from_dict(_scenario(g, crack_gas)), out_dir=tmp_path / g) for g in ("off", "on"))
    if ref.model.device != "cpu":
        pytest.skip("bit-identity is a CPU property")
    assert not ref.coupled_graph and cap.coupled_graph
    steps, dts, boxes, listed, rebuilds, large = 700, set(), set(), set(), 0, 0
    for k in range(steps):
        rebuilds += cap.coupler._since >= cap.coupler.rebuild_interval
        ref.step()
        cap.step()
        large = max(large, int(cap.coupler.cls_count.numpy()[1]))
        dts.add(cap.dt)
        boxes.add(cap.gas.grid.box)
        listed.add(ref.coupler.n_exposed)
        if k % 100 == 99:
            a, b = _state(ref), _state(cap)
            for name in a:
                assert np.array_equal(a[name], b[name]), (k, name)
            assert ref.time == cap.time and ref.dt == cap.dt
    assert ref.energies() == cap.energies()
    mode = cap.state.pair_mode.numpy()
    print(f"\n  {cap.coupled_graph_steps} of {steps} steps replayed, {cap.coupled_graph_captures} graphs captured, "
          f"{len(cap.graphs.cache)} held; {len(dts)} time "
          f"steps, {len(boxes)} MPM boxes, {rebuilds} list rebuilds, {len(listed)} list lengths, up to {large} large; {int(np.count_nonzero(mode))} springs broken, "
          f"{cap.coupler.n_exposed} listed elements; warnings {cap.warnings}")
    assert ref.coupled_graph_steps == 0
    assert not cap.warnings
    assert cap.coupled_graph_steps > steps // 2         # the graph carried most steps ...
    assert cap.coupled_graph_captures > 4               # ... captured again after Δt or the box changed
    # through Δt changes, box renewals, rebuilds of the coupler's list whose length the graph never reads
    assert len(dts) > 2 and len(boxes) > 1 and rebuilds > 50 and len(listed) > 2
    assert np.count_nonzero(mode) > 50                   # and fracture
    assert (large > 0) == two_hashes                     # the large elements' hash was searched, or not
    if crack_gas:                                        # gas in the cracks, fed through mouths
        assert cap.crack_gas.gas.mass.numpy().sum() > 0 and cap.crack_gas.report()["mouths"] > 0


def test_a_run_resumed_with_captured_steps_is_bit_identical(tmp_path):
    """simulation.graph may change at a restart: a run through the launches, checkpointed and stopped, then resumed
    with its coupled steps captured (the coupler's hash rebuilt from the saved list with its saved cell width), ends
    where the run that went through ends, to the bit."""
    from blastfrac.run_control import CHECKPOINT_NAME

    full = Simulation(scenario_from_dict(_scenario("off")), out_dir=tmp_path / "full")
    full.run()
    sc = _scenario("off")
    sc["output"]["checkpoint_interval"] = 1e-6
    part = Simulation(scenario_from_dict(sc), out_dir=tmp_path / "part", max_steps=400)
    part.run()
    sc["simulation"]["graph"] = "on"
    resumed = Simulation(scenario_from_dict(sc), out_dir=tmp_path / "part")
    resumed.run(restart=tmp_path / "part" / CHECKPOINT_NAME)
    assert resumed.steps == full.steps and resumed.coupled_graph_steps > (full.steps - 400) // 2
    a, b = _state(full), _state(resumed)
    for name in a:
        assert np.array_equal(a[name], b[name]), name
    assert full.energies() == resumed.energies()


def test_the_gpu_form_of_the_dropped_spring_check_reads_the_same(tmp_path):
    """The run switches block contact on at the first dropped spring (checked every 16 steps). On a GPU the check
    reads a device flag, not the whole array: run here on the CPU, the flag form must say what the array says."""
    sim = Simulation(scenario_from_dict(_scenario("off")), out_dir=tmp_path)
    c, st = sim.cdem.contact, sim.state
    n = sim.model.spring_count
    for dropped in ([], [0], [n - 1], [n // 3, n // 2]):
        st.pair_dropped.assign(np.isin(np.arange(n), dropped).astype(np.int32))
        c._cpu = True
        on_cpu = c.any_dropped(st)
        c._cpu = False                                   # the GPU form: flag_any_dropped and a 4-byte read
        assert c.any_dropped(st) == on_cpu == bool(dropped)


@pytest.mark.parametrize("where", ["begin", "inside"])
def test_a_failed_capture_falls_back_to_the_launches(tmp_path, monkeypatch, where):
    """A capture that fails (a GPU without conditional graph nodes, say) leaves the run on the launches with a
    warning, its stages' flags and host schedules as they were: the run ends where one through the launches ends."""
    import warp as wp

    ref, cap = (Simulation(scenario_from_dict(_scenario(g, True)), out_dir=tmp_path / g) for g in ("off", "on"))
    if where == "begin":
        def fail(*a, **k):
            raise RuntimeError("no graph here")
        monkeypatch.setattr(wp, "capture_begin", fail)
    else:
        real = cap.coupler._contacts

        def fail_in_capture(*a, **k):
            if cap.coupler.captured:
                raise RuntimeError("no conditional nodes")
            return real(*a, **k)
        monkeypatch.setattr(cap.coupler, "_contacts", fail_in_capture)
    for _ in range(300):
        ref.step()
        cap.step()
    assert not cap.coupled_graph and cap.coupled_graph_steps == 0
    assert len(cap.warnings) == 1 and "capturing one failed" in cap.warnings[0]
    assert not (cap.coupler.captured or cap.gas.captured or cap.crack_gas.captured or cap.cdem._capturing)
    a, b = _state(ref), _state(cap)
    for name in a:
        assert np.array_equal(a[name], b[name]), name


def test_nothing_is_read_back_or_allocated_inside_a_capture(tmp_path, monkeypatch):
    """What a CUDA stream capture refuses, refused here on the CPU: inside the capture of a coupled step no array is
    read to the host (``numpy``, ``list``), nothing synchronises, and nothing is allocated or uploaded from host data
    (views of existing arrays are fine). A CPU capture would record such a step without complaint, and the
    bit-identity above only catches the reads whose values change what the step does; on a GPU each of them fails
    the capture (the run then falls back to the launches, issue 14 item 1). Nor is a wp.HashGrid built: a CUDA graph
    replays such a build by copying its descriptor from one host buffer that every float64 grid shares (Warp 1.19,
    native/hashgrid.cpp), so two captured builds would alias; the coupler's hashes are cell grids of its own
    (kernels_contact.ListedHash), and its rebuild steps are replayed too. Crack gas on, so that every captured stage
    takes part; the run still ends where the launches' run ends, to the bit."""
    import warp as wp

    from blastfrac import coupled_graph

    inside, seen = [False], []

    def guard(owner, name, allowed=lambda *a, **k: False):
        real = getattr(owner, name)

        def checked(*a, **k):
            if inside[0] and not allowed(*a, **k):
                seen.append(name)
                raise RuntimeError(f"{name} inside a captured step")
            return real(*a, **k)
        monkeypatch.setattr(owner, name, checked)

    for name in ("numpy", "list"):
        guard(wp.array, name)
    # a view (ptr given, no host data) is not an allocation
    guard(wp.array, "__init__", allowed=lambda self, data=None, *a, **k: data is None and k.get("ptr") is not None)
    for name in ("synchronize", "synchronize_device", "synchronize_stream", "empty", "zeros", "full", "clone",
                 "empty_like", "zeros_like", "full_like", "from_numpy"):
        guard(wp, name)
    guard(wp.HashGrid, "build")
    real_capture = coupled_graph.CoupledGraphs._capture

    def capture(self, sim, dt):
        inside[0] = True
        try:
            return real_capture(self, sim, dt)
        finally:
            inside[0] = False
    monkeypatch.setattr(coupled_graph.CoupledGraphs, "_capture", capture)
    ref, cap = (Simulation(scenario_from_dict(_scenario(g, crack_gas=True)), out_dir=tmp_path / g)
                for g in ("off", "on"))
    rebuilds = replayed_rebuilds = 0
    for _ in range(500):
        rebuild, replayed = cap.coupler.rebuild_due(), cap.coupled_graph_steps
        ref.step()
        cap.step()
        rebuilds += rebuild
        replayed_rebuilds += rebuild and cap.coupled_graph_steps > replayed
    assert not seen and not cap.warnings, (seen, cap.warnings)
    assert cap.coupled_graph and cap.coupled_graph_captures > 4 and rebuilds > 50
    # the graphs carried most steps, the coupler's rebuilds among them
    assert cap.coupled_graph_steps > 200 and replayed_rebuilds > 20, replayed_rebuilds
    assert cap.crack_gas.gas.mass.numpy().sum() > 0          # the captured stages carried gas into the cracks
    a, b = _state(ref), _state(cap)
    for name in a:
        assert np.array_equal(a[name], b[name]), name
