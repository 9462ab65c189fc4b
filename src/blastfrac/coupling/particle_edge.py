"""Particle–edge contact law between MPM gas particles and exposed CDEM block edges (METHOD §3, Y27–Y30).

A material point is a disk of radius r_p [m]. For one element, every *exposed* edge (on the mesh
boundary, on a borehole wall, or an interface whose two springs have both broken) and every vertex of
an exposed edge is a candidate:

* edge a→b (outward unit normal n̂ = (t_y, −t_x) for counter-clockwise triangles, t̂ = (x_b − x_a)/L):
  ξ = (x_p − x_a)·t̂/L, d = (x_p − x_a)·n̂; contact if 0 ≤ ξ ≤ 1 and −r_c < d < r_c, overlap δ = r_c − d
  (contact radius r_c ≥ r_p, below);
  the guard d > −r_c keeps a particle from being caught by an edge from inside the rock (Y27);
* vertex a: contact if |x_p − x_a| < r_c, δ = r_c − |x_p − x_a|, normal along x_p − x_a. Vertices close
  convex corners (crack mouths, fragment corners) through which a particle could otherwise slip.

Only the candidate with the largest overlap counts per (particle, element), so a particle near an
element corner is not pushed twice by the same block.

Force on the particle (per unit thickness) [N/m]:
  F_n = max(min(k_c·δ, F_cap) − c_n·v_n, 0) along n̂, F_cap = κ·(p + ρ·v_a²)·2r_p (see normal_force_cap) (total penalty form, Y28, with a normal dashpot
  c_n = 2ζ√(m_eff·k_c), m_eff = m_p·m_c/(m_p + m_c), v_n = (v_p − v_c)·n̂);
  F_t = −min(μ·F_n, c_n·|v_t|)·v_t/|v_t| (Coulomb friction with viscous regularisation instead of the
  incremental history of Y29; μ = 0 by default: an inviscid gas).
The reaction −f goes to the edge nodes with weights (1 − ξ, ξ) (linear interpolation; see the note on Y30
in METHOD §3), so momentum is conserved exactly.

**Where the force acts on the gas** (``surface`` in the kernel, on by default). The wall pushes on the gas
where the two touch, at the disk's surface x_p − r_p·n̂, not at its centre. The force enters the grid as
f·N_I(x_p) + M·∇N_I(x_p) with the moment M = f ⊗ (−r_p·n̂) (mpm.kernels_p2g.p2g), the first-order
expansion of f·N_I(x_p − r_p·n̂): the same total force and torque, at the right place. Applied at the
centre instead, the force lands half a particle inside the gas, while the gas's own pressure acts on the
grid out to the particle's edge. At the nodes behind the outer particles the pressure then pushes outwards
unopposed and at the nodes inside the contact pulls inwards unopposed. The outer layer is stretched (its
pressure fell from 195 to 139 MPa in 6 µs in a 200 MPa gas-filled hole), the gas behind it is compressed,
and the wall load rose to 1.15–1.5 × the gas pressure. The same moment makes the work bookkeeping use the
gas velocity at the contact point, v_p + L_p·(−r_p·n̂).

**Contact radius** (``preload``, on by default). A gas particle of pressure p touching a wall must push on
it with p per unit length, i.e. F = p·2r_p. A plain penalty needs an overlap δ = p·2r_p/k_c for that, so the
gas has to expand into the wall by δ before the wall feels its pressure: when a charge ignites at the wall
the outer gas accelerates across δ and strikes the wall (24 % above p for a 200 MPa step with k_c = 20·P_CJ
and ζ = 0.7, 39 % on a near-rigid wall). The contact radius is therefore r_c = r_p + p·2r_p/k_c
(``pressure_offset``, capped at r_p/4): the force is k_c·(r_c − d), equal to p·2r_p when the disk just
touches the wall, so a gas at rest against a wall loads it at once with its own pressure.

**Initial overlaps** (``initial_overlap``). A contact can appear already deep: an interface becomes exposed
when its last spring separates while an expanded particle (r_p up to h/2) sits in the opening, or a rotating
fragment sweeps over a particle between two steps. The full penalty k_c·δ would then fire a light gas
particle at tens of km/s (it did: tests/verification/test_coupling_initial_overlap.py). A contact seen for
the first time may overlap by δ_new = v_a·Δt + 0.1·r_p (what one step of approach at v_a = max(−v_n, 0)
plus the equilibrium overlap at P_CJ produce); the excess δ₀ = δ − δ_new is ignored, the force is
k_c·(δ − δ₀), and δ₀ only shrinks (δ₀ ← min(δ₀, δ)) as the particle backs out, so the contact never
pulls. The penalty energy then no longer comes from nowhere. δ₀ is kept per (particle, element) for up to
CONTACT_HISTORY elements per particle and forgotten once the contact ends (LS-DYNA's treatment of initial
penetrations, IGNORE = 1, is the same idea).
"""

