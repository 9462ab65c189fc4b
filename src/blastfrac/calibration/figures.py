"""PNG figures of the calibration tests: curves and failed specimens (cracks by mode).

Matplotlib is imported lazily (Agg backend), as in :mod:`blastfrac.plot`.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

TENSILE_COLOR, SHEAR_COLOR = "#d62728", "#1f77b4"


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def interface_modes(model, pair_mode: np.ndarray) -> np.ndarray:
    """Mode of each interface: 0 intact, else the mode of its first failed spring (1 tensile, 2 shear)."""
    a, b = pair_mode[0::2], pair_mode[1::2]
    return np.where(a > 0, a, b)


def draw_specimen(ax, spec, pair_mode: np.ndarray, x: np.ndarray | None = None, marks=None, title: str = "") -> None:
    """Mesh (thin grey), boundary, and broken interfaces coloured by mode on the reference geometry."""
    from matplotlib.collections import LineCollection

    m = spec.model
    X = m.host["node_X"] if x is None else x
    tri = X.reshape(-1, 3, 2)
    edges = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
    ax.add_collection(LineCollection(edges, colors="0.85", linewidths=0.25))
    pn = m.topology.pair_nodes
    mode = interface_modes(m, pair_mode)
    seg = np.stack([X[pn[0::2, 0]], X[pn[1::2, 0]]], 1)
    for code, color, label in ((1, TENSILE_COLOR, "tensile"), (2, SHEAR_COLOR, "shear")):
        sel = mode == code
        ax.add_collection(LineCollection(seg[sel], colors=color, linewidths=1.4, label=f"{label} ({sel.sum()})"))
    if marks is not None and len(marks):
        ax.plot(marks[:, 0], marks[:, 1], "o", mfc="none", mec="k", ms=6, label="first tensile failures")
    ax.set_aspect("equal")
    ax.autoscale_view()
    ax.set_xticks([]), ax.set_yticks([])
    ax.set_title(title, fontsize=10)
    ax.legend(loc="lower center", bbox_to_anchor=(0.5, -0.2), fontsize=7, ncol=3, frameon=False)


def curves_figure(path: Path, ucs=None, braz=None, title: str = "") -> Path:
    """Stress–strain curve of the UCS test (axial and lateral) and load–closure of the Brazilian test."""
    plt = _plt()
    n = (ucs is not None) + (braz is not None)
    fig, axes = plt.subplots(1, n, figsize=(6 * n, 5.0), squeeze=False)
    k = 0
    if ucs is not None:
        ax = axes[0, k]
        k += 1
        s = ucs.stress / 1e6
        ax.plot(ucs.strain * 1e3, s, "k-", lw=1.3, label="axial strain")
        ax.plot(-ucs.lateral_strain * 1e3, s, "-", color="0.55", lw=1.0, label="lateral strain")
        ip = ucs.peak_index
        ax.plot(ucs.strain[ip] * 1e3, s[ip], "o", color=SHEAR_COLOR, label=f"UCS {ucs.ucs / 1e6:.1f} MPa")
        e = np.linspace(0, ucs.strain[ip], 20)
        ax.plot(e * 1e3, ucs.youngs_modulus_ps * e / 1e6, "--", color="tab:green", lw=0.9,
                label=f"E' {ucs.youngs_modulus_ps / 1e9:.1f} GPa (E {ucs.youngs_modulus / 1e9:.1f} GPa, "
                      f"ν {ucs.poisson_ratio:.3f})")
        ax.axvline(0, color="0.8", lw=0.6)
        # the lateral strain runs away after an undamped, brittle failure: keep the pre-peak part readable
        lat_peak = abs(float(ucs.lateral_strain[ip]))
        left = -max(2.5 * lat_peak, 0.3 * float(ucs.strain[ip])) * 1e3
        if np.nanmin(-ucs.lateral_strain) * 1e3 < left:
            ax.set_xlim(left=left)
            ax.text(left, 0.5 * s[ip], " post-peak lateral\n strain off scale", fontsize=7, color="0.4")
        ax.set_xlabel("strain [‰] (lateral: extension to the left)")
        ax.set_ylabel("axial stress [MPa] (plane strain)")
        ref = ucs.reference.get("static")
        if ref:
            ax.plot(e * 1e3, ref["youngs_modulus_ps"] * e / 1e6, ":", color="tab:purple", lw=1.2,
                    label=f"static solve E' {ref['youngs_modulus_ps'] / 1e9:.2f} GPa")
        ax.set_title(f"UCS test, {ucs.specimen.element_count} elements, platen speed "
                     f"{ucs.settings.speed * 1e3:g} mm/s, α = {ucs.settings.damping:g}", fontsize=10)
        ax.legend(fontsize=8, loc="upper center", bbox_to_anchor=(0.5, -0.14), ncol=2, frameon=False)
        ax.set_ylim(bottom=0)
    if braz is not None:
        ax = axes[0, k]
        import math

        sig = 2 * braz.load / (math.pi * braz.specimen.width) / 1e6
        ax.plot(braz.closure * 1e6, sig, "k-", lw=1.3)
        ip = braz.peak_index
        ax.plot(braz.closure[ip] * 1e6, sig[ip], "o", color=TENSILE_COLOR,
                label=f"σt = 2P/(πD) = {braz.tensile_strength / 1e6:.2f} MPa")
        ax.set_xlabel("platen closure [µm]")
        ax.set_ylabel("2P/(πD) [MPa]")
        ax.set_title(f"Brazilian test, {braz.specimen.element_count} elements, platen speed "
                     f"{braz.settings.speed * 1e3:g} mm/s, α = {braz.settings.damping:g}", fontsize=10)
        ax.legend(fontsize=8, loc="lower right")
        ax.set_ylim(bottom=0)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path


def specimens_figure(path: Path, ucs=None, braz=None, title: str = "") -> Path:
    """Failed specimens at the end of each test, broken interfaces red (tensile) / blue (shear)."""
    plt = _plt()
    n = (ucs is not None) + (braz is not None)
    fig, axes = plt.subplots(1, n, figsize=(3.6 * n + 1, 5.4), squeeze=False,
                             gridspec_kw={"width_ratios": [1, 1.4][:n] if n == 2 else [1]})
    k = 0
    if ucs is not None:
        run = ucs.run
        if run.pair_mode_failure is not None:
            # undamped, the prism shatters within a few samples after the peak; the state when the
            # load first drops below the peak shows the failure mechanism
            i = run.failure_index
            draw_specimen(axes[0, k], ucs.specimen, run.pair_mode_failure,
                          title=f"UCS at failure (ε = {ucs.strain[i] * 1e3:.2f} ‰,\n"
                                f"σ = {ucs.stress[i] / 1e6:.0f} MPa after the {ucs.ucs / 1e6:.0f} MPa peak)")
        else:
            draw_specimen(axes[0, k], ucs.specimen, run.pair_mode,
                          title=f"UCS at the end (ε = {ucs.strain[-1] * 1e3:.2f} ‰)")
        k += 1
    if braz is not None:
        draw_specimen(axes[0, k], braz.specimen, braz.run.pair_mode, marks=braz.first_tensile_xy,
                      title="Brazilian disc after the peak")
        if braz.settings.loading_arc > 0:
            import math

            r = braz.specimen.width / 2
            a = math.radians(braz.settings.loading_arc / 2)
            for sgn in (1, -1):
                th = np.linspace(-a, a, 20)
                axes[0, k].plot(1.04 * r * np.sin(th), sgn * 1.04 * r * np.cos(th), "-", color="0.3", lw=3)
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    fig.savefig(path, dpi=130)
    plt.close(fig)
    return path
