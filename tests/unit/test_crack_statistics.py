"""Crack statistics (analysis/cracks.py) on crack patterns drawn into a real mesh, with known answers.

Cracks are drawn by marking broken the interfaces that a straight segment crosses (a ray from the hole wall for
a radial crack); the expected crack count, lengths, crushed-zone radius and detached crack sets follow from how
the pattern was drawn, not from the code.
"""

import numpy as np
import pytest

from blastfrac.analysis.cracks import (
    circle_crossings,
    crack_statistics,
    detached_interface_mask,
    group_crossings,
    radial_interfaces,
)
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


def _segment_hits(a, b, p, q):
    """Interfaces a→b crossed by the segment p→q [m]."""
    d1, d2 = b - a, q - p

    def cross(x, y):
        return x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0]

    den = cross(d1, d2)
    ok = np.abs(den) > 1e-18
    s = np.where(ok, cross(p - a, d2) / np.where(ok, den, 1), -1)       # along the interface
    t = np.where(ok, cross(p - a, d1) / np.where(ok, den, 1), -1)       # along the segment
    return ok & (s >= 0) & (s <= 1) & (t >= 0) & (t <= 1)


def _ray_hits(a, b, theta, r0, r1):
    """Interfaces a→b crossed by the ray segment from r0 to r1 at polar angle theta."""
    u = np.array([np.cos(theta), np.sin(theta)])
    return _segment_hits(a, b, r0 * u, r1 * u)


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
    assert s["dense_cracking_radius"] == R_B
    assert s["detached_crack_sets"] == 0               # every ray starts at the wall
    assert s["connected_interfaces"] == s["cracked_interfaces"] == int(mode[0::2].sum())
    assert s["radial_crack_count"] == 8
    assert s["radial_crack_count_tensile"] == 8
    expect = np.sort(ENDS - s["dense_cracking_radius"])[::-1]      # lengths start at r_k
    # a crack's last sampled circle lies within one ring width w of its tip, and the last interface the ray
    # crosses can reach one local element size h beyond the tip
    h = np.array(s["crossings"]["mesh_size"]).max()
    assert np.all(np.abs(np.array(s["radial_crack_lengths"]) - expect) <= w + 1.5 * h)


def test_network_joined_by_crushed_zone_still_counts_cracks(model):
    """The cracks meet in a fully broken zone of 2.5 r_b: r_c (and r_k, every interface being cracked there) is found
    and the 8 cracks are still 8 (the shortest still reaches more than three elements beyond the zone)."""
    mode = _draw(model, crushed=2.5 * R_B)
    s = crack_statistics(model, mode, np.zeros(2), R_B)
    w = s["ring_width"]
    assert abs(s["crushed_zone_radius"] - 2.5 * R_B) <= 1.5 * w
    assert abs(s["dense_cracking_radius"] - 2.5 * R_B) <= 1.5 * w
    assert s["radial_crack_count"] == 8


def test_radial_class_is_within_45_degrees_of_the_radius(model):
    """radial_interfaces against the angle between each interface and the radius through its midpoint, from atan2."""
    a, b = _interfaces(model)
    mid = 0.5 * (a + b)
    ang = np.abs(np.arctan2(b[:, 1] - a[:, 1], b[:, 0] - a[:, 0]) - np.arctan2(mid[:, 1], mid[:, 0])) % np.pi
    ang = np.minimum(ang, np.pi - ang)                  # angle between the two lines, 0 … π/2
    clear = np.abs(ang - np.pi / 4) > 1e-9
    assert np.array_equal(radial_interfaces(a, b, np.zeros(2))[clear], (ang < np.pi / 4)[clear])
    assert 0.35 < np.mean(ang < np.pi / 4) < 0.65      # a random mesh: about half in each class


@pytest.mark.parametrize("R1", [2.0 * R_B, 3.0 * R_B])
def test_crushed_zone_is_broken_in_every_direction(model, R1):
    """Rock broken in every direction out to R1 and only along the radius from there to 5 r_b (a dense fan of radial
    cracks): r_c is R1 within 1.5 ring widths; the dense-cracking radius r_k, which counts all interfaces together,
    cannot tell the fan (about half of its interfaces cracked) from crushed rock."""
    a, b = _interfaces(model)
    r = np.linalg.norm(0.5 * (a + b), axis=1)
    radial = radial_interfaces(a, b, np.zeros(2))
    cracked = (r < R1) | (radial & (r < 5 * R_B))
    s = crack_statistics(model, np.repeat(cracked.astype(np.int32), 2), np.zeros(2), R_B)
    w = s["ring_width"]
    print(f"\n  broken in every direction to {R1 / R_B:.0f} r_b, radial fan to 5 r_b: r_c/r_b "
          f"{s['crushed_zone_radius_over_rb']:.2f}, r_k/r_b {s['dense_cracking_radius_over_rb']:.2f}")
    assert abs(s["crushed_zone_radius"] - R1) <= 1.5 * w
    assert s["dense_cracking_radius"] >= s["crushed_zone_radius"]


