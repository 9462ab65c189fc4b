"""The captured rock step (CDEMSolver.step_captured, issue 14 item 1): a CPU graph replays what the launches do.

A rock-only run with a time-dependent borehole pulse that breaks springs, stepped twice from the same start:
once with every step through the launches (``Simulation.use_graph = False``), once with the steps replayed from
a captured graph wherever one can stand for them (on a GPU the same path is a CUDA graph). Every state array, the
break times (read from the device clock) and the energy books must agree to the last bit, and the graph must
have carried every step but the first (which has no previous step), with and without block contact (whose
schedule runs on the device inside the graph). The in-situ relaxation (a rock-only stage of its own) likewise.
"""

import numpy as np
import pytest

from blastfrac.simulation import Simulation
from conftest import scenario

STATE = ("x", "v", "f", "sigma", "pair_F", "pair_mode", "pair_dropped", "pair_tbreak", "pair_inelastic", "pair_damp",
         "elem_damp", "elem_absorbed", "energy_acc")


def _blast_like(tmp_path, name, contact=False):
    sc = scenario(rock={"unbreakable": False, "tensile_strength": 5e6, "cohesion": 20e6, "block_contact": contact},
                  geometry={"domain": {"type": "rectangle", "width": 0.06, "height": 0.06}, "mesh_size": 0.004,
                            "mesh_size_near": 0.0015, "refinement_distance": 0.01, "boreholes": [{"radius": 0.005}]},
                  borehole_pressure=[{"borehole": 0, "pulse": {"type": "triangle", "peak": 150e6,
                                                                "rise_time": 2e-6, "duration": 20e-6}}],
                  boundaries={s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
                  simulation={"end_time": 30e-6, "progress": False})
    return Simulation(sc, out_dir=tmp_path / name)


def _same(a, b):
    for k in STATE:
        assert np.array_equal(getattr(a.state, k).numpy(), getattr(b.state, k).numpy()), k
    assert np.array_equal(a.ppv.ppv.numpy(), b.ppv.ppv.numpy())
    assert a.time == b.time


def _pair(tmp_path, contact):
    ref, cap = (_blast_like(tmp_path, f"{name}{contact}", contact) for name in ("launches", "graph"))
    ref.use_graph = False
    if ref.model.device != "cpu":
        pytest.skip("bit-identity is a CPU property")
    return ref, cap


def test_captured_rock_steps_are_bit_identical_through_fracture(tmp_path):
    ref, cap = _pair(tmp_path, contact=False)
    steps = 1500
    for k in range(steps):
        ref.step()
        cap.step()
        if k % 100 == 99:
            _same(ref, cap)
    _same(ref, cap)
    mode = cap.state.pair_mode.numpy()
    tb = cap.state.pair_tbreak.numpy()[mode > 0]
    print(f"graph steps {cap.cdem.graph_steps} of {steps}; {int(np.count_nonzero(mode))} springs broken between "
          f"{tb.min() * 1e6:.2f} and {tb.max() * 1e6:.2f} µs")
    assert ref.cdem.graph_steps == 0 and cap.cdem.graph_steps == steps - 1
    assert len(tb) > 100                                   # fracture happened under the graph
    assert 0.0 < tb.min() < tb.max() < cap.time            # at the times of the device clock


def test_captured_steps_with_block_contact_are_bit_identical(tmp_path):
    """Block contact inside the graph: its schedule (step count, hash check and rebuild) on the device, its branches
    through wp.capture_if, its launches over every item. Through fracture, contact, hash rebuilds and fan-cache
    refreshes, the replay must do what the launches do, to the last bit."""
    ref, cap = _pair(tmp_path, contact=True)
    for sim in (ref, cap):                  # a thin skin, so that the hash is rebuilt as the wall moves (h_min/4:
        c = sim.cdem.contact                # once in these 30 µs)
        c.rebuild_skin = 0.01 * c.h_min
    steps, contacts = 1500, 0
    for k in range(steps):
        ref.step()
        cap.step()
        contacts = max(contacts, cap.cdem.contact.active_count()) if k % 50 == 49 else contacts
        if k % 100 == 99:
            _same(ref, cap)
    _same(ref, cap)
    for name in ("contact_slot", "contact_state", "loss_acc", "elem_near",
                 "query_after", "fan_count", "node_flag"):
        assert np.array_equal(getattr(ref.cdem.contact, name).numpy(), getattr(cap.cdem.contact, name).numpy()), name
    c = cap.cdem.contact
    broken = int(np.count_nonzero(cap.state.pair_mode.numpy()))
    print(f"graph steps {cap.cdem.graph_steps} of {steps}; {broken} springs broken; hash rebuilds {c.rebuilds} "
          f"(launches: {ref.cdem.contact.rebuilds}); most contacts at once {contacts}; slip loss "
          f"{c.losses()['slip']:.3e} J/m")
    assert ref.cdem.graph_steps == 0 and cap.cdem.graph_steps == steps - 1
    assert c.rebuilds == ref.cdem.contact.rebuilds >= 5      # rebuilt inside the graph (the first build is not)
    assert broken > 100 and contacts >= 10                   # fracture and contact happened under the graph


def test_captured_insitu_relaxation_is_bit_identical(tmp_path):
    runs = []
    for use in (False, True):
        sc = scenario(geometry={"domain": {"type": "rectangle", "width": 0.06, "height": 0.06}, "mesh_size": 0.004,
                                "boreholes": [{"radius": 0.005}]},
                      insitu={"method": "relax", "sxx": -10e6, "syy": -5e6, "max_steps": 3000})
        sim = Simulation(sc, out_dir=tmp_path / f"insitu{use}")
        sim.use_graph = use
        report = sim.relax_insitu()
        runs.append((sim, report))
    _same(runs[0][0], runs[1][0])
    assert runs[0][1] == runs[1][1]
    assert runs[0][0].cdem.graph_steps == 0
    assert runs[1][0].cdem.graph_steps == runs[1][1]["steps"] - 1 > 0
