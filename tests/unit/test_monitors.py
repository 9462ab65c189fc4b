"""Monitors average the rock field over a radius R (analysis/monitors.py), checked against analytic fields.

Fields used (plane strain, tension positive):
- Lamé, pressurised thick cylinder (inner radius a, outer b, pressure p) about a centre O; in Cartesian
  components, with C = p a²/(b² − a²), d = x − O, r = |d|, θ = arg d:
      σxx = C (1 − b²/r² cos 2θ),  σyy = C (1 + b²/r² cos 2θ),  σxy = −C b²/r² sin 2θ,
  i.e. σrr = C (1 − b²/r²), σθθ = C (1 + b²/r²) (VALIDATION §3). The b² terms are harmonic (Re/Im of b²/d²),
  so their mean over a disc equals the value at its centre: a disc average has no curvature bias, only the
  discreteness of the element set.
- a linear velocity field v = v0 + G x, whose mass-weighted mean over any node set is v at the set's mass centre.
"""

from __future__ import annotations

import numpy as np
import pytest

from blastfrac.analysis.monitors import MonitorSet
from blastfrac.model.builder import ModelBuilder
from blastfrac.scenario import ScenarioError
from blastfrac.scenario.schema import Monitor
from conftest import scenario
from verification.static_helpers import static_pressurised_hole

SCATTER = 0.2          # ± relative per-element perturbation (uniform): std SCATTER/√3
K_SPRING = 5.0e15      # Pa/m


def lame_cartesian(P: np.ndarray, a: float, b: float, p: float, center=(0.0, 0.0)) -> np.ndarray:
    """Lamé (σxx, σyy, σxy) [Pa] at points P [..., 2] [m] of a cylinder a < r < b under inner pressure p [Pa]."""
    d = P - np.asarray(center)
    r2 = d[..., 0] ** 2 + d[..., 1] ** 2
    c2, s2 = (d[..., 0] ** 2 - d[..., 1] ** 2) / r2, 2 * d[..., 0] * d[..., 1] / r2
    C = p * a**2 / (b**2 - a**2)
    return np.stack([C * (1 - b**2 / r2 * c2), C * (1 + b**2 / r2 * c2), -C * b**2 / r2 * s2], -1)


def to_polar(S: np.ndarray, P: np.ndarray) -> np.ndarray:
    """(σrr, σθθ) [Pa] from Cartesian (σxx, σyy, σxy) [M, 3] at points P [M, 2] about the origin."""
    n = P / np.hypot(P[:, 0], P[:, 1])[:, None]
    c, s = n[:, 0], n[:, 1]
    return np.stack([S[:, 0] * c * c + S[:, 1] * s * s + 2 * S[:, 2] * c * s,
                     S[:, 0] * s * s + S[:, 1] * c * c - 2 * S[:, 2] * c * s], 1)


def centroids(X: np.ndarray) -> np.ndarray:
    return (X[0::3] + X[1::3] + X[2::3]) / 3


def monitor_set(points, model, radius=None, quantities=("sxx", "syy", "sxy")) -> MonitorSet:
    mons = [Monitor(name=f"m{k}", position=tuple(map(float, q)), radius=radius, quantities=list(quantities))
            for k, q in enumerate(points)]
    return MonitorSet(mons, model.host["node_X"], model.host["node_mass"])


def sampled_stress(ms: MonitorSet, X: np.ndarray, sigma: np.ndarray) -> np.ndarray:
    """(σxx, σyy, σxy) per monitor through sample() (the path the run takes); ms samples sxx, syy, sxy."""
    return np.array(ms.sample(X, X, np.zeros_like(X), sigma)).reshape(-1, 3)


@pytest.fixture(scope="module")
def square():
    """0.1 m square, mesh size 2.5 mm (≈ 4300 CST blocks)."""
    sc = scenario(geometry={"domain": {"type": "rectangle", "width": 0.1, "height": 0.1}, "mesh_size": 0.0025})
    return ModelBuilder(sc).finalize("cpu")


