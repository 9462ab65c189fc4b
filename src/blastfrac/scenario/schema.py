"""Scenario schema: the validated, documented description of one blastfrac run.

Every user-facing option lives here, with its SI unit and allowed range in the field
description. Unknown keys are rejected (``extra="forbid"``) so that a typo is an error,
not a silently ignored setting. The resolved scenario (all defaults filled in) is
written beside the results as ``resolved.toml``.

Sign conventions: continuum stress is positive in tension, so an in-situ compressive
stress of 15 MPa is ``syy = -15e6``. Lengths are metres, times seconds, stresses
pascals, angles degrees (as users quote friction angles), energies J/m².
"""

from __future__ import annotations

import math
from typing import Annotated, Literal, Union

from pydantic import Field, field_validator, model_validator

from . import _geometry as geo
from ._base import Point, _Strict  # noqa: F401 (re-exported)
from .explosive import ExplosiveConfig


# --------------------------------------------------------------------------- simulation
class SimulationConfig(_Strict):
    """Clock, time step and compute device."""

    end_time: float = Field(1e-4, gt=0, le=1.0, description="Simulated end time of the dynamic stage [s], at most 1 s.")
    dt_safety: float = Field(
        0.8, gt=0, le=1.0, description="Safety factor applied to the Gershgorin stable time step (0, 1]."
    )
    device: str = Field("cpu", pattern=r"^(cpu|cuda(:\d+)?)$", description="Warp device: 'cpu', 'cuda' or 'cuda:N'.")
    damping: float = Field(
        0.0, ge=0, lt=1, description="Cundall local damping factor of the dynamic stage [-]; 0 for blasts."
    )
    seed: int = Field(0, ge=0, le=2**31 - 1, description="Seed of gmsh's random factor and of any random field. The gmsh Delaunay mesh does not change with it (measured: seeds 0, 1, 2 give identical meshes); for another mesh realisation change a mesh size by about 1 % (examples/confined_blast/mesh_study.md).")
    max_steps: int | None = Field(None, gt=0, description="Stop after this many steps even before end_time.")
    progress: bool = Field(True, description="Show a progress bar on the terminal.")
    threads: int = Field(
        2, ge=1, le=2, description="CPU threads of a coupled step [-]: 2 runs the gas stages (particle–edge "
        "contact, crack gas, P2G, grid, G2P, EOS) beside the rock's (CST, loads, block contact, integration) in a "
        "second Python thread (Warp's CPU kernels release the GIL), and the springs in two halves; the motion and "
        "fracture are the same as with 1, the energy books too (tests/unit/test_threads.py). With 2 the run times its "
        "own steps on one thread and on two in short trials and uses the second thread only where it measured "
        "faster, tried again every 2000 steps (blastfrac/second_thread.py; summary.json → threads): the shipped "
        "confined P0 ran 1.5x faster on two, the demo 10-20 % slower before this choice, the same with it "
        "(benchmarks/RESULTS.md). One thread on a 1-core machine or a GPU; a sweep runs each case with 1 (its cases "
        "fill the cores).",
    )
    graph: Literal["auto", "on", "off"] = Field(
        "auto", description="Replay steps from a captured graph (a CUDA graph on a GPU, Warp's C++ replay of the "
        "recorded operations on a CPU), with the same results to the bit as the launches on a CPU (tests/unit/"
        "test_rock_graph.py, test_coupled_graph.py): 'auto' replays the rock-only steps everywhere and the coupled "
        "steps on a GPU; 'on' the coupled steps on a CPU too, in one thread (on a CPU the launches, in two threads "
        "where that is faster, cost less: docs/scenario.md, 'Graphs'); 'off' runs every step through the launches. "
        "A step a graph cannot stand for (the first, one after the time step changed) runs through the launches "
        "either way.",
    )


# --------------------------------------------------------------------------- output
class OutputConfig(_Strict):
    """Where and how often results are written."""

    directory: str = Field("out", description="Output directory (created if missing).")
    interval: float | None = Field(
        None, gt=0, description="Time between ParaView frames [s]; default end_time/20."
    )
    monitor_interval: float | None = Field(
        None, gt=0, description="Time between monitor/fracture-history samples [s]; default end_time/200."
    )
    paraview: bool = Field(
        True, description="Write the ParaView (VTU + PVD) time series of the rock (and of the gas particles)."
    )
    figures: bool = Field(True, description="Write PNG figures at the end of the run.")
    snapshot_times: list[float] = Field(
        default_factory=list,
        description="Times [s] at which displacement (and gas) snapshots are kept for the Fig. 4-style panel; "
        "default: four equally spaced times.",
    )
    checkpoint_interval: float | None = Field(
        None, gt=0, description="Simulated time between checkpoints [s] (checkpoint.npz in the output directory, "
        "written atomically; the last one is kept); default none. SIGINT/SIGTERM always write one. Continue with "
        "`blastfrac run --restart DIR` (on a CPU bit-identical to a run that went through, io/checkpoint.py; on a GPU "
        "atomic sums make no two runs bit-identical).",
    )
    budget_warning: float = Field(
        0.05, gt=0, le=1,
        description="Relative energy-budget error (|budget_error_relative|) above which the run warns on stderr "
        "(once) and lists a warning in summary.json → warnings; in (0, 1], default 0.05 (5 %).",
    )

    @field_validator("snapshot_times")
    @classmethod
    def _snapshots(cls, v: list[float]) -> list[float]:
        if any(t < 0 for t in v):
            raise ValueError("snapshot times must be >= 0 s")
        if len(v) > 12:
            raise ValueError("at most 12 snapshot times")
        if len(set(v)) != len(v):
            raise ValueError(f"snapshot times must be distinct (got {v})")
        return sorted(v)


