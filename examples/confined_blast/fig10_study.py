"""Issue 13, item 2: the tensile phase of Yue et al.'s Fig. 10 monitor under P = 0 (confined blast, plane strain).

    python examples/confined_blast/fig10_study.py [--work /tmp/fig10] [--rerun] [--only CASE ...] [--fd-only]

Runs the shipped P = 0 scenario (scenario_P0.toml) and variants of it, one after the other, with extra monitors
(radial σxx and hoop σyy along +x at 10…200 mm, the shipped 50 mm monitor with its default averaging radius and
with R = 3 mm (a single element there), the same point on +y, the gas pressure next to the wall). Cases (each ≈ 40–120 s on 2 cores):

    base          the shipped scenario: non-reflecting (viscous) sides, breakable rock, MPM gas, 90 µs
    free          the same with free (traction-free) sides, 150 µs (a P = 0 boundary load is a free face)
    elastic       unbreakable rock (rock.unbreakable), viscous sides, MPM gas, 90 µs
    elastic_free  unbreakable rock, free sides, 150 µs
    vent          rock only (no gas): the wall pressure of `base` until 10 µs, then let down linearly to 0 at
                  20 µs (a vented hole), breakable rock, viscous sides, 90 µs
    vent_elastic  the same pulse on unbreakable rock
    paper_law     the paper's rock law: lumped mass, no shock viscosity, spring dashpots or fracture energies

and an independent reference: a 1D axisymmetric plane-strain elastic finite-difference solution of a cylindrical
cavity (radius 5 mm, the rock's E, ν, ρ) loaded by a given wall-pressure history, averaged over the same disc as
the 2D monitor. It is driven by the wall gas pressure measured in the coupled runs and by the vent pulse.

Writes fig10_base.png, fig10_elastic_fd.png, fig10_boundaries.png, fig10_vent.png, fig10_radii.png into this
folder and prints a table (also written as <work>/fig10_table.json). Runs already present in <work> are reused
unless --rerun.
"""

from __future__ import annotations

import argparse
import csv
import json
import sys
import time
import tomllib
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

HERE = Path(__file__).parent
SCENARIO = HERE / "scenario_P0.toml"
A = 0.005                       # hole radius [m]
E, NU, RHO = 50e9, 0.2, 2600.0  # Table 2
T_PAPER = 90e-6                 # the paper's duration
XS_MM = (10, 20, 30, 50, 75, 100, 150, 200)    # +x monitors [mm]
WALL_GAS = [(0.0042, 0.0), (0.0, 0.0042), (-0.0042, 0.0), (0.0, -0.0042)]   # gas next to the wall (r = 4.2 mm)
VENT_START, VENT_END = 10e-6, 20e-6


# ----------------------------------------------------------------------------------------------- scenarios
def monitors(gas: bool) -> list[dict]:
    st = ["sxx", "syy", "sxy", "pressure"]
    m = [{"name": "m50mm", "position": [0.05, 0.0], "quantities": st + ["vx"]},
         {"name": "m50r3", "position": [0.05, 0.0], "quantities": st, "radius": 0.003},
         {"name": "y50", "position": [0.0, 0.05], "quantities": st},
         {"name": "wall", "position": [0.0058, 0.0], "quantities": st, "radius": 0.0008}]
    m += [{"name": f"x{r}", "position": [r / 1000, 0.0], "quantities": st} for r in XS_MM if r != 50]
    if gas:
        m.append({"name": "charge", "position": [0.0, 0.0], "quantities": ["gas_pressure"]})
        m += [{"name": f"gw{k}", "position": list(p), "quantities": ["gas_pressure"]} for k, p in enumerate(WALL_GAS)]
    return m


def base_dict() -> dict:
    d = tomllib.loads(SCENARIO.read_text())
    d["rock"].pop("fracture_band_width", None)     # as measured (fig10_monitor.md), before the example's fracture band
    d["simulation"]["progress"] = False
    d["output"].update(paraview=False, figures=True, monitor_interval=0.2e-6, snapshot_times=[])
    d["monitors"] = monitors(gas=True)
    return d


