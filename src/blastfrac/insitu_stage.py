"""The in-situ stage of a run (METHOD §1.8): the initial stress σ⁰ with consistent spring forces and boundary
tractions, a quasi-static relaxation of the rock alone (rock-only steps, replayed from a captured graph where they
can be), and the books of the blast started from its end state."""

from __future__ import annotations

import sys

import numpy as np

from .analysis.energy import rock_energies
from .analysis.insitu import wall_stress_check


def relaxation_floor(model, scenario, dt: float) -> int:
    """The least number of relaxation steps of Δt = dt [s]: insitu.min_transits P-wave transits of the domain's
    extent, after which the tolerance is trusted."""
    span = float(np.ptp(model.host["node_X"], axis=0).max())
    return int(scenario.insitu.min_transits * span / scenario.rock.p_wave_speed / dt) + 1


def relax_insitu(sim, progress=None) -> dict:
    """Initialise σ⁰, apply consistent tractions and relax quasi-statically (METHOD §1.8)."""
    ins = sim.scenario.insitu
    sim.cdem.initialise_stress(sim.state, ins.sxx, ins.syy, ins.sxy)
    steps, converged, ratio = 0, ins.method == "initial", float("nan")
    breakable = sim.model.breakable
    if not ins.allow_failure:
        sim.model.breakable = 0
    saved_alpha, sim.alpha = sim.alpha, ins.damping
    min_steps = relaxation_floor(sim.model, sim.scenario, sim.dt)
    limit = ins.max_steps if sim.max_steps is None else min(ins.max_steps, sim.max_steps)   # --max-steps too
    task = progress.add_task("in-situ relaxation", total=limit) if progress else None
    while not converged and steps < limit:
        sim.step(gas=False)
        steps += 1
        if steps % 200 == 0:
            e = rock_energies(sim.model, sim.state)
            ratio = e["kinetic"] / max(e["strain"] + e["springs"], 1e-300)
            sim._guard(e)
            converged = steps >= min_steps and ratio < ins.tolerance
            if task is not None:
                progress.update(task, completed=steps, description=f"in-situ relaxation (KE/U {ratio:.1e})")
    if task is not None:
        progress.update(task, completed=limit)
    if not converged:
        msg = (f"in-situ stage did not converge: KE/U = {ratio:.2e} after {steps} steps (insitu.tolerance "
               f"{ins.tolerance:g}, limit {limit}" + (" from --max-steps" if limit < ins.max_steps else
                                                     " = insitu.max_steps") + "); the blast starts from a "
               "state that is still moving: raise insitu.max_steps, or check insitu.damping")
        sim.warnings.append(msg)
        print(f"warning: {msg}", file=sys.stderr, flush=True)
    sim.model.breakable, sim.alpha = breakable, saved_alpha
    t_relax = sim.time
    tb = sim.state.pair_tbreak.numpy().copy()
    mode = sim.state.pair_mode.numpy()
    tb[mode > 0] -= t_relax                      # pre-stress failures get negative break times
    sim.state.pair_tbreak.assign(tb)
    sim.state.v.zero_()
    sim.state.energy_acc.zero_()
    sim.state.pair_damp.zero_()
    sim.state.elem_damp.zero_()
    sim.state.elem_absorbed.zero_()
    sim.ppv.ppv.zero_()                         # vibration is the blast's, not the relaxation's
    sim.cdem.dt_prev = 0.0
    sim.initial_dissipated = sim.cdem.rebase_spring_work(sim.state)
    e = rock_energies(sim.model, sim.state)
    sim.initial_stored = e["strain"] + e["springs"]
    counts = sim.fracture.counts(mode)
    # intact springs already on their softening branch (fracture energies given): damaged, not broken
    s_now, h = sim.state.pair_str.numpy(), sim.model.host
    softening = (mode == 0) & ((s_now[:, 0] < h["pair_t0"] * (1 - 1e-9)) | (s_now[:, 1] < h["pair_c0"] * (1 - 1e-9)))
    sim.insitu_report = {
        "method": ins.method, "steps": steps, "pseudo_time": t_relax, "converged": bool(converged),
        "kinetic_to_strain_ratio": ratio, "broken_tensile": counts["tensile"], "broken_shear": counts["shear"],
        "broken_crushed": counts["crushed"],
        "softening": int(softening.sum()), "failures_allowed": ins.allow_failure, "wall_check": _kirsch_check(sim),
    }
    sim.time, sim.steps = 0.0, 0
    return sim.insitu_report

def _kirsch_check(sim) -> list[dict]:
    """Hoop stress on each borehole wall after the in-situ stage against Kirsch (analysis.insitu)."""

    ins, rock = sim.scenario.insitu, sim.scenario.rock
    x, sig = sim.state.x.numpy(), sim.state.sigma.numpy()
    return [wall_stress_check(x, sig, b.center, b.radius, ins.sxx, ins.syy, ins.sxy, rock.tensile_strength)
            for b in sim.scenario.geometry.boreholes]