# --------------------------------------------------------------------------- rock
HeterogeneityField = Literal["tensile_strength", "cohesion", "stiffness"]


class HeterogeneityConfig(_Strict):
    """Weibull scatter of the spring properties from interface to interface (model/heterogeneity.py,
    docs/heterogeneity.md); seeded by simulation.seed."""

    weibull_modulus: float | None = Field(
        None, gt=0, description="Weibull modulus m of the per-interface factors [-], > 0; None (default) = "
        "homogeneous rock. The factors have mean 1 (the rock's values are the means) and coefficient of "
        "variation √(Γ(1+2/m) − Γ(1+1/m)²)/Γ(1+1/m): 0.52 at m = 2, 0.23 at m = 5, 0.12 at m = 10.",
    )
    fields: list[HeterogeneityField] = Field(
        default_factory=lambda: ["tensile_strength", "cohesion"], min_length=1,
        description="Properties that scatter: 'tensile_strength' (T), 'cohesion' (c), 'stiffness' (kn and ks "
        "by the same factor; needs weibull_modulus > 1). Both springs of an interface get the same factor.",
    )
    correlated: bool = Field(
        True, description="One factor per interface shared by every listed property (a weak interface is weak in "
        "tension and shear alike); false: an independent draw per property.",
    )
    reference_length: float | None = Field(
        None, gt=0, description="Weakest-link size scaling [m], > 0; None (default) = none (i.i.d. factors "
        "whatever the interface length). Set: the strength factors (tensile_strength, cohesion; not stiffness) "
        "of an interface of length L are multiplied by (reference_length/L)^(1/m), so a crack path of length l "
        "survives a uniform stress s with exp(−(l/L_ref)(s/(λT))^m) however many interfaces it is cut into; "
        "tensile_strength and cohesion are then the mean strengths of an interface of length reference_length. "
        "Ignored while weibull_modulus is None.",
    )
    correlation_length: float | None = Field(
        None, gt=0, description="Spatial correlation length ℓ of the factors [m], > 0; None (default) = an "
        "independent draw per interface. Set: the factor is a function of position, a Gaussian random field "
        "of covariance exp(−r²/(2ℓ²)) mapped onto the Weibull marginal and sampled at each interface's "
        "midpoint, the same at the same place on any mesh (docs/heterogeneity.md \"Correlated field\"). "
        "Not together with reference_length. Ignored while weibull_modulus is None.",
    )

    @field_validator("fields")
    @classmethod
    def _distinct_fields(cls, v: list[str]) -> list[str]:
        for j, f in enumerate(v):
            if f in v[:j]:
                raise ValueError(f"'{f}' is listed twice; each property once")
        return v

    @model_validator(mode="after")
    def _stiffness_modulus(self) -> "HeterogeneityConfig":
        m = self.weibull_modulus
        if m is not None and "stiffness" in self.fields and m <= 1.0:
            raise ValueError(f"weibull_modulus: {m} is too small for 'stiffness' in fields: the spring compliance "
                             "1/k of a Weibull stiffness has no finite mean for m <= 1 (give m > 1)")
        return self

    @model_validator(mode="after")
    def _one_length_rule(self) -> "HeterogeneityConfig":
        if self.correlation_length is not None and self.reference_length is not None:
            raise ValueError("correlation_length and reference_length are exclusive: the weakest-link scaling "
                             "treats every interface as an independent link, a correlated field does not "
                             "(give one of them)")
        return self

    @property
    def active(self) -> bool:
        return self.weibull_modulus is not None