def set_sides(d: dict, kind: str) -> None:
    d["boundaries"] = {s: {"type": kind} for s in ("left", "right", "top", "bottom")}


def rock_only(d: dict, pulse_t: np.ndarray, pulse_p: np.ndarray) -> None:
    d.pop("explosive", None)
    d.pop("coupling", None)
    d["borehole_pressure"] = [{"borehole": 0, "pulse": {"type": "table", "times": [float(t) for t in pulse_t],
                                                        "values": [float(p) for p in pulse_p]}}]
    d["monitors"] = monitors(gas=False)


CASES = {
    "base": "shipped P0: viscous sides, breakable, gas",
    "free": "free sides, breakable, gas, 150 µs",
    "elastic": "unbreakable, viscous sides, gas",
    "elastic_free": "unbreakable, free sides, gas, 150 µs",
    "vent": "rock only, vented wall pressure (base until 10 µs → 0 at 20 µs), breakable",
    "vent_elastic": "rock only, same vented pulse, unbreakable",
    "paper_law": "the paper's rock law (lumped mass, no shock viscosity, dashpots or fracture energies), gas",
}


def case_dict(name: str, work: Path) -> dict:
    d = base_dict()
    if name in ("free", "elastic_free"):
        set_sides(d, "free")
        d["simulation"]["end_time"] = 150e-6
    if name.startswith("elastic") or name == "vent_elastic":
        d["rock"]["unbreakable"] = True
    if name.startswith("vent"):
        t, p = vent_pulse(work)
        rock_only(d, t, p)
    if name == "paper_law":
        d["rock"]["mass_matrix"] = "lumped"
        for k in ("bulk_viscosity_linear", "bulk_viscosity_quadratic", "spring_damping", "tensile_fracture_energy",
                  "shear_fracture_energy"):
            d["rock"].pop(k, None)
    return d


def run_case(name: str, work: Path, rerun: bool) -> float | None:
    out = work / name
    if (out / "summary.json").exists() and not rerun:
        return None
    from blastfrac.scenario.load import scenario_from_dict
    from blastfrac.simulation import Simulation

    sc = scenario_from_dict(case_dict(name, work), source=f"fig10:{name}")
    t0 = time.perf_counter()
    s = Simulation(sc, out_dir=out).run(progress=False)
    wall = time.perf_counter() - t0
    print(f"  {name}: {s['steps']} steps, {s['simulated_time'] * 1e6:.0f} µs, {wall:.0f} s", flush=True)
    return wall


# ----------------------------------------------------------------------------------------------- reading
def read_csv(path: Path) -> dict[str, np.ndarray]:
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    data = np.array(rows[1:], float)
    return {k.split(" [")[0].strip(): data[:, i] for i, k in enumerate(rows[0])}


