"""Simulation: clock, stable time step, the ordered stages of one step, and the run loop.

The run loop wraps :meth:`Simulation.step` with its callbacks, each on its own schedule:
ParaView frames (``output.interval``), histories (``output.monitor_interval``), the
progress bar and a NaN guard. The in-situ stress stage, when asked for, runs first.
"""

from __future__ import annotations

import math
import time as _time
from pathlib import Path

import numpy as np
import warp as wp

from . import __version__
from ._warp import resolve_device
from .analysis.energy import budget_error, rock_energies
from .analysis.fracture import FractureDegree
from .analysis.monitors import MonitorSet
from .cdem.solver import CDEMSolver
from .io.paraview import ParaviewSeries, crack_segments
from .io.tables import CsvHistory, write_summary
from .model.builder import ModelBuilder
from .scenario.load import write_resolved
from .scenario.schema import Scenario


class SimulationError(RuntimeError):
    """The run became unphysical (NaN, blow-up); the message says where and when."""


class Simulation:
    def __init__(self, scenario: Scenario, out_dir: str | Path | None = None, device: str | None = None,
                 max_steps: int | None = None, mesh=None):
        if scenario.explosive is not None:
            from .scenario.errors import ScenarioError

            raise ScenarioError(
                "[explosive] is validated (see `blastfrac check`, `blastfrac explosive`) but the gas–rock coupling "
                "is not implemented yet; load the borehole with [[borehole_pressure]] for now"
            )
        self.scenario = scenario
        self.device = resolve_device(device or scenario.simulation.device)
        self.out_dir = Path(out_dir or scenario.output.directory)
        self.max_steps = max_steps if max_steps is not None else scenario.simulation.max_steps
        self.builder = ModelBuilder(scenario, mesh)
        self.model = self.builder.finalize(self.device)
        self.state = self.model.state()
        # Node-to-edge block contact (cdem/contact.py) is switched off: its kernel produces spurious forces on
        # first contact (tests/verification/test_block_contact.py, xfail). Broken springs still act as
        # unilateral frictional contacts until they separate.
        self.cdem = CDEMSolver(self.model, block_contact=False)
        self.dt = scenario.simulation.dt_safety * self.model.stable_dt
        self.time = 0.0
        self.steps = 0
        self.alpha = scenario.simulation.damping
        X = self.model.host["node_X"]
        self.fracture = FractureDegree(X[self.model.topology.pair_nodes[:, 0]], scenario.zones)
        self.monitors = MonitorSet(scenario.monitors, X)
        self.insitu_report: dict | None = None
        self.initial_stored = 0.0

    # ------------------------------------------------------------------ one step
    def step(self) -> None:
        """Advance the rock by one explicit step (the MPM and coupling stages join in later issues)."""
        dt = self.dt
        self.cdem.forces(self.state, dt, self.time)        # 3. springs + failure, CST, loads, block contact
        self.cdem.integrate(self.state, dt, self.alpha)    # 4. central difference on rock nodes
        self.time += dt
        self.steps += 1
        if self.cdem.contact is not None and not self.cdem.contact.active and self.steps % 16 == 0:
            self.cdem.contact.active = bool(np.any(self.state.pair_dropped.numpy()))

    # ------------------------------------------------------------------ in-situ stage
    def relax_insitu(self, progress=None) -> dict:
        """Initialise σ⁰, apply consistent tractions and relax quasi-statically (METHOD §1.8)."""
        ins = self.scenario.insitu
        self.cdem.initialise_stress(self.state, ins.sxx, ins.syy, ins.sxy)
        steps, converged, ratio = 0, ins.method == "initial", float("nan")
        breakable = self.model.breakable
        if not ins.allow_failure:
            self.model.breakable = 0
        saved_alpha, self.alpha = self.alpha, ins.damping
        # at least two P-wave transits of the domain before the criterion is trusted
        span = float(np.ptp(self.model.host["node_X"], axis=0).max())
        min_steps = int(2 * span / self.scenario.rock.p_wave_speed / self.dt) + 1
        task = progress.add_task("in-situ relaxation", total=ins.max_steps) if progress else None
        while not converged and steps < ins.max_steps:
            self.step()
            steps += 1
            if steps % 200 == 0:
                e = rock_energies(self.model, self.state)
                ratio = e["kinetic"] / max(e["strain"] + e["springs"], 1e-300)
                self._guard(e)
                converged = steps >= min_steps and ratio < ins.tolerance
                if task is not None:
                    progress.update(task, completed=steps, description=f"in-situ relaxation (KE/U {ratio:.1e})")
        if task is not None:
            progress.update(task, completed=ins.max_steps)
        self.model.breakable, self.alpha = breakable, saved_alpha
        t_relax = self.time
        tb = self.state.pair_tbreak.numpy().copy()
        mode = self.state.pair_mode.numpy()
        tb[mode > 0] -= t_relax                      # pre-stress failures get negative break times
        self.state.pair_tbreak.assign(tb)
        self.state.v.zero_()
        self.state.energy_acc.zero_()
        self.cdem.dt_prev = 0.0
        e = rock_energies(self.model, self.state)
        self.initial_stored = e["strain"] + e["springs"]
        counts = self.fracture.counts(mode)
        self.insitu_report = {
            "method": ins.method, "steps": steps, "pseudo_time": t_relax, "converged": bool(converged),
            "kinetic_to_strain_ratio": ratio, "broken_tensile": counts["tensile"], "broken_shear": counts["shear"],
            "failures_allowed": ins.allow_failure,
        }
        self.time, self.steps = 0.0, 0
        return self.insitu_report

    # ------------------------------------------------------------------ run loop
    def run(self, progress: bool | None = None) -> dict:
        sc = self.scenario
        self.out_dir.mkdir(parents=True, exist_ok=True)
        write_resolved(sc, self.out_dir / "resolved.toml")
        show = sc.simulation.progress if progress is None else progress
        end = sc.simulation.end_time
        frame_dt = sc.output.interval or end / 20
        sample_dt = sc.output.monitor_interval or end / 200
        n_total = math.ceil(end / self.dt)
        if self.max_steps is not None:
            n_total = min(n_total, self.max_steps)
        series = ParaviewSeries(self.out_dir) if sc.output.paraview else None
        mon = CsvHistory(self.out_dir / "monitors.csv", self.monitors.columns)
        frac = CsvHistory(self.out_dir / "fracture_degree.csv", list(self.fracture.sample(self.state.pair_mode.numpy())))
        energy_cols = ["kinetic", "strain", "springs", "fracture", "friction", "viscous_absorbed", "damping",
                       "external_work", "budget_error"]
        energy = CsvHistory(self.out_dir / "energy.csv", energy_cols)
        wall0 = _time.perf_counter()
        with _progress(show) as bar:
            if sc.insitu.active:
                self.relax_insitu(bar)
            task = bar.add_task("dynamic stage", total=n_total) if bar else None
            next_frame, next_sample = 0.0, 0.0
            while self.steps < n_total:
                if self.time >= next_sample - 1e-15:
                    self._sample(mon, frac, energy)
                    next_sample += sample_dt
                if series is not None and self.time >= next_frame - 1e-15:
                    series.write(self.model, self.state, self.time)
                    next_frame += frame_dt
                self.step()
                if task is not None and (self.steps % 50 == 0 or self.steps == n_total):
                    bar.update(task, completed=self.steps,
                               description=f"dynamic stage t = {self.time * 1e6:8.2f} µs")
            wp.synchronize()
            self._sample(mon, frac, energy)
            if series is not None:
                series.write(self.model, self.state, self.time)
        wall = _time.perf_counter() - wall0
        for h in (mon, frac, energy):
            h.flush()
        summary = self.summary(wall)
        write_summary(self.out_dir / "summary.json", summary)
        if sc.output.figures:
            self.write_figures(mon, frac, energy)
        return summary

    def _sample(self, mon: CsvHistory, frac: CsvHistory, energy: CsvHistory) -> None:
        st = self.state
        x, v, sig = st.x.numpy(), st.v.numpy(), st.sigma.numpy()
        mon.append(self.time, self.monitors.sample(x, self.model.host["node_X"], v, sig))
        frac.append(self.time, self.fracture.sample(st.pair_mode.numpy()).values())
        e = rock_energies(self.model, st)
        self._guard(e)
        err, _ = budget_error(e, self.initial_stored)
        energy.append(self.time, [*(e[k] for k in energy.columns[1:-1]), err])

    def _guard(self, e: dict) -> None:
        if not all(math.isfinite(v) for v in e.values()):
            raise SimulationError(
                f"non-finite energy at step {self.steps} (t = {self.time:.4e} s); "
                "reduce simulation.dt_safety or check the loads"
            )

    # ------------------------------------------------------------------ results
    def summary(self, wall: float) -> dict:
        m, st = self.model, self.state
        mode = st.pair_mode.numpy()
        e = rock_energies(m, st)
        err, rel = budget_error(e, self.initial_stored)
        counts = self.fracture.counts(mode)
        return {
            "blastfrac_version": __version__,
            "title": self.scenario.title,
            "device": self.device,
            "counts": {"elements": m.element_count, "nodes": m.node_count, "springs": m.spring_count,
                       "interfaces": m.interface_count, "loaded_edges": m.loaded_edge_count},
            "time_step": self.dt,
            "stable_time_step": m.stable_dt,
            "steps": self.steps,
            "simulated_time": self.time,
            "wall_time_s": wall,
            "element_steps_per_s": m.element_count * self.steps / wall if wall > 0 else None,
            "broken_springs": {"tensile": counts["tensile"], "shear": counts["shear"],
                               "total": counts["tensile"] + counts["shear"]},
            "fracture_degree": self.fracture.sample(mode),
            "energy": {**e, "initial_stored": self.initial_stored, "budget_error": err, "budget_error_relative": rel},
            "insitu_stage": self.insitu_report,
        }

    def write_figures(self, mon: CsvHistory, frac: CsvHistory, energy: CsvHistory) -> None:
        from .plot import figures

        x = self.state.x.numpy()
        seg, cmode = crack_segments(self.model, self.state.pair_mode.numpy(), self.state.pair_tbreak.numpy())
        circles = [(b.center, b.radius) for b in self.scenario.geometry.boreholes]
        title = self.scenario.title or "blastfrac"
        figures.fracture_pattern(self.out_dir / "fracture_pattern.png", x, seg, cmode,
                                 title=f"{title}: cracks at t = {self.time * 1e6:.1f} µs",
                                 show_mesh=self.model.element_count <= 60_000, circles=circles)
        figures.displacement_map(self.out_dir / "displacement.png", x, x - self.model.host["node_X"],
                                 title=f"{title}: |u| at t = {self.time * 1e6:.1f} µs")
        t = np.array([r[0] for r in frac.rows])
        figures.histories(self.out_dir / "fracture_degree.png", t,
                          {k: frac.column(k) for k in frac.columns[1:] if not k.endswith("D_global")},
                          "fracture degree [-]", "Fracture degree")
        figures.histories(self.out_dir / "energy.png", t, {k: energy.column(k) for k in energy.columns[1:]},
                          "energy [J/m]", "Energy budget")
        if mon.columns[1:]:
            tm = np.array([r[0] for r in mon.rows])
            stress = {k: mon.column(k) for k in mon.columns[1:] if k.split(":")[1] in ("sxx", "syy", "sxy", "pressure")}
            if stress:
                figures.histories(self.out_dir / "monitors_stress.png", tm, stress, "stress [MPa]",
                                  "Monitor stresses (tension +)", yscale=1e-6)
            vel = {k: mon.column(k) for k in mon.columns[1:] if k.split(":")[1] in ("vx", "vy", "speed")}
            if vel:
                figures.histories(self.out_dir / "monitors_velocity.png", tm, vel, "velocity [m/s]", "Monitor velocities")


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