class RockConfig(_Strict):
    """Rock: elastic blocks (CST) and the breakable interface springs between them."""

    density: float = Field(2600.0, gt=0, le=1e5, description="Mass density [kg/m³], at most 1e5.")
    youngs_modulus: float = Field(50e9, gt=0, le=1e13, description="Young's modulus of the blocks [Pa], at most 1e13.")
    poisson_ratio: float = Field(0.2, ge=0, lt=0.5, description="Poisson's ratio of the blocks [-], in [0, 0.5).")
    stiffness_mode: Literal["penalty", "per_area"] = Field(
        "penalty",
        description="'penalty': kn = ks = spring_penalty·E'/h (h mean element height of the edge); "
        "'per_area': kn, ks given directly in Pa/m as in the paper's Table 3.",
    )
    spring_penalty: float = Field(
        20.0, gt=0, description="Penalty factor β on E'/h used when stiffness_mode='penalty' [-]."
    )
    compensate_spring_compliance: bool = Field(
        True, description="Give the blocks the moduli that make the block–spring assembly's effective E and ν equal "
        "youngs_modulus and poisson_ratio (the springs add compliance: with spring_penalty = 20 the uncompensated "
        "assembly is 8 % softer and its P wave 4 % slow at any mesh size). Default: true in 'penalty' mode (the "
        "rock is given by its macro properties), false in 'per_area' mode (the paper's micro-parameters, kept as "
        "given; the assembly's effective moduli are reported by `check` and in summary.json → elastic).",
    )
    mass_matrix: Literal["lumped", "averaged", "consistent"] = Field(
        "averaged", description="Mass matrix of each block (cdem/kernels_integrate.py): 'lumped' (ρA/3 per node), "
        "'consistent' (the CST's), or 'averaged' (their mean, θ = ½), whose opposite phase errors cancel so a steep "
        "front leaves far less mesh-scale ringing behind it (docs/rock_fronts.md). Each block owns its nodes, so the "
        "inverse is exact and local; 'averaged' costs about 27 % more steps (its smallest eigen-mass is 5/8 of ρA/3).",
    )
    kn: float | None = Field(None, gt=0, description="Normal spring stiffness per unit area [Pa/m] (per_area mode).")
    ks: float | None = Field(None, gt=0, description="Shear spring stiffness per unit area [Pa/m] (per_area mode).")
    tensile_strength: float = Field(10e6, ge=0, description="Spring tensile strength T [Pa].")
    cohesion: float = Field(40e6, ge=0, description="Spring cohesion c [Pa].")
    friction_angle: float = Field(40.0, ge=0, lt=90, description="Spring internal friction angle φ [deg].")
    residual_friction_angle: float | None = Field(
        None, ge=0, lt=90, description="Friction angle of broken interfaces and block contact [deg]; default φ."
    )
    crushing_strength: float | None = Field(
        None, gt=0, le=1e11, description="Compressive cap of the springs σ_cr [Pa] (not in the paper): a spring whose "
        "normal compression reaches σ_cr breaks in the 'crushed' mode and goes on as a closed broken spring (it keeps "
        "its normal force, its shear falls to residual friction). Mohr–Coulomb springs cannot fail in uniaxial "
        "strain at usual friction angles, so without it a blast crushes only by hoop tension and shear near the "
        "wall. None: no cap (the paper's law). See docs/scenario.md, 'Crushing'.",
    )
    tensile_fracture_energy: float | None = Field(
        None, gt=0, description="Mode I fracture energy G_fI [J/m²]; enables linear tension softening."
    )
    shear_fracture_energy: float | None = Field(
        None, gt=0, description="Mode II fracture energy G_fII [J/m²]; enables linear cohesion softening."
    )
    fracture_band_width: float | None = Field(
        None, ge=0, le=1.0, description="Width w_c of the fracture process band [m] (not in the paper), (0, 1]; None "
        "(default) or 0: every interface carries the full G_fI, G_fII (0 lets `--set rock.fracture_band_width=0` "
        "switch off a band that a scenario file sets, e.g. the confined examples'). Set: an interface whose two blocks have the mean "
        "height h̄ = (A1 + A2)/L < w_c carries the share h̄/w_c of both fracture energies (min(1, h̄/w_c)), so that "
        "fragmenting a region finer than w_c costs 3·G_f/w_c per unit area on any mesh, and a physical crack "
        "resolved by w_c/h̄ parallel lattice cracks costs G_f. Needs a fracture energy. See docs/scenario.md, "
        "'Fracture band'.",
    )
    unbreakable: bool = Field(False, description="Springs never fail (elastic verification runs).")

    @field_validator("fracture_band_width")
    @classmethod
    def _band_zero_is_none(cls, v: float | None) -> float | None:
        return None if v == 0 else v
    block_contact: bool = Field(
        True, description="Node-to-edge frictional contact between blocks whose springs have broken and separated "
        "(METHOD §1.5). Off: separated fragments pass through each other; a run is about 1.7× faster when "
        "fragmentation is heavy.",
    )
    bulk_viscosity_linear: float = Field(
        0.0, ge=0, le=2, description="Linear artificial bulk viscosity coefficient C_l of the blocks [-] "
        "(q = ρl(C_q·l·trD² − C_l·c_p·trD) in compression, l = √A). Damps the mesh-scale ringing behind steep "
        "blast fronts that otherwise breaks springs no continuum stress would break; see docs/scenario.md.",
    )
    spring_damping: float = Field(
        0.0, ge=0, le=1, description="Dashpot beside every loaded spring as a fraction ζ of the critical damping "
        "of its two-node oscillator [-]. Damps mesh-scale vibration of the node pairs (the model's highest "
        "frequency); its force is not part of the spring force that the failure criteria see.",
    )
    bulk_viscosity_quadratic: float = Field(
        0.0, ge=0, le=4, description="Quadratic (von Neumann–Richtmyer) artificial bulk viscosity coefficient "
        "C_q of the blocks [-]; see bulk_viscosity_linear.",
    )
    heterogeneity: HeterogeneityConfig = Field(
        default_factory=HeterogeneityConfig,
        description="Per-interface Weibull scatter of T, c and the spring stiffness around the values above "
        "(which are the means); off unless heterogeneity.weibull_modulus is given (docs/heterogeneity.md).",
    )

    @model_validator(mode="before")
    @classmethod
    def _default_compensation(cls, data):
        # the default depends on the stiffness mode: macro properties (penalty) are honoured by the assembly,
        # micro-parameters (per_area) are kept as given
        if isinstance(data, dict) and data.get("compensate_spring_compliance") is None:
            data = {**data, "compensate_spring_compliance": data.get("stiffness_mode", "penalty") == "penalty"}
        return data

    @model_validator(mode="after")
    def _check_stiffness(self) -> "RockConfig":
        if self.stiffness_mode == "per_area" and (self.kn is None or self.ks is None):
            raise ValueError("stiffness_mode='per_area' needs both rock.kn and rock.ks [Pa/m]")
        for gf, s, name in (
            (self.tensile_fracture_energy, self.tensile_strength, "tensile"),
            (self.shear_fracture_energy, self.cohesion, "shear"),
        ):
            if gf is not None and s == 0:
                raise ValueError(f"{name}_fracture_energy given but the matching strength is 0")
        if self.fracture_band_width is not None and self.tensile_fracture_energy is None \
                and self.shear_fracture_energy is None:
            raise ValueError("fracture_band_width scales the fracture energies, but neither "
                             "tensile_fracture_energy nor shear_fracture_energy is given")
        return self

    @property
    def residual_friction(self) -> float:
        """Residual friction angle [deg] (φ_r, defaults to φ)."""
        return self.friction_angle if self.residual_friction_angle is None else self.residual_friction_angle

    @property
    def plane_strain_modulus(self) -> float:
        """E' = E/(1-ν²) [Pa]."""
        return self.youngs_modulus / (1.0 - self.poisson_ratio**2)

    @property
    def p_wave_speed(self) -> float:
        """Plane-strain P-wave speed c_p = sqrt((λ+2G)/ρ) [m/s]."""
        e, nu = self.youngs_modulus, self.poisson_ratio
        return math.sqrt(e * (1 - nu) / ((1 + nu) * (1 - 2 * nu)) / self.density)

    @property
    def s_wave_speed(self) -> float:
        """Shear-wave speed c_s = sqrt(G/ρ) [m/s]."""
        return math.sqrt(self.youngs_modulus / (2 * (1 + self.poisson_ratio)) / self.density)


