"""Simulation: clock, stable time step, the ordered stages of one step, and the run loop.

The run loop wraps :meth:`Simulation.step` with its callbacks, each on its own schedule:
ParaView frames (``output.interval``), histories (``output.monitor_interval``), the
progress bar and a NaN guard. The in-situ stress stage, when asked for, runs first.
"""

from __future__ import annotations

import math
import os
import sys
import time as _time
from pathlib import Path

import numpy as np
import warp as wp

from . import __version__
from ._warp import resolve_device
from .analysis.energy import budget_error, gas_energies, rock_energies
from .analysis.fracture import FractureDegree, joint_spring_mask
from .analysis.monitors import MonitorSet
from .blowup import diagnose_nonfinite
from .cdem.solver import CDEMSolver
from .coupled_graph import CoupledGraphs
from .io.paraview import GasSeries, ParaviewSeries, crack_segments, joint_segments
from .io.tables import CsvHistory, monitor_unit, write_summary
from .model.builder import ModelBuilder
from .scenario.load import write_resolved
from .run_control import (CHECKPOINT_NAME, RunInterrupted, _install_stop_handlers, _progress,  # noqa: F401
                          _restart_key, _restore_handlers, clear_previous_outputs)
from .scenario.schema import Scenario


_BUDGET_MIN_STEPS = 50      # energy-budget samples before this step are not checked against output.budget_warning


class SimulationError(RuntimeError):
    """The run became unphysical (NaN, blow-up); the message says where and when.

    ``details`` (a dict, also written to summary.json → ``failure``) holds the step, time, the non-finite
    energy terms and the first non-finite node / element / particle with its position.
    """

    def __init__(self, message: str, details: dict | None = None):
        super().__init__(message)
        self.details = details or {}


