"""Figures of the crack-gas study (study.py): the fracture patterns, the wall-pressure histories, the crack lengths and
their growth. Imported by study.main; the study's constants and readers come from study.py."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from study import (
    CASES,
    DRIVEN,
    EXAMPLES,
    NEAR_R,
    STYLE,
    near_radial_stress,
    read_csv,
    read_frame,
    vtu_frames,
)


def _plt():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def fig_patterns(example: str, runs: dict[str, Path], metrics: dict, path: Path) -> None:
    """Final crack pattern of each case (tensile red, shear blue, on the deformed mesh, in mm), the whole model on
    top and the hole's surroundings below; in b, the pressurised crack-gas cells (p ≥ 1 MPa) in green."""
    from matplotlib.collections import LineCollection
    from matplotlib.ticker import MaxNLocator

    plt = _plt()
    cases = [k for k in CASES if k in runs]
    fig, axes = plt.subplots(2, len(cases), figsize=(3.6 * len(cases), 7.9), dpi=110, squeeze=False)
    zoom = 1e3 * EXAMPLES[example]["zoom"]
    for j, k in enumerate(cases):
        t, f = vtu_frames(runs[k])[-1]
        fr = read_frame(f)
        x = 1e3 * fr["x"]
        for i, ax in enumerate(axes[:, j]):
            if i == 1:
                tri = fr["tri"]
                e = np.concatenate([tri[:, [0, 1]], tri[:, [1, 2]], tri[:, [2, 0]]])
                ax.add_collection(LineCollection(x[e], colors="0.85", linewidths=0.15))
            for code, col in ((1, "#d62728"), (2, "#1f5fbf")):
                s = fr["seg"][fr["mode"] == code]
                ax.add_collection(LineCollection(x[s], colors=col, linewidths=0.5 if i == 0 else 0.8))
            if fr["pgas"] is not None:
                s = fr["seg"][fr["pgas"] >= 1e6]
                ax.add_collection(LineCollection(x[s], colors="#2ca02c", linewidths=1.2 if i == 0 else 2.2))
            ax.set_aspect("equal")
            if i == 0:
                ax.set_xlim(x[:, 0].min(), x[:, 0].max())
                ax.set_ylim(x[:, 1].min(), x[:, 1].max())
                ax.add_patch(plt.Rectangle((-zoom, -zoom), 2 * zoom, 2 * zoom, fill=False, ls="--", lw=0.6))
                mm = metrics[k]
                ax.set_title(f"({k}) {CASES[k]}\nN = {mm['radial_crack_count']}, "
                             f"mean {mm['mean_radial_crack_length_mm']:.0f} mm, "
                             f"longest {mm['longest_radial_crack_mm']:.0f} mm\n"
                             f"connected {mm['connected_crack_length_m']:.2f} m, D = {mm['D']:.3f}, {t * 1e6:.0f} µs",
                             fontsize=8.5)
            else:
                ax.set_xlim(-zoom, zoom)
                ax.set_ylim(-zoom, zoom)
                if fr["pgas"] is not None:
                    n = int((fr["pgas"] >= 1e6).sum())
                    ax.set_title(f"centre; green: {n} crack-gas cells at p ≥ 1 MPa", fontsize=8.5)
                else:
                    ax.set_title("centre", fontsize=8.5)
            ax.xaxis.set_major_locator(MaxNLocator(5))
            ax.yaxis.set_major_locator(MaxNLocator(5))
            ax.tick_params(labelsize=7)
            ax.set_xlabel("x [mm]", fontsize=7)
    fig.suptitle(f"{EXAMPLES[example]['label']}: cracks (red tensile, blue shear)", fontsize=11)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    from PIL import Image  # a 128-colour palette: a third of the file size

    with Image.open(path) as im:
        im.convert("RGB").quantize(colors=128).save(path, optimize=True)


def fig_wall(results: dict, runs: dict, path: Path) -> None:
    """Per example: (1) borehole_pressure.csv of a and b and the loads that c and d's table pulses put on the
    wall; (2) the radial sum of every gas-particle load of a and b on the rock and the loads of e and f; (3) the
    first 10 µs of both; (4) the mean radial stress of the near-wall monitors."""
    plt = _plt()
    exs = list(results)
    fig, axes = plt.subplots(len(exs), 4, figsize=(21, 4.4 * len(exs)), dpi=110, squeeze=False)
    for i, ex in enumerate(exs):
        r = runs[ex]
        for k in ("a", "b"):
            if k not in r:
                continue
            col, ls = STYLE[k]
            _, a = read_csv(r[k] / "borehole_pressure.csv")
            _, g = read_csv(r[k] / "gas_load.csv")
            for ax in (axes[i, 0], axes[i, 2]):
                ax.plot(a[:, 0] * 1e6, a[:, 1] / 1e6, color=col, lw=1.6, label=f"({k}) borehole_pressure.csv")
            for ax in (axes[i, 1], axes[i, 2]):
                ax.plot(g[:, 0] * 1e6, (g[:, 1] + g[:, 2] + g[:, 3]) / 1e6, color=col, lw=1.0, ls=(0, (3, 1, 1, 1)),
                        label=f"({k}) all particle loads, radial / G")
        for k in DRIVEN:
            if k not in r:
                continue
            col, ls = STYLE[k]
            tb = results[ex]["tables"][k]
            _, g = read_csv(r[k] / "gas_load.csv")
            for ax in (axes[i, 0 if DRIVEN[k][1] == "csv" else 1], axes[i, 2]):
                ax.plot(g[:, 0] * 1e6, g[:, 1] / 1e6, color=col, ls=ls, lw=1.2,
                        label=f"({k}) load of its table pulse ({len(tb['times'])} points)")
        for k in CASES:
            if k in r:
                t, s = near_radial_stress(r[k])
                col, ls = STYLE[k]
                axes[i, 3].plot(t * 1e6, -s / 1e6, color=col, ls=ls, lw=1.1, label=f"({k}) {CASES[k]}")
        lab = EXAMPLES[ex]["label"]
        axes[i, 0].set_title(f"{lab}: wall pressure (csv) and c, d", fontsize=10)
        axes[i, 1].set_title(f"{lab}: all particle loads and e, f", fontsize=10)
        axes[i, 2].set_xlim(0, 10)
        axes[i, 2].set_title("first 10 µs of both", fontsize=10)
        axes[i, 3].set_title(f"mean radial stress at r = {NEAR_R * 1e3:.0f} mm (4 monitors), compression +",
                             fontsize=10)
        for ax in axes[i]:
            ax.set_xlabel("time [µs]")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=7)
        for ax in axes[i, :3]:
            ax.set_ylabel("pressure or radial load / G [MPa]")
        axes[i, 3].set_ylabel("−σ_rr [MPa]")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