def smooth(y: np.ndarray, n: int) -> np.ndarray:
    """Centred running mean over n samples (edges padded with the end values)."""
    if n <= 1:
        return y
    yp = np.concatenate([np.full(n // 2, y[0]), y, np.full(n - 1 - n // 2, y[-1])])
    return np.convolve(yp, np.ones(n) / n, mode="valid")


def wall_pressure(mon: dict) -> np.ndarray:
    """Gas pressure next to the wall: mean over the four points at r = 4.2 mm, smoothed over 1 µs [Pa]."""
    g = np.mean([mon[f"gw{k}:gas_pressure"] for k in range(len(WALL_GAS))], axis=0)
    return smooth(g, 5)


def vent_pulse(work: Path) -> tuple[np.ndarray, np.ndarray]:
    """The base run's wall pressure until VENT_START, then a linear let-down to 0 at VENT_END (kept at 0)."""
    mon = read_csv(work / "base" / "monitors.csv")
    t, p = mon["time"], wall_pressure(mon)
    keep = t < VENT_START
    tt = np.concatenate([t[keep], [VENT_START, VENT_END, 1.0]])
    pp = np.concatenate([p[keep], [np.interp(VENT_START, t, p), 0.0, 0.0]])
    return tt, pp


# ----------------------------------------------------------------------------------------------- 1D reference
def fd_cavity(t_p, p_p, t_end, a=A, dr=1e-4, dt_out=0.2e-6, cfl=0.5):
    """Plane-strain axisymmetric elastodynamics of a cylindrical cavity, wall pressure p(t) (compression +).

    Nodal displacements u(r) on r = a … a + 1.05 c_p t_end (no reflection can come back in time), finite-volume
    form ρ r ü = ∂(r σ_r)/∂r − σ_θ with the wall traction as the flux at r = a, leapfrog in time.
    Returns (times [s], r [m], σ_r [T, N], σ_θ [T, N]) in Pa, tension positive. Checked against the static Lamé
    field −p a²/r², +p a²/r² (within 1 % after 100 µs of a step load at r = 10 a).
    """
    lam = E * NU / ((1 + NU) * (1 - 2 * NU))
    mu = E / (2 * (1 + NU))
    M = lam + 2 * mu
    cp = np.sqrt(M / RHO)
    n = int(np.ceil((cp * t_end * 1.05 + 10 * dr) / dr)) + 1
    r = a + dr * np.arange(n)
    rh = 0.5 * (r[1:] + r[:-1])
    w = np.full(n, dr)
    w[0] = w[-1] = dr / 2
    rc = r.copy()
    rc[0] += dr / 4
    rc[-1] -= dr / 4
    m = RHO * rc * w
    u, v = np.zeros(n), np.zeros(n)
    dt = cfl * dr / cp
    steps = int(np.ceil(t_end / dt))
    ts, srs, sts = [], [], []
    next_out, t = 0.0, 0.0
    for _ in range(steps + 1):
        du = (u[1:] - u[:-1]) / dr
        srh = M * du + lam * 0.5 * (u[1:] + u[:-1]) / rh
        dn = np.gradient(u, dr)
        stn = lam * dn + M * u / r
        p = np.interp(t, t_p, p_p, left=0.0, right=p_p[-1])
        if t >= next_out - 1e-15:
            srn = M * dn + lam * u / r
            srn[0] = -p
            ts.append(t)
            srs.append(srn.astype(np.float32))
            sts.append(stn.astype(np.float32))
            next_out += dt_out
        f = np.zeros(n)
        flux = rh * srh
        f[:-1] += flux
        f[1:] -= flux
        f[0] += a * p
        f -= stn * w
        f[-1] = 0.0
        v += dt * f / m
        u += dt * v
        t += dt
    return np.array(ts), r, np.array(srs), np.array(sts)


def disc_average(r, sr, st, centre, radius, n_r=12, n_phi=24):
    """Area mean of σxx, σyy over a disc (the 2D monitor's stencil) of an axisymmetric field σ_r(r), σ_θ(r)."""
    cx, cy = centre
    if radius <= 0:
        rho_s, ph_s, wts = np.array([0.0]), np.array([0.0]), np.array([1.0])
    else:
        rho_s = (np.arange(n_r) + 0.5) / n_r * radius
        ph_s = np.arange(n_phi) * 2 * np.pi / n_phi
        rho_s, ph_s = np.meshgrid(rho_s, ph_s)
        wts = rho_s.ravel()
        rho_s, ph_s = rho_s.ravel(), ph_s.ravel()
    x = cx + rho_s * np.cos(ph_s)
    y = cy + rho_s * np.sin(ph_s)
    rr, th = np.hypot(x, y), np.arctan2(y, x)
    keep = rr > r[0]
    x, y, rr, th, wts = x[keep], y[keep], rr[keep], th[keep], wts[keep] / wts[keep].sum()
    c2, s2 = np.cos(th) ** 2, np.sin(th) ** 2
    out_xx, out_yy = np.zeros(len(sr)), np.zeros(len(sr))
    for k in range(len(sr)):
        a_r = np.interp(rr, r, sr[k])
        a_t = np.interp(rr, r, st[k])
        out_xx[k] = np.sum(wts * (a_r * c2 + a_t * s2))
        out_yy[k] = np.sum(wts * (a_r * s2 + a_t * c2))
    return out_xx, out_yy


def fd_self_check() -> dict:
    """Step load 100 MPa (1 µs rise): σ_r, σ_θ at r = 10 a after 150 µs against Lamé (−1, +1 MPa), and the
    radial undershoot behind the front."""
    t, r, sr, st = fd_cavity(np.array([0.0, 1e-6, 1.0]), np.array([0.0, 100e6, 100e6]), 150e-6)
    i = int(np.argmin(np.abs(r - 10 * A)))
    return {"lame_sr_MPa": -1.0, "fd_sr_end_MPa": float(sr[-1, i] / 1e6), "fd_st_end_MPa": float(st[-1, i] / 1e6),
            "fd_sr_peak_MPa": float(sr[:, i].min() / 1e6), "fd_sr_max_after_MPa": float(sr[:, i].max() / 1e6),
            "fd_sr_max_after_t_us": float(t[sr[:, i].argmax()] * 1e6)}


def fd_at_monitor(t_p, p_p, t_end, radius):
    """FD σxx (radial), σyy (hoop) at (50 mm, 0): disc-averaged over `radius` and at the point [Pa]."""
    t, r, sr, st = fd_cavity(t_p, p_p, t_end)
    xx, yy = disc_average(r, sr, st, (0.05, 0.0), radius)
    xp, yp = disc_average(r, sr, st, (0.05, 0.0), 0.0)
    return {"t": t, "sxx": xx, "syy": yy, "sxx_pt": xp, "syy_pt": yp, "r": r, "sr": sr, "st": st}


# ----------------------------------------------------------------------------------------------- measures
def phase_numbers(t, srad, shoop, t_max, arrival_level=1e6):
    """Peaks of one monitor history up to t_max: compressive radial peak, the largest radial stress after that
    peak (> 0: a tensile phase; < 0: the least compression behind the front), how long σ_r > 0.1 MPa after the
    front (first |σ_r| > `arrival_level`), hoop extremes, in-plane mean p = −(σr+σθ)/2 (min after the front)."""
    k = t <= t_max + 1e-12
    t, srad, shoop = t[k], srad[k], shoop[k]
    arr = np.flatnonzero(np.abs(srad) > arrival_level)
    i0 = arr[0] if len(arr) else len(t) - 1
    after = slice(max(i0, int(srad.argmin())), None)
    p = -(srad + shoop) / 2
    pos = srad[i0:] > 0.1e6
    dt = t[1] - t[0] if len(t) > 1 else 0.0
    return {"arrival_us": float(t[i0] * 1e6),
            "radial_comp_peak_MPa": float(-srad.min() / 1e6),
            "radial_comp_peak_t_us": float(t[srad.argmin()] * 1e6),
            "radial_tens_peak_MPa": float(srad[after].max() / 1e6),
            "radial_tens_peak_t_us": float(t[after][srad[after].argmax()] * 1e6),
            "radial_tension_duration_us": float(pos.sum() * dt * 1e6),
            "hoop_max_MPa": float(shoop[i0:].max() / 1e6), "hoop_min_MPa": float(shoop.min() / 1e6),
            "mean_p_min_MPa": float(p[i0:].min() / 1e6), "mean_p_max_MPa": float(p.max() / 1e6),
            "radial_end_MPa": float(srad[-1] / 1e6), "hoop_end_MPa": float(shoop[-1] / 1e6)}


def reflection_arrival(x: float, side: float = 0.25) -> float:
    """First arrival of the P wave reflected at the nearest side (x = +side) at (x, 0) [s]."""
    cp = np.sqrt(E * (1 - NU) / ((1 + NU) * (1 - 2 * NU) * RHO))
    return (side - A + side - x) / cp


# ----------------------------------------------------------------------------------------------- figures
def mpa(y):
    return np.asarray(y) / 1e6


def fig_base(runs, fd, out):
    b = runs["base"]
    t = b["time"] * 1e6
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2), dpi=130)
    ax[0].plot(t, mpa(b["m50mm:sxx"]), label="radial σxx, R = 13 mm (shipped monitor)")
    ax[0].plot(t, mpa(b["m50r3:sxx"]), lw=0.7, alpha=0.6, label="radial σxx, single element (R = 3 mm)")
    ax[0].plot(t, mpa(b["m50mm:syy"]), label="hoop σyy, R = 13 mm")
    ax[0].plot(t, mpa(b["m50r3:syy"]), lw=0.7, alpha=0.6, label="hoop σyy, single element")
    ax[0].plot(t, -mpa(b["m50mm:pressure"]), "k--", lw=1, label="−p, p = −(σxx+σyy)/2")
    pl = runs["paper_law"]
    ax[0].plot(pl["time"] * 1e6, mpa(pl["m50mm:sxx"]), color="grey", lw=1.2, label="radial σxx, the paper's rock law")
    ax[0].set_title("breakable rock + gas (shipped run): (50 mm, 0)", fontsize=10)
    ax[0].set_ylabel("stress [MPa], tension +")
    e = runs["elastic"]
    te = e["time"] * 1e6
    ax[1].plot(te, mpa(e["m50mm:sxx"]), label="radial σxx, R = 13 mm")
    ax[1].plot(te, mpa(e["m50r3:sxx"]), lw=0.7, alpha=0.6, label="radial σxx, single element (R = 3 mm)")
    ax[1].plot(te, mpa(e["m50mm:syy"]), label="hoop σyy, R = 13 mm")
    ax[1].plot(te, -mpa(e["m50mm:pressure"]), "k--", lw=1, label="−p")
    ax[1].set_title("unbreakable rock + gas: (50 mm, 0)", fontsize=10)
    for a_ in ax[:2]:
        a_.axhline(0, color="grey", lw=0.6)
        a_.set_ylim(-380, 140)
    ax[2].plot(t, mpa(wall_pressure(b)), label="breakable (shipped)")
    ax[2].plot(te, mpa(wall_pressure(e)), label="unbreakable")
    ax[2].plot(t, mpa(b["charge:gas_pressure"]), lw=0.5, alpha=0.5, label="breakable, hole centre")
    ax[2].set_yscale("log")
    ax[2].set_ylim(50, 1e4)
    ax[2].set_title("gas pressure at the wall (r = 4.2 mm, 4 points, 1 µs mean)", fontsize=10)
    ax[2].set_ylabel("gas pressure [MPa]")
    for a_ in ax:
        a_.set_xlabel("time [µs]")
        a_.grid(alpha=0.3)
        a_.legend(fontsize=7)
    fig.suptitle("Monitor of Fig. 10 (P = 0): no radial tension in the shipped run; the intact rock shows one")
    fig.tight_layout()
    fig.savefig(out / "fig10_base.png")
    plt.close(fig)


def fig_elastic_fd(runs, fd, out):
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2), dpi=130)
    e = runs["elastic"]
    te = e["time"] * 1e6
    f = fd["elastic"]
    tf = f["t"] * 1e6
    ax[0].plot(te, mpa(e["m50mm:sxx"]), "C0", label="2D unbreakable, radial σxx (R = 13 mm)")
    ax[0].plot(tf, mpa(f["sxx"]), "C0--", label="1D FD, same disc average")
    ax[0].plot(te, mpa(e["m50mm:syy"]), "C1", label="2D unbreakable, hoop σyy")
    ax[0].plot(tf, mpa(f["syy"]), "C1--", label="1D FD, hoop")
    ax[0].set_title("unbreakable rock: 2D coupled run vs 1D elastic cavity (its own wall pressure)", fontsize=9)
    fb = fd["base"]
    b = runs["base"]
    ax[1].plot(b["time"] * 1e6, mpa(b["m50mm:sxx"]), "C0", label="2D breakable (shipped), radial σxx")
    ax[1].plot(fb["t"] * 1e6, mpa(fb["sxx"]), "C0--", label="1D elastic FD driven by the shipped run's wall pressure")
    ax[1].plot(b["time"] * 1e6, mpa(b["m50mm:syy"]), "C1", label="2D breakable, hoop σyy")
    ax[1].plot(fb["t"] * 1e6, mpa(fb["syy"]), "C1--", label="1D FD, hoop")
    ax[1].set_title("shipped run vs what intact elastic rock would give under the same gas", fontsize=9)
    for a_ in ax:
        a_.axhline(0, color="grey", lw=0.6)
        a_.set_xlabel("time [µs]")
        a_.set_ylabel("stress at (50 mm, 0) [MPa], tension +")
        a_.grid(alpha=0.3)
        a_.legend(fontsize=7)
        a_.set_ylim(-400, 160)
    fig.tight_layout()
    fig.savefig(out / "fig10_elastic_fd.png")
    plt.close(fig)


