"""Crack statistics around a borehole: crushed-zone radius, radial crack count and lengths.

Definitions (documented in docs/results.md):

* An interface is *cracked* when at least one of its two springs has broken; its position is the midpoint
  of the edge in the reference configuration, r its distance from the hole centre.
* Bin width w: the median length of the interfaces within 2 r_b of the centre (the mesh size at the wall).
* **Crushed-zone radius r_c**: the outer radius of the run of consecutive rings [r_b + k·w, r_b + (k+1)·w),
  starting at the wall, in which at least half of the interfaces are cracked (r_c = r_b when the first ring
  is below one half). It is the radius within which most springs have broken.
* **Radial cracks**: cracked interfaces beyond r_c + w (one ring of buffer, so that the dense crushed zone
  does not join neighbouring cracks) are grouped into connected sets through shared mesh vertices. A set that
  starts within 2w of that buffer and reaches at least 2w beyond it is a radial crack; its *length* is
  r_max − r_c, from the edge of the crushed zone to its farthest point (branches included).
"""

from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components


def crack_statistics(model, mode: np.ndarray, center: np.ndarray, r_b: float) -> dict:
    """Statistics of the cracks around the hole at ``center`` [m] of radius ``r_b`` [m] (SI units)."""
    topo = model.topology
    X = model.host["node_X"]
    pn = topo.pair_nodes
    a = X[pn[0::2, 0]]                      # the two ends of each interface (side e1)
    b = X[pn[1::2, 0]]
    mid = 0.5 * (a + b)
    r = np.linalg.norm(mid - center, axis=1)
    L = np.linalg.norm(b - a, axis=1)
    cracked = (mode.reshape(-1, 2) > 0).any(axis=1)
    near = r < 2.0 * r_b
    w = float(np.median(L[near])) if near.any() else float(np.median(L))
    # crushed zone: consecutive rings from the wall with at least half of the interfaces cracked
    r_c, k = r_b, 0
    while True:
        ring = (r >= r_b + k * w) & (r < r_b + (k + 1) * w)
        if ring.sum() == 0 or cracked[ring].mean() < 0.5:
            break
        k += 1
        r_c = r_b + k * w
    # radial cracks: connected sets of cracked interfaces beyond the crushed zone
    r0 = r_c + w
    sel = np.flatnonzero(cracked & (r >= r0))
    cracks = []
    if len(sel):
        va = topo.node_vertex[pn[2 * sel, 0]]
        vb = topo.node_vertex[pn[2 * sel + 1, 0]]
        nv = int(topo.node_vertex.max()) + 1
        m = len(sel)
        # bipartite graph interface–vertex; components of interfaces through shared vertices
        rows = np.concatenate([np.arange(m), np.arange(m)])
        cols = np.concatenate([va, vb]) + m
        g = coo_matrix((np.ones(2 * m), (rows, cols)), shape=(m + nv, m + nv))
        _, lab = connected_components(g, directed=False)
        lab = lab[:m]
        ra = np.linalg.norm(a[sel] - center, axis=1)
        rb_ = np.linalg.norm(b[sel] - center, axis=1)
        for c in np.unique(lab):
            idx = lab == c
            rmin = float(min(ra[idx].min(), rb_[idx].min()))
            rmax = float(max(ra[idx].max(), rb_[idx].max()))
            if rmin <= r0 + 2 * w and rmax >= r0 + 2 * w:
                cracks.append({"length": rmax - r_c, "segments": int(idx.sum()),
                               "path_length": float(L[sel][idx].sum())})
    cracks.sort(key=lambda c: -c["length"])
    lengths = [c["length"] for c in cracks]
    return {
        "center": [float(center[0]), float(center[1])],
        "borehole_radius": r_b,
        "ring_width": w,
        "crushed_zone_radius": r_c,
        "crushed_zone_radius_over_rb": r_c / r_b,
        "radial_crack_count": len(cracks),
        "radial_crack_lengths": lengths,
        "longest_radial_crack": max(lengths) if lengths else 0.0,
        "mean_radial_crack_length": float(np.mean(lengths)) if lengths else 0.0,
    }