def test_fan_of_radial_cracks_is_not_a_crushed_zone(model):
    """Every radial interface within 4 r_b cracked and no circumferential one, the near-hole pattern of the blast
    examples (docs/results.md, r_c): about half of each ring is cracked, yet nothing is crushed, r_c = r_b."""
    a, b = _interfaces(model)
    r = np.linalg.norm(0.5 * (a + b), axis=1)
    radial = radial_interfaces(a, b, np.zeros(2))
    cracked = radial & (r < 4 * R_B)
    s = crack_statistics(model, np.repeat(cracked.astype(np.int32), 2), np.zeros(2), R_B)
    near = r < 4 * R_B
    assert 0.35 < cracked[near].mean() < 0.65            # the fraction the former rule thresholded at one half
    assert s["crushed_zone_radius"] == R_B


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


# A second pattern for the crack-network tests: K wall cracks out to R_WALL_TIP, and M cracks between them that
# start away from the hole, at R_DET[0] … R_DET[1]: at every radius of that span all K + M cracks coexist.
K, M = 4, 4
WALL_ANGLES = 0.1 + 2 * np.pi * np.arange(K) / K
DET_ANGLES = WALL_ANGLES + np.pi / K              # half way between two wall cracks (> 7 mesh sizes apart)
R_WALL_TIP, R_DET = 0.09, (0.04, 0.08)


def _rays(model, rays):
    """Mask of the interfaces crossed by the rays (theta, r0, r1)."""
    a, b = _interfaces(model)
    hit = np.zeros(len(a), bool)
    for th, r0, r1 in rays:
        hit |= _ray_hits(a, b, th, r0, r1)
    return hit


def _mode(cracked):
    return np.repeat(cracked.astype(np.int32), 2)     # both springs of a cracked interface, tensile


def test_detached_cracks_are_reported_apart(model):
    """Adding M cracks that do not reach the hole changes nothing in N(R) and the radial count; they are reported as
    M detached sets with the drawn length. Over all cracked interfaces (the count before the crack network) the
    same circles are crossed by K + M cracks."""
    wall = _rays(model, [(th, R_B, R_WALL_TIP) for th in WALL_ANGLES])
    detached = _rays(model, [(th, *R_DET) for th in DET_ANGLES])
    assert not (wall & detached).any()                # the construction keeps the two families apart
    s = crack_statistics(model, _mode(wall | detached), np.zeros(2), R_B)
    s_wall = crack_statistics(model, _mode(wall), np.zeros(2), R_B)
    a, b = _interfaces(model)
    L = np.linalg.norm(b - a, axis=1)
    prof = s["crossings"]
    R, n, n_all = (np.asarray(prof[k]) for k in ("radius", "count", "count_all"))
    mid = (R > R_DET[0] + 0.01) & (R < R_DET[1] - 0.01)
    print(f"{K} wall + {M} detached cracks: count {s['radial_crack_count']} (wall cracks alone "
          f"{s_wall['radial_crack_count']}, all cracked interfaces {n_all.max()}); median N(R) over "
          f"{R[mid].min():.3f}-{R[mid].max():.3f} m: {np.median(n[mid]):g} (all: {np.median(n_all[mid]):g}); "
          f"detached sets {s['detached_crack_sets']} ({s['detached_crack_sets_long']} long), "
          f"length {s['detached_crack_length']:.4f} m vs drawn {L[detached].sum():.4f} m")
    assert mid.any()
    assert prof["count"] == s_wall["crossings"]["count"]            # the detached cracks are not counted anywhere
    assert prof["count_tensile"] == s_wall["crossings"]["count_tensile"]
    assert s["radial_crack_count"] == s_wall["radial_crack_count"]
    assert s["radial_crack_lengths"] == s_wall["radial_crack_lengths"]
    assert np.median(n[mid]) == K                     # where the detached cracks run, K cracks are counted ...
    assert np.median(n_all[mid]) == K + M             # ... and counting every cracked interface would give K + M
    assert n_all.max() >= K + M                       # the radial count before the crack network
    assert s["detached_crack_sets"] == M
    assert s["detached_crack_sets_long"] == M         # each spans 40 mm, about 10 elements
    assert s["detached_crack_length"] == pytest.approx(L[detached].sum(), rel=1e-12)
    assert s["connected_interfaces"] == int(wall.sum())
    assert s["connected_crack_length"] == pytest.approx(L[wall].sum(), rel=1e-12)
    # the per-interface mask for the figure is exactly the drawn detached set
    assert np.array_equal(detached_interface_mask(model, _mode(wall | detached), [((0.0, 0.0), R_B)]), detached)