def fig_boundaries(runs, out):
    fig, ax = plt.subplots(2, 2, figsize=(12, 7.5), dpi=130, sharex=True)
    for j, (v, f, lab) in enumerate((("base", "free", "breakable + gas"), ("elastic", "elastic_free", "unbreakable + gas"))):
        for i, (col, xmm) in enumerate((("m50mm", 50), ("x150", 150))):
            a_ = ax[i, j]
            for case, style in ((v, "-"), (f, "--")):
                m = runs[case]
                sides = "viscous" if case == v else "free"
                a_.plot(m["time"] * 1e6, mpa(m[f"{col}:sxx"]), "C0" + style, label=f"radial σxx, {sides} sides")
                a_.plot(m["time"] * 1e6, mpa(m[f"{col}:syy"]), "C1" + style, lw=0.9, label=f"hoop σyy, {sides} sides")
            a_.axvline(T_PAPER * 1e6, color="k", lw=0.8)
            a_.axvline(reflection_arrival(xmm / 1000) * 1e6, color="r", lw=0.8, ls=":")
            a_.axhline(0, color="grey", lw=0.6)
            a_.set_title(f"{lab}, ({xmm} mm, 0)", fontsize=9)
            a_.set_ylim(-130 if xmm == 50 else -60, 60)
            a_.grid(alpha=0.3)
            a_.set_ylabel("stress [MPa], tension +")
    for a_ in ax[1]:
        a_.set_xlabel("time [µs]")
    ax[0, 0].legend(fontsize=7)
    fig.suptitle("Free vs non-reflecting sides (fronts clipped). Red: the P wave reflected at x = 0.25 m reaches the "
                 "point\n(the monitor's disc sees it ≈ 3 µs earlier); black: 90 µs, the paper's end", fontsize=10)
    fig.tight_layout()
    fig.savefig(out / "fig10_boundaries.png")
    plt.close(fig)