# --------------------------------------------------------------------------- geometry (scenario/geometry_config.py)
from .geometry_config import (Borehole, DiscDomain, Domain, GeometryConfig, JointNetworkConfig, JointSetConfig, PolygonDomain, RectangleDomain, TraceDistribution, TraceLengthConfig, _seg_dist)  # noqa: E402,F401


# --------------------------------------------------------------------------- loads (scenario/pulses.py)
from .pulses import (BoreholePressure, ConstantPulse, ExponentialPulse, Pulse, TablePulse,  # noqa: E402,F401
                     TrianglePulse, _rise_rate)


# --------------------------------------------------------------------------- boundaries
class BoundarySide(_Strict):
    type: Literal["free", "fixed", "roller", "viscous", "pressure"] = Field(
        "free",
        description="free; fixed (u = 0); roller (normal displacement 0, free to slide); "
        "viscous (Lysmer–Kuhlemeyer dashpots, non-reflecting); pressure (applied pulse).",
    )
    pulse: Pulse | None = Field(None, description="Pressure history for type='pressure'.")

    @model_validator(mode="after")
    def _pulse(self) -> "BoundarySide":
        if self.type == "pressure" and self.pulse is None:
            raise ValueError("type='pressure' needs a pulse")
        if self.type != "pressure" and self.pulse is not None:
            raise ValueError(f"a pulse is only allowed with type='pressure' (got type='{self.type}')")
        return self


# --------------------------------------------------------------------------- in-situ stress
class InSituConfig(_Strict):
    """Far-field (pre-existing) stress applied as a quasi-static stage before the dynamic one."""

    sxx: float = Field(0.0, description="Far-field σxx [Pa], tension positive (compression negative).")
    syy: float = Field(0.0, description="Far-field σyy [Pa], tension positive.")
    sxy: float = Field(0.0, description="Far-field τxy [Pa].")
    method: Literal["relax", "initial"] = Field(
        "relax",
        description="'relax': initialise σ⁰, apply consistent tractions and relax quasi-statically (METHOD §1.8); "
        "'initial': only initialise σ⁰ and tractions, no relaxation.",
    )
    damping: float = Field(
        0.3, gt=0, lt=1,
        description="Cundall local damping of the relaxation stage [-]. 0.8 (a common DEM choice) over-damps the "
        "low modes of a block model and relaxes far more slowly; 0.2-0.3 converges fastest in our tests.",
    )
    tolerance: float = Field(1e-5, gt=0, description="Stop when kinetic energy / external work falls below this.")
    min_transits: float = Field(
        1.0, ge=0,
        description="P-wave transits of the domain's extent the relaxation runs at least before the tolerance is "
        "trusted [-]. 1: every point has met the holes' unloading wave once. 2 until 2026-12-06; on the 10 mm "
        "confined P15 the wall's hoop stress then differed by 0.07 % (docs/scenario.md).",
    )
    max_steps: int = Field(200_000, gt=0, description="Upper bound on relaxation steps.")
    allow_failure: bool = Field(
        True, description="Let springs fail during relaxation (failures are always reported in the summary)."
    )

    @property
    def active(self) -> bool:
        return any(v != 0.0 for v in (self.sxx, self.syy, self.sxy))