def test_branch_of_a_wall_crack_is_connected(model):
    """A crack branching off a wall crack at 50 mm (0.8 rad off its direction, 40 mm long, tip at 83 mm) belongs to
    the network; beyond the branch point it crosses the circles as one more crack."""
    wall = _rays(model, [(th, R_B, R_WALL_TIP) for th in WALL_ANGLES])
    th0, s0, turn, length = WALL_ANGLES[0], 0.05, 0.8, 0.04
    p = s0 * np.array([np.cos(th0), np.sin(th0)])
    q = p + length * np.array([np.cos(th0 + turn), np.sin(th0 + turn)])
    a, b = _interfaces(model)
    branch = _segment_hits(a, b, p, q)
    assert (branch & ~wall).sum() > 10
    s = crack_statistics(model, _mode(wall | branch), np.zeros(2), R_B)
    assert s["detached_crack_sets"] == 0
    assert s["detached_crack_length"] == 0.0
    assert s["connected_interfaces"] == int((wall | branch).sum())
    R, n = np.asarray(s["crossings"]["radius"]), np.asarray(s["crossings"]["count"])
    # from 64 mm the branch is more than 12 mm (3 elements) away from its parent crack; its tip is at 83 mm
    span = (R > 0.064) & (R < 0.078)
    assert span.any()
    assert np.median(n[span]) == K + 1


def test_crack_figures_show_detached_cracks(model, tmp_path):
    """The crack-profile and fracture-pattern figures render with the detached sets (smoke test)."""
    from blastfrac.io.paraview import crack_segments
    from blastfrac.plot.figures import crack_profile, fracture_pattern

    wall = _rays(model, [(th, R_B, R_WALL_TIP) for th in WALL_ANGLES])
    detached = _rays(model, [(th, *R_DET) for th in DET_ANGLES])
    mode = _mode(wall | detached)
    s = crack_statistics(model, mode, np.zeros(2), R_B)
    crack_profile(tmp_path / "profile.png", [s])
    X = model.host["node_X"]
    seg, cmode = crack_segments(model, mode, np.zeros(len(mode)))
    seg_detached = detached_interface_mask(model, mode, [((0.0, 0.0), R_B)])[wall | detached]
    assert seg_detached.sum() == detached.sum()
    fracture_pattern(tmp_path / "pattern.png", X, seg, cmode, circles=[((0.0, 0.0), R_B)], detached=seg_detached)
    assert (tmp_path / "profile.png").stat().st_size > 0 and (tmp_path / "pattern.png").stat().st_size > 0


def test_crack_extent_is_the_radius_enclosing_a_fraction_of_the_cracked_length():
    """Cracked segments of known lengths at known radii: the extent radii follow from the cumulative length."""
    from blastfrac.analysis.cracks import crack_extent

    r = np.arange(1.0, 11.0) * 0.01                       # ten segments at 1 … 10 cm from the centre
    ang = np.linspace(0, 2 * np.pi, 10, endpoint=False)
    mid = np.stack([r * np.cos(ang), r * np.sin(ang)], 1)
    L = np.ones(10) * 1e-3
    cracked = np.ones(10, bool)
    e = crack_extent(mid, L, cracked, np.zeros(2))
    assert e["crack_length_total"] == pytest.approx(0.01)
    assert e["crack_extent_r50"] == pytest.approx(0.05) and e["crack_extent_r90"] == pytest.approx(0.09)
    # make the outermost segment 10× longer: it then holds more than half of the length, so r50 jumps to it ...
    L2 = L.copy()
    L2[-1] = 10e-3
    e2 = crack_extent(mid, L2, cracked, np.zeros(2))
    assert e2["crack_extent_r50"] == pytest.approx(0.10) and e2["crack_extent_r80"] == pytest.approx(0.10)
    # ... and uncracked interfaces do not count
    cracked[-1] = False
    assert crack_extent(mid, L2, cracked, np.zeros(2))["crack_extent_r90"] == pytest.approx(0.09)