def fig_vent(runs, fd, out, pulse):
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2), dpi=130)
    tp = np.linspace(0, T_PAPER, 2000)
    ax[0].plot(tp * 1e6, mpa(np.maximum(np.interp(tp, *pulse), 1.0)), "k", label="vented wall pressure (rock-only load)")
    ax[0].plot(runs["base"]["time"] * 1e6, mpa(wall_pressure(runs["base"])), "C3", lw=0.8, label="shipped run, wall gas")
    ax[0].set_xlim(0, 90)
    ax[0].set_yscale("log")
    ax[0].set_ylim(10, 1e4)
    ax[0].set_ylabel("wall pressure [MPa]")
    for case, c in (("vent", "C0"), ("vent_elastic", "C2")):
        m = runs[case]
        lab = "breakable" if case == "vent" else "unbreakable"
        ax[1].plot(m["time"] * 1e6, mpa(m["m50mm:sxx"]), c, label=f"2D {lab}, radial σxx (R = 13 mm)")
        ax[1].plot(m["time"] * 1e6, mpa(m["m50mm:syy"]), c, lw=0.7, ls="-.", label=f"2D {lab}, hoop σyy")
    f = fd["vent"]
    ax[1].plot(f["t"] * 1e6, mpa(f["sxx"]), "k--", label="1D elastic FD, radial (disc mean)")
    ax[1].plot(f["t"] * 1e6, mpa(f["syy"]), "k:", label="1D elastic FD, hoop")
    ax[1].axhline(0, color="grey", lw=0.6)
    ax[1].set_ylim(-400, 160)
    ax[1].set_ylabel("stress at (50 mm, 0) [MPa], tension +")
    for a_ in ax:
        a_.set_xlabel("time [µs]")
        a_.grid(alpha=0.3)
        a_.legend(fontsize=7)
    fig.suptitle("Hole let down to 0 between 10 and 20 µs: intact rock swings to radial tension, the cracked rock "
                 "stays in compression")
    fig.tight_layout()
    fig.savefig(out / "fig10_vent.png")
    plt.close(fig)