# --------------------------------------------------------------------------- monitors and zones
MonitorQuantity = Literal["ux", "uy", "vx", "vy", "speed", "sxx", "syy", "sxy", "pressure", "gas_pressure"]


class Monitor(_Strict):
    name: str = Field(pattern=r"^[A-Za-z0-9_\-]+$", description="Column prefix in monitors.csv.")
    position: Point = Field(description="Point [m]; the rock around it is sampled (see radius).")
    quantities: list[MonitorQuantity] = Field(
        default_factory=lambda: ["vx", "vy", "sxx", "syy", "sxy", "pressure"],
        description="Quantities: ux, uy, vx, vy, speed, sxx, syy, sxy, pressure (=-(sxx+syy)/2 in rock), gas_pressure.",
    )
    radius: float | None = Field(
        None, ge=0, description="Averaging radius R [m]: stresses are the area-weighted mean over the elements "
        "whose reference centroids lie within R of the point, ux..speed the node_mass-weighted mean over the "
        "nodes within R (the containing element if none). None = 2·h with h = √(2A) of the element containing "
        "the point (nearest one if outside); 0 = that single element, nodes by barycentric weights.",
    )

    @field_validator("quantities")
    @classmethod
    def _distinct(cls, v: list[str]) -> list[str]:
        for j, q in enumerate(v):
            if q in v[:j]:
                raise ValueError(f"'{q}' is listed twice; each quantity once")
        return v


class AnnulusZone(_Strict):
    type: Literal["annulus"] = "annulus"
    name: str
    center: Point = (0.0, 0.0)
    r_inner: float = Field(ge=0, description="Inner radius [m].")
    r_outer: float = Field(gt=0, description="Outer radius [m].")

    @model_validator(mode="after")
    def _radii(self) -> "AnnulusZone":
        if self.r_outer <= self.r_inner:
            raise ValueError("r_outer must exceed r_inner")
        return self


class SectorZone(AnnulusZone):
    type: Literal["sector"] = "sector"  # type: ignore[assignment]
    angle_start: float = Field(description="Start angle [deg], counter-clockwise from +x.")
    angle_end: float = Field(description="End angle [deg].")


class RectangleZone(_Strict):
    type: Literal["rectangle"] = "rectangle"
    name: str
    xmin: float
    xmax: float
    ymin: float
    ymax: float

    @model_validator(mode="after")
    def _order(self) -> "RectangleZone":
        if self.xmax <= self.xmin or self.ymax <= self.ymin:
            raise ValueError("need xmin < xmax and ymin < ymax")
        return self


Zone = Annotated[Union[AnnulusZone, SectorZone, RectangleZone], Field(discriminator="type")]


