"""PNG figures of a run (matplotlib, imported lazily, Agg backend)."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


TENSILE_COLOR = "#d62728"
SHEAR_COLOR = "#1f77b4"
CRUSHED_COLOR = "#8c564b"          # compressive cap (rock.crushing_strength)
CRUSHED_DETACHED_COLOR = "#c49c94"


TENSILE_DETACHED_COLOR = "#f0a8a8"
SHEAR_DETACHED_COLOR = "#a9c8e6"


def fracture_pattern(path: Path, x: np.ndarray, seg: np.ndarray, mode: np.ndarray, title: str = "",
                     show_mesh: bool = True, circles=(), detached: np.ndarray | None = None,
                     joints: np.ndarray | None = None) -> None:
    """Deformed mesh (light) with tensile (red) and shear (blue) cracks; detached cracks in lighter shades;
    pre-existing joints grey and dashed.

    ``seg`` [K, 2], ``mode`` [K]: the cracked interfaces and their mode (io.paraview.crack_segments); the
    legend counts cracked interfaces (summary.json → broken_springs counts springs, up to two per interface).
    ``detached`` [K] (optional): the segments in crack sets connected to no borehole
    (analysis.cracks.detached_interface_mask, indexed by the cracked interfaces).
    ``joints`` [J, 2] (optional): every joint interface (io.paraview.joint_segments), drawn grey and dashed, dark
    where open or broken; cracked segments on a joint are drawn as joints, not as cracks.
    """
    plt = _plt()
    from matplotlib.collections import LineCollection

    fig, ax = plt.subplots(figsize=(7, 7), dpi=150)
    tri = np.arange(len(x)).reshape(-1, 3)
    if show_mesh:
        edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        ax.add_collection(LineCollection(x[edges], colors="0.82", linewidths=0.2))
    if joints is not None and len(joints):
        joints = np.asarray(joints, np.int64).reshape(-1, 2)
        nmax = int(max(joints.max(), seg.max() if len(seg) else 0)) + 1
        on_joint = np.isin(seg[:, 0] * nmax + seg[:, 1], joints[:, 0] * nmax + joints[:, 1]) if len(seg) else \
            np.zeros(0, bool)
        opened = np.isin(joints[:, 0] * nmax + joints[:, 1], seg[on_joint, 0] * nmax + seg[on_joint, 1])
        for sel, color, label in ((~opened, "0.55", "joint, intact"), (opened, "0.25", "joint, open or broken")):
            if sel.any():
                ax.add_collection(LineCollection(x[joints[sel]], colors=color, linewidths=0.8, linestyles="--",
                                                 label=f"{label} ({int(sel.sum())})", zorder=1.5))
        seg, mode = seg[~on_joint], mode[~on_joint]
        if detached is not None:
            detached = np.asarray(detached, bool)[~on_joint]
    det = np.zeros(len(seg), bool) if detached is None else np.asarray(detached, bool)
    styles = ((1, False, TENSILE_COLOR, "tensile"), (2, False, SHEAR_COLOR, "shear"),
              (1, True, TENSILE_DETACHED_COLOR, "tensile, detached"),
              (2, True, SHEAR_DETACHED_COLOR, "shear, detached"),
              (3, False, CRUSHED_COLOR, "crushed"), (3, True, CRUSHED_DETACHED_COLOR, "crushed, detached"))
    for code, off, color, label in styles:
        s = seg[(mode == code) & (det == off)]
        if len(s):
            ax.add_collection(LineCollection(x[s], colors=color, linewidths=0.9 if not off else 0.7,
                                             label=f"{label} ({len(s)})", zorder=2 if not off else 1))
    for c, r in circles:
        ax.add_patch(plt.Circle(c, r, fill=False, color="k", lw=0.6))
    ax.set_xlim(x[:, 0].min(), x[:, 0].max())
    ax.set_ylim(x[:, 1].min(), x[:, 1].max())
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title or "Fracture pattern", fontsize=9, wrap=True)
    if len(seg) or (joints is not None and len(joints)):
        head = "cracked interfaces" + ("" if detached is None else " (detached: not joined to a hole)")
        ax.legend(loc="upper right", fontsize=8, title=head, title_fontsize=8)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def displacement_map(path: Path, x: np.ndarray, u: np.ndarray, title: str = "") -> None:
    """Displacement magnitude on the deformed blocks (paper Fig. 4 style)."""
    plt = _plt()
    import matplotlib.tri as mtri

    fig, ax = plt.subplots(figsize=(7, 6), dpi=150)
    tri = np.arange(len(x)).reshape(-1, 3)
    t = mtri.Triangulation(x[:, 0], x[:, 1], tri)
    pc = ax.tripcolor(t, np.linalg.norm(u, axis=1) * 1e3, shading="gouraud", cmap="viridis")
    fig.colorbar(pc, ax=ax, label="|u| [mm]")
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title or "Displacement magnitude")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def histories(path: Path, t: np.ndarray, series: dict[str, np.ndarray], ylabel: str, title: str,
              tscale: float = 1e6, tunit: str = "µs", yscale: float = 1.0) -> None:
    """Several time histories on one axis."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=150)
    for name, y in series.items():
        ax.plot(np.asarray(t) * tscale, np.asarray(y) * yscale, label=name, lw=1.2)
    ax.set_xlabel(f"time [{tunit}]")
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.grid(alpha=0.3)
    if series:
        ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def displacement_snapshots(path: Path, snapshots: list[dict], title: str = "") -> None:
    """Displacement magnitude at several times side by side (paper Fig. 4 style), gas particles in grey."""
    plt = _plt()
    import matplotlib.tri as mtri
    from matplotlib.colors import Normalize

    n = len(snapshots)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n + 0.8, 3.9), dpi=150, squeeze=False)
    vmax = max(float(np.linalg.norm(s["u"], axis=1).max()) for s in snapshots) * 1e3 or 1.0
    norm = Normalize(0.0, vmax)
    pc = None
    for ax, s in zip(axes[0], snapshots):
        x = s["x"]
        tri = np.arange(len(x)).reshape(-1, 3)
        t = mtri.Triangulation(x[:, 0], x[:, 1], tri)
        pc = ax.tripcolor(t, np.linalg.norm(s["u"], axis=1) * 1e3, shading="gouraud", cmap="viridis", norm=norm)
        if "gas_x" in s and len(s["gas_x"]):
            ax.scatter(s["gas_x"][:, 0], s["gas_x"][:, 1], s=0.2, c="0.6", linewidths=0)
        ax.set_aspect("equal")
        ax.set_xlim(x[:, 0].min(), x[:, 0].max())
        ax.set_ylim(x[:, 1].min(), x[:, 1].max())
        ax.set_title(f"t = {s['time'] * 1e6:.1f} µs", fontsize=9)
        ax.tick_params(labelsize=7)
    fig.colorbar(pc, ax=axes[0].tolist(), label="|u| [mm]", shrink=0.85)
    fig.suptitle(title or "Displacement magnitude", fontsize=10)
    fig.savefig(path, bbox_inches="tight")
    plt.close(fig)