def fig_radii(runs, out):
    fig, ax = plt.subplots(1, 2, figsize=(12, 4.2), dpi=130, sharey=True)
    for a_, case, lab in ((ax[0], "base", "breakable + gas (shipped)"), (ax[1], "elastic", "unbreakable + gas")):
        m = runs[case]
        for i, xmm in enumerate((20, 30, 50, 100, 150, 200)):
            col = "m50mm" if xmm == 50 else f"x{xmm}"
            a_.plot(m["time"] * 1e6, mpa(m[f"{col}:sxx"]), f"C{i}", lw=1, label=f"x = {xmm} mm")
        a_.axhline(0, color="grey", lw=0.6)
        a_.set_title(f"radial σxx along +x, {lab}", fontsize=10)
        a_.set_xlabel("time [µs]")
        a_.grid(alpha=0.3)
        a_.legend(fontsize=7)
    ax[0].set_ylim(-300, 60)
    ax[0].set_ylabel("radial stress [MPa], tension +")
    fig.tight_layout()
    fig.savefig(out / "fig10_radii.png")
    plt.close(fig)


# ----------------------------------------------------------------------------------------------- main
def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--work", type=Path, default=Path("/tmp/fig10"))
    ap.add_argument("--out", type=Path, default=HERE)
    ap.add_argument("--rerun", action="store_true")
    ap.add_argument("--only", nargs="*", default=None, help="run only these cases (the figures need all)")
    a = ap.parse_args(argv)
    a.work.mkdir(parents=True, exist_ok=True)
    names = a.only if a.only is not None else list(CASES)
    walls = {}
    for name in ["base"] + [n for n in names if n != "base"]:   # vent needs the base run's wall pressure
        if name not in CASES:
            sys.exit(f"unknown case {name}; choose from {', '.join(CASES)}")
        w = run_case(name, a.work, a.rerun)
        if w is not None:
            walls[name] = w
    if any(not (a.work / n / "summary.json").exists() for n in CASES):
        print("not all cases are present: no figures")
        return
    runs = {n: read_csv(a.work / n / "monitors.csv") for n in CASES}
    summ = {n: json.loads((a.work / n / "summary.json").read_text()) for n in CASES}
    R50 = next(m["radius"] for m in summ["base"]["monitors"] if m["name"] == "m50mm")
    fd = {}
    for n in ("base", "elastic"):
        fd[n] = fd_at_monitor(runs[n]["time"], wall_pressure(runs[n]), T_PAPER, R50)
    pulse = vent_pulse(a.work)
    fd["vent"] = fd_at_monitor(*pulse, T_PAPER, R50)

    a.out.mkdir(parents=True, exist_ok=True)
    fig_base(runs, fd, a.out)
    fig_elastic_fd(runs, fd, a.out)
    fig_boundaries(runs, a.out)
    fig_vent(runs, fd, a.out, pulse)
    fig_radii(runs, a.out)

    table = {}
    for n in CASES:
        m, s = runs[n], summ[n]
        for tmax in sorted({T_PAPER, s["simulated_time"]}):
            row = phase_numbers(m["time"], m["m50mm:sxx"], m["m50mm:syy"], tmax)
            row3 = phase_numbers(m["time"], m["m50r3:sxx"], m["m50r3:syy"], tmax)
            row["R3_radial_tens_peak_MPa"] = row3["radial_tens_peak_MPa"]
            row["R3_radial_comp_peak_MPa"] = row3["radial_comp_peak_MPa"]
            row["x150_radial_tens_peak_MPa"] = phase_numbers(m["time"], m["x150:sxx"], m["x150:syy"], tmax)["radial_tens_peak_MPa"]
            row["x200_radial_tens_peak_MPa"] = phase_numbers(m["time"], m["x200:sxx"], m["x200:syy"], tmax)["radial_tens_peak_MPa"]
            k = m["time"] <= tmax + 1e-12
            row["wall_gas_end_MPa"] = float(wall_pressure(m)[k][-1] / 1e6) if "gw0:gas_pressure" in m else None
            fdg = read_csv(a.work / n / "fracture_degree.csv")
            row["broken_springs"] = int(round(np.interp(tmax, fdg["time"], fdg["D"]) * s["counts"]["springs"]))
            row["wall_time_s"] = s["wall_time_s"]
            row["t_max_us"] = round(tmax * 1e6)
            table[f"{n}@{round(tmax * 1e6)}us"] = row
    for n in fd:
        f = fd[n]
        row = phase_numbers(f["t"], f["sxx"], f["syy"], T_PAPER)
        rp = phase_numbers(f["t"], f["sxx_pt"], f["syy_pt"], T_PAPER)
        row["point_radial_tens_peak_MPa"] = rp["radial_tens_peak_MPa"]
        row["point_radial_comp_peak_MPa"] = rp["radial_comp_peak_MPa"]
        table[f"FD[{n}]@90us"] = row
    chk = fd_self_check()
    table["FD_self_check_step_100MPa_r50mm"] = chk
    (a.work / "fig10_table.json").write_text(json.dumps(table, indent=1))
    cols = [("arrival_us", "arr µs"), ("radial_comp_peak_MPa", "σr comp"), ("radial_tens_peak_MPa", "σr max"),
            ("radial_tens_peak_t_us", "at µs"), ("radial_tension_duration_us", "σr>0 µs"),
            ("R3_radial_tens_peak_MPa", "σr max 1el"), ("hoop_max_MPa", "σθ max"), ("hoop_min_MPa", "σθ min"),
            ("mean_p_min_MPa", "p min"), ("radial_end_MPa", "σr end"), ("x150_radial_tens_peak_MPa", "σr+ 150"),
            ("x200_radial_tens_peak_MPa", "σr+ 200"), ("wall_gas_end_MPa", "gas end"), ("broken_springs", "broken")]
    print(f"\nmonitor (50 mm, 0), disc R = {R50 * 1e3:.1f} mm; MPa, tension +. σr comp: compressive radial peak; "
          "σr max: largest radial stress after it (> 0 = tensile phase), at µs; σr>0 µs: time with σr > 0.1 MPa;\n"
          "σr max 1el: the same for the single element at the point (R = 3 mm); σθ: hoop; p min: least in-plane mean "
          "−(σr+σθ)/2; σr+ 150/200: σr max at (150, 0), (200, 0) mm; gas end: wall gas pressure at t; broken: "
          "springs broken by t")
    print(f"{'case':22s}" + "".join(f"{h:>11s}" for _, h in cols))
    for k, row in table.items():
        if "arrival_us" not in row:
            continue
        vals = []
        for c, _ in cols:
            v = row.get(c)
            vals.append("–" if v is None else (f"{v:d}" if isinstance(v, int) else f"{v:.1f}"))
        print(f"{k:22s}" + "".join(f"{v:>11s}" for v in vals))
    print(f"FD check, 100 MPa step at r = 10 a: σr → {chk['fd_sr_end_MPa']:.2f} MPa at 150 µs (Lamé −1.00), "
          f"σθ → {chk['fd_st_end_MPa']:.2f} (+1.00); front peak {chk['fd_sr_peak_MPa']:.1f} MPa, then radial "
          f"tension {chk['fd_sr_max_after_MPa']:+.2f} MPa at {chk['fd_sr_max_after_t_us']:.1f} µs")
    if walls:
        print("wall times this call [s]: " + ", ".join(f"{k} {v:.0f}" for k, v in walls.items()))


if __name__ == "__main__":
    main()