# --------------------------------------------------------------------------- coupling
class CouplingConfig(_Strict):
    """Gas–rock particle–edge contact (METHOD §3); used when [explosive] is given."""

    contact_stiffness: float | None = Field(
        None, gt=0, description="Contact stiffness k_c [Pa] (force per unit thickness per metre of overlap); "
        "default stiffness_factor·P_CJ.",
    )
    stiffness_factor: float = Field(
        20.0, ge=1, le=1000, description="k_c/P_CJ when contact_stiffness is not given [-]; the overlap at pressure p "
        "is about 2p/k_c·r_p, so 20 keeps it below r_p/10 at P_CJ.",
    )
    force_cap: float = Field(
        0.0, ge=0, le=100, description="Experimental: κ of a cap on each contact's normal force, κ·(p + ρ·v_a²)·2r_p "
        "with the particle's pressure p, density ρ and approach speed v_a [-]; 0 (default) = no cap. κ = 2 removes "
        "the chatter spikes on the wall but lets particles leak through it (piston and leak tests fail).",
    )
    damping_ratio: float = Field(
        0.7, ge=0, le=1, description="Normal contact dashpot as a fraction of critical [-]. 0.7 (default) damps the "
        "ringing of the penalty contacts on a borehole wall (peaks 240 → 214 MPa under a 200 MPa gas, "
        "tests/verification/test_coupling_wall_load.py); 0 = elastic contacts. The energy it removes is part of "
        "contact_energy (energy.csv).",
    )
    friction: float = Field(0.0, ge=0, le=2, description="Gas–rock friction coefficient [-]; 0 for an inviscid gas.")
    surface_forces: bool = Field(
        True, description="Apply each contact force to the gas grid at the contact point on the particle's surface "
        "(through a first moment in P2G) instead of at the particle centre [-]. Off, the wall load exceeds the gas "
        "pressure by up to r_b/(r_b − r_p) at rest and by 30–40 % while the wall recedes (docs/explosive.md).",
    )
    pressure_preload: bool = Field(
        True, description="Grow the contact radius by the overlap p·2r_p/k_c that the particle's pressure p needs "
        "(capped at r_p/4), so that a particle touching a wall pushes with its own pressure at once instead of first "
        "accelerating into it [-]. Off, a suddenly loaded wall sees about 1.2–1.4 p at ignition.",
    )
    contact_heating: bool = Field(
        True, description="Hand what the gas–rock contacts dissipate (dashpot, friction and force-cap losses: the "
        "work they absorbed less the penalty energy they hold) to the gas points in contact as internal energy, in "
        "proportion to their contacts' dissipation this step: the contact stands for an unresolved stagnation shock, "
        "whose heat stays in the gas [-]. The energy budget is unchanged (the heat leaves the contact book); "
        "summary.json energy → contact_heat. Not with elastic MPM bodies (their contacts share the book).",
    )
    rebuild_interval: int = Field(
        5, ge=1, le=100, description="Steps between rebuilds of the exposed-edge search structure [-]."
    )
    wall_clearance: float = Field(
        1.0, ge=0, le=3, description="Seeded particles must lie at least this many nominal particle radii "
        "(h/(2·points_per_cell)) from a rock edge [-]. Those short of it by less than half of it are moved straight "
        "away from the edge (the outer ring of a conformal seeding then touches the meshed wall, whose chords cut "
        "inside the circle); the others, and any inside the rock, are removed and the charge's area is kept by "
        "scaling the rest. 1 = a particle touches the wall.",
    )


class CrackGasConfig(_Strict):
    """Detonation gas inside cracks narrower than a material point (coupling/crack_gas.py, docs/explosive.md)."""

    enabled: bool = Field(
        False, description="Carry the MPM gas into broken interfaces connected to the gas-filled hole as a network of "
        "crack cells whose pressure loads both crack faces [-]. Needs [explosive]. Off: gas enters a crack only as "
        "particles, when the crack is wider than a particle.",
    )
    viscosity: float = Field(
        1e-4, gt=0, le=1.0, description="Dynamic viscosity μ of the products in the cubic law "
        "ṁ = ρw³Δp/(12μΔx) [Pa·s]; 1e-4 is that of a gas at about 3000 K. The flux never exceeds the choked "
        "flux of the donor, which governs wide, steeply loaded cracks whatever μ is.",
    )
    min_aperture: float = Field(
        5e-6, gt=0, le=1e-3, description="Floor of a crack cell's volume per unit length (aperture) [m]: the gas "
        "of a closed crack is held at this aperture (its pressure then capped at P_CJ). It bounds the stiffness "
        "γp·L/w_min of the gas on the face nodes (below the rock's springs for 5 µm at P_CJ).",
    )
    mouth_radius: float | None = Field(
        None, gt=0, description="A broken interface ending on a surface vertex (borehole wall, free face) is fed by "
        "the nearest fully burnt particle within this distance of its end [m]; default the MPM cell size.",
    )
    particle_floor: float = Field(
        0.5, ge=0.05, le=0.95, description="A particle feeding a crack keeps at least this fraction of its initial "
        "mass [-]; the gas-rock contact's stable step is taken with the floor mass.",
    )