class Simulation:
    def __init__(self, scenario: Scenario, out_dir: str | Path | None = None, device: str | None = None,
                 max_steps: int | None = None, mesh=None):
        self.scenario = scenario
        self.device = resolve_device(device or scenario.simulation.device)
        self.out_dir = Path(out_dir or scenario.output.directory)
        self.max_steps = max_steps if max_steps is not None else scenario.simulation.max_steps
        self.builder = ModelBuilder(scenario, mesh)
        self.model = self.builder.finalize(self.device)
        self.state = self.model.state()
        # Node-to-edge block contact between separated blocks (cdem/contact.py, METHOD §1.5) is on whenever the
        # springs can break (rock.block_contact); broken springs that have not separated act as unilateral
        # frictional contacts.
        self.cdem = CDEMSolver(self.model, block_contact=scenario.rock.block_contact and self.model.breakable == 1)
        self.gas = None
        self.coupler = None
        self.crack_gas = None
        self.wall_load = None
        from .analysis.ppv import PeakVelocity

        self.ppv = PeakVelocity(self.model.node_count, self.device)      # peak particle velocity per node
        self.cdem.ppv_out = self.ppv.ppv                               # updated by the integration kernel
        self._rock_after = None                                        # nothing after a rock step (graph key)
        # rock-only steps (no gas, or gas frozen) are replayed from a captured graph where they can be
        # (CDEMSolver.step_captured: bit-identical; False runs every step through the launches), and coupled steps
        # with simulation.graph = 'on', or 'auto' on a GPU (coupled_graph.py)
        graph = scenario.simulation.graph
        self.use_graph = graph != "off"
        self.coupled_graph = graph == "on" or (graph == "auto" and self.device != "cpu")
        self.graphs = CoupledGraphs()                       # captured coupled steps (coupled_graph.py)
        self.coupled_graph_steps = 0                        # coupled steps replayed from a graph
        self.coupled_graph_captures = 0                     # ... and graphs captured
        self._dt_since = 0                                  # the step at which Δt last changed
        self.gas_report: dict = {}
        self.charge_mirror = 1.0        # whole charge over modelled charge (half and quarter models)
        if scenario.explosive is not None:
            self._build_explosive()
        self.dt = self._time_step()
        self._pool = None
        self._second = None
        self._parallel = False                             # this step runs stage groups in two threads
        if scenario.simulation.threads > 1 and self.gas is not None and self.device == "cpu" and \
                (os.cpu_count() or 1) > 1:
            from concurrent.futures import ThreadPoolExecutor

            from .second_thread import SecondThread

            self._pool = ThreadPoolExecutor(max_workers=1, thread_name_prefix="blastfrac-gas")
            self._second = SecondThread()                  # whether a step uses it: timed (second_thread.py)
        self.time = 0.0
        self.steps = 0
        self.alpha = scenario.simulation.damping
        X = self.model.host["node_X"]
        self.fracture = FractureDegree(X[self.model.topology.pair_nodes[:, 0]], scenario.zones,
                                       exclude=joint_spring_mask(self.model))      # D counts blast cracks only
        self.monitors = MonitorSet(scenario.monitors, X, self.model.host["node_mass"])
        self.insitu_report: dict | None = None
        self.initial_stored = 0.0
        self.initial_dissipated = 0.0   # fracture energy of springs broken before the dynamic stage [J/m]
        self.warnings: list[str] = []
        self._budget_warned = False

    # ------------------------------------------------------------------ explosive and coupling
    def _build_explosive(self) -> None:
        """MPM products on a grid covering the rock (default) and the particle–edge coupler (METHOD §3)."""
        from .coupling import GasRockCoupler, clear_from_rock, default_contact_stiffness
        from .explosives.library import cj_report
        from .mpm.solver import MPMSolver
        from .scenario.errors import ScenarioError

        sc = self.scenario
        ex = sc.explosive
        if ex.grid.bounds is None and ex.grid.margin is None:
            X = self.model.host["node_X"]
            lo, hi = X.min(axis=0), X.max(axis=0)
            ex = ex.model_copy(update={"grid": ex.grid.model_copy(update={"bounds": (tuple(lo), tuple(hi))})})
        lines = sc.geometry.symmetry_lines()          # half and quarter models: charges cut at the symmetry lines,
        if lines:                                     # the grid's slip walls on them (mpm/seeding.py, grid_from_config)
            from .mpm.seeding import cut_charges, fold_to_modelled_side, symmetry_cuts

            full = sum(c.area for c in ex.charges)
            ex = ex.model_copy(update={"charges": cut_charges(ex.charges, lines)})
            self.charge_mirror = full / sum(c.area for c in ex.charges) if ex.charges else 1.0
        cp = sc.coupling
        spacing = ex.grid.cell_size / ex.grid.points_per_cell
        clearance = cp.wall_clearance * 0.5 * spacing
        removed = [0]

        def keep_clear(x, vol):                 # called for the charges' points, then for each elastic body's
            x2, vol2, n_removed, keep = clear_from_rock(x, vol, self.model, clearance, return_mask=True)
            if lines:                           # a point pushed off a wall across a symmetry line: its image
                x2 = fold_to_modelled_side(x2, symmetry_cuts(ex.charges))
            removed[0] += n_removed
            return x2, vol2, keep

        if sc.crack_gas.enabled and not ex.charges:
            raise ScenarioError("crack_gas.enabled: needs explosive.charges (the crack gas is the charges' products; "
                                "this run has elastic bodies only)")
        self.gas = MPMSolver(ex, device=self.device, particle_filter=keep_clear)
        if self.gas.n == 0:
            what = "charges" if ex.charges else "bodies"
            raise ScenarioError(f"explosive.{what}: no material point left after clearing the rock; the {what} must "
                                "lie in boreholes or outside the rock, at least one particle spacing wide")
        cj = cj_report(self.gas.material, ex.name or "custom") if self.gas.is_jwl else None
        if cp.contact_stiffness:
            kc = cp.contact_stiffness
        elif self.gas.is_jwl:
            kc = default_contact_stiffness(self.gas.p_cj, cp.stiffness_factor)
        else:                                       # no charges: scaled on the stiffest body (mpm/bodies.py)
            from .mpm.bodies import body_contact_stiffness

            kc = body_contact_stiffness(self.gas.bodies, cp.stiffness_factor)
        self.coupler = GasRockCoupler(self.model, self.gas, kc, cp.damping_ratio, cp.friction, cp.rebuild_interval,
                                      force_cap=cp.force_cap, surface_forces=cp.surface_forces,
                                      pressure_preload=cp.pressure_preload, contact_heating=cp.contact_heating)
        if sc.geometry.boreholes:
            from .analysis.wall_load import WallLoad

            self.wall_load = WallLoad(self.model, sc.geometry.boreholes, self.device)
        if sc.crack_gas.enabled:
            from .coupling.crack_gas import CrackGas

            cg = sc.crack_gas
            self.crack_gas = CrackGas(self.model, self.gas, cg.viscosity, cg.min_aperture,
                                      cg.mouth_radius if cg.mouth_radius is not None else self.gas.spec.h,
                                      rebuild_interval=cp.rebuild_interval, particle_floor=cg.particle_floor)
            self.coupler.mass_floor = cg.particle_floor      # particles that feed cracks get lighter
        self.gas_report = {
            "particles": self.gas.n, "removed_at_seeding": removed[0], "grid_nodes": self.gas.spec.node_count,
            "cell_size": self.gas.spec.h, "contact_stiffness": kc, "contact_dt": self.coupler.stable_dt(),
            "cj_check": cj,
        }
        if ex.bodies:
            self.gas_report["bodies"] = self._body_report(ex.bodies)

    def _body_report(self, bodies) -> list[dict]:
        """summary.json → explosive.bodies: each elastic body's name, points, mass [kg/m], P-wave speed [m/s],
        impedance ρc_p [Pa·s/m] and initial velocity [m/s]."""
        mass, bid = self.gas.mass.numpy(), self.gas.body_id
        return [{"name": b.name or f"body{k}", "particles": int((bid == k).sum()), "mass": float(mass[bid == k].sum()),
                 "p_wave_speed": b.p_wave_speed, "impedance": b.density * b.p_wave_speed,
                 "velocity": list(b.velocity)} for k, b in enumerate(bodies)]

    def _time_step(self) -> float:
        """min(safety·Δt_rock, safety·Δt_contact, Δt_MPM) [s]; the MPM CFL factor is its own safety."""
        safety = self.scenario.simulation.dt_safety
        dt = safety * self.model.stable_dt
        if self.gas is not None:
            dt = min(dt, safety * self.coupler.stable_dt(), self.gas.stable_dt())
        return dt

    # ------------------------------------------------------------------ one step
    def step(self, gas: bool = True) -> None:
        """Advance rock (and gas) by one explicit step (METHOD §3.1); ``gas=False`` freezes the explosive.

        Order: springs and failure, then the rock's CST with the springs' forces; then its loads and block contact, and (reading only
        x, v and the new pair_mode) the gas's particle–edge contact, crack gas, P2G and grid update, which write
        their rock loads into their own buffers; the gas loads are added to the rock's forces; then the rock's
        integration and the gas's G2P and EOS. With ``simulation.threads = 2``, on the steps where timing found it
        faster (second_thread.py), the rock's per-item stages run in two halves and the gas's stage groups beside
        the rock's where the second thread is free (CDEMSolver.forces_rest); the arithmetic is the same, so the
        results are too.
        """
        dt = self.dt
        st = self.state
        couple = gas and self.gas is not None
        graph = couple and self.coupled_graph
        if self._second is not None and not graph:         # the second thread where it measured faster
            self._parallel = couple and self._second.use(self.steps)
            self.cdem.pool = self._pool if self._parallel else None
        if not couple and self.use_graph and self.cdem.step_captured(st, dt, self.time, self.alpha, self._rock_after):
            pass                                           # the rock step below, replayed from a captured graph
        elif graph and self.graphs.step(self, dt):
            pass                                           # the coupled step below, replayed from a captured graph
        elif couple:
            self.cdem.forces_springs_blocks(st, dt, self.time)   # springs + failure (this step's pair_mode), CST
            # the rock's rest, and the gas's forces beside it in the second thread (handed over where it is free)
            self.cdem.forces_rest(st, dt, self.time, beside=lambda: self._gas_forces(dt), blocks_done=True)
            self.coupler.add_reactions(st)                 # the gas loads on the rock, in a fixed order
            if self.crack_gas is not None:
                self.crack_gas.add_loads(st)
            if self.cdem.splits("integrate", self.model.element_count):
                # in two parts, the gas's advance before the second one in the second thread (balanced)
                self.cdem.integrate(st, dt, self.alpha, beside=lambda: self._gas_advance(dt))
            else:
                self._concurrently(lambda: self.cdem.integrate(st, dt, self.alpha), lambda: self._gas_advance(dt))
        else:
            self.cdem.forces_springs(st, dt, self.time)    # springs + failure
            self.cdem.forces_rest(st, dt, self.time)       # CST, loads, block contact
            self.cdem.integrate(st, dt, self.alpha)        # central difference on rock nodes, PPV: max |v| per node
        self.time += dt
        self.steps += 1
        if couple and self.gas.grid.box_age == 0:
            self.coupler.note_reach()                      # with the box's renewal: the hash's next cell width
        if couple and self.steps % 10 == 0:
            dt_new = self._time_step()
            if dt_new != self.dt:
                self._dt_since = self.steps                # a captured step waits until Δt has settled
            self.dt = dt_new
        if self.cdem.contact is not None and not self.cdem.contact.active and self.steps % 16 == 0:
            self.cdem.contact.active = self.cdem.contact.any_dropped(self.state)

    def _gas_forces(self, dt: float) -> None:
        """Particle–edge contact (gas f_ext_p, rock reactions into f_react), wall load, crack gas, P2G, grid."""
        st = self.state
        self.coupler.apply(st, dt)
        if self.wall_load is not None:
            self.wall_load.accumulate(self.coupler.f_react, dt)
        if self.crack_gas is not None:
            self.crack_gas.apply(st, dt)                   # face loads into its buffer, flow, exchange at mouths
        self.gas.to_grid(dt)                               # P2G with the contact forces
        self.gas.update_grid(dt)

    def _gas_advance(self, dt: float) -> None:
        self.gas.to_particles(dt)                          # G2P, MUSL remap, particle motion
        self.gas.update_eos(dt, self.time)                 # burn, viscosity, JWL

    def _concurrently(self, rock, gas) -> None:
        """Run the two stage groups, in the second thread when simulation.threads = 2 and this step uses it (never the
        first step, which loads every kernel's module, which Warp does not guard against two threads; after it, where
        timing the run's steps found it faster: second_thread.py)."""
        if not self._parallel:
            rock()
            gas()
            return
        fut = self._pool.submit(gas)
        try:
            rock()
        finally:
            fut.result()

    # ------------------------------------------------------------------ in-situ stage
    def relax_insitu(self, progress=None) -> dict:
        """Initialise σ⁰, apply consistent tractions and relax quasi-statically (METHOD §1.8; insitu_stage.py);
        returns the stage's report (summary.json → insitu_stage)."""
        from .insitu_stage import relax_insitu

        return relax_insitu(self, progress)

    # ------------------------------------------------------------------ run loop
    def run(self, progress: bool | None = None, restart: str | Path | None = None) -> dict:
        """Run to ``simulation.end_time`` (or ``max_steps``) and write the results; returns the summary.

        ``restart``: a checkpoint file (io/checkpoint.py) of this scenario to continue from. SIGINT/SIGTERM finish
        the current step, write a checkpoint, every CSV and summary.json (status 'interrupted') and raise
        :class:`RunInterrupted`.
        """
        sc = self.scenario
        self.out_dir.mkdir(parents=True, exist_ok=True)
        if restart is None:
            self.cleared = clear_previous_outputs(self.out_dir)
        write_resolved(sc, self.out_dir / "resolved.toml")
        show = sc.simulation.progress if progress is None else progress
        self._open_outputs()
        if restart is not None:
            self._load_checkpoint(Path(restart))
        wall0 = _time.perf_counter() - self._wall_before
        self._stop_signal = None
        handlers = _install_stop_handlers(self)
        try:
            self._run_loop(show)
        except SimulationError as err:
            self._write_failed(err, _time.perf_counter() - wall0, (self._mon, self._frac, self._energy))
            raise
        finally:
            _restore_handlers(handlers)
        wall = _time.perf_counter() - wall0
        if self._stop_signal is not None:
            self.write_checkpoint(wall)          # before the closing sample: a restart continues the schedule
            self._sample()
            self._flush_histories()
            summary = self.summary(wall)
            summary["status"] = "interrupted"
            summary["checkpoint"] = str(self.out_dir / CHECKPOINT_NAME)
            write_summary(self.out_dir / "summary.json", summary)
            raise RunInterrupted(self._stop_signal, self.out_dir)
        self._flush_histories()
        summary = self.summary(wall)
        write_summary(self.out_dir / "summary.json", summary)
        self.write_fragments()
        self.write_vibration()
        if sc.output.figures:
            self.write_figures(self._mon, self._frac, self._energy, cracks=summary["cracks"])
        return summary

    def _open_outputs(self) -> None:
        """The histories, ParaView series and the run loop's schedule (what a checkpoint saves besides the state)."""
        sc = self.scenario
        end = sc.simulation.end_time
        self._frame_dt = sc.output.interval or end / 20
        self._sample_dt = sc.output.monitor_interval or end / 200
        self._snap_times = list(sc.output.snapshot_times) or [end * k / 4 for k in (1, 2, 3, 4)]
        self._checkpoint_dt = sc.output.checkpoint_interval
        self.snapshots: list[dict] = []
        self._series = ParaviewSeries(self.out_dir) if sc.output.paraview else None
        self._gas_series = GasSeries(self.out_dir) if sc.output.paraview and self.gas is not None else None
        self._mon = CsvHistory(self.out_dir / "monitors.csv", self.monitors.columns, unit=monitor_unit)
        self._frac = CsvHistory(self.out_dir / "fracture_degree.csv",
                                list(self.fracture.sample(self.state.pair_mode.numpy())), unit="-")
        energy_cols = ["kinetic", "strain", "springs", "fracture", "friction", "viscous_absorbed", "damping",
                       "external_work"]
        if self.gas is not None:
            energy_cols += ["explosive_released", "gas_internal", "gas_kinetic", "contact_energy"]
            if self.gas.n_solid:
                energy_cols += ["body_kinetic", "body_strain"]
            if self.crack_gas is not None:
                energy_cols += ["crack_gas"]
        self._energy = CsvHistory(self.out_dir / "energy.csv", energy_cols + ["budget_error"], unit="J/m")
        self._wall_csv = (CsvHistory(self.out_dir / "borehole_pressure.csv", self.wall_load.names, unit="Pa")
                          if self.wall_load is not None else None)
        self._next_frame = self._next_sample = 0.0
        self._k_snap = 0
        self._next_checkpoint = self._checkpoint_dt if self._checkpoint_dt else math.inf
        self._insitu_done = False
        self._wall_before = 0.0

    def _histories(self) -> dict:
        return {"monitors": self._mon, "fracture_degree": self._frac, "energy": self._energy,
                "borehole_pressure": self._wall_csv}

    def _flush_histories(self) -> None:
        for h in self._histories().values():
            if h is not None:
                h.flush()

    # ------------------------------------------------------------------ checkpoint and restart
    def write_checkpoint(self, wall: float | None = None) -> Path:
        """The full state of the run now, atomically, as ``checkpoint.npz`` in the output directory."""
        from .io import checkpoint as ckpt
        from .scenario.load import resolved_dict

        run = {"next_frame": self._next_frame, "next_sample": self._next_sample, "k_snap": self._k_snap,
               "next_checkpoint": self._next_checkpoint, "insitu_done": self._insitu_done,
               "wall": wall if wall is not None else self._wall_before, "warnings": list(self.warnings),
               "budget_warned": self._budget_warned, "insitu_report": self.insitu_report,
               "rows": {k: h.rows for k, h in self._histories().items() if h is not None},
               "frames": {"rock": self._series.frames if self._series else [],
                          "gas": self._gas_series.frames if self._gas_series else []},
               "snapshots": [{k: v for k, v in s.items() if not isinstance(v, np.ndarray)} for s in self.snapshots]}
        extra = {f"snap{i}/{k}": v for i, s in enumerate(self.snapshots) for k, v in s.items() if isinstance(v, np.ndarray)}
        path = self.out_dir / CHECKPOINT_NAME
        ckpt.write(path, self, run, _restart_key(resolved_dict(self.scenario)), __version__, extra=extra)
        return path

    def _load_checkpoint(self, path: Path) -> None:
        from .io import checkpoint as ckpt
        from .scenario.load import resolved_dict

        arrays, meta = ckpt.read(path)
        if meta.get("scenario_hash") != ckpt.scenario_hash(_restart_key(resolved_dict(self.scenario))):
            raise ValueError(f"--restart {path}: the checkpoint was made from another scenario (only "
                             "simulation.end_time, max_steps, progress, device, threads, graph and [output] may change)")
        extra = {k: arrays.pop(k) for k in list(arrays) if k.startswith("snap")}
        ckpt.restore(self, arrays, meta["scalars"])
        run = meta["run"]
        self._next_frame, self._next_sample, self._k_snap = run["next_frame"], run["next_sample"], run["k_snap"]
        self._next_checkpoint = (self.time + self._checkpoint_dt) if self._checkpoint_dt else math.inf
        self._insitu_done, self._wall_before = run["insitu_done"], run["wall"]
        self.warnings, self._budget_warned, self.insitu_report = run["warnings"], run["budget_warned"], run["insitu_report"]
        for k, h in self._histories().items():
            if h is not None:
                h.rows = [list(r) for r in run["rows"].get(k, [])]
        if self._series is not None:
            self._series.frames = [tuple(f) for f in run["frames"]["rock"]]
        if self._gas_series is not None:
            self._gas_series.frames = [tuple(f) for f in run["frames"]["gas"]]
        self.snapshots = []
        for i, s in enumerate(run["snapshots"]):
            d = dict(s)
            d.update({k.split("/", 1)[1]: v for k, v in extra.items() if k.startswith(f"snap{i}/")})
            self.snapshots.append(d)

    def _write_failed(self, err: SimulationError, wall: float, histories) -> None:
        """After a blow-up: the CSV histories up to the failure and summary.json with ``status = 'failed'``."""
        for h in (*histories, getattr(self, "_wall_csv", None)):
            if h is not None:
                h.flush()
        try:
            summary = self.summary(wall)
        except Exception as e2:  # noqa: BLE001 - the state is broken; keep what can be said
            summary = {"blastfrac_version": __version__, "title": self.scenario.title, "device": self.device,
                       "steps": self.steps, "simulated_time": self.time, "time_step": self.dt,
                       "summary_error": f"{type(e2).__name__}: {e2}"}
        summary["status"] = "failed"
        summary["error"] = str(err)
        summary["failure"] = err.details
        write_summary(self.out_dir / "summary.json", summary)

    def _run_loop(self, show) -> None:
        sc = self.scenario
        end = sc.simulation.end_time
        series, gas_series = self._series, self._gas_series
        with _progress(show) as bar:
            if sc.insitu.active and not self._insitu_done:
                self.relax_insitu(bar)
                self._insitu_done = True
            n_est = self.steps + math.ceil(max(end - self.time, 0.0) / self.dt)
            if self.max_steps is not None:
                n_est = min(n_est, self.max_steps)
            task = bar.add_task("dynamic stage", total=n_est, completed=self.steps) if bar else None
            while self.time < end * (1 - 1e-12) and (self.max_steps is None or self.steps < self.max_steps):
                if self.time >= self._next_sample - 1e-15:
                    self._sample()
                    self._next_sample += self._sample_dt
                if self.time >= self._next_frame - 1e-15:
                    if series is not None:
                        series.write(self.model, self.state, self.time, crack_gas=self.crack_gas, ppv=self.ppv.values())
                    if gas_series is not None:
                        gas_series.write(self.gas, self.time)
                    self._next_frame += self._frame_dt
                if self._k_snap < len(self._snap_times) and self.time >= self._snap_times[self._k_snap] - 0.5 * self.dt:
                    self._snapshot()
                    self._k_snap += 1
                self.step()
                if self.time >= self._next_checkpoint - 1e-15:
                    self.write_checkpoint()
                    self._flush_histories()
                    self._next_checkpoint += self._checkpoint_dt
                if self._stop_signal is not None:
                    return
                if task is not None and self.steps % 50 == 0:
                    if self.gas is not None:   # the step may change with the gas speed: re-estimate the total
                        n_est = self.steps + math.ceil(max(end - self.time, 0.0) / self.dt)
                        if self.max_steps is not None:
                            n_est = min(n_est, self.max_steps)
                    bar.update(task, completed=self.steps, total=n_est,
                               description=f"dynamic stage t = {self.time * 1e6:8.2f} µs")
            wp.synchronize()
            if task is not None:
                bar.update(task, completed=self.steps, total=self.steps)
            if self._checkpoint_dt:                # the end state too, before the closing sample: a restart with a
                self.write_checkpoint()            # later end_time continues from here
            self._sample()
            if series is not None:
                series.write(self.model, self.state, self.time, crack_gas=self.crack_gas, ppv=self.ppv.values())
            if gas_series is not None:
                gas_series.write(self.gas, self.time)
            if self._k_snap < len(self._snap_times) or not self.snapshots:
                self._snapshot()

    def energies(self) -> dict[str, float]:
        """All energy terms of rock, gas and contact [J/m] (see analysis.energy)."""
        e = rock_energies(self.model, self.state)
        if self.gas is not None:
            e.update(gas_energies(self.gas))
            c = self.coupler.energies()
            e["contact_energy"] = c["contact_energy"]
            if self.coupler.contact_heating:
                e["contact_heat"] = c["contact_heat"]          # already in gas_internal: not a budget term
            if self.crack_gas is not None:
                e["crack_gas"] = self.crack_gas.energies()["crack_gas"]
        return e

    def _gas_pressure(self, pts: np.ndarray) -> np.ndarray:
        return self.gas.pressure_at(pts)

    def _sample(self) -> None:
        mon, frac, energy = self._mon, self._frac, self._energy
        st = self.state
        x, v, sig = st.x.numpy(), st.v.numpy(), st.sigma.numpy()
        gp = self._gas_pressure if self.gas is not None else None
        mon.append(self.time, self.monitors.sample(x, self.model.host["node_X"], v, sig, gas_pressure=gp))
        frac.append(self.time, self.fracture.sample(st.pair_mode.numpy()).values())
        e = self.energies()
        err, rel = budget_error(e, self.initial_stored + self.initial_dissipated)
        energy.append(self.time, [*(e[k] for k in energy.columns[1:-1]), err])
        if getattr(self, "_wall_csv", None) is not None:
            t0 = self.wall_load._t_last
            p = self.wall_load.sample(self.time)
            if self.time > t0:
                self._wall_csv.append(0.5 * (t0 + self.time), p)   # the mean over (t0, t]: at the interval's middle
        self._guard(e)
        self._check_budget(err, rel)

    def _check_budget(self, err: float, rel: float, final: bool = False) -> None:
        """Warn once (stderr and summary.json → warnings) when |budget_error_relative| > output.budget_warning.

        Samples of the first ``_BUDGET_MIN_STEPS`` steps are not checked, not even the final one of so short a run
        (the work sums lag the state by one step, a large fraction of the tiny energies at the start); the final
        state of a longer run always is.
        """
        limit = self.scenario.output.budget_warning
        if self._budget_warned or not abs(rel) > limit or self.steps < _BUDGET_MIN_STEPS:
            return
        self._budget_warned = True
        msg = (f"energy budget error {rel * 100:+.1f} % ({err:.4g} J/m) at step {self.steps} (t = {self.time:.4e} s) "
               f"exceeds output.budget_warning = {limit * 100:g} %; the energy terms do not balance "
               "(see docs/results.md, 'Energy budget'); check the time step (simulation.dt_safety) and the contact "
               "settings before trusting the energies")
        self.warnings.append(msg)
        print(f"warning: {msg}", file=sys.stderr, flush=True)

    def _snapshot(self) -> None:
        x = self.state.x.numpy().copy()
        snap = {"time": self.time, "x": x, "u": x - self.model.host["node_X"]}
        if self.gas is not None:
            f = self.gas.particle_fields()
            snap["gas_x"], snap["gas_p"] = f["position"], f["pressure"]
        self.snapshots.append(snap)

    def _guard(self, e: dict) -> None:
        if not all(math.isfinite(v) for v in e.values()):
            msg, details = diagnose_nonfinite(self, e)
            raise SimulationError(msg, details)

    # ------------------------------------------------------------------ results
    def summary(self, wall: float) -> dict:
        m, st = self.model, self.state
        mode = st.pair_mode.numpy()
        e = self.energies()
        err, rel = budget_error(e, self.initial_stored + self.initial_dissipated)
        counts = self.fracture.counts(mode)
        out = {
            "blastfrac_version": __version__,
            "title": self.scenario.title,
            "device": self.device,
            "counts": {"elements": m.element_count, "nodes": m.node_count, "springs": m.spring_count,
                       "interfaces": m.interface_count, "loaded_edges": m.loaded_edge_count,
                       "particles": self.gas.n if self.gas is not None else 0},
            "time_step": self.dt,
            "stable_time_step": m.stable_dt,
            "steps": self.steps,
            "simulated_time": self.time,
            "wall_time_s": wall,
            "element_steps_per_s": m.element_count * self.steps / wall if wall > 0 else None,
            "broken_springs": {"tensile": counts["tensile"], "shear": counts["shear"], "crushed": counts["crushed"],
                               "total": counts["tensile"] + counts["shear"] + counts["crushed"]},
            "fracture_degree": self.fracture.sample(mode),
            "energy": {**e, "initial_stored": self.initial_stored, "initial_dissipated": self.initial_dissipated,
                       "budget_error": err, "budget_error_relative": rel},
            "elastic": m.elastic.as_dict(),
            "insitu_stage": self.insitu_report,
            "cracks": self.crack_statistics(),
            "fragmentation": self.fragmentation()[1],
            "vibration": self.vibration()[0],
            "monitors": self.monitors.report(),
            "status": "completed",
            "warnings": list(self.warnings),
        }
        if self.scenario.geometry.symmetry:                # a half or quarter model (analysis/symmetry.py)
            from .analysis.symmetry import symmetry_report

            out["symmetry"] = symmetry_report(self.scenario)
        if self._second is not None:
            out["threads"] = self._second.report()
        out["graph"] = {"mode": self.scenario.simulation.graph, "rock_steps_replayed": self.cdem.graph_steps,
                        "coupled_steps_replayed": self.coupled_graph_steps,
                        "coupled_graphs_captured": self.coupled_graph_captures}
        if self.gas is not None:
            out["explosive"] = {**self.gas_report, "deactivated_particles": self.gas.deactivated_count,
                                "contact_dt": self.coupler.stable_dt(), "contacts_now": self.coupler.energies()["contacts"]}
            if self.crack_gas is not None:
                out["crack_gas"] = self.crack_gas.report()
        if not self._budget_warned and abs(rel) > self.scenario.output.budget_warning:
            self._check_budget(err, rel, final=True)   # the final state is over the limit: warn now
            out["warnings"] = list(self.warnings)
        return out

    def fragmentation(self) -> tuple[dict, dict]:
        """(per-fragment arrays, summary report) of the present state (analysis/fragments.py)."""
        from .analysis.fragments import fragmentation_report, fragments

        key = (self.steps, self.time)          # summary, fragments.csv and the figure read it at one state
        cached = getattr(self, "_fragmentation_at", None)
        if cached is None or cached[0] != key:
            fr = fragments(self.model, self.state)
            self._fragmentation_at = (key, (fr, fragmentation_report(fr)))
        return self._fragmentation_at[1]

    def vibration(self) -> tuple[dict | None, dict | None]:
        """(summary.json → vibration, ring profile) from the nodes' PPV about the holes (analysis/ppv.py); (None,
        None) without a hole or charge to measure distances from."""
        from .analysis.ppv import vibration_report

        key = (self.steps, self.time)
        cached = getattr(self, "_vibration_at", None)
        if cached is not None and cached[0] == key:
            return cached[1]
        centres = self.crack_centres()
        if not centres:
            return None, None
        Q = None
        if self.gas is not None:
            # the whole hole's charge (a half or quarter model seeds its modelled part, analysis/symmetry.py)
            Q = float(self.gas.mass0_total) * self.charge_mirror / len(centres) or None  # None: no charge
        rep, prof = vibration_report(self.model.host["node_X"], self.ppv.values(), centres, Q if Q else 1.0,
                                     self.scenario.rock)
        if Q is None:
            rep["charge_per_hole"] = None
            rep["attenuation"]["law"] = "PPV = K R^-beta (no charge: R unscaled)"
        self._vibration_at = (key, (rep, prof))
        return rep, prof

    def write_fragments(self) -> None:
        """fragments.csv: one row per fragment, largest first (analysis/fragments.py)."""
        from .io.tables import write_table

        fr, _ = self.fragmentation()
        cols = [("area", "m^2"), ("size", "m"), ("centroid_x", "m"), ("centroid_y", "m"), ("velocity_x", "m/s"),
                ("velocity_y", "m/s"), ("blocks", "-"), ("touches_outer_boundary", "-")]
        write_table(self.out_dir / "fragments.csv", [(f"{k} [{u}]", fr[k]) for k, u in cols])

    def write_vibration(self) -> None:
        """ppv_profile.csv: the ring medians and maxima of the PPV against the distance from the holes."""
        from .io.tables import write_table

        _, prof = self.vibration()
        if prof is not None:
            write_table(self.out_dir / "ppv_profile.csv", [("radius [m]", prof["radius"]), ("ppv_median [m/s]", prof["median"]),
                                                            ("ppv_max [m/s]", prof["max"]), ("nodes [-]", prof["nodes"])])

    def crack_statistics(self) -> list[dict]:
        """Crushed-zone radius, radial crack count and lengths around each borehole (analysis.cracks)."""
        from .analysis.cracks import crack_statistics

        mode = self.state.pair_mode.numpy()
        return [crack_statistics(self.model, mode, np.asarray(c, float), r) for c, r in self.crack_centres()]

    def crack_centres(self) -> list[tuple[tuple[float, float], float]]:
        """(centre [m], radius [m]) about which cracks are counted: the boreholes, else the charges."""
        centres = [(b.center, b.radius) for b in self.scenario.geometry.boreholes]
        if not centres and self.scenario.explosive is not None:
            from .mpm.seeding import charge_area_centroid, charge_bbox

            for c in self.scenario.explosive.charges:
                lo, hi = charge_bbox(c)
                centres.append((tuple(charge_area_centroid(c)[1]), 0.5 * float(np.min(hi - lo))))
        return centres

    def write_figures(self, mon: CsvHistory, frac: CsvHistory, energy: CsvHistory, cracks: list[dict] | None = None) -> None:
        from .plot import figures

        x = self.state.x.numpy()
        from .analysis.cracks import detached_interface_mask

        pm = self.state.pair_mode.numpy()
        seg, cmode = crack_segments(self.model, pm, self.state.pair_tbreak.numpy())
        circles = [(b.center, b.radius) for b in self.scenario.geometry.boreholes]
        holes = self.crack_centres()
        detached = (detached_interface_mask(self.model, pm, holes)[(pm.reshape(-1, 2) > 0).any(axis=1)]
                    if holes else None)
        title = self.scenario.title or "blastfrac"
        figures.fracture_pattern(self.out_dir / "fracture_pattern.png", x, seg, cmode,
                                 title=f"{title}: cracks at t = {self.time * 1e6:.1f} µs",
                                 show_mesh=self.model.element_count <= 60_000, circles=circles, detached=detached,
                                 joints=joint_segments(self.model))
        figures.displacement_map(self.out_dir / "displacement.png", x, x - self.model.host["node_X"],
                                 title=f"{title}: |u| at t = {self.time * 1e6:.1f} µs")
        if self.snapshots:
            figures.displacement_snapshots(self.out_dir / "displacement_snapshots.png", self.snapshots,
                                           title=f"{title}: displacement magnitude")
        if self.gas is not None:
            f = self.gas.particle_fields()
            gas_seg = gas_p = None
            if self.crack_gas is not None:
                from .coupling.crack_gas import PRESSURISED

                filled = np.flatnonzero(self.crack_gas.gas.pres.numpy()[: self.crack_gas.Q] >= PRESSURISED)
                pn = self.model.topology.pair_nodes
                gas_seg = np.stack([pn[2 * filled, 0], pn[2 * filled + 1, 0]], 1)
                gas_p = self.crack_gas.gas.pres.numpy()[filled]
            figures.gas_particles(self.out_dir / "gas_pressure.png", f["position"], f["pressure"], x, seg, cmode,
                                  title=f"{title}: gas pressure at t = {self.time * 1e6:.1f} µs",
                                  gas_seg=gas_seg, gas_p=gas_p)
        fr, frep = self.fragmentation()
        figures.fragment_sizes(self.out_dir / "fragment_sizes.png", fr["size"], fr["area"],
                               ~fr["touches_outer_boundary"], frep,
                               title=f"{title}: fragment sizes at t = {self.time * 1e6:.1f} µs (fragments not touching "
                                     "the outer boundary; single blocks are at the mesh scale)")
        vib, prof = self.vibration()
        if vib is not None:
            figures.ppv_map(self.out_dir / "ppv_map.png", self.model.host["node_X"], self.ppv.values(),
                            self.crack_centres(), vib, title=f"{title}: peak particle velocity up to "
                                                             f"t = {self.time * 1e6:.1f} µs")
            figures.ppv_distance(self.out_dir / "ppv_distance.png", prof, vib,
                                 title=f"{title}: PPV against the distance from the hole")
        cracks = self.crack_statistics() if cracks is None else cracks
        if cracks:
            figures.crack_profile(self.out_dir / "crack_profile.png", cracks,
                                  title=f"{title}: cracks crossing circles about the hole (dotted: r_c; grey dashed: "
                                        "r_k; dash-dot: r_d)")
        t = np.array([r[0] for r in frac.rows])
        figures.fracture_degree_zones(self.out_dir / "fracture_degree.png", t,
                                      {k: frac.column(k) for k in frac.columns[1:]}, title=f"{title}: fracture degree")
        figures.histories(self.out_dir / "energy.png", t, {k: energy.column(k) for k in energy.columns[1:]},
                          "energy [J/m]", "Energy budget")
        if mon.columns[1:]:
            tm = np.array([r[0] for r in mon.rows])
            stress = {k: mon.column(k) for k in mon.columns[1:]
                      if k.split(":")[1] in ("sxx", "syy", "sxy", "pressure", "gas_pressure")}
            if stress:
                figures.histories(self.out_dir / "monitors_stress.png", tm, stress, "stress [MPa]",
                                  "Monitor stresses (tension +) and pressures (compression +)", yscale=1e-6)
            vel = {k: mon.column(k) for k in mon.columns[1:] if k.split(":")[1] in ("vx", "vy", "speed")}
            if vel:
                figures.histories(self.out_dir / "monitors_velocity.png", tm, vel, "velocity [m/s]", "Monitor velocities")
