"""Figures of the crack-gas verification cases (docs/explosive.md, "Gas in cracks"; the assertions are in
tests/verification/test_crack_gas.py, whose set-ups this script reuses).

    python examples/crack_gas/verification_figures.py          # writes crack_gas_verification.png here (~1 min)
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path[:0] = [str(ROOT / "tests"), str(ROOT / "tests" / "verification")]


def main() -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from test_crack_gas import _channel, _griffith_opening

    fig, ax = plt.subplots(1, 3, figsize=(15, 4.3), dpi=130)
    errs, hs = [], []
    for n, c in zip((8, 16, 32), ("tab:blue", "tab:orange", "tab:green")):
        xs, w, we, lift, w0 = _griffith_opening(n)
        a = 0.01
        ax[0].plot(xs / a, w / w0, "o", ms=3, color=c, label=f"h = a/{n}")
        errs.append(math.sqrt(np.mean((w - we) ** 2)) / w0)
        hs.append(1.0 / n)
    xx = np.linspace(-1, 1, 400)
    ax[0].plot(xx, np.sqrt(1 - xx**2), "k-", lw=1, label="Sneddon: w = 4p(1−ν²)/E·√(a²−x²)")
    ax[0].set_xlabel("x / a")
    ax[0].set_ylabel("opening w / (4p(1−ν²)a/E)")
    ax[0].set_title("Griffith crack under internal pressure (crack-cell face loads)", fontsize=9)
    ax[0].legend(fontsize=7)
    ax[1].loglog(hs, errs, "o-", color="k", label="rms error of w")
    ax[1].loglog(hs, errs[0] * np.array(hs) / hs[0], "--", color="0.5", label="first order")
    ax[1].set_xlabel("h / a")
    ax[1].set_ylabel("rms(w − w_exact) / w(0)")
    ax[1].set_title("Convergence under mesh refinement", fontsize=9)
    ax[1].legend(fontsize=7)
    ws = np.array([5e-6, 10e-6, 20e-6, 40e-6])
    flux, cubic = [], []
    for w in ws:
        f, c, _ = _channel(w)
        flux.append(f)
        cubic.append(c)
    ax[2].loglog(ws * 1e6, flux, "o", color="k", label="network flux (steady, held reservoirs)")
    ax[2].loglog(ws * 1e6, cubic, "-", color="tab:red", lw=1, label="cubic law ρ̄w³Δp/(12μℓ)")
    ax[2].set_xlabel("aperture w [µm]")
    ax[2].set_ylabel("mass flux [kg/(m·s)]")
    ax[2].set_title("Straight channel of fixed aperture", fontsize=9)
    ax[2].legend(fontsize=7)
    for a_ in ax:
        a_.grid(alpha=0.3, which="both")
    fig.tight_layout()
    fig.savefig(HERE / "crack_gas_verification.png")
    print("Griffith rms errors", [f"{e:.4f}" for e in errs], "channel flux / cubic law",
          [f"{f / c:.4f}" for f, c in zip(flux, cubic)])


if __name__ == "__main__":
    main()
