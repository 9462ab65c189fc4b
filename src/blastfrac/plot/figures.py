"""PNG figures of a run (matplotlib, imported lazily, Agg backend)."""

from __future__ import annotations

from pathlib import Path

import numpy as np


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


TENSILE_COLOR = "#d62728"
SHEAR_COLOR = "#1f77b4"


def fracture_pattern(path: Path, x: np.ndarray, seg: np.ndarray, mode: np.ndarray, title: str = "",
                     show_mesh: bool = True, circles=()) -> None:
    """Deformed mesh (light) with tensile (red) and shear (blue) cracks."""
    plt = _plt()
    from matplotlib.collections import LineCollection

    fig, ax = plt.subplots(figsize=(7, 7), dpi=150)
    tri = np.arange(len(x)).reshape(-1, 3)
    if show_mesh:
        edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
        ax.add_collection(LineCollection(x[edges], colors="0.82", linewidths=0.2))
    for code, color, label in ((1, TENSILE_COLOR, "tensile"), (2, SHEAR_COLOR, "shear")):
        s = seg[mode == code]
        if len(s):
            ax.add_collection(LineCollection(x[s], colors=color, linewidths=0.9, label=f"{label} ({len(s)})"))
    for c, r in circles:
        ax.add_patch(plt.Circle(c, r, fill=False, color="k", lw=0.6))
    ax.set_xlim(x[:, 0].min(), x[:, 0].max())
    ax.set_ylim(x[:, 1].min(), x[:, 1].max())
    ax.set_aspect("equal")
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title(title or "Fracture pattern")
    if len(seg):
        ax.legend(loc="upper right", fontsize=8)
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