from __future__ import annotations

import numpy as np
import warp as wp

NO_CONTACT = -1.0
#: overlap a new contact may have without being treated as an initial penetration, as a fraction of r_p [-]
NEW_CONTACT_SLACK_NP = 0.1
NEW_CONTACT_SLACK = wp.constant(wp.float64(NEW_CONTACT_SLACK_NP))
#: largest pressure offset of the contact radius, as a fraction of r_p [-]
MAX_PRESSURE_OFFSET_NP = 0.25
MAX_PRESSURE_OFFSET = wp.constant(wp.float64(MAX_PRESSURE_OFFSET_NP))
#: (particle, element) contact histories kept per particle
CONTACT_HISTORY = wp.constant(8)


@wp.func
def edge_overlap(xp: wp.vec2d, rp: wp.float64, xa: wp.vec2d, xb: wp.vec2d):
    """(δ [m], n̂, ξ) of a disk at xp with radius rp against edge a→b; δ = −1 when not in contact."""
    d = xb - xa
    L = wp.length(d)
    t = d / L
    n = wp.vec2d(t[1], -t[0])
    r = xp - xa
    xi = wp.dot(r, t) / L
    g = wp.dot(r, n)
    delta = wp.float64(NO_CONTACT)
    if xi >= wp.float64(0.0) and xi <= wp.float64(1.0) and g > -rp and g < rp:
        delta = rp - g
    return delta, n, xi


@wp.func
def vertex_overlap(xp: wp.vec2d, rp: wp.float64, xa: wp.vec2d):
    """(δ [m], n̂) of a disk at xp with radius rp against the vertex xa; δ = −1 when not in contact."""
    r = xp - xa
    dist = wp.length(r)
    delta = wp.float64(NO_CONTACT)
    n = wp.vec2d(wp.float64(0.0), wp.float64(0.0))
    if dist < rp and dist > wp.float64(1e-12) * rp:
        delta = rp - dist
        n = r / dist
    return delta, n


@wp.func
def contact_force(delta: wp.float64, n: wp.vec2d, vrel: wp.vec2d, kc: wp.float64, cn: wp.float64, mu: wp.float64,
                  fcap: wp.float64):
    """Force on the particle [N/m] and the power it dissipates [W/m] for overlap δ and relative velocity vrel.

    The elastic normal force is capped at fcap [N/m] (no cap when fcap <= 0), see :func:`normal_force_cap`.
    """
    vn = wp.dot(vrel, n)
    fn_el = kc * delta
    if fcap > wp.float64(0.0):
        fn_el = wp.min(fn_el, fcap)
    fn = wp.max(fn_el - cn * vn, wp.float64(0.0))
    diss = -(fn - fn_el) * vn
    vt = vrel - vn * n
    svt = wp.length(vt)
    f = fn * n
    if mu > wp.float64(0.0) and svt > wp.float64(0.0):
        ft = wp.min(mu * fn, cn * svt)
        f = f - ft * vt / svt
        diss = diss + ft * svt
    return f, diss


