"""Crack statistics (analysis/cracks.py) on crack patterns drawn into a real mesh, with known answers.

Cracks are drawn by marking broken the interfaces that a straight ray from the hole centre crosses; the
expected crack count, lengths and crushed-zone radius follow from how the pattern was drawn, not from the code.
"""

import numpy as np
import pytest

from blastfrac.analysis.cracks import circle_crossings, crack_statistics, group_crossings
from blastfrac.model.builder import ModelBuilder
from blastfrac.scenario import scenario_from_dict

R_B = 0.005
ENDS = 0.025 + 0.01 * np.arange(8)             # tip radius of each of the 8 drawn cracks [m]
ANGLES = 2 * np.pi * np.arange(8) / 8 + 0.1


@pytest.fixture(scope="module")
def model():
    sc = scenario_from_dict({
        "rock": {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2},
        "geometry": {"domain": {"type": "disc", "radius": 0.12}, "mesh_size": 0.004, "mesh_size_near": 0.001,
                     "refinement_distance": 0.03, "boreholes": [{"center": [0.0, 0.0], "radius": R_B}]},
        "simulation": {"progress": False}, "output": {"paraview": False, "figures": False},
    })
    return ModelBuilder(sc).finalize("cpu")


def _interfaces(model):
    X = model.host["node_X"]
    pn = model.topology.pair_nodes
    return X[pn[0::2, 0]], X[pn[1::2, 0]]


def _ray_hits(a, b, theta, r0, r1):
    """Interfaces a→b crossed by the ray segment from r0 to r1 at polar angle theta."""
    u = np.array([np.cos(theta), np.sin(theta)])
    p, q = r0 * u, r1 * u
    d1, d2 = b - a, q - p

    def cross(x, y):
        return x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0]

    den = cross(d1, d2)
    ok = np.abs(den) > 1e-18
    s = np.where(ok, cross(p - a, d2) / np.where(ok, den, 1), -1)       # along the interface
    t = np.where(ok, cross(p - a, d1) / np.where(ok, den, 1), -1)       # along the ray
    return ok & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)


def _draw(model, crushed=0.0, shattered=None):
    a, b = _interfaces(model)
    cracked = np.zeros(len(a), bool)
    for th, r1 in zip(ANGLES, ENDS):
        cracked |= _ray_hits(a, b, th, R_B, r1)
    mid = np.linalg.norm(0.5 * (a + b), axis=1)
    if crushed:
        cracked |= mid < crushed
    if shattered:
        cracked |= (mid > shattered[0]) & (mid < shattered[1])
    mode = np.repeat(cracked.astype(np.int32), 2)     # both springs of a cracked interface, tensile
    return mode


def test_group_crossings_wraps_around_zero():
    R, w = 0.05, 0.001
    th = np.array([-0.005, 0.004, 1.0, 1.01, 3.0])   # two crossings astride θ = 0 form one crack
    g = group_crossings(th, R, w)
    assert len(g) == 3
    assert sorted(n for _, _, n in g) == [1, 2, 2]


def test_circle_crossing_angle_is_exact():
    a, b = np.array([[0.0, 0.01]]), np.array([[0.03, 0.01]])         # horizontal chord at y = 1 cm
    R = 0.02
    th = circle_crossings(a, b, np.zeros(2), R)
    assert th[0] == pytest.approx(np.arcsin(0.01 / R), rel=1e-12)


def test_separate_cracks_counted_with_lengths(model):
    mode = _draw(model)
    s = crack_statistics(model, mode, np.zeros(2), R_B)
    w = s["ring_width"]
    print(f"drawn 8 cracks: count {s['radial_crack_count']}, r_c/r_b {s['crushed_zone_radius_over_rb']:.2f}, "
          f"lengths {np.round(s['radial_crack_lengths'], 4)} vs {np.round(ENDS[::-1] - R_B, 4)}")
    assert s["crushed_zone_radius"] == R_B            # 8 cracks cannot crack half of the first ring
    assert s["radial_crack_count"] == 8
    assert s["radial_crack_count_tensile"] == 8
    expect = np.sort(ENDS - s["crushed_zone_radius"])[::-1]
    # a crack's last sampled circle lies within one ring width w of its tip, and the last interface the ray
    # crosses can reach one local element size h beyond the tip
    h = np.array(s["crossings"]["mesh_size"]).max()
    assert np.all(np.abs(np.array(s["radial_crack_lengths"]) - expect) <= w + 1.5 * h)


def test_network_joined_by_crushed_zone_still_counts_cracks(model):
    """The cracks meet in a fully broken zone of 2.5 r_b: r_c is found and the 8 cracks are still 8 (the shortest
    still reaches more than three elements beyond the zone)."""
    mode = _draw(model, crushed=2.5 * R_B)
    s = crack_statistics(model, mode, np.zeros(2), R_B)
    w = s["ring_width"]
    assert abs(s["crushed_zone_radius"] - 2.5 * R_B) <= 1.5 * w
    assert s["radial_crack_count"] == 8


def test_shattered_ring_is_not_counted_as_cracks(model):
    """A fully broken annulus (spalling-like) beyond the crack tips adds no crack crossings."""
    mode = _draw(model, shattered=(0.1, 0.11))
    s = crack_statistics(model, mode, np.zeros(2), R_B)
    prof = s["crossings"]
    R = np.array(prof["radius"])
    inside = (R > 0.1 + 2 * s["ring_width"]) & (R < 0.11 - 2 * s["ring_width"])
    assert inside.any()
    assert np.all(np.array(prof["count"])[inside] == 0)
    assert np.all(np.array(prof["shattered_arc"])[inside] > 0.9 * 2 * np.pi * R[inside])
    assert s["radial_crack_count"] == 8