# --------------------------------------------------------------------------- scenario
class Scenario(_Strict):
    """A complete blastfrac run."""

    title: str = Field("", description="Free text shown in the summary and figures.")
    simulation: SimulationConfig = Field(default_factory=SimulationConfig)
    output: OutputConfig = Field(default_factory=OutputConfig)
    rock: RockConfig = Field(default_factory=RockConfig)
    geometry: GeometryConfig
    boundaries: dict[str, BoundarySide] = Field(
        default_factory=dict,
        description="Per side: rectangle sides 'bottom','right','top','left'; disc 'outer'; polygon 'side0'..; "
        "borehole walls 'hole0'.. (default free).",
    )
    borehole_pressure: list[BoreholePressure] = Field(default_factory=list)
    insitu: InSituConfig = Field(default_factory=InSituConfig)
    monitors: list[Monitor] = Field(default_factory=list)
    zones: list[Zone] = Field(default_factory=list)
    explosive: ExplosiveConfig | None = Field(
        None, description="MPM explosive (JWL products, programmed burn); see blastfrac.scenario.explosive."
    )
    coupling: CouplingConfig = Field(default_factory=CouplingConfig)
    crack_gas: CrackGasConfig = Field(default_factory=CrackGasConfig)

    @model_validator(mode="after")
    def _cross_checks(self) -> "Scenario":
        if self.crack_gas.enabled and self.explosive is None:
            raise ValueError("crack_gas.enabled: needs an [explosive] section (the crack gas comes from the MPM products)")
        sides = set(self.geometry.domain.sides) | {f"hole{i}" for i in range(len(self.geometry.boreholes))}
        for name in self.boundaries:
            if name not in sides:
                raise ValueError(f"boundaries.{name}: unknown side; this domain has {sorted(sides)}")
        _apply_symmetry(self)
        loaded: dict[int, int] = {}
        for i, bp in enumerate(self.borehole_pressure):
            if bp.borehole >= len(self.geometry.boreholes):
                raise ValueError(
                    f"borehole_pressure[{i}].borehole = {bp.borehole} but only {len(self.geometry.boreholes)} boreholes exist"
                )
            if bp.borehole in loaded:
                raise ValueError(f"borehole_pressure[{i}]: borehole {bp.borehole} already has a pulse "
                                 f"(borehole_pressure[{loaded[bp.borehole]}]); give one pulse per borehole")
            if self.boundary(f"hole{bp.borehole}").type == "pressure":
                raise ValueError(f"borehole_pressure[{i}]: borehole {bp.borehole} already has a pulse "
                                 f"(boundaries.hole{bp.borehole}); give one pulse per borehole")
            loaded[bp.borehole] = i
        _unique_names(self.monitors, "monitors")
        _unique_names(self.zones, "zones")
        for i, m in enumerate(self.monitors):
            if "gas_pressure" in m.quantities and self.explosive is None:
                raise ValueError(f"monitors[{i}].quantities: 'gas_pressure' needs an [explosive] section (there is no gas)")
        if self.geometry.mesh_file is None:
            for i, m in enumerate(self.monitors):
                if not self.geometry.domain.contains(m.position):
                    raise ValueError(f"monitors[{i}] ({m.name}) at {m.position} is outside the domain")
            if self.explosive is not None:
                _explosive_fits_rock(self.explosive, self.geometry)
        if any(js.dfn is not None for js in self.geometry.joints):
            # draw the networks once, so that a set that cannot be placed is reported at load time
            from ..geometry.joints import check_joint_network

            check_joint_network(self.geometry, self.simulation.seed)
        return self

    def boundary(self, side: str) -> BoundarySide:
        return self.boundaries.get(side, BoundarySide())


def _apply_symmetry(sc: "Scenario") -> None:
    """geometry.symmetry (half and quarter models, docs/explosive.md): a roller on each symmetry side and a slip wall
    on the MPM grid's side of the same name, both written to resolved.toml; initiators and charges on the modelled
    side. An explicit conflicting condition is an error."""
    lines = sc.geometry.symmetry_lines()
    if not lines:
        return
    for side, *_ in lines:
        b = sc.boundaries.get(side)
        if b is not None and b.type != "roller":
            raise ValueError(f"boundaries.{side}: type '{b.type}' on a symmetry line (geometry.symmetry); a symmetry "
                             f"line is a roller (normal displacement 0, free to slide): remove boundaries.{side} or "
                             "give type = 'roller'")
        sc.boundaries[side] = BoundarySide(type="roller")
    ex = sc.explosive
    if ex is None:
        return
    gb = ex.grid.boundaries
    for side, *_ in lines:
        if side in gb.model_fields_set and getattr(gb, side) != "slip":
            raise ValueError(f"explosive.grid.boundaries.{side}: '{getattr(gb, side)}' on a symmetry line (geometry."
                             "symmetry); the MPM grid has a slip wall exactly on it (an exact plane of symmetry): "
                             "remove it or give 'slip'")
        setattr(gb, side, "slip")
    (x0, y0), (x1, y1) = sc.geometry.domain.bbox
    tol = 1e-9 * max(x1 - x0, y1 - y0)

    def beyond(p) -> str | None:
        for side, axis, c, sign in lines:
            if sign * (p[axis] - c) > tol:
                return f"beyond the symmetry line on the {side} side ({'xy'[axis]} = {c:.6g} m)"
        return None

    hint = ("outside the modelled part; a half or quarter model mirrors what lies on its side of the line, so give "
            "the initiator there or on the line")
    for k, dp in enumerate(ex.detonation_points):
        if beyond(dp.position):
            raise ValueError(f"explosive.detonation_points[{k}]: position {_fmt(dp.position)} lies "
                             f"{beyond(dp.position)}, {hint}")
    for k, dl in enumerate(ex.detonation_lines):
        for end in ("start", "end"):
            p = getattr(dl, end)
            if beyond(p):
                raise ValueError(f"explosive.detonation_lines[{k}].{end}: {_fmt(p)} lies {beyond(p)}, {hint}")
    for i, ch in enumerate(ex.charges):
        (a0, b0), (a1, b1) = _modelled_box(ch.bbox, sc.geometry)
        if a1 - a0 <= tol or b1 - b0 <= tol:
            raise ValueError(f"explosive.charges[{i}]: lies wholly beyond a symmetry line (geometry.symmetry = "
                             f"{sc.geometry.symmetry}), outside the modelled part")
    for i, b in enumerate(getattr(ex, "bodies", None) or []):
        if _modelled_box(b.bbox, sc.geometry) != tuple(map(tuple, b.bbox)):
            raise ValueError(f"explosive.bodies[{i}]: reaches across a symmetry line (geometry.symmetry); an elastic "
                             "body cut by a symmetry line is not supported, keep it on the modelled side")