def gas_particles(path: Path, xp: np.ndarray, p: np.ndarray, x: np.ndarray, seg: np.ndarray, mode: np.ndarray,
                  title: str = "", zoom: float | None = None, gas_seg: np.ndarray | None = None,
                  gas_p: np.ndarray | None = None) -> None:
    """Gas particles coloured by pressure over the cracked rock (cracks red tensile / blue shear); with
    ``gas_seg``/``gas_p`` the crack cells holding gas are drawn over them as thick lines in the same colours."""
    plt = _plt()
    from matplotlib.collections import LineCollection
    from matplotlib.colors import LogNorm

    fig, ax = plt.subplots(figsize=(7, 6), dpi=150)
    for code, color in ((1, TENSILE_COLOR), (2, SHEAR_COLOR), (3, CRUSHED_COLOR)):
        s = seg[mode == code]
        if len(s):
            ax.add_collection(LineCollection(x[s], colors=color, linewidths=0.6))
    if len(xp):
        pp = np.maximum(p, 1e5) / 1e6
        lo_p = pp.min()
        if gas_p is not None and len(gas_p):
            lo_p = min(lo_p, float(np.maximum(gas_p, 1e5).min()) / 1e6)
        sc = ax.scatter(xp[:, 0], xp[:, 1], c=pp, s=1.5, cmap="inferno", norm=LogNorm(vmin=max(lo_p, 0.1),
                                                                                   vmax=max(pp.max(), 1.0)))
        if gas_seg is not None and len(gas_seg):
            lc = LineCollection(x[gas_seg], cmap="inferno", norm=sc.norm, linewidths=2.0)
            lc.set_array(np.maximum(gas_p, 1e5) / 1e6)
            ax.add_collection(lc)
            ax.plot([], [], color="tab:orange", lw=2.0, label="gas in cracks (thick lines, same colour scale)")
            ax.legend(loc="upper right", fontsize=7)
        fig.colorbar(sc, ax=ax, label="gas pressure [MPa]")
        c = xp.mean(axis=0)
        span = zoom or max(4.0 * float(np.ptp(xp, axis=0).max()), 1e-3)
        lo = np.maximum(c - span / 2, x.min(axis=0))
        hi = np.minimum(c + span / 2, x.max(axis=0))
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    fig.suptitle(title or "Gas pressure", fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def fracture_degree_zones(path: Path, t: np.ndarray, cols: dict[str, np.ndarray], title: str = "") -> None:
    """Fracture degree over time: the whole model and one panel per zone, tensile and shear (Figs. 7, 11 style)."""
    plt = _plt()
    zones = []
    for k in cols:
        if ":" in k:
            z = k.split(":")[0]
            if z not in zones:
                zones.append(z)
    panels = ["model"] + zones
    n = len(panels)
    ncol = min(n, 4)
    nrow = (n + ncol - 1) // ncol
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.3 * ncol, 2.7 * nrow), dpi=150, squeeze=False, sharex=True)
    ts = np.asarray(t) * 1e6
    for ax, name in zip(axes.flat, panels):
        pre = "" if name == "model" else f"{name}:"
        ax.plot(ts, cols[f"{pre}D_tensile"], color=TENSILE_COLOR, label="tensile")
        ax.plot(ts, cols[f"{pre}D_shear"], color=SHEAR_COLOR, label="shear")
        if np.any(np.asarray(cols.get(f"{pre}D_crushed", [0.0])) > 0):
            ax.plot(ts, cols[f"{pre}D_crushed"], color=CRUSHED_COLOR, label="crushed")
        ax.plot(ts, cols[f"{pre}D"], color="k", lw=0.8, ls="--", label="total")
        ax.set_title(name, fontsize=9)
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=7)
    for ax in axes.flat[n:]:
        ax.axis("off")
    for ax in axes[-1]:
        ax.set_xlabel("time [µs]", fontsize=8)
    for ax in axes[:, 0]:
        ax.set_ylabel("fracture degree [-]", fontsize=8)
    axes.flat[0].legend(fontsize=7)
    fig.suptitle(title or "Fracture degree", fontsize=10)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def crack_profile(path: Path, stats: list[dict], title: str = "") -> None:
    """Cracks connected to each hole crossing circles about it, N(R), and the shattered fraction of each circle.

    ``stats``: the entries of summary.json → cracks (analysis.cracks.crack_statistics), one per hole. N(R)
    counts only the crack network joined to the hole's wall or densely cracked zone; the detached crack sets are
    drawn as a light line (``count_all``, all cracked interfaces) and summed up in the legend.
    """
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4), dpi=150)
    ax2 = ax.twinx()
    for i, s in enumerate(stats):
        p = s["crossings"]
        R = np.asarray(p["radius"]) / s["borehole_radius"]
        lab = f" (hole {i})" if len(stats) > 1 else ""
        ax.plot(R, p["count"], color="k", label=f"connected to the hole{lab}")
        ax.plot(R, p["count_tensile"], color=TENSILE_COLOR, ls="--", label=f"connected, tensile{lab}")
        if "count_all" in p:
            ax.plot(R, p["count_all"], color="0.6", lw=0.8, label=f"all cracks incl. detached{lab}: "
                    f"{_detached_note(s)}")
        frac = np.asarray(p["shattered_arc"]) / (2 * np.pi * np.asarray(p["radius"]))
        ax2.fill_between(R, 0, np.minimum(frac, 1.0), color="0.6", alpha=0.3, lw=0)
        ax.axvline(s["crushed_zone_radius_over_rb"], color=SHEAR_COLOR, lw=1.2, ls=":")
        if "dense_cracking_radius_over_rb" in s:
            ax.axvline(s["dense_cracking_radius_over_rb"], color="0.4", lw=0.8, ls="--")
        if "damaged_zone_radius_over_rb" in s:
            ax.axvline(s["damaged_zone_radius_over_rb"], color=SHEAR_COLOR, lw=0.8, ls="-.")
    ax.set_xlabel("radius R / r_b [-]")
    ax.set_ylabel("cracks crossing the circle R [-]")
    ax2.set_ylabel("shattered fraction of the circle (grey) [-]")
    ax2.set_ylim(0, 1)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7, loc="best")
    ax.set_title(textwrap.fill(title or "Radial cracks connected to the hole (dotted: crushed-zone radius r_c; grey "
                               "dashed: dense-cracking radius r_k, where the count starts; dash-dot: damaged-zone "
                               "radius r_d)", 90), fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def _detached_note(s: dict) -> str:
    """Legend text for the detached crack sets of one crack_statistics entry."""
    if "detached_crack_sets" not in s:
        return "detached sets not computed"
    return (f"{s['detached_crack_sets']} detached sets ({s['detached_crack_sets_long']} with > 3 interfaces), "
            f"{s['detached_crack_length'] * 1e3:.0f} mm in all")


def fragment_sizes(path: Path, size: np.ndarray, area: np.ndarray, blasted: np.ndarray, report: dict,
                   title: str = "") -> None:
    """Passing curve (mass fraction finer than x) of the blasted fragments with x50, x80 and the Swebrec fit."""
    from ..analysis.fragments import passing_curve, swebrec

    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=150)
    if blasted.any():
        x, P = passing_curve(size[blasted], area[blasted])
        ax.step(x * 1e3, 100 * P, where="post", color="k", label=f"{int(blasted.sum())} blasted fragments")
        sw = report.get("swebrec", {})
        if np.isfinite(sw.get("x50", np.nan)):
            xs = np.geomspace(x[0], sw["x_max"], 200)
            bad = bool(sw.get("at_bound"))
            ax.plot(xs * 1e3, 100 * swebrec(xs, sw["x50"], sw["x_max"], sw["b"]), color="tab:orange",
                    ls="--" if bad else "-",
                    label=f"Swebrec x50 {sw['x50'] * 1e3:.1f} mm, x_max {sw['x_max'] * 1e3:.1f} mm, b {sw['b']:.2f}"
                    + (f" (not Swebrec-like: {', '.join(sw['at_bound'])} on its bound)" if bad else ""))
        for q, key in ((50, "x50"), (80, "x80")):
            v = report.get(key)
            if v is not None and np.isfinite(v):
                ax.axvline(v * 1e3, color="0.5", lw=0.8, ls=":")
                ax.text(v * 1e3, q, f" {key} {v * 1e3:.1f} mm", fontsize=7, va="bottom")
        ax.set_xscale("log")
    else:
        ax.text(0.5, 0.5, "no fragment detached from the rock mass", transform=ax.transAxes, ha="center")
    ax.set_xlabel("fragment size x = 2√(A/π) [mm]")
    ax.set_ylabel("passing (area = mass fraction finer) [%]")
    ax.set_ylim(0, 100)
    ax.grid(alpha=0.3, which="both")
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=7, loc="upper left")
    ax.set_title(textwrap.fill(title or "Fragment sizes (fragments not touching the outer boundary; single blocks "
                                        "are at the mesh scale)", 90), fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def ppv_map(path: Path, X: np.ndarray, ppv: np.ndarray, centres: list, vib: dict, title: str = "") -> None:
    """Peak particle velocity over the rock (per block, the mean of its nodes; log colour scale), with the damage
    radius (PPV_crit = σ_t c_p/E) drawn about each hole."""
    plt = _plt()
    from matplotlib.collections import PolyCollection
    from matplotlib.colors import LogNorm

    span = np.ptp(X, axis=0)
    aspect = float(span[1] / max(span[0], 1e-300))
    fig, ax = plt.subplots(figsize=(7.5, max(2.8, min(7.0, 6.3 * aspect + 1.2))), dpi=150)
    tri = X.reshape(-1, 3, 2)
    val = np.maximum(ppv.reshape(-1, 3).mean(axis=1), 1e-3)
    crit = vib["ppv_critical"]
    pc = PolyCollection(tri, array=val, cmap="viridis", norm=LogNorm(vmin=max(val.min(), 1e-2), vmax=val.max()),
                        edgecolors="none")
    ax.add_collection(pc)
    ax.set_xlim(X[:, 0].min(), X[:, 0].max())
    ax.set_ylim(X[:, 1].min(), X[:, 1].max())
    ax.set_aspect("equal")
    from mpl_toolkits.axes_grid1 import make_axes_locatable

    cax = make_axes_locatable(ax).append_axes("right", size="3%", pad=0.08)     # as tall as the map
    fig.colorbar(pc, cax=cax, label="peak particle velocity [m/s]")
    rd = vib.get("damage_radius")
    th = np.linspace(0, 2 * np.pi, 200)
    if rd is not None and np.isfinite(rd) and not vib.get("damage_beyond_model"):
        for (c, r) in centres:
            ax.plot(c[0] + rd * np.cos(th), c[1] + rd * np.sin(th), color="w", lw=1.2, ls="--")
        ax.plot([], [], color="k", ls="--", label=f"damage radius {rd * 1e3:.0f} mm (PPV > PPV_crit = σ_t c_p/E "
                                                   f"= {crit:.1f} m/s)")
        ax.legend(fontsize=7, loc="upper right")
    elif rd is not None and np.isfinite(rd):
        ax.text(0.01, 0.99, f"PPV > PPV_crit = σ_t c_p/E = {crit:.2g} m/s up to the model's edge", fontsize=7,
                va="top", transform=ax.transAxes, color="w")
    ax.set_xlim(X[:, 0].min(), X[:, 0].max())
    ax.set_ylim(X[:, 1].min(), X[:, 1].max())
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(textwrap.fill(title or "Peak particle velocity", 80), fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def ppv_distance(path: Path, prof: dict, vib: dict, title: str = "") -> None:
    """Ring medians and maxima of the PPV against the distance from the holes, the fitted law and PPV_crit."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(7, 4.2), dpi=150)
    R = prof["radius"]
    ax.loglog(R * 1e3, prof["median"], "o", ms=3, color="k", label="ring median")
    ax.loglog(R * 1e3, prof["max"], ".", ms=3, color="0.6", label="ring maximum")
    at = vib["attenuation"]
    Q = vib.get("charge_per_hole") or 1.0
    if np.isfinite(at.get("K", np.nan)):
        Rf = R[R > at["fit_from_radius"]]
        if len(Rf):
            ax.loglog(Rf * 1e3, at["K"] * (Rf / np.sqrt(Q)) ** (-at["beta"]), color="tab:orange",
                      label=f"fit K (R/√Q)^-β: K = {at['K']:.3g}, β = {at['beta']:.2f} (R² {at['r2']:.3f})")
    ax.axhline(vib["ppv_critical"], color="tab:red", lw=0.8, ls="--", label=f"PPV_crit = σ_t c_p/E = {vib['ppv_critical']:.1f} m/s")
    ax.set_xlabel("distance from the hole centre R [mm]")
    ax.set_ylabel("peak particle velocity [m/s]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7)
    ax.set_title(textwrap.fill(title or "PPV against distance", 90), fontsize=9)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