@wp.func
def initial_overlap(delta: wp.float64, vn: wp.float64, dt: wp.float64, rp: wp.float64):
    """Part δ₀ [m] of a first-seen overlap δ that one step of approach at −v_n [m/s] cannot explain."""
    allowed = wp.max(-vn, wp.float64(0.0)) * dt + NEW_CONTACT_SLACK * rp
    return wp.max(delta - allowed, wp.float64(0.0))


@wp.func
def pressure_offset(p: wp.float64, rp: wp.float64, kc: wp.float64):
    """Equilibrium overlap p·2r_p/k_c [m] of a particle of pressure p [Pa] and radius r_p [m] against a wall,
    capped at MAX_PRESSURE_OFFSET·r_p."""
    return wp.min(wp.max(p, wp.float64(0.0)) * wp.float64(2.0) * rp / kc, MAX_PRESSURE_OFFSET * rp)


@wp.func
def normal_force_cap(kappa: wp.float64, p: wp.float64, rho: wp.float64, vn: wp.float64, rp: wp.float64):
    """κ·(p + ρ·v_a²)·2r_p [N/m]: the most a gas particle of pressure p [Pa], density ρ [kg/m³] approaching at
    v_a = max(−v_n, 0) [m/s] may push on one contact. It holds a particle at rest against its pressure (needs
    p·2r_p) and stops an approaching one within r_p/κ, while a particle squeezed into a crack narrower than
    itself can no longer push its faces apart with the full penalty force k_c·δ (a disk is not a solid)."""
    va = wp.max(-vn, wp.float64(0.0))
    return kappa * (wp.max(p, wp.float64(0.0)) + rho * va * va) * wp.float64(2.0) * rp


# ---------------------------------------------------------------------------------------------- NumPy twins
def edge_overlap_np(xp, rp, xa, xb):
    """NumPy twin of :func:`edge_overlap`; returns (δ, n̂, ξ)."""
    xp, xa, xb = (np.asarray(a, float) for a in (xp, xa, xb))
    d = xb - xa
    L = np.linalg.norm(d)
    t = d / L
    n = np.array([t[1], -t[0]])
    r = xp - xa
    xi, g = r @ t / L, r @ n
    delta = rp - g if (0.0 <= xi <= 1.0 and -rp < g < rp) else NO_CONTACT
    return delta, n, xi


def vertex_overlap_np(xp, rp, xa):
    """NumPy twin of :func:`vertex_overlap`; returns (δ, n̂)."""
    r = np.asarray(xp, float) - np.asarray(xa, float)
    dist = np.linalg.norm(r)
    if rp > dist > 1e-12 * rp:
        return rp - dist, r / dist
    return NO_CONTACT, np.zeros(2)


def initial_overlap_np(delta, vn, dt, rp):
    """NumPy twin of :func:`initial_overlap` [m]."""
    return max(delta - (max(-vn, 0.0) * dt + NEW_CONTACT_SLACK_NP * rp), 0.0)


def pressure_offset_np(p, rp, kc):
    """NumPy twin of :func:`pressure_offset` [m]."""
    return min(max(p, 0.0) * 2.0 * rp / kc, MAX_PRESSURE_OFFSET_NP * rp)


def normal_force_cap_np(kappa, p, rho, vn, rp):
    """NumPy twin of :func:`normal_force_cap` [N/m]."""
    va = max(-vn, 0.0)
    return kappa * (max(p, 0.0) + rho * va * va) * 2.0 * rp


def contact_force_np(delta, n, vrel, kc, cn, mu, fcap=0.0):
    """NumPy twin of :func:`contact_force`; returns (f [N/m], dissipated power [W/m])."""
    n, vrel = np.asarray(n, float), np.asarray(vrel, float)
    vn = vrel @ n
    fn_el = kc * delta
    if fcap > 0:
        fn_el = min(fn_el, fcap)
    fn = max(fn_el - cn * vn, 0.0)
    diss = -(fn - fn_el) * vn
    vt = vrel - vn * n
    svt = np.linalg.norm(vt)
    f = fn * n
    if mu > 0 and svt > 0:
        ft = min(mu * fn, cn * svt)
        f = f - ft * vt / svt
        diss += ft * svt
    return f, diss