@pytest.mark.parametrize("R1", [2.5 * R_B, 4.0 * R_B])
@pytest.mark.parametrize("inner, outer", [(1.0, 0.0), (0.6, 0.15)])
def test_damaged_zone_radius_of_a_drawn_step(model, R1, inner, outer):
    """Interfaces cracked with probability ``inner`` within R1 and ``outer`` beyond. A ring r_b wide centred at x
    holds the share s = (R1 − x)/r_b + 1/2 of its interfaces inside R1 (interfaces spread evenly over the ring), so
    its cracked fraction inner·s + outer·(1 − s) falls to half the first ring's (``inner``) at
    x = R1 + r_b·(1/2 − (inner/2 − outer)/(inner − outer)): R1 for a sharp edge, R1 + r_b/6 for 0.6 / 0.15,
    where the absolute threshold of r_c would give R1 − 0.28 r_b."""
    a, b = _interfaces(model)
    mid = np.linalg.norm(0.5 * (a + b), axis=1)
    u = np.random.default_rng(7).random(len(a))
    cracked = np.where(mid < R1, u < inner, u < outer)
    s = crack_statistics(model, np.repeat(cracked.astype(np.int32), 2), np.zeros(2), R_B)
    expect = R1 + R_B * (0.5 - (0.5 * inner - outer) / (inner - outer))
    print(f"R1 {R1 / R_B:.1f} r_b, {inner}/{outer}: r_d/r_b {s['damaged_zone_radius_over_rb']:.3f} vs "
          f"{expect / R_B:.3f}; r_c/r_b {s['crushed_zone_radius_over_rb']:.2f}")
    # the interfaces are not spread quite evenly over a ring (its perimeter grows with r, the mesh coarsens with r
    # from 1 mm at the wall), which moves the crossing by a few hundredths of r_b; so does the binomial noise of
    # ~1000 interfaces per ring
    assert abs(s["damaged_zone_radius"] - expect) < 0.1 * R_B
    assert s["damaged_zone_radius_censored"] is False


def test_damaged_zone_radius_without_cracks_is_the_wall(model):
    a, _ = _interfaces(model)
    s = crack_statistics(model, np.zeros(2 * len(a), np.int32), np.zeros(2), R_B)
    assert s["damaged_zone_radius"] == R_B


def test_damaged_zone_radius_of_rock_cracked_throughout_is_censored(model):
    """A third of the interfaces cracked everywhere: the fraction never halves, so r_d is the last ring's centre
    (within one ring width r_b of the disc's edge, 0.12 m) and flagged as a lower bound."""
    a, b = _interfaces(model)
    cracked = np.random.default_rng(3).random(len(a)) < 1 / 3
    s = crack_statistics(model, np.repeat(cracked.astype(np.int32), 2), np.zeros(2), R_B)
    assert s["damaged_zone_radius_censored"] is True
    assert 0.12 - R_B <= s["damaged_zone_radius"] <= 0.12


def test_zone_radii_reads_summaries_from_before_the_crushed_zone_rule_changed(model):
    """A summary written before 2026-12-06 reported the rule now called r_k as crushed_zone_radius; zone_radii gives
    it as r_k and r_c as unknown (NaN), and a new summary's radii as they are."""
    from blastfrac.analysis.cracks import zone_radii

    old = {"crushed_zone_radius": 0.00885, "crushed_zone_radius_over_rb": 1.77}
    z = zone_radii(old)
    assert z["dense_cracking_radius"] == 0.00885 and z["dense_cracking_radius_over_rb"] == 1.77
    assert np.isnan(z["crushed_zone_radius"]) and np.isnan(z["crushed_zone_radius_over_rb"])
    s = crack_statistics(model, _draw(model, crushed=2.5 * R_B), np.zeros(2), R_B)
    assert zone_radii(s) == {k: s[k] for k in ("crushed_zone_radius", "crushed_zone_radius_over_rb",
                                               "dense_cracking_radius", "dense_cracking_radius_over_rb")}