def _modelled_box(box, geom: GeometryConfig) -> tuple[Point, Point]:
    """A box ((x0, y0), (x1, y1)) clamped to the modelled side of geometry.symmetry's lines: the part of a charge
    that a half or quarter model seeds."""
    lo, hi = [float(v) for v in box[0]], [float(v) for v in box[1]]
    for _, axis, c, sign in geom.symmetry_lines():
        if sign < 0:
            lo[axis] = max(lo[axis], c)
        else:
            hi[axis] = min(hi[axis], c)
    return (lo[0], lo[1]), (hi[0], hi[1])


def _unique_names(items, what: str) -> None:
    first: dict[str, int] = {}
    for j, it in enumerate(items):
        if it.name in first:
            raise ValueError(f"{what}[{j}].name: '{it.name}' is already used by {what}[{first[it.name]}]; names must be unique")
        first[it.name] = j


def _fmt(p) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


def _explosive_fits_rock(ex: ExplosiveConfig, geom: GeometryConfig) -> None:
    """Each charge and each elastic body lies inside a borehole or wholly outside the rock domain; the default grid
    covers it.

    Raises ValueError naming the first charge (or body) that breaks a rule (tolerance 1e-9 of the lengths involved).
    """
    d, holes = geom.domain, geom.boreholes
    shapes = [(f"explosive.charges[{i}]", ch, "charge") for i, ch in enumerate(ex.charges)]
    shapes += [(f"explosive.bodies[{i}]", b, "body") for i, b in enumerate(ex.bodies)]
    for key, ch, a in shapes:
        if ch.kind == "circle":
            c, r, pts = ch.center, ch.radius, None
            what = f"circle centre {_fmt(c)}, radius {r:.6g} m"
        else:
            pts = list(ch.vertices)
            c, r = geo.polygon_centroid(pts), None
            what = f"polygon with centroid {_fmt(c)}"
        host = next((j for j, b in enumerate(holes) if math.dist(c, b.center) < b.radius), None)
        if host is not None:
            b = holes[host]
            tol = 1e-9 * b.radius
            if pts is None:
                if r > b.radius + tol:
                    raise ValueError(f"{key}: radius {r:.6g} m is larger than its borehole geometry.boreholes[{host}] "
                                     f"(radius {b.radius:.6g} m); a {a} must fit inside its hole")
                inside = math.dist(c, b.center) + r <= b.radius + tol
            else:
                inside = all(math.dist(p, b.center) <= b.radius + tol for p in pts)
            if not inside:
                raise ValueError(f"{key}: {what} extends past the wall of geometry.boreholes[{host}] (centre "
                                 f"{_fmt(b.center)}, radius {b.radius:.6g} m) into the rock; a {a} must lie "
                                 "inside its borehole or outside the rock")
        else:
            if d.contains(c):
                raise ValueError(f"{key}: {what} lies in the rock (inside the domain and in no borehole); a {a} "
                                 "must lie inside a borehole or outside the rock")
            if _overlaps_domain(d, c, r, pts):
                raise ValueError(f"{key}: {what} overlaps the rock across the domain boundary; a {a} must lie "
                                 "inside a borehole or outside the rock")
    if ex.grid.bounds is None and ex.grid.margin is None:
        # the run's default grid covers the rock's box (simulation.py)
        (x0, y0), (x1, y1) = d.bbox
        tol = 1e-9 * max(x1 - x0, y1 - y0)
        for key, ch, _ in shapes:
            (a0, b0), (a1, b1) = _modelled_box(ch.bbox, geom)
            if a0 < x0 - tol or b0 < y0 - tol or a1 > x1 + tol or b1 > y1 + tol:
                raise ValueError(f"{key}: lies outside the rock's box {_fmt((x0, y0))}–{_fmt((x1, y1))} "
                                 "that the default grid covers; give explosive.grid.bounds or explosive.grid.margin")


def _overlaps_domain(d, c, r, pts) -> bool:
    """True when a circle (c, r) or polygon pts whose centre c lies outside domain d shares area with it."""
    if pts is None:
        tol = 1e-9 * r
        if isinstance(d, DiscDomain):
            return math.dist(c, d.center) < d.radius + r - tol
        return geo.polygon_dist(c, d.polygon) < r - tol
    if isinstance(d, DiscDomain):
        tol = 1e-9 * d.radius
        if geo.point_in_polygon(d.center, pts) or any(math.dist(p, d.center) < d.radius - tol for p in pts):
            return True
        return geo.polygon_dist(d.center, pts) < d.radius - tol
    (x0, y0), (x1, y1) = d.bbox
    return geo.polygons_overlap(pts, d.polygon, 1e-9 * max(x1 - x0, y1 - y0))
