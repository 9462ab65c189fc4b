"""Quasi-static platen loading of a specimen: the time loop shared by the UCS and Brazilian tests.

Control (METHOD §5.2, second option): both platens close at the same constant speed v [m/s]
(default 0.05 m/s each), reached over a smooth ramp of 20 P-wave transits, with **no damping**
(α = 0). The loading is slow enough that halving v moves the strengths by < 1 % on the paper-sized
specimens (docs/calibration.md, examples/calibration/README.md).

Why not Cundall local damping α = 0.8 (METHOD §1.6)? Its force −α|f|·sign(v) opposes the *motion*
of every node that carries an unbalanced force, also the steady motion of a specimen that is
being compressed; the platens then push against that drag as well as against the specimen. Measured
on the coarse prism with the paper's springs: E' 53.15 GPa at 0.1 m/s and 52.96 at 0.025 m/s against
51.63 GPa from the exact static solve (:func:`.elastic.static_moduli`) and 52.08 GPa for the blocks
alone, and a coarse-disc σt that falls 18 % when 0.1 m/s is halved; with α = 0 the same runs give
51.68 GPa and +0.2 %. α is still a setting (``damping``) for comparisons.
Samples of the platen reactions and the specimen's node displacements are taken every
``sample_strain`` of nominal strain (platen closure / specimen height); the run stops once
the load has dropped below ``stop_drop`` × peak after the peak, or at ``max_strain``.
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, field

import numpy as np

from ..cdem.solver import CDEMSolver
from ..model.builder import has_contact_allowance
from .loading import Platens, ramped_displacement


@dataclass
class LoadSettings:
    """Loading control of one test (SI units).

    speed: speed of each platen [m/s]; damping: local damping α [-];
    ramp_transits: duration of the speed ramp in P-wave transits of the specimen height [-];
    dt_safety: fraction of the Gershgorin stable step [-];
    sample_strain: nominal strain between samples [-]; max_strain: nominal strain cap [-];
    stop_drop: stop once the load falls below this fraction of the peak, after the peak [-];
    failure_drop: relative drop below the running maximum that marks macroscopic failure; the
    strength is that running maximum (the first peak) [-];
    post_peak_strain: after failure, continue up to this multiple of the nominal strain at the
    first peak (for the post-peak curve and the crack picture) [-];
    jaw_ratio: jaw radius / disc radius (0 = flat platens) [-];
    loading_arc: if > 0, only rim nodes within ±loading_arc/2 of the loaded diameter touch the
    platens (a loading arc 2α, as in numerical Brazilian tests) [deg];
    bonded: tie contacting nodes laterally (no-slip platen) instead of free slip;
    penalty: platen node stiffness as a multiple of the median spring stiffness Kn = kn·Ac [-].
    """

    speed: float = 0.05
    damping: float = 0.0
    ramp_transits: float = 20.0
    dt_safety: float = 0.8
    sample_strain: float = 2e-5
    max_strain: float = 0.02
    stop_drop: float = 0.6
    failure_drop: float = 0.02
    post_peak_strain: float = 1.5
    jaw_ratio: float = 0.0
    loading_arc: float = 0.0
    bonded: bool = False
    penalty: float = 0.5

    def as_dict(self) -> dict:
        return asdict(self)


@dataclass
class LoadHistory:
    """Samples of one test; arrays of equal length. Units: s, m, N/m, counts."""

    time: list = field(default_factory=list)
    platen_u: list = field(default_factory=list)           # displacement of each platen [m]
    reaction_top: list = field(default_factory=list)       # [N/m]
    reaction_bottom: list = field(default_factory=list)    # [N/m]
    axial_u: list = field(default_factory=list)            # shortening of the specimen between its faces [m]
    lateral_u: list = field(default_factory=list)          # widening between the side faces [m]
    tensile: list = field(default_factory=list)            # broken springs (tensile mode)
    shear: list = field(default_factory=list)

    def arrays(self) -> dict[str, np.ndarray]:
        return {k: np.asarray(v, float) for k, v in asdict(self).items()}

    @property
    def reaction(self) -> np.ndarray:
        """Mean of the two platen reactions [N/m]."""
        return 0.5 * (np.asarray(self.reaction_top) + np.asarray(self.reaction_bottom))


@dataclass
class LoadResult:
    history: LoadHistory
    steps: int
    dt: float
    wall_s: float
    stopped: str
    t_ramp: float
    x_final: np.ndarray
    pair_mode: np.ndarray
    pair_tbreak: np.ndarray
    pair_mode_failure: np.ndarray | None = None   # spring modes at the sample that declared failure
    failure_index: int | None = None              # that sample's index


def run_loading(spec, settings: LoadSettings, on_sample=None) -> LoadResult:
    """Load ``spec`` (a :class:`~.specimens.Specimen`) until failure; returns the sampled history.

    on_sample(fraction_of_max_strain, nominal_stress_Pa) is called at every sample (progress bars).
    """
    m, s = spec.model, settings
    st = m.state()
    solver = CDEMSolver(m, block_contact=False)
    kp = s.penalty * float(np.median(m.host["pair_kn"])) if m.spring_count else 1e9
    radius = s.jaw_ratio * spec.width / 2.0
    top, bottom = spec.top, spec.bottom
    if s.loading_arc > 0:
        X = m.host["node_X"]
        half = math.radians(0.5 * s.loading_arc)
        top = top[np.abs(np.arctan2(X[top, 0], X[top, 1])) <= half + 1e-9]
        bottom = bottom[np.abs(np.arctan2(X[bottom, 0], -X[bottom, 1])) <= half + 1e-9]
    platens = Platens(m, top, bottom, (spec.height / 2, -spec.height / 2), radius, kp, s.bonded)
    # the builder's Gershgorin step of a breakable model allows for one block contact per node,
    # 2·k_c·t_n (METHOD §1.7; about four median spring stiffnesses on a uniform specimen mesh), which
    # covers the platen penalty; a model without it (unbreakable, or rock.block_contact off) takes a margin of 1/√2
    dt = s.dt_safety * m.stable_dt * (1.0 if has_contact_allowance(spec.scenario.rock) else 1.0 / math.sqrt(2.0))
    cp = spec.scenario.rock.p_wave_speed
    t_ramp = s.ramp_transits * spec.height / cp
    every = max(1, int(round(s.sample_strain * spec.height / (2 * s.speed * dt))))
    max_steps = int(math.ceil((s.max_strain * spec.height / (2 * s.speed) + 0.5 * t_ramp) / dt))
    X = m.host["node_X"]
    groups = {k: getattr(spec, k) for k in ("top", "bottom", "left", "right")}
    hist, peak, stopped = LoadHistory(), 0.0, "max_strain"
    u_peak, failed = 0.0, False
    mode_failure, i_failure = None, None
    t, wall0 = 0.0, time.perf_counter()
    step = 0
    for step in range(1, max_steps + 1):
        solver.forces(st, dt, t)
        platens.apply(st, ramped_displacement(t, s.speed, t_ramp))
        solver.integrate(st, dt, s.damping)
        t += dt
        if step % every:
            continue
        r = platens.reaction.numpy()
        u = st.x.numpy() - X
        mode = st.pair_mode.numpy()
        hist.time.append(t)
        hist.platen_u.append(ramped_displacement(t, s.speed, t_ramp))
        hist.reaction_top.append(float(r[0]))
        hist.reaction_bottom.append(float(r[1]))
        hist.axial_u.append(float(u[groups["top"], 1].mean() - u[groups["bottom"], 1].mean()) * -1.0)
        lat = float(u[groups["right"], 0].mean() - u[groups["left"], 0].mean()) if len(groups["left"]) else 0.0
        hist.lateral_u.append(lat)
        hist.tensile.append(int(np.sum(mode == 1)))
        hist.shear.append(int(np.sum(mode >= 2)))          # shear, or crushed (rock.crushing_strength)
        if on_sample is not None:
            on_sample(min(1.0, step / max_steps), 0.5 * float(r[0] + r[1]) / spec.width)
        load = 0.5 * float(r[0] + r[1])
        if t < t_ramp:          # failure is only looked for at steady platen speed
            continue
        if load > peak and not failed:
            peak, u_peak = load, hist.platen_u[-1]
        if not failed and peak > 0 and load < (1.0 - s.failure_drop) * peak:
            failed, mode_failure, i_failure = True, mode.copy(), len(hist.time) - 1
        if failed and load < s.stop_drop * peak:
            stopped = "post_peak_drop"
            break
        if failed and hist.platen_u[-1] > s.post_peak_strain * u_peak:
            stopped = "post_peak_strain"
            break
        if not np.isfinite(load):
            stopped = "non_finite"
            break
    return LoadResult(hist, step, dt, time.perf_counter() - wall0, stopped, t_ramp,
                      st.x.numpy().copy(), st.pair_mode.numpy().copy(), st.pair_tbreak.numpy().copy(),
                      mode_failure, i_failure)


def run_start(run: LoadResult) -> int:
    """Index of the first sample at full platen speed (after the ramp)."""
    return int(np.searchsorted(np.asarray(run.history.time), run.t_ramp))