@pytest.fixture(scope="module")
def grid_points():
    g = np.linspace(-0.035, 0.035, 6)
    return np.array([[x, y] for x in g for y in g])


def test_default_radius_is_two_local_element_sizes(square, grid_points):
    """R = 2√(2A) of the containing element; the averaged elements cover ≈ πR²."""
    ms = monitor_set(grid_points, square)
    A = square.host["elem_area0"]
    rep = ms.report()
    R = np.array([r["radius"] for r in rep])
    assert R == pytest.approx(2 * np.sqrt(2 * A[ms.elems]), rel=1e-12)
    covered = np.array([r["elements"] for r in rep]) * A.mean() / (np.pi * R**2)
    print(f"default R = {R.mean() * 1e3:.2f} mm, {np.mean([r['elements'] for r in rep]):.1f} elements and "
          f"{np.mean([r['nodes'] for r in rep]):.1f} nodes per monitor; "
          f"N·Ā/πR² = {covered.min():.2f}..{covered.max():.2f}")
    assert np.all(np.abs(covered - 1) < 0.35)
    assert set(rep[0]) == {"name", "position", "radius", "elements", "nodes"}
    one = monitor_set(grid_points[:1], square, radius=0.0).report()[0]
    assert (one["elements"], one["nodes"], one["radius"]) == (1, 3, 0.0)
    tiny = monitor_set(grid_points[:1], square, radius=1e-7).report()[0]   # no centroid within R: containing element
    assert (tiny["elements"], tiny["nodes"]) == (1, 3)


def test_averaged_stress_recovers_smooth_field_through_element_scatter(square, grid_points):
    """Lamé field at the centroids × (1 + ξ), ξ uniform ±20 % (zero mean, seeded), 36 monitor points.

    Averaging N elements (area weights w_e) of independent scatter ξ (std s = 0.2/√3) leaves an error of
    variance s²·Σ w_e² σ_e² about the field, ≈ (sσ)²/N; a single element (R = 0) keeps s²σ_e². The smooth
    part is recovered without bias (harmonic field, discreteness only).
    """
    X = square.host["node_X"]
    a, b, p, O = 0.01, 0.2, 100e6, (-0.07, 0.0)          # centre outside the square: smooth in it
    exact = lame_cartesian(grid_points, a, b, p, O)
    scale = np.abs(exact).max(1, keepdims=True)         # error per point relative to its largest component
    smooth = lame_cartesian(centroids(X), a, b, p, O)
    rng = np.random.default_rng(20240607)
    xi = rng.uniform(-SCATTER, SCATTER, smooth.shape)
    xi -= xi.mean(0)
    noisy = smooth * (1 + xi)
    avg, one = monitor_set(grid_points, square), monitor_set(grid_points, square, radius=0.0)
    s = SCATTER / np.sqrt(3)
    pred = s * np.sqrt(np.mean(_noise_variance(smooth, _stencils(avg, square), square) / scale**2))
    pred_one = s * np.sqrt(np.mean(smooth[one.elems] ** 2 / scale**2))
    bias = np.abs(sampled_stress(avg, X, smooth) - exact) / scale
    bias_one = np.abs(sampled_stress(one, X, smooth) - exact) / scale
    err = (sampled_stress(avg, X, noisy) - exact) / scale
    err_one = (sampled_stress(one, X, noisy) - exact) / scale
    rms, rms_one = np.sqrt(np.mean(err**2)), np.sqrt(np.mean(err_one**2))
    print(f"smooth field: averaged max |err| {bias.max():.2%} (rms {np.sqrt(np.mean(bias**2)):.2%}), "
          f"single element max {bias_one.max():.2%}")
    print(f"±{SCATTER:.0%} scatter: averaged rms {rms:.2%} (predicted s·√(Σw²σ²) = {pred:.2%}), "
          f"mean {err.mean():+.2%}; "
          f"single element rms {rms_one:.2%} (predicted {pred_one:.2%}), max {np.abs(err_one).max():.1%}")
    assert bias.max() < 0.02                            # the smooth field within 2 % at every point
    assert np.sqrt(np.mean(bias**2)) < 0.01
    assert rms < 1.3 * pred + 0.01                      # noise reduced as 1/√N, plus the discreteness bias
    assert abs(err.mean()) < 0.01                       # no bias over the 36 points
    assert rms_one > 0.75 * pred_one                    # a single element keeps the scatter
    assert rms < rms_one / 3