#: the comparisons of fig_lengths: (title, cases)
LENGTH_PANELS = (("crack gas on / off, 2 meshes", ("a", "b", "a_p", "b_p")),
                 ("b and its rock-only replicas", ("b", "c", "f", "b_p", "c_p")),
                 ("a and its rock-only replicas", ("a", "d", "e")))


def fig_lengths(results: dict, path: Path) -> None:
    """Per example and comparison: connected crack crossings N(R) (cracks of the hole's network crossing the
    circle R) and the radial cracks' tip radii sorted (the k-th longest reaches R_k = max{R: N(R) ≥ k}; its
    length in summary.json is R_k − r_c, and r_c differs between cases)."""
    plt = _plt()
    exs = list(results)
    fig, axes = plt.subplots(2 * len(exs), len(LENGTH_PANELS), figsize=(16, 3.6 * 2 * len(exs)), dpi=110,
                             squeeze=False)
    for i, ex in enumerate(exs):
        cases = results[ex]["cases"]
        for j, (title, keys) in enumerate(LENGTH_PANELS):
            a0, a1 = axes[2 * i, j], axes[2 * i + 1, j]
            for k in keys:
                if k not in cases:
                    continue
                mm = cases[k]
                col, ls = STYLE.get(k, ("C7", "-"))
                lab = f"({k}) {CASES.get(k[0], '')}{' (mesh 2)' if k.endswith('_p') else ''}"
                cr = mm["crossings"]
                a0.plot(cr["radius_mm"], cr["count"], color=col, ls=ls, lw=1.2, label=lab)
                L = np.asarray(mm["radial_crack_lengths_mm"]) + mm.get("dense_cracking_radius_mm",
                                                                       mm.get("crushed_zone_radius_mm"))
                a1.plot(np.arange(1, len(L) + 1), L, color=col, ls=ls, marker=".", ms=3, lw=1.1,
                        label=f"({k}): {len(L)} cracks, mean tip radius {mm['mean_tip_radius_mm']:.0f} mm, "
                              f"r_k {mm.get('dense_cracking_radius_mm', mm.get('crushed_zone_radius_mm')):.0f} mm")
            a0.set_title(f"{EXAMPLES[ex]['label']}: {title}", fontsize=9.5)
            a0.set_xlabel("R [mm]")
            a0.set_ylabel("connected cracks crossing R, N(R)")
            a1.set_xlabel("rank k")
            a1.set_ylabel("tip radius R_k of the k-th longest [mm]")
            for ax in (a0, a1):
                ax.grid(alpha=0.3)
                ax.legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


def fig_growth(results: dict, path: Path) -> None:
    """Per example, against time (the ParaView frames): length of the crack network connected to the hole, mean
    length of the radial cracks, and their number (crack_history, the statistics of summary.json per frame)."""
    plt = _plt()
    exs = list(results)
    fig, axes = plt.subplots(len(exs), 3, figsize=(15, 4.0 * len(exs)), dpi=120, squeeze=False)
    style = STYLE
    keys = (("connected_crack_length_m", "connected crack length [m]"),
            ("mean_radial_crack_length_mm", "mean radial crack length [mm]"),
            ("radial_crack_count", "radial cracks, max N(R)"))
    for i, ex in enumerate(exs):
        for k, h in results[ex]["crack_history"].items():
            col, ls = style.get(k, ("C7", "-"))
            t = [r["t_us"] for r in h]
            for j, (q, lab) in enumerate(keys):
                axes[i, j].plot(t, [r[q] for r in h], color=col, ls=ls, marker=".", lw=1.1,
                                label=f"({k}) {CASES.get(k[0], '')}{' (mesh 2)' if k.endswith('_p') else ''}")
        for j, (q, lab) in enumerate(keys):
            axes[i, j].set_xlabel("time [µs]")
            axes[i, j].set_ylabel(lab)
            axes[i, j].set_title(f"{EXAMPLES[ex]['label']}: {lab.split(' [')[0]}", fontsize=10)
            axes[i, j].grid(alpha=0.3)
        axes[i, 0].legend(fontsize=7)
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)


# ----------------------------------------------------------------------------------------------------- main
