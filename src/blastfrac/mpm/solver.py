"""MPMSolver: explicit MUSL material point method for detonation products (METHOD §2) and elastic bodies.

One step (``step``) is four stages that a coupled simulation may interleave:

1. ``to_grid(dt)``       P2G: node mass, momentum, internal force -V sigma grad N and the
                          external particle forces ``f_ext_p`` (N per unit thickness);
2. ``update_grid(dt)``   mass cut-off, p_I += dt f_I, boundary conditions;
3. ``to_particles(dt)``  G2P (FLIP/PIC blend or APIC), MUSL remap of momentum, velocity gradient,
                          volume/density update, particle motion (particles leaving the grid
                          are deactivated);
4. ``update_eos(dt, t)`` burn fraction at t + dt, artificial viscosity, JWL energy/pressure,
                          sound speed, stress of the gas points; the linear-elastic update of the
                          elastic points (bodies, :mod:`blastfrac.mpm.bodies`).

Each point has a material kind (``mat_kind``: gas or elastic) and its own Lamé constants, so the products
and any number of elastic bodies share one grid, with one launch per stage.

All arrays are allocated once in the constructor; a step allocates nothing.  2D plane
strain: masses [kg/m], volumes [m^2/m = m^2], energies [J/m], forces [N/m].
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import warp as wp

from blastfrac._warp import Launcher, resolve_device
from blastfrac.materials.cj import cj_state
from blastfrac.materials.jwl import JWLParams, jwl_sound_speed_sq_np
from blastfrac.materials.linear_elastic_mp import LinearElasticMP, strain_energy_density_np
from blastfrac.mpm.apic import (
    TRANSFERS,
    affine_angular_momentum_np,
    affine_from_moments_np,
    affine_inertia_np,
    affine_kinetic_energy_np,
)
from blastfrac.mpm.bodies import body_material, point_materials
from blastfrac.mpm.burn import BURN_MODES
from blastfrac.mpm.initiation import body_lighting_times
from blastfrac.mpm.grid import BOX_STEPS, Grid, GridSpec
from blastfrac.mpm.kernels_eos import update_jwl_state
from blastfrac.mpm.kernels_g2p import g2p_velocity, g2p_velocity_apic, particle_extent, update_particle_kinematics
from blastfrac.mpm.kernels_grid import (
    clear_grid_box,
    fold_wall_images,
    set_wall_ghosts,
    update_grid_momentum,
    velocity_from_momentum,
)
from blastfrac.mpm.kernels_misc import max_signal_speed
from blastfrac.mpm.kernels_p2g import p2g, p2g_gas, p2g_momentum
from blastfrac.mpm.kernels_solid import update_elastic_state
from blastfrac.mpm.seeding import charge_area_centroid, charge_bbox, seed_charges
from blastfrac.mpm.shape import SHAPE_IDS, grid_geometry, shape_1d_np

F64 = np.float64


@dataclass(frozen=True)
class MPMOptions:
    """Numerical options (see ExplosiveConfig for meanings and units; the defaults are the scenario's)."""

    shape: str = "bspline2"
    ppc: int = 2
    transfer: str = "flip"
    flip: float = 0.99
    flip_bodies: float = 1.0
    blend_heating: bool = True
    cfl: float = 0.2
    q1: float = 1.5
    q2: float = 2.0
    mass_cutoff: float = 1e-5
    v_max: float = 100.0
    burn_mode: str = "combined"
    burn_width: float = 1.5
    p_cj: float | None = None


def grid_from_config(config) -> GridSpec:
    """Grid covering ``grid.bounds`` or the charges' box plus margin (+2 stencil cells).

    The symmetry lines of a half or quarter model (the charges' ``cuts``, :mod:`blastfrac.mpm.seeding`) are box
    edges whatever the bounds say there: on that axis the grid is shifted so that the line is a node line 2 cells
    inside its edge, where :func:`boundary_walls` puts a slip wall (an exact plane of symmetry).
    """
    g = config.grid
    if g.bounds is not None:
        lo, hi = np.asarray(g.bounds[0], float), np.asarray(g.bounds[1], float)
    else:
        boxes = [charge_bbox(c) for c in config.charges]
        lo = np.min([b[0] for b in boxes], axis=0)
        hi = np.max([b[1] for b in boxes], axis=0)
        margin = g.margin if g.margin is not None else float(np.max(hi - lo))
        lo, hi = lo - margin, hi + margin
    from blastfrac.mpm.seeding import symmetry_cuts

    spec = GridSpec.from_bounds(lo, hi, g.cell_size)
    cuts = symmetry_cuts(config.charges)
    if not cuts:
        return spec
    h = g.cell_size
    x0, n = [spec.x0, spec.y0], [spec.nx, spec.ny]
    for c in cuts:
        a = c.axis
        if c.sign < 0:                                   # the line is the lower edge: x0 = line − 2h
            top = x0[a] + (n[a] - 1) * h
            x0[a] = c.coord - 2 * h
            n[a] = max(int(np.ceil((top - x0[a]) / h - 1e-9)) + 1, 5)
        else:                                            # the upper edge: the last node 2 cells beyond the line
            n[a] = max(int(np.ceil((c.coord + 2 * h - x0[a]) / h - 1e-9)) + 1, 5)
            x0[a] = c.coord + 2 * h - (n[a] - 1) * h
    return GridSpec(x0[0], x0[1], h, n[0], n[1])


def boundary_walls(config, spec: GridSpec) -> dict[str, tuple[float, str]]:
    """The non-open sides of ``config.grid.boundaries``: side -> (wall coordinate [m], 'slip' | 'fixed').

    The wall is the box of :func:`grid_from_config` widened outwards to grid lines: the nodes 2 cells inside the
    grid's edges (``GridSpec.from_bounds`` pads 2 cells and aligns), which leaves two ghost-node rows behind it.
    A symmetry line of a half or quarter model (the charges' ``cuts``) is a slip wall exactly on the line.
    """
    from blastfrac.mpm.seeding import symmetry_cuts

    b = getattr(config.grid, "boundaries", None)
    walls = {}
    if b is not None:
        h = spec.h
        xu, yu = spec.upper
        pos = {"left": spec.x0 + 2 * h, "right": xu - 2 * h, "bottom": spec.y0 + 2 * h, "top": yu - 2 * h}
        walls = {side: (pos[side], getattr(b, side)) for side in pos if getattr(b, side) != "open"}
    for c in symmetry_cuts(getattr(config, "charges", None) or []):
        walls[c.side] = (c.coord, "slip")
    return walls


def _grid_covering_bodies(config):
    """``config`` itself, or with no ``grid.bounds`` and elastic bodies a copy whose bounds are the box of the
    charges and bodies plus ``grid.margin`` (default: the box's larger side), the rule of :func:`grid_from_config`
    extended to the bodies."""
    bodies = getattr(config, "bodies", None) or []
    if config.grid.bounds is not None or not bodies:
        return config
    boxes = [charge_bbox(c) for c in [*config.charges, *bodies]]
    lo = np.min([b[0] for b in boxes], axis=0)
    hi = np.max([b[1] for b in boxes], axis=0)
    margin = config.grid.margin if config.grid.margin is not None else float(np.max(hi - lo))
    bounds = (tuple(map(float, lo - margin)), tuple(map(float, hi + margin)))
    return config.model_copy(update={"grid": config.grid.model_copy(update={"bounds": bounds})})


class MPMSolver:
    """Explicit MUSL MPM for JWL detonation products and linear-elastic bodies (or a linear-elastic solid alone,
    the MPM core benchmarks).

    Particle arrays (shape [n]): x, v, v_pic [m/s], f_ext_p [N/m] (vec2d); f_ext_moment [N] (mat22d: first
    moment Σ f ⊗ (x_f − x_p) of external forces applied off the particle centre, see ``p2g``); b_aff [m^2/s]
    (mat22d: the APIC affine moment B_p, C_p = B_p D_p⁻¹, :mod:`blastfrac.mpm.apic`; stays 0 with FLIP/PIC); mass [kg/m];
    vol, vol0, vol_prev [m^2]; rho [kg/m^3]; ie [J/m] (JWL internal energy; elastic solid: the work
    done on it); p, q [Pa]; burn [-]; light_time [s]; cs [m/s]; stress, grad_v (mat22d) [Pa], [1/s]; active (int32);
    mat_kind (int32: gas or elastic, :mod:`blastfrac.mpm.bodies`); lam, mu [Pa] (the elastic points' Lamé constants,
    0 for gas). Host: body_id [n] (the body of each point, −1 for gas), charge_id [n] (the charge, −1 for bodies),
    bodies (one LinearElasticMP per body), point_materials (:class:`blastfrac.mpm.bodies.PointMaterials`).
    Grid arrays: ``self.grid`` (:class:`Grid`).
    """

    # ------------------------------------------------------------------ construction
    def __init__(self, config, device: str = "cpu", particle_filter=None):
        """Seed the charges and elastic bodies of ``config`` (an ExplosiveConfig); ``particle_filter(x, vol) -> (x,
        vol[, keep])``, if given, edits the seeded points before lighting times are computed (e.g. to clear them from
        the rock); ``keep`` (a mask of the seeded points) keeps each point's charge or body, which the lighting times
        and the body materials need. It is called once for the charges' points and once for each body's. Without
        charges there is no JWL (``is_jwl`` False, ``p_cj`` None)."""
        params: JWLParams | None = config.jwl()
        bodies = list(getattr(config, "bodies", None) or [])
        opts = MPMOptions(
            shape=config.shape,
            ppc=config.grid.points_per_cell,
            transfer=config.transfer,
            flip=config.flip,
            flip_bodies=config.flip_bodies,
            blend_heating=config.blend_heating,
            cfl=config.cfl,
            q1=config.q1,
            q2=config.q2,
            mass_cutoff=config.mass_cutoff,
            v_max=config.v_max,
            burn_mode=config.burn.mode,
            burn_width=config.burn.width_factor,
            p_cj=config.burn.p_cj,
        )
        spec = grid_from_config(_grid_covering_bodies(config))
        # the bodies are seeded as further shapes after the charges (shape index >= number of charges)
        x, vol, sid = seed_charges([*config.charges, *bodies], spec, opts.ppc, mode=config.seeding)
        nc = len(config.charges)
        if particle_filter is not None:         # the charges' points together (as without bodies), each body apart
            parts = []
            for sel in [sid < nc] + [sid == nc + k for k in range(len(bodies))]:
                if sel.any():
                    res = particle_filter(x[sel], vol[sel])
                    parts.append((res[0], res[1], sid[sel][res[2]] if len(res) > 2 else sid[sel]))
            if parts:
                x, vol, sid = (np.concatenate([q[i] for q in parts]) for i in range(3))
        body_id = np.where(sid >= nc, sid - nc, -1).astype(np.int32)
        cid = np.where(sid < nc, sid, -1)
        gas = body_id < 0
        t_l = np.full(len(x), np.inf)                   # bodies never light
        if nc:
            if config.detonation_points or config.detonation_lines:
                pts = np.array([d.position for d in config.detonation_points], float).reshape(-1, 2)
                delays = np.array([d.delay for d in config.detonation_points], float)
            else:                                   # each charge at its own centroid
                pts = np.array([charge_area_centroid(c)[1] for c in config.charges])
                delays = np.zeros(len(pts))
            t_l[gas] = body_lighting_times(x[gas], vol[gas], cid[gas], config.charges, pts, delays,
                                           config.detonation_lines, params.D)
        self.charge_id = np.asarray(cid, np.int32)      # charge of each particle (host) [-], -1 for bodies
        self.config = config
        v0 = None
        if bodies:
            v0 = np.zeros((len(x), 2))
            for k, b in enumerate(bodies):
                v0[body_id == k] = b.velocity
        self._build(x, vol, spec, params, opts, device, v=v0, light_time=t_l, body_id=body_id,
                    bodies=[body_material(b) for b in bodies])
        for k, ch in enumerate(config.charges):        # gas regions: burnt products in a given state
            st = getattr(ch, "gas_state", None)
            if st is not None:
                sel = self.charge_id == k
                self.set_gas_state(st.density, st.pressure, np.broadcast_to(np.asarray(st.velocity, F64), (self.n, 2)),
                                   mask=sel)
        self.walls = boundary_walls(config, spec)
        key = {"left": "xmin", "right": "xmax", "bottom": "ymin", "top": "ymax"}
        for kind in ("slip", "fixed"):
            kw = {key[side]: val for side, (val, k) in self.walls.items() if k == kind}
            if kw:
                self.grid.set_walls(**kw, kind=kind)

    @classmethod
    def from_arrays(
        cls,
        x: np.ndarray,
        vol: np.ndarray,
        grid: GridSpec,
        material: JWLParams | LinearElasticMP | None,
        options: MPMOptions | None = None,
        device: str = "cpu",
        v: np.ndarray | None = None,
        light_time: np.ndarray | None = None,
        burn: np.ndarray | None = None,
        body_id: np.ndarray | None = None,
        bodies=(),
    ) -> MPMSolver:
        """Build from host arrays: x [n,2] m, vol [n] m^2, optional v [n,2] m/s, light_time [n] s, burn [n].

        ``material``: the products' JWL set (None: elastic bodies only) or one LinearElasticMP for all points (the
        MPM core benchmarks). ``body_id`` [n] (−1: gas) and ``bodies`` (LinearElasticMP list) make points elastic.
        """
        self = cls.__new__(cls)
        self.config = None
        self.walls = {}
        self.charge_id = np.where(np.asarray(body_id) >= 0, -1, 0).astype(np.int32) if body_id is not None else None
        self._build(x, vol, grid, material, options or MPMOptions(), device, v=v, light_time=light_time, burn=burn,
                    body_id=body_id, bodies=bodies)
        return self

    def _build(self, x, vol, spec: GridSpec, material, opts: MPMOptions, device, v=None, light_time=None, burn=None,
               body_id=None, bodies=()):
        self.device = resolve_device(device)
        self._launch = Launcher()                 # recorded launches of the per-step stages (_warp.Launcher)
        self.spec, self.material, self.opts = spec, material, opts
        self.is_jwl = isinstance(material, JWLParams)
        x = np.ascontiguousarray(x, dtype=F64).reshape(-1, 2)
        vol = np.ascontiguousarray(vol, dtype=F64).reshape(-1)
        n = len(x)
        self.n = n
        self.elastic_only = isinstance(material, LinearElasticMP)   # one elastic material for all points
        if self.elastic_only:
            bodies, body_id = [material], np.zeros(n, np.int32)
        self.bodies = list(bodies)
        self.body_id = np.full(n, -1, np.int32) if body_id is None else np.asarray(body_id, np.int32).reshape(-1)
        gas = self.body_id < 0
        self.n_solid = int((~gas).sum())                 # elastic points [-]
        if not self.is_jwl and gas.any():
            raise ValueError("gas points (body_id < 0) need a JWL material")
        pm = point_materials(self.body_id, self.bodies, material.rho0 if self.is_jwl else None)
        self.point_materials = pm
        # reference density of the mass cut-off: the explosive's, else the lightest body's
        rho0 = material.rho0 if material is not None else min(b.rho0 for b in self.bodies)
        self.shape_kind = SHAPE_IDS[opts.shape]
        if opts.transfer not in TRANSFERS:
            raise ValueError(f"unknown velocity transfer '{opts.transfer}' (one of {', '.join(TRANSFERS)})")
        self.apic = opts.transfer == "apic"
        self.shape_l = 0.5 / opts.ppc  # uGIMP l_p / h
        self.m_cut = opts.mass_cutoff * rho0 * spec.h**2
        d = self.device
        # gas and elastic bodies on one grid with a FLIP/PIC blend: the gas's PIC share aims at the gas's own nodal
        # velocity (kernels_p2g.p2g_gas), kept in arrays of its own
        self.own_gas_velocity = bool(self.n_solid and gas.any() and not self.apic and opts.flip < 1.0)
        nn = spec.node_count if self.own_gas_velocity else 1
        self.gas_mass, self.gas_mom, self.gas_vel, self.gas_scratch = (
            wp.zeros(nn, dtype=t, device=d) for t in (wp.float64, wp.vec2d, wp.vec2d, wp.vec2d))
        self.gas_no_bc = wp.zeros(nn, dtype=wp.int32, device=d)

        def z(dtype):
            return wp.zeros(n, dtype=dtype, device=d)

        self.x = wp.array(x, dtype=wp.vec2d, device=d)
        self.v = wp.array(np.zeros((n, 2)) if v is None else np.asarray(v, F64), dtype=wp.vec2d, device=d)
        self.v_pic, self.f_ext_p = z(wp.vec2d), z(wp.vec2d)
        self.f_ext_moment = z(wp.mat22d)
        self.b_aff = z(wp.mat22d)
        mass = pm.rho0 * vol
        self.mass = wp.array(mass, dtype=wp.float64, device=d)
        # the charges' mass at seeding [kg/m] (all points for an elastic-only solver)
        self.mass0_total = float(np.sum(mass if self.elastic_only or self.n_solid == 0 else mass[gas]))
        sv = self.v.numpy()[~gas]
        self.body_energy0 = 0.5 * float((mass[~gas] * (sv * sv).sum(axis=1)).sum())   # bodies' KE at seeding [J/m]
        self.vol = wp.array(vol, dtype=wp.float64, device=d)
        self.vol0 = wp.array(vol, dtype=wp.float64, device=d)
        self.vol_prev = wp.array(vol, dtype=wp.float64, device=d)
        self.rho = wp.array(pm.rho0.copy(), dtype=wp.float64, device=d)
        self.mat_kind = wp.array(pm.kind, dtype=wp.int32, device=d)
        self.lam = wp.array(pm.lam, dtype=wp.float64, device=d)
        self.mu = wp.array(pm.mu, dtype=wp.float64, device=d)
        self.ie, self.p, self.q, self.cs = z(wp.float64), z(wp.float64), z(wp.float64), z(wp.float64)
        if burn is not None:                 # elastic points never burn
            burn = np.where(gas, np.asarray(burn, F64), 0.0)
        self.burn = wp.array(np.zeros(n) if burn is None else burn, dtype=wp.float64, device=d)
        lt = np.zeros(n) if light_time is None else np.asarray(light_time, F64)
        self.light_time = wp.array(lt, dtype=wp.float64, device=d)
        self.stress, self.grad_v = z(wp.mat22d), z(wp.mat22d)
        self.active = wp.array(np.ones(n, dtype=np.int32), dtype=wp.int32, device=d)
        self.grid = Grid(spec, d)
        self._deactivated = wp.zeros(1, dtype=wp.int32, device=d)
        self._smax = wp.zeros(1, dtype=wp.float64, device=d)
        self.clock = wp.zeros(1, dtype=wp.float64, device=d)      # time at the start of the step [s] (update_eos)
        self.captured = False                    # a graph is capturing the step: the box's schedule is the caller's
        self._clock_host = self.clock.numpy() if d == "cpu" else None
        if self.is_jwl:
            P = material
            self.p_cj = opts.p_cj if opts.p_cj is not None else cj_state(P).p
            self.burn_mode = BURN_MODES[opts.burn_mode]
            chem = np.where(gas, P.E0 * vol, 0.0)
            self.ie.assign(chem)
            c0 = np.sqrt(jwl_sound_speed_sq_np(1.0, P.E0, 0.0, P.rho0, P.A, P.B, P.R1, P.R2, P.omega))
            self.cs.assign(np.where(gas, max(float(c0), P.D), pm.cs0))
            if burn is not None:  # products already (partly) burnt: pressure and stress consistent with F
                from blastfrac.materials.jwl import jwl_pressure_np

                p0 = np.asarray(burn, F64) * jwl_pressure_np(1.0, P.E0, P.A, P.B, P.R1, P.R2, P.omega)
                self.p.assign(p0)
                self.stress.assign(-p0[:, None, None] * np.eye(2)[None])
            self._chem0 = chem
            self.chem0 = chem.copy()         # E0·V0 of each particle at seeding [J/m] (0 for bodies; analysis.energy)
        else:                                # elastic points only
            self.p_cj = None
            self.burn_mode = BURN_MODES[opts.burn_mode]
            self._chem0 = np.zeros(n)
            self.chem0 = np.zeros(n)
            self.cs.assign(pm.cs0)
        self._check_in_grid(x)
        self._init_active_box()
        self._geo = (
            float(spec.x0),
            float(spec.y0),
            1.0 / spec.h,
            spec.nx,
            spec.ny,
            int(spec.periodic_x),
            int(spec.periodic_y),
            self.shape_kind,
            self.shape_l,
        )
        self.geo = grid_geometry(*self._geo)       # the same, as the transfer kernels take it

    def set_gas_state(self, rho: np.ndarray, p: np.ndarray, v: np.ndarray | None = None,
                      mask: np.ndarray | None = None) -> None:
        """Start the particles (all, or those in ``mask``) as fully burnt products in a given state (JWL only;
        e.g. a shock tube, a gas region of a scenario).

        rho [n] kg/m^3 and p [n] Pa per particle (v [n,2] m/s optional).  Keeps the volumes; sets
        m_p = rho V_p, the reference volume V_p0 = m_p / rho0 (so that V = rho0/rho and the JWL sound
        speed are those of the given density), ie = E V_p0 with p = a(V) + (omega/V) E, F = 1, sigma = -p I,
        c from the JWL and an infinite lighting time.  ``energies()['initial_internal']`` and ``chem0`` (the
        energy the budget counts as supplied) become this state's internal energy. Elastic points (bodies) are
        never changed.
        """
        if self.n_solid and self.is_jwl:
            sel = self.body_id < 0 if mask is None else np.asarray(mask, bool) & (self.body_id < 0)
            mask = sel
        if mask is not None:
            sel = np.asarray(mask, bool)
            keep = {k: getattr(self, k).numpy().copy() for k in ("mass", "vol0", "vol_prev", "rho", "ie", "p", "q",
                                                                 "burn", "stress", "cs", "b_aff", "v", "light_time")}
            chem_keep, chem0_keep = self._chem0.copy(), self.chem0.copy()
            self._set_all_gas_state(rho, p, v)
            for k, old in keep.items():
                new = getattr(self, k).numpy().copy()
                new[~sel] = old[~sel]
                getattr(self, k).assign(new)
            self._chem0 = np.where(sel, self._chem0, chem_keep)
            self.chem0 = np.where(sel, self.chem0, chem0_keep)
            return
        self._set_all_gas_state(rho, p, v)

    def _set_all_gas_state(self, rho, p, v=None) -> None:
        """:meth:`set_gas_state` on every point."""
        if not self.is_jwl:
            raise TypeError("set_gas_state needs a JWL material")
        from blastfrac.materials.jwl import V_FLOOR, jwl_a_np

        P = self.material
        vol = self.vol.numpy().copy()
        rho = np.broadcast_to(np.asarray(rho, F64), vol.shape).copy()
        p = np.broadcast_to(np.asarray(p, F64), vol.shape).copy()
        mass = rho * vol
        vol0 = mass / P.rho0
        Vc = np.maximum(vol / vol0, V_FLOOR)
        E = (p - jwl_a_np(Vc, P.A, P.B, P.R1, P.R2, P.omega)) * Vc / P.omega
        ie = E * vol0
        c2 = jwl_sound_speed_sq_np(Vc, E, p, P.rho0, P.A, P.B, P.R1, P.R2, P.omega)
        self.mass.assign(mass)
        self.vol0.assign(vol0)
        self.vol_prev.assign(vol)
        self.rho.assign(rho)
        self.ie.assign(ie)
        self.p.assign(p)
        self.q.zero_()
        self.burn.assign(np.ones(len(vol)))
        self.stress.assign(-p[:, None, None] * np.eye(2)[None])
        self.cs.assign(np.sqrt(c2))
        self.b_aff.zero_()
        if v is not None:
            self.v.assign(np.asarray(v, F64).reshape(-1, 2))
        self._chem0 = ie.copy()
        self.chem0 = ie.copy()
        self.light_time.fill_(np.inf)

    def _init_active_box(self) -> None:
        """The grid's active node box around the seeded particles (:mod:`blastfrac.mpm.grid`)."""
        s = self.spec
        self.grid.reset_extent()
        wp.launch(particle_extent, dim=self.n, inputs=[self.active, self.x, F64(s.x0), F64(s.y0), F64(1.0 / s.h)],
                  outputs=[self.grid.extent], device=self.device)
        self.grid.renew_box(check=False)

    def _check_in_grid(self, x: np.ndarray) -> None:
        s = self.spec
        ok = np.ones(len(x), dtype=bool)
        for ax, (o, nn, per) in enumerate(((s.x0, s.nx, s.periodic_x), (s.y0, s.ny, s.periodic_y))):
            if not per:
                b = np.floor((x[:, ax] - o) / s.h - 0.5)
                ok &= (b >= 0) & (b + 2 <= nn - 1)
        if not ok.all():
            act = self.active.numpy().copy()
            act[~ok] = 0
            self.active.assign(act)
            self._deactivated.assign(np.array([int((~ok).sum())], dtype=np.int32))

    # ------------------------------------------------------------------ the four stages
    def to_grid(self, dt: float) -> None:
        """P2G (mass, momentum, forces incl. f_ext_p) at the current positions."""
        g = self.grid
        self._launch(clear_grid_box, dim=g.box_node_count, inputs=[*g.box_args(), 1],
                     outputs=[g.mass, g.mom, g.force], device=self.device, key="p2g")
        self._launch(
            p2g,
            dim=self.n,
            inputs=[self.x, self.v, self.b_aff, self.mass, self.vol, self.stress, self.f_ext_p, self.f_ext_moment, self.active,
                    self.geo, int(self.apic)],
            outputs=[g.mass, g.mom, g.force],
            device=self.device,
        )
        self._fold_walls(1)
        if self.own_gas_velocity:
            gas = (self.gas_mass, self.gas_mom, self.gas_scratch)
            self._launch(clear_grid_box, dim=g.box_node_count, inputs=[*g.box_args(), 1], outputs=list(gas),
                         device=self.device, key="p2g_gas")
            self._launch(p2g_gas, dim=self.n, inputs=[self.x, self.v, self.mass, self.active, self.mat_kind, self.geo],
                         outputs=[self.gas_mass, self.gas_mom], device=self.device)
            self._fold_walls(1, gas)

    def update_grid(self, dt: float) -> None:
        """Integrate node momenta over dt [s] with the mass cut-off and boundary conditions."""
        g = self.grid
        self._launch(
            update_grid_momentum,
            dim=g.box_node_count,
            inputs=[*g.box_args(), g.mass, g.bc_mask, g.bc_vel, g.force, F64(dt), F64(self.m_cut)],
            outputs=[g.mom, g.vel, g.dvel],
            device=self.device,
        )
        self._wall_ghosts(1)
        if self.own_gas_velocity:                # the gas's own velocity before the update: p^gas / m^gas, no BC
            self._launch(velocity_from_momentum, dim=g.box_node_count,
                         inputs=[*g.box_args(), self.gas_mass, self.gas_no_bc, g.bc_vel, self.gas_mom],
                         outputs=[self.gas_vel], device=self.device, key="gas")
            self._wall_ghosts(0, (self.gas_mass, self.gas_vel, self.gas_scratch, self.gas_mom))

    def _fold_walls(self, with_mass_force: int, arrays=None) -> None:
        """Image walls: fold the ghosts' P2G sums (mass, momentum, force) onto their images, x walls then y."""
        g = self.grid
        out = list(arrays or (g.mass, g.mom, g.force))
        for a in g.mirror_axes:
            self._launch(fold_wall_images, dim=g.box_node_count,
                         inputs=[*g.box_args(), g.mirror[a], g.mirror_sign[a], with_mass_force],
                         outputs=out, device=self.device, key=(a, arrays is None))

    def _wall_ghosts(self, with_dvel: int, arrays=None) -> None:
        """Image walls: ghosts take their images' velocities (mass, velocity, increment, momentum), x walls then y."""
        g = self.grid
        m, *out = arrays or (g.mass, g.vel, g.dvel, g.mom)
        for a in g.mirror_axes:
            self._launch(set_wall_ghosts, dim=g.box_node_count,
                         inputs=[*g.box_args(), g.mirror[a], g.mirror_sign[a], m, with_dvel],
                         outputs=out, device=self.device, key=(a, arrays is None))

    def to_particles(self, dt: float) -> None:
        """G2P (FLIP/PIC or APIC), MUSL remap (with the affine term), velocity gradient, volume and position update."""
        g, geo, d = self.grid, self.geo, self.device
        if self.apic:
            v_max = self.opts.v_max if self.is_jwl else float("inf")
            self._launch(g2p_velocity_apic, dim=self.n,
                         inputs=[self.x, self.active, g.vel, geo, self.vol, self.vol0, F64(v_max)],
                         outputs=[self.v, self.v_pic, self.b_aff], device=d)
        else:
            self._launch(
                g2p_velocity,
                dim=self.n,
                inputs=[self.x, self.active, g.vel, g.dvel, geo, F64(self.opts.flip), F64(self.opts.flip_bodies),
                        int(bool(self.opts.blend_heating) and self.opts.flip < 1.0), self.mass, self.mat_kind,
                        int(self.own_gas_velocity), self.gas_vel],
                outputs=[self.v, self.v_pic, self.ie],
                device=d,
            )
        self._launch(clear_grid_box, dim=g.box_node_count, inputs=[*g.box_args(), 0],
                     outputs=[g.mass, g.mom, g.force], device=d, key="remap")
        self._launch(p2g_momentum, dim=self.n, inputs=[self.x, self.v, self.b_aff, self.mass, self.active, geo, int(self.apic)],
                     outputs=[g.mom], device=d)
        self._fold_walls(0)
        self._launch(
            velocity_from_momentum,
            dim=g.box_node_count,
            inputs=[*g.box_args(), g.mass, g.bc_mask, g.bc_vel, g.mom],
            outputs=[g.vel],
            device=d,
        )
        self._wall_ghosts(0)
        self._launch(
            update_particle_kinematics,
            dim=self.n,
            inputs=[self.active, self.mass, g.vel, self.v_pic, geo, F64(dt)],
            outputs=[self.x, self.vol, self.vol_prev, self.rho, self.grad_v, self._deactivated, g.extent],
            device=d,
        )
        if not self.captured:
            self.advance_box()

    def advance_box(self) -> None:
        """The active box's schedule, on the host, after a step's particle update: every BOX_STEPS steps it is renewed
        from the particles' extent (read from the device: mpm/grid.py). A captured step (``captured``) leaves it to the
        caller, after the replay."""
        g = self.grid
        g.box_age += 1
        if g.box_age >= BOX_STEPS:
            g.renew_box()

    def update_eos(self, dt: float, t: float) -> None:
        """The elastic points' stress update, then the gas points' burn fraction at t + dt and JWL update (each
        kernel skips the points of the other kind)."""
        d = self.device
        if self.n_solid:
            self._launch(
                update_elastic_state,
                dim=self.n,
                inputs=[self.active, self.mat_kind, self.grad_v, self.rho, self.vol_prev, self.vol, self.lam, self.mu,
                        F64(dt)],
                outputs=[self.stress, self.p, self.cs, self.ie],
                device=d,
            )
        if not self.is_jwl:
            return
        P, o = self.material, self.opts
        self.set_clock(t)
        self._launch(
            update_jwl_state,
            dim=self.n,
            inputs=[self.active, self.mat_kind, self.vol0, self.vol, self.vol_prev, self.rho, self.grad_v,
                    self.light_time, self.clock, F64(dt), F64(self.p_cj), F64(o.burn_width), self.burn_mode,
                    F64(P.rho0), F64(P.D),
                    F64(P.A), F64(P.B), F64(P.R1), F64(P.R2), F64(P.omega), F64(o.q1), F64(o.q2), F64(o.v_max)],
            outputs=[self.burn, self.ie, self.p, self.q, self.cs, self.stress],
            device=d,
        )

    def set_clock(self, t: float) -> None:
        """clock[0] = t [s], the time at the start of the step that update_eos reads on the device: a write into the
        array's view on a CPU, a fill on a GPU (not while a graph is being captured: a captured step's clock is set
        before each replay, Simulation)."""
        if self._clock_host is not None:
            self._clock_host[0] = t
        elif not wp.get_device(self.device).is_capturing:
            self.clock.fill_(t)

    def step(self, dt: float, t: float) -> None:
        """One MUSL step from t to t + dt [s]."""
        self.to_grid(dt)
        self.update_grid(dt)
        self.to_particles(dt)
        self.update_eos(dt, t)

    # ------------------------------------------------------------------ diagnostics
    def stable_dt(self) -> float:
        """alpha h / max(c + |v|) over active particles [s] (inf if none)."""
        self._smax.zero_()
        self._launch(max_signal_speed, dim=self.n, inputs=[self.active, self.v, self.cs], outputs=[self._smax],
                     device=self.device)
        s = float(self._smax.numpy()[0])
        return self.opts.cfl * self.spec.h / s if s > 0 else float("inf")

    @property
    def deactivated_count(self) -> int:
        """Number of particles deactivated so far (left the grid or inverted)."""
        return int(self._deactivated.numpy()[0])

    def _act(self) -> np.ndarray:
        return self.active.numpy().astype(bool)

    def total_mass(self) -> float:
        """Mass of the active particles [kg/m]."""
        return float(self.mass.numpy()[self._act()].sum())

    def total_momentum(self) -> np.ndarray:
        """Momentum of the active particles [N s/m], shape [2]."""
        a = self._act()
        return (self.mass.numpy()[a, None] * self.v.numpy()[a]).sum(axis=0)

    def affine_inertia(self) -> np.ndarray:
        """D_p = Σ N_I (x_I − x_p) ⊗ (x_I − x_p) [m^2] of every particle, shape [n, 2, 2] (h²/4 I for B-splines)."""
        return affine_inertia_np(self.x.numpy(), self.spec, self.opts.shape, self.shape_l)

    def affine_velocity(self) -> np.ndarray:
        """APIC affine velocity C_p = B_p D_p⁻¹ [1/s] of every particle, shape [n, 2, 2] (0 with FLIP/PIC)."""
        return affine_from_moments_np(self.b_aff.numpy(), self.affine_inertia())

    def total_angular_momentum(self, origin=(0.0, 0.0)) -> float:
        """Angular momentum of the active particles about ``origin`` [kg m^2/s per m]: Σ m (x − o) × v plus,
        with APIC, the affine spin Σ m [B_yx − B_xy] (:mod:`blastfrac.mpm.apic`)."""
        a = self._act()
        m, x, v = self.mass.numpy()[a], self.x.numpy()[a] - np.asarray(origin, F64), self.v.numpy()[a]
        out = float((m * (x[:, 0] * v[:, 1] - x[:, 1] * v[:, 0])).sum())
        if self.apic:
            out += float(affine_angular_momentum_np(m, self.b_aff.numpy()[a]).sum())
        return out

    def energies(self) -> dict[str, float]:
        """Energies of the active particles [J/m].

        ``kinetic`` is Σ ½ m v², plus with APIC the affine part Σ ½ m tr(B D⁻¹ Bᵀ) (also given alone as
        ``kinetic_affine``; 0 with FLIP/PIC), the kinetic energy of the particles' linear velocity fields.

        Gas (JWL; over the gas points only, all 0 without charges): internal (sum ie), kinetic, total (internal +
        kinetic), released_chemical (sum F E0 V0: chemical energy liberated by the burn), initial_internal (sum E0 V0)
        and gas_work (initial_internal - internal: work done by the products so far).
        Elastic bodies (only when there are some): body_kinetic (with its affine part body_kinetic_affine),
        body_strain (the work done on them, kept in ``ie``) and body_strain_closed_form (sum 1/2 sigma : C^-1 :
        sigma V), as for an elastic-only solver below.
        Elastic-only solver (one LinearElasticMP for all points): kinetic, strain (the work done on the particles,
        kept in ``ie``: the stored energy of the hypoelastic law), total (kinetic + strain) and strain_closed_form
        (sum 1/2 sigma : C^-1 : sigma V, equal to strain at small strain; see
        :mod:`blastfrac.materials.linear_elastic_mp`).
        """
        a = self._act()
        if self.elastic_only:
            ke, ke_aff, se, cf = self._kinetic_strain(a)
            return {"kinetic": ke, "kinetic_affine": ke_aff, "strain": se, "total": ke + se, "strain_closed_form": cf}
        g = a if self.n_solid == 0 else a & (self.body_id < 0)
        v = self.v.numpy()[g]
        ke = 0.5 * float((self.mass.numpy()[g] * (v * v).sum(axis=1)).sum())
        ke_aff = 0.0
        if self.apic:
            B, D = self.b_aff.numpy()[g], self.affine_inertia()[g]
            ke_aff = float(affine_kinetic_energy_np(self.mass.numpy()[g], B, D).sum())
            ke += ke_aff
        ie = float(self.ie.numpy()[g].sum())
        chem0 = self._chem0[g]
        out = {
            "internal": ie,
            "kinetic": ke,
            "kinetic_affine": ke_aff,
            "total": ie + ke,
            "released_chemical": float((self.burn.numpy()[g] * chem0).sum()),
            "initial_internal": float(chem0.sum()),
            "gas_work": float(chem0.sum() - ie),
        }
        if self.n_solid:
            bke, bke_aff, bse, bcf = self._kinetic_strain(a & (self.body_id >= 0))
            out.update({"body_kinetic": bke, "body_kinetic_affine": bke_aff, "body_strain": bse,
                        "body_strain_closed_form": bcf})
        return out

    def _kinetic_strain(self, sel: np.ndarray) -> tuple[float, float, float, float]:
        """(kinetic incl. affine, affine kinetic, stress work Σ ie, closed-form strain energy) of the elastic points
        ``sel`` [J/m]."""
        v = self.v.numpy()[sel]
        m = self.mass.numpy()[sel]
        ke = 0.5 * float((m * (v * v).sum(axis=1)).sum())
        ke_aff = 0.0
        if self.apic:
            ke_aff = float(affine_kinetic_energy_np(m, self.b_aff.numpy()[sel], self.affine_inertia()[sel]).sum())
            ke += ke_aff
        pm = self.point_materials
        w = strain_energy_density_np(self.stress.numpy()[sel], pm.E[sel], pm.nu[sel])
        return ke, ke_aff, float(self.ie.numpy()[sel].sum()), float((w * self.vol.numpy()[sel]).sum())

    def particle_fields(self) -> dict[str, np.ndarray]:
        """Host copies of the active particles' fields for output (SI units).

        position [n,2] m, velocity [n,2] m/s, pressure [n] Pa, density [n] kg/m^3,
        burn_fraction [n], relative_volume [n], internal_energy [n] J/m (elastic points: the work done on
        them), volume [n] m^2, body [n] (the elastic body of each point, -1 for gas).
        """
        a = self._act()
        return {
            "body": self.body_id[a].copy(),
            "position": self.x.numpy()[a].copy(),
            "velocity": self.v.numpy()[a].copy(),
            "pressure": self.p.numpy()[a].copy(),
            "density": self.rho.numpy()[a].copy(),
            "burn_fraction": self.burn.numpy()[a].copy(),
            "relative_volume": (self.vol.numpy() / self.vol0.numpy())[a],
            "internal_energy": self.ie.numpy()[a].copy(),
            "volume": self.vol.numpy()[a].copy(),
        }

    def pressure_at(self, points: np.ndarray) -> np.ndarray:
        """Gas pressure [Pa] at points [k,2] [m]: mass-weighted B-spline average of particle pressures.

        Only particles within 1.5 h per axis contribute; 0 where there are none.
        """
        from scipy.spatial import cKDTree

        pts = np.atleast_2d(np.asarray(points, F64))
        a = self._act()
        xp, pp, mp = self.x.numpy()[a], self.p.numpy()[a], self.mass.numpy()[a]
        out = np.zeros(len(pts))
        if len(xp) == 0:
            return out
        h = self.spec.h
        tree = cKDTree(xp)
        for k, nb in enumerate(tree.query_ball_point(pts, r=1.5 * np.sqrt(2.0) * h)):
            if not nb:
                continue
            r = (xp[nb] - pts[k]) / h
            w = shape_1d_np(r[:, 0])[0] * shape_1d_np(r[:, 1])[0] * mp[nb]
            if w.sum() > 0:
                out[k] = float((w * pp[nb]).sum() / w.sum())
        return out

    def set_light_times(self, t_light: np.ndarray) -> None:
        """Override the lighting times [s] (e.g. a plane-wave initiation)."""
        self.light_time.assign(np.asarray(t_light, F64))

    def cj_check(self) -> dict:
        """The CJ consistency report of the JWL set (see :func:`blastfrac.explosives.library.cj_report`); None
        without one (elastic bodies only)."""
        from blastfrac.explosives.library import cj_report

        if not self.is_jwl:
            return None
        name = self.config.name if self.config is not None and self.config.name else "custom"
        return cj_report(self.material, name)