def _noise_variance(smooth: np.ndarray, stencils: list, model) -> np.ndarray:
    """Σ w_e² σ_e² per point and component [Pa²] (w_e = area weights of each stencil), per unit variance of ξ."""
    A = model.host["elem_area0"]
    return np.array([((A[i] / A[i].sum())[:, None] ** 2 * smooth[i] ** 2).sum(0) for i in stencils])


def _stencils(ms: MonitorSet, model):
    """Element sets that a disc of radius R around each point holds (independent of the MonitorSet internals)."""
    c = centroids(model.host["node_X"])
    return [np.flatnonzero(np.linalg.norm(c - p, axis=1) <= R) for p, R in zip(ms.points, ms.radii)]


def test_mass_weighted_velocity_of_a_linear_field(square, grid_points):
    """v = v0 + G x: the mean over the nodes within R is v at their mass centre x̄, |error| ≤ ‖G‖₂·|x̄ − p|.

    The nodes (spacing ≈ h, the local element size) fill the disc; x̄ − p comes only from the granularity
    of its rim, |x̄ − p| ≲ h·(h/R) = h/2 for R = 2h. Tolerance: ‖G‖₂·h/2. A constant field and a rigid
    translation are reproduced exactly (weights sum to 1).
    """
    X = square.host["node_X"]
    G = np.array([[300.0, -120.0], [80.0, 200.0]])      # [1/s]
    v0 = np.array([1.0, -2.0])                          # [m/s]
    v = v0 + X @ G.T
    ms = monitor_set(grid_points, square, quantities=("ux", "uy", "vx", "vy"))
    shift = np.array([3e-4, -1e-4])
    row = np.array(ms.sample(X + shift, X, v, np.zeros((len(X) // 3, 3)))).reshape(-1, 4)
    h = ms.radii / 2
    err = np.linalg.norm(row[:, 2:] - (v0 + grid_points @ G.T), axis=1) / (np.linalg.norm(G, 2) * h)
    print(f"linear velocity: max |v̄ − v(p)| = {err.max():.3f}·‖G‖h (tolerance 0.5), mean {err.mean():.3f}")
    assert err.max() < 0.5
    assert row[:, :2] == pytest.approx(np.tile(shift, (len(row), 1)), rel=1e-12)
    const = np.array(ms.sample(X, X, np.tile(v0, (len(X), 1)), np.zeros((len(X) // 3, 3)))).reshape(-1, 4)
    assert const[:, 2:] == pytest.approx(np.tile(v0, (len(row), 1)), rel=1e-12)


def test_lame_cylinder_static_solution_monitors():
    """Static block–spring solution of a thick cylinder under inner pressure: monitors at r = 3a vs Lamé.

    K u = f from the intact model's stiffness, f = consistent nodal pressure forces p·L/2 on each hole-wall
    edge node, along −n (n = the block's outward normal, into the hole); the load is self-equilibrated, the
    rigid modes are pinned at two outer nodes. Stresses are set by equilibrium (independent of E, ν and the
    spring compliance), σ = D·B·u_e per CST block.
    """
    a, b, p = 0.005, 0.05, 100e6
    sc = scenario(rock={"stiffness_mode": "per_area", "kn": K_SPRING, "ks": K_SPRING},
                  geometry={"domain": {"type": "disc", "radius": b}, "boreholes": [{"radius": a}],
                            "mesh_size": 0.0025, "mesh_size_near": 0.0006, "refinement_distance": 0.02})
    m = ModelBuilder(sc).finalize("cpu")
    X = m.host["node_X"]
    u = static_pressurised_hole(m, a, p)
    sigma = _cst_stress(X, u, m.lam, m.mu)
    th = np.linspace(0, 2 * np.pi, 12, endpoint=False)
    P = 3 * a * np.stack([np.cos(th), np.sin(th)], 1)
    exact = to_polar(lame_cartesian(P, a, b, p), P)
    C = p * a**2 / (b**2 - a**2)
    print(f"Lamé at r = 3a: σrr = {exact[0, 0] / 1e6:.3f} MPa (C(1 − b²/r²)), "
          f"σθθ = {exact[0, 1] / 1e6:.3f} MPa (C = {C / 1e6:.4f} MPa)")
    res = {}
    for label, radius in (("averaged", None), ("single", 0.0)):
        ms = monitor_set(P, m, radius)
        rel = to_polar(sampled_stress(ms, X, sigma), P) / exact - 1
        res[label] = rel
        print(f"{label:8s} (R = {ms.radii.mean() * 1e3:.2f} mm, {np.mean([r['elements'] for r in ms.report()]):.0f} "
              f"elements): σrr rms {np.sqrt(np.mean(rel[:, 0] ** 2)):.2%} max {np.abs(rel[:, 0]).max():.2%}; "
              f"σθθ rms {np.sqrt(np.mean(rel[:, 1] ** 2)):.2%} max {np.abs(rel[:, 1]).max():.2%}")
    rms = np.sqrt(np.mean(res["averaged"] ** 2, axis=0))
    rms_one = np.sqrt(np.mean(res["single"] ** 2, axis=0))
    assert np.all(rms < 0.02)
    assert np.abs(res["averaged"]).max() < 0.04
    assert np.abs(res["averaged"].mean(axis=0)).max() < 0.01    # unbiased around the ring
    assert np.all(rms_one > 2.5 * rms)
    assert np.abs(res["single"]).max() > 0.08


def _cst_stress(X: np.ndarray, u: np.ndarray, lam: float, mu: float) -> np.ndarray:
    """Plane-strain CST stresses σ = D·B·u_e (xx, yy, xy) [Pa], [E, 3] (B as in model.builder.cst_stiffness)."""
    p0, p1, p2 = X[0::3], X[1::3], X[2::3]
    A2 = (p1[:, 0] - p0[:, 0]) * (p2[:, 1] - p0[:, 1]) - (p1[:, 1] - p0[:, 1]) * (p2[:, 0] - p0[:, 0])
    bx = np.stack([p1[:, 1] - p2[:, 1], p2[:, 1] - p0[:, 1], p0[:, 1] - p1[:, 1]], 1) / A2[:, None]
    cy = np.stack([p2[:, 0] - p1[:, 0], p0[:, 0] - p2[:, 0], p1[:, 0] - p0[:, 0]], 1) / A2[:, None]
    ux, uy = u[:, 0].reshape(-1, 3), u[:, 1].reshape(-1, 3)
    exx, eyy = (bx * ux).sum(1), (cy * uy).sum(1)
    gxy = (cy * ux + bx * uy).sum(1)
    return np.stack([(lam + 2 * mu) * exx + lam * eyy, lam * exx + (lam + 2 * mu) * eyy, mu * gxy], 1)


def test_negative_radius_is_refused():
    with pytest.raises(ScenarioError) as e:
        scenario(geometry={"domain": {"type": "rectangle", "width": 0.1, "height": 0.1}, "mesh_size": 0.0025},
                 monitors=[{"name": "m", "position": [0.0, 0.0], "radius": -1e-3}])
    msg = str(e.value)
    print(f"negative radius: {msg}")
    assert "monitors[0].radius" in msg and "greater than or equal to 0" in msg
