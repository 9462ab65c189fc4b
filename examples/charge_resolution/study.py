"""Charge resolution: wall impulse and wall pressure against cells across the charge (issue 12, item 1).

Set-up (the blastfrac default blast: examples/confined_blast/scenario_P0.toml's rock, explosive and coupling):
a 5 mm radius emulsion charge filling a 5 mm borehole in unbreakable elastic rock (Table 2: 2600 kg/m³,
E = 50 GPa, ν = 0.2, penalty springs ×20, P0's bulk viscosity and spring damping), centre-initiated (the
default), default coupling, in a 0.24 m square with viscous sides (the P wave reaches them after 21 µs and its
reflection the hole after 45 µs: the rock is infinite for this run). Background grid ±2 R around the hole.
At each level N = cells across the charge diameter the MPM cell is h = 2R/N, 2 points per cell, and the
rock mesh at the wall is h too (graded to 6 mm at 30 mm from the wall).

Cases: n10, n20, n40, n80 (25 µs), n160 (10 µs: the early window only); n10..n80 with flip = 0.99 (1 % PIC);
n10..n80 to 12 µs with the emulsion lit at its JWL set's own CJ speed (5522 m/s instead of the library's 4000 m/s);
points per cell 3 at 10 and 20 cells; 20 cells with the rock mesh of level 40.

Quantities per run (the time-mean wall pressure of analysis/wall_load.py, the run's borehole_pressure.csv,
sampled every 0.05 µs; its integral is exact whatever the interval):
  I(t) = ∫ p_wall dt at 2, 5, 10, 20 µs [Pa·s]; the largest |I_N(t)/I_ref(t) − 1| over 5–10 µs and 10–20 µs;
  the peak of p_wall, its arrival (first crossing of half the peak); the peak radial compression −σ_rr and
  radial velocity at r = 2.5 R (mean of four monitors on the axes, averaging radius 1 mm); the hole's area
  A(t) and the gas's total particle volume (record.npz), the energies (energy.csv).
Reference levels (REFERENCE_CELLS): 80 cells up to 10 µs and 40 cells for 10–20 µs (at 80 cells and more the gas
volume drifts after ~7000 steps and, with the library emulsion, the detonation speeds up: README). Richardson
extrapolation from the three finest levels up to 80 cells (ratio 2) gives a quantity's observed order and converged
value when its differences are monotone; otherwise the reference level's value is the reference.

Physics check: once the hole's gas has rung down (t > 10 µs) its mean wall pressure should equal the JWL
pressure at the hole's relative volume V = A(t)/(πR²) and the gas's mean internal energy E = E_gas/(πR²)
(uniform-gas estimate), and lie below the isentrope through the constant-volume explosion state (V = 1, E0),
p_isen(V), by the energy the gas gave the rock.

    python examples/charge_resolution/study.py --out out/charge_resolution             # every case (~35 min on 2 cores)
    python examples/charge_resolution/study.py --out out/charge_resolution --reuse     # skip finished cases
    python examples/charge_resolution/study.py --out out/charge_resolution --cases n10 n20 n40 --end 12e-6

Each run goes into OUT/<case>/ (blastfrac's outputs plus case.json and record.npz); results.json, table.md and
the figures go to OUT; --figures also copies the figures and results.json into examples/charge_resolution/.
``--cases`` with no names analyses the finished runs only.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import shutil
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent

R = 0.005                       # m: charge = borehole radius
R_MON = 2.5 * R                 # m: monitor radius (2.5 charge radii)
MON_AVG = 0.001                 # m: monitor averaging radius (the same at every level)
BOX = 2.0                       # grid box half-width in charge radii
DOMAIN = 0.24                   # m: rock square side
MESH_FAR, MESH_DIST = 0.006, 0.03
MONITOR_INTERVAL = 5e-8         # s: wall-pressure sampling
TIMES = (2e-6, 5e-6, 10e-6, 20e-6)
WINDOWS = ((5e-6, 10e-6), (10e-6, 20e-6))
LEVELS = (10, 20, 40, 80, 160)
END = 25e-6


# ----------------------------------------------------------------------------------------------- scenario
def emulsion_at_cj() -> dict:
    """The library emulsion with its lighting speed D set to the JWL set's own CJ speed (5522 m/s, not 4000)."""
    from dataclasses import asdict

    from blastfrac.explosives.library import get_explosive
    from blastfrac.materials.cj import cj_state

    P = get_explosive("emulsion")
    return {**asdict(P), "D": float(cj_state(P).D)}


def scenario(cells: int, ppc: int = 2, end: float = END, rock_h: float | None = None,
             flip: float | None = None, d_cj: bool = False, current: bool = False) -> dict:
    """The study's scenario at ``cells`` MPM cells across the charge diameter (a plain dict)."""
    h = 2 * R / cells
    mons = []
    for name, (cx, cy) in {"e": (1, 0), "n": (0, 1), "w": (-1, 0), "s": (0, -1)}.items():
        mons.append({"name": name, "position": [R_MON * cx, R_MON * cy], "radius": MON_AVG,
                     "quantities": ["sxx", "syy", "vx", "vy"]})
    d = {
        "title": f"charge resolution: {cells} cells across, {ppc} points per cell",
        "simulation": {"end_time": end, "dt_safety": 0.8, "progress": False},
        "output": {"interval": end, "snapshot_times": [end], "monitor_interval": MONITOR_INTERVAL,
                   "paraview": False, "figures": False},
        "rock": {"density": 2600.0, "youngs_modulus": 50e9, "poisson_ratio": 0.2, "tensile_strength": 10e6,
                 "cohesion": 40e6, "friction_angle": 40.0, "residual_friction_angle": 30.0,
                 "stiffness_mode": "penalty", "spring_penalty": 20.0, "bulk_viscosity_linear": 0.03,
                 "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.1, "tensile_fracture_energy": 50.0,
                 "shear_fracture_energy": 500.0, "unbreakable": True},
        "geometry": {"domain": {"type": "rectangle", "width": DOMAIN, "height": DOMAIN}, "mesh_size": MESH_FAR,
                     "mesh_size_near": rock_h or h, "refinement_distance": MESH_DIST,
                     "boreholes": [{"center": [0.0, 0.0], "radius": R}]},
        "boundaries": {s: {"type": "viscous"} for s in ("left", "right", "top", "bottom")},
        "explosive": {"name": "emulsion", "charges": [{"kind": "circle", "center": [0.0, 0.0], "radius": R}],
                      "grid": {"cell_size": h, "points_per_cell": ppc,
                               "bounds": [[-BOX * R, -BOX * R], [BOX * R, BOX * R]]}},
        "monitors": mons,
    }
    # the first series ran before 0.2's gas defaults (1 % PIC with heating, q2 = 2 on the products' own sound
    # speed): they pin what they measured, pure FLIP ("default" series, named so before 0.2) and the plain 1 % PIC
    # blend (flip99), both with q2 = 0.06. The "v02" series runs the defaults as they are.
    if not current:
        d["explosive"]["flip"] = 1.0 if flip is None else flip
        d["explosive"]["blend_heating"] = False
        d["explosive"]["q2"] = 0.06
    if d_cj:
        del d["explosive"]["name"]
        d["explosive"]["constants"] = emulsion_at_cj()
    return d


CASES: dict[str, dict] = {f"n{n}": {"cells": n, "series": "default"} for n in LEVELS}
CASES["n160"]["end"] = 10e-6                                      # early window only (~15 min)
for _n in LEVELS[:-1]:                                            # 1 % PIC in the velocity update
    CASES[f"n{_n}_flip99"] = {"cells": _n, "flip": 0.99, "series": "flip99"}
for _n in LEVELS[:-1]:                                            # lighting at the JWL's own CJ speed
    CASES[f"n{_n}_dcj"] = {"cells": _n, "d_cj": True, "series": "dcj", "end": 12e-6}
for _n in LEVELS[:-1]:                                            # the defaults of 0.2 (not pinned)
    CASES[f"n{_n}_v02"] = {"cells": _n, "current": True, "series": "v02"}
CASES["n10_ppc3"] = {"cells": 10, "ppc": 3, "series": "variant", "base": "n10"}
CASES["n20_ppc3"] = {"cells": 20, "ppc": 3, "series": "variant", "base": "n20"}
CASES["n20_rock40"] = {"cells": 20, "rock_h": 2 * R / 40, "series": "variant", "base": "n20"}   # rock of level 40
REFERENCE_CELLS = (80, 40)   # reference levels: to 10 µs, and for 10–20 µs (80 cells drifts after 10 µs, README)
SERIES_LABEL = {"default": "pure FLIP, q2 = 0.06 (the defaults before 0.2)", "flip99": "explosive.flip = 0.99",
                "v02": "the defaults of 0.2 (1 % PIC with heating, q2 = 2)",
                "dcj": "emulsion lit at its own CJ speed (D = 5522 m/s)"}


# ----------------------------------------------------------------------------------------------- one run
def run_case(name: str, out: Path, end: float | None = None) -> dict:
    """Run one case into out/name; returns its case.json record (sizes, steps, run time)."""
    from blastfrac.scenario import scenario_from_dict
    from blastfrac.simulation import Simulation

    spec = CASES[name]
    end = end or spec.get("end", END)
    sc = scenario_from_dict(scenario(spec["cells"], spec.get("ppc", 2), end, spec.get("rock_h"), spec.get("flip"),
                                     spec.get("d_cj", False), spec.get("current", False)))

    class Recorder(Simulation):
        """Records the cumulative wall impulse, the hole's area and the gas's volume at every sample."""

        def _sample(self):
            self._imp += float(self.wall_load.acc.numpy()[0]) / self.wall_load.perimeter[0]   # before the reset
            super()._sample()
            x = self.state.x.numpy()
            xa, xb = x[self._wa], x[self._wb]
            area = 0.5 * abs(float(np.sum(xa[:, 0] * xb[:, 1] - xa[:, 1] * xb[:, 0])))
            self._rec.append((self.time, self._imp, area, float(np.sum(self.gas.vol.numpy()))))

    d = out / name
    t0 = time.perf_counter()
    sim = Recorder(sc, out_dir=d)
    topo = sim.model.topology
    slots = np.array([s for s, t in zip(topo.boundary_slots, topo.boundary_slot_tags) if t == "hole0"], np.int64)
    sim._wa, sim._wb = slots, 3 * (slots // 3) + (slots % 3 + 1) % 3     # wall edges a → b
    sim._imp, sim._rec = 0.0, []
    t_setup = time.perf_counter() - t0
    summary = sim.run()
    wall = time.perf_counter() - t0
    rec = np.array(sim._rec)
    np.savez(d / "record.npz", t=rec[:, 0], impulse=rec[:, 1], area=rec[:, 2], gas_volume=rec[:, 3])
    info = {"case": name, **spec, "ppc": spec.get("ppc", 2), "h": 2 * R / spec["cells"], "end_time": end,
            "wall_s": wall, "setup_s": t_setup, "run_s": summary["wall_time_s"], "steps": summary["steps"],
            "dt": summary["time_step"], "elements": summary["counts"]["elements"], "particles": sim.gas.n,
            "grid_nodes": sim.gas.spec.node_count, "energy": summary["energy"]}
    (d / "case.json").write_text(json.dumps(info, indent=1))
    print(f"{name}: {wall:.1f} s, {info['steps']} steps, {info['elements']} elements, "
          f"{info['particles']} particles, {info['grid_nodes']} grid nodes", flush=True)
    return info


# ----------------------------------------------------------------------------------------------- analysis
def read_csv(path: Path) -> dict[str, np.ndarray]:
    """A blastfrac CSV history as {column name without unit: values}."""
    with open(path) as f:
        rows = list(csv.reader(f))
    cols = [c.split(" [")[0] for c in rows[0]]
    data = np.array([[float(v) for v in r] for r in rows[1:]])
    return {c: data[:, i] for i, c in enumerate(cols)}


def impulse_from_csv(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """(interval ends, cumulative ∫p dt) from borehole_pressure.csv alone (interval means at interval middles)."""
    w = read_csv(path)
    ends = np.empty_like(w["time"])
    prev = 0.0
    for k, m in enumerate(w["time"]):
        ends[k] = 2 * m - prev
        prev = ends[k]
    return ends, np.cumsum(w["hole0"] * np.diff(np.r_[0.0, ends]))


def analyse_case(d: Path) -> dict:
    """The study's quantities of one finished run in ``d``."""
    from blastfrac.explosives.library import get_explosive
    from blastfrac.materials.jwl import isentrope_constant, isentrope_pressure_np, jwl_pressure_np

    out = json.loads((d / "case.json").read_text())
    rec = np.load(d / "record.npz")
    t, imp, area = rec["t"], rec["impulse"], rec["area"]
    wall = read_csv(d / "borehole_pressure.csv")
    tm, pw = wall["time"], wall["hole0"]
    ends, imp_csv = impulse_from_csv(d / "borehole_pressure.csv")
    out["impulse"] = {f"{tt * 1e6:g}us": float(np.interp(tt, t, imp)) for tt in TIMES if tt <= t[-1] * (1 + 1e-9)}
    out["impulse_csv_check"] = float(np.max(np.abs(np.interp(ends, t, imp) - imp_csv)) / max(imp[-1], 1e-300))
    k = int(np.argmax(pw))
    out["peak_pa"], out["peak_time_s"] = float(pw[k]), float(tm[k])
    j = int(np.argmax(pw >= 0.5 * pw[k]))
    out["arrival_s"] = (float(tm[j - 1] + (0.5 * pw[k] - pw[j - 1]) / (pw[j] - pw[j - 1]) * (tm[j] - tm[j - 1]))
                        if j else float(tm[0]))
    mon = read_csv(d / "monitors.csv")
    srr = (mon["e:sxx"] + mon["w:sxx"] + mon["n:syy"] + mon["s:syy"]) / 4
    vr = (mon["e:vx"] - mon["w:vx"] + mon["n:vy"] - mon["s:vy"]) / 4
    out["monitor"] = {"peak_compression_pa": float(-srr.min()), "peak_compression_time_s": float(mon["time"][np.argmin(srr)]),
                      "peak_velocity_ms": float(vr.max()), "peak_velocity_time_s": float(mon["time"][np.argmax(vr)])}
    en = read_csv(d / "energy.csv")
    P = get_explosive("emulsion")
    C = isentrope_constant(P)
    A0 = math.pi * R**2
    checks = []
    for a, b in ((10e-6, 15e-6), (15e-6, 20e-6), (20e-6, 25e-6)):
        if b > t[-1] * (1 + 1e-9):
            continue
        sel = (t >= a) & (t <= b)
        V = float(np.mean(area[sel])) / A0
        E = float(np.mean(np.interp(t[sel], en["time"], en["gas_internal"]))) / A0
        checks.append({"window_us": [a * 1e6, b * 1e6],
                       "p_wall": float((np.interp(b, t, imp) - np.interp(a, t, imp)) / (b - a)), "V": V, "E_gas": E,
                       "gas_volume_over_hole": float(np.mean(rec["gas_volume"][sel] / area[sel])),
                       "p_jwl_VE": float(jwl_pressure_np(V, E, P.A, P.B, P.R1, P.R2, P.omega)),
                       "p_isentrope_E0": float(isentrope_pressure_np(V, P, C))})
    out["quasi_static"] = checks
    out["gas_volume_over_hole_end"] = float(rec["gas_volume"][-1] / area[-1])
    out["series_data"] = {"t": t.tolist(), "impulse": imp.tolist(), "area": area.tolist(), "tm": tm.tolist(),
                          "p_wall": pw.tolist(), "t_mon": mon["time"].tolist(), "srr": srr.tolist(), "vr": vr.tolist(),
                          "t_en": en["time"].tolist(), "gas_internal": en["gas_internal"].tolist(),
                          "damping": en["damping"].tolist()}
    return out


def richardson(fs: list[float]) -> dict:
    """Observed order and extrapolated value from the last three values (h halved each time); when the two
    differences do not have the same sign and shrink, no order: the finest value is the reference."""
    f1, f2, f3 = fs[-3:]
    d12, d23 = f1 - f2, f2 - f3
    if d23 != 0 and d12 / d23 > 1:
        p = math.log(d12 / d23) / math.log(2.0)
        return {"order": p, "extrapolated": f3 + d23 / (2.0**p - 1), "monotone": True}
    return {"order": None, "extrapolated": f3, "monotone": False}


def fit_order(cells, errs) -> tuple[float, float]:
    """Least-squares |err| = C·N^-p on log-log; returns (p, C)."""
    x, y = np.log(np.asarray(cells, float)), np.log(np.abs(np.asarray(errs, float)))
    p, c = np.polyfit(x, y, 1)
    return float(-p), float(math.exp(c))


QUANTITIES = {
    **{f"I({tt * 1e6:g} µs)": (lambda c, k=f"{tt * 1e6:g}us": c["impulse"].get(k)) for tt in TIMES},
    "peak p_wall": lambda c: c["peak_pa"],
    "arrival": lambda c: c["arrival_s"],
    "-σ_rr max at 2.5R": lambda c: c["monitor"]["peak_compression_pa"],
    "v_r max at 2.5R": lambda c: c["monitor"]["peak_velocity_ms"],
}


def window_error(c: dict, ref: dict, a: float, b: float) -> float | None:
    """Largest |I_c(t)/I_ref(t) − 1| over [a, b] (None when either run ends before b)."""
    s, r = c["series_data"], ref["series_data"]
    if s["t"][-1] < b * (1 - 1e-9) or r["t"][-1] < b * (1 - 1e-9):
        return None
    tt = np.linspace(a, b, 401)
    return float(np.max(np.abs(np.interp(tt, s["t"], s["impulse"]) / np.interp(tt, r["t"], r["impulse"]) - 1)))


def history_error(c: dict, ref: dict, a: float, b: float, smooth: float = 0.0) -> float | None:
    """∫|p_c − p_ref| dt / ∫|p_ref| dt over [a, b] of the wall-pressure histories (both on a 0.01 µs grid, after a
    running mean over ``smooth`` seconds when given); None when either run ends before b."""
    s, r = c["series_data"], ref["series_data"]
    if s["tm"][-1] < b - 2 * MONITOR_INTERVAL or r["tm"][-1] < b - 2 * MONITOR_INTERVAL:
        return None
    tt = np.arange(a, b, 1e-8)
    pc, pr = np.interp(tt, s["tm"], s["p_wall"]), np.interp(tt, r["tm"], r["p_wall"])
    if smooth:
        n = max(1, round(smooth / 1e-8))
        k = np.ones(n) / n
        pc, pr = np.convolve(pc, k, "same"), np.convolve(pr, k, "same")
    return float(np.sum(np.abs(pc - pr)) / np.sum(np.abs(pr)))


def analyse(out: Path) -> tuple[dict, dict]:
    cases = {d.name: analyse_case(d) for d in sorted(out.iterdir()) if (d / "record.npz").exists()}
    res: dict = {"set_up": {"R": R, "grid_box_half_width": BOX * R, "domain": DOMAIN, "monitor_radius": R_MON,
                            "monitor_interval": MONITOR_INTERVAL},
                 "cases": {k: {kk: vv for kk, vv in v.items() if kk != "series_data"} for k, v in cases.items()},
                 "series": {}}
    for series in ("default", "flip99", "dcj", "v02"):
        lv = sorted((c for c in cases.values() if c.get("series") == series), key=lambda c: c["cells"])
        if not lv:
            continue
        early = max((c for c in lv if c["cells"] <= REFERENCE_CELLS[0]), key=lambda c: c["cells"])
        lv_ref = [c for c in lv if c["cells"] <= early["cells"]]
        late = [c for c in lv if c["cells"] == REFERENCE_CELLS[1] and c["end_time"] >= 20e-6 * (1 - 1e-9)]
        sres: dict = {"levels": [c["case"] for c in lv], "reference_early": early["case"],
                      "reference_late": late[0]["case"] if late else None, "quantities": {}, "windows": {}}
        for qname, get in QUANTITIES.items():
            have = [c for c in lv_ref if get(c) is not None]
            if len(have) < 2:
                continue
            fs = [get(c) for c in have]
            ex = richardson(fs) if len(have) >= 3 else {"order": None, "extrapolated": fs[-1], "monotone": False}
            if qname == "I(20 µs)" and late and not ex["monotone"]:    # the finest late level is off (drift)
                ex["extrapolated"] = get(late[0])
            ref_name = "Richardson" if ex["monotone"] else (late[0]["case"] if qname == "I(20 µs)" and late
                                                            else have[-1]["case"])
            ex["reference"] = ref_name
            ex["values"] = {c["case"]: get(c) for c in lv if get(c) is not None}
            ex["errors"] = {c["case"]: get(c) / ex["extrapolated"] - 1 for c in lv if get(c) is not None}
            errs = [(c["cells"], ex["errors"][c["case"]]) for c in have
                    if c["case"] != ref_name and ex["errors"][c["case"]] != 0]
            ex["fitted_order"] = fit_order(*zip(*errs))[0] if len(errs) >= 2 else None
            sres["quantities"][qname] = ex
        for (a, b), ref in zip(WINDOWS, (early, late[0] if late else None)):
            key = f"{a * 1e6:g}-{b * 1e6:g} µs"
            sres["windows"][key] = {}
            for r in {ref["case"]: ref, lv[-1]["case"]: lv[-1]}.values() if ref is not None else ():
                errs = {c["case"]: window_error(c, r, a, b) for c in lv if c["cells"] < r["cells"]}
                errs = {k: v for k, v in errs.items() if v is not None}
                if errs:
                    sres["windows"][key][r["case"]] = errs
        ref = early
        sres["history"] = {"reference": ref["case"], "window_us": [0, 10],
                           "l1": {c["case"]: history_error(c, ref, 0.0, 10e-6) for c in lv if c is not ref},
                           "l1_0.5us_means": {c["case"]: history_error(c, ref, 0.0, 10e-6, 0.5e-6) for c in lv
                                              if c is not ref}}
        res["series"][series] = sres
    var = {}
    for name, c in cases.items():
        if c.get("series") == "variant" and c["base"] in cases:
            b = cases[c["base"]]
            var[name] = {"against": c["base"],
                         **{q: get(c) / get(b) - 1 for q, get in QUANTITIES.items() if get(c) is not None},
                         "max 5-10 µs": window_error(c, b, *WINDOWS[0])}
    res["variants"] = var
    return res, cases


# ----------------------------------------------------------------------------------------------- figures
def figures(res: dict, cases: dict, out: Path) -> list[Path]:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    paths = []
    sd = res["series"].get("default")
    if sd is None:
        return paths
    levels = [cases[k] for k in sd["levels"]]
    colors = dict(zip(sd["levels"], plt.cm.viridis(np.linspace(0, 0.9, len(levels)))))

    # 1. impulse vs time per level; relative errors against a finer level
    def rel(ax, c, ref, tmin, tmax, **kw):
        s, r = c["series_data"], ref["series_data"]
        t = np.array(s["t"])
        sel = (t > tmin) & (t <= min(tmax, r["t"][-1]) * (1 + 1e-9))
        ax.plot(t[sel] * 1e6, (np.array(s["impulse"])[sel] / np.interp(t[sel], r["t"], r["impulse"]) - 1) * 100, **kw)

    fig, (a1, a2, a3) = plt.subplots(1, 3, figsize=(17, 4.6))
    for c in levels:
        s = c["series_data"]
        a1.plot(np.array(s["t"]) * 1e6, np.array(s["impulse"]) * 1e-3, color=colors[c["case"]],
                label=f"{c['cells']} cells across")
    for k, ls in (("n80_flip99", "--"), ("n80_dcj", ":")):
        if k in cases:
            s = cases[k]["series_data"]
            a1.plot(np.array(s["t"]) * 1e6, np.array(s["impulse"]) * 1e-3, "k", ls=ls, lw=1, label=k)
    a1.set_xlabel("t [µs]")
    a1.set_ylabel("wall impulse I(t) = ∫p_wall dt [kPa·s]")
    a1.set_title("Wall impulse (default emulsion, pure FLIP)")
    a1.legend(fontsize=8)
    a1.grid(alpha=0.3)
    by_cells = {c["cells"]: c for c in levels}
    r80, r40 = by_cells.get(80), by_cells.get(40)
    for c in levels:
        col = colors[c["case"]]
        if r80 is not None and c["cells"] < 80:
            rel(a2, c, r80, 1.5e-6, 10e-6, color=col, lw=1.3, label=f"{c['cells']} vs 80")
        if r40 is not None and c["cells"] < 40:
            rel(a2, c, r40, 8e-6, END, color=col, lw=1.3, ls="--", label=f"{c['cells']} vs 40 (dashed)")
        if r80 is not None and c["cells"] > 80:
            rel(a2, c, r80, 1.5e-6, 10e-6, color="gray", lw=1.0, ls="-.", label=f"{c['cells']} vs 80")
    a2.set_title("Default emulsion: against 80 cells (≤ 10 µs), 40 cells (dashed)")
    dl = sorted((c for c in cases.values() if c.get("series") == "dcj"), key=lambda c: c["cells"])
    if dl:
        dref = dl[-1]
        for c in dl[:-1]:
            rel(a3, c, dref, 1.5e-6, 12e-6, color=colors.get(f"n{c['cells']}"), lw=1.3,
                label=f"{c['cells']} vs {dref['cells']}")
    a3.set_title("Emulsion lit at its CJ speed (5522 m/s): against 80 cells")
    for ax in (a2, a3):
        for y in (-2, 2):
            ax.axhline(y, color="gray", ls=":", lw=1)
        ax.set_ylim(-15, 8)
        ax.set_xlabel("t [µs]")
        ax.set_ylabel("I_N(t) / I_ref(t) − 1 [%]")
        ax.legend(fontsize=7, ncol=2, loc="lower right")
        ax.grid(alpha=0.3)
    fig.tight_layout()
    p = out / "impulse_vs_time.png"
    fig.savefig(p, dpi=120)
    plt.close(fig)
    paths.append(p)

    # 2. error vs cells across, log-log, with the fitted order
    fig, ax = plt.subplots(figsize=(7, 5))

    def plot_errs(pts, marker, label, **kw):
        pts = [(n, e) for n, e in pts if e]
        if len(pts) < 2:
            return
        n, e = map(np.array, zip(*pts))
        pf, cf = fit_order(n, e)
        line, = ax.loglog(n, e * 100, marker, ms=7, label=f"{label}: order {pf:.2f}", **kw)
        nn = np.geomspace(n.min() * 0.85, n.max() * 1.2)
        ax.loglog(nn, cf * nn**-pf * 100, color=line.get_color(), lw=0.8)

    for series, m, lab in (("default", "o", "default"), ("flip99", "s", "flip 0.99"), ("dcj", "D", "D = D_CJ")):
        sres = res["series"].get(series)
        if sres is None:
            continue
        w = sres["windows"].get("5-10 µs", {})
        r80 = next((k for k in w if cases[k]["cells"] == 80), None)
        if r80:
            plot_errs([(cases[k]["cells"], e) for k, e in w[r80].items()], m,
                      f"{lab}: max over 5–10 µs vs 80 cells")
        w = sres["windows"].get("10-20 µs", {})
        r40 = next((k for k in w if cases[k]["cells"] == 40), None)
        if r40:
            plot_errs([(cases[k]["cells"], e) for k, e in w[r40].items()], m,
                      f"{lab}: max over 10–20 µs vs 40 cells", mfc="none")
    ex = sd["quantities"].get("I(2 µs)")
    if ex and ex["monotone"]:
        plot_errs([(cases[k]["cells"], abs(e)) for k, e in ex["errors"].items()
                   if cases[k]["cells"] <= REFERENCE_CELLS[0]], "v", "default: I(2 µs) vs Richardson (20/40/80)")
    ax.axhline(2, color="gray", ls=":", label="2 %")
    ax.set_xlabel("cells across the charge diameter N = 2R/h")
    ax.set_ylabel("|relative error of the wall impulse| [%]")
    ax.set_title("Convergence of the wall impulse")
    ax.legend(fontsize=7)
    ax.grid(alpha=0.3, which="both")
    fig.tight_layout()
    p = out / "error_vs_cells.png"
    fig.savefig(p, dpi=120)
    plt.close(fig)
    paths.append(p)

    # 3. wall pressure histories, quasi-static check, monitor stress
    fig, axs = plt.subplots(1, 3, figsize=(16, 4.4))
    for c in levels:
        s = c["series_data"]
        col = colors[c["case"]]
        axs[0].plot(np.array(s["tm"]) * 1e6, np.array(s["p_wall"]) * 1e-9, color=col, lw=1, label=f"{c['cells']} cells")
        axs[1].plot(np.array(s["tm"]) * 1e6, np.array(s["p_wall"]) * 1e-9, color=col, lw=1, label=f"{c['cells']} cells")
        axs[2].plot(np.array(s["t_mon"]) * 1e6, -np.array(s["srr"]) * 1e-6, color=col, lw=1, label=f"{c['cells']} cells")
    if "n80_flip99" in cases:
        s = cases["n80_flip99"]["series_data"]
        axs[1].plot(np.array(s["tm"]) * 1e6, np.array(s["p_wall"]) * 1e-9, "k--", lw=0.8, label="80 cells, flip 0.99")
    ref_long = by_cells.get(40, levels[-1])
    for qs in ref_long["quasi_static"]:
        axs[1].plot(qs["window_us"], [qs["p_jwl_VE"] * 1e-9] * 2, "r-", lw=2.5, label=f"JWL p(V, E_gas), {ref_long['cells']} cells")
        axs[1].plot(qs["window_us"], [qs["p_isentrope_E0"] * 1e-9] * 2, "m:", lw=2.5, label="isentrope from (V = 1, E0)")
    h, lab = axs[1].get_legend_handles_labels()
    uniq = dict(zip(lab, h))
    axs[1].legend(uniq.values(), uniq.keys(), fontsize=7, loc="upper right", ncol=2)
    axs[0].set_xlim(0, 6)
    axs[0].set_title("Wall pressure (0.05 µs means), first 6 µs")
    axs[1].set_title("Wall pressure, whole run (quasi-static checks in red)")
    axs[1].set_ylim(1.0, 4.2)
    axs[2].set_title(f"Radial compression −σ_rr at r = {R_MON * 1e3:g} mm (4 monitors)")
    axs[2].set_xlim(0, 15)
    for ax in axs[:2]:
        ax.set_xlabel("t [µs]")
        ax.set_ylabel("p_wall [GPa]")
        ax.grid(alpha=0.3)
    axs[0].legend(fontsize=8)
    axs[2].set_xlabel("t [µs]")
    axs[2].set_ylabel("−σ_rr [MPa]")
    axs[2].grid(alpha=0.3)
    axs[2].legend(fontsize=8)
    fig.tight_layout()
    p = out / "wall_pressure.png"
    fig.savefig(p, dpi=120)
    plt.close(fig)
    paths.append(p)

    # 4. what goes wrong late at fine levels: gas volume drift (pure FLIP) and the energy the rock's viscosity takes
    fig, (b1, b2) = plt.subplots(1, 2, figsize=(12, 4.2))
    for series, ls in (("default", "-"), ("flip99", "--")):
        for k in res["series"].get(series, {}).get("levels", []):
            c = cases[k]
            rec = np.load(out / k / "record.npz")
            col = colors.get(f"n{c['cells']}")
            b1.plot(rec["t"] * 1e6, rec["gas_volume"] / rec["area"], color=col, ls=ls, lw=1,
                    label=f"{c['cells']} cells" + (", flip 0.99" if series == "flip99" else ""))
            s = c["series_data"]
            b2.plot(np.array(s["t_en"]) * 1e6, np.array(s["gas_internal"]) * 1e-3, color=col, ls=ls, lw=1,
                    label=f"{c['cells']} cells" + (", flip 0.99" if series == "flip99" else ""))
    b1.set_xlabel("t [µs]")
    b1.set_ylabel("Σ V_p / hole area [-]")
    b1.set_title("Gas particle volume against the hole it fills")
    b1.legend(fontsize=7, ncol=2)
    b1.grid(alpha=0.3)
    b2.set_xlabel("t [µs]")
    b2.set_ylabel("gas internal energy [kJ/m]")
    b2.set_title("Gas internal energy (released: 330 kJ/m)")
    b2.legend(fontsize=7, ncol=2)
    b2.grid(alpha=0.3)
    fig.tight_layout()
    p = out / "late_time_drift.png"
    fig.savefig(p, dpi=120)
    plt.close(fig)
    paths.append(p)
    return paths


# ----------------------------------------------------------------------------------------------- tables
def _fmt(q: str, v: float) -> str:
    if q.startswith("I("):
        return f"{v * 1e-3:.3f}"
    if q == "peak p_wall":
        return f"{v * 1e-9:.2f}"
    if q == "arrival":
        return f"{v * 1e6:.3f}"
    if q.startswith("-σ_rr"):
        return f"{v * 1e-6:.0f}"
    return f"{v:.0f}"


UNITS = {"I(2 µs)": "kPa·s", "I(5 µs)": "kPa·s", "I(10 µs)": "kPa·s", "I(20 µs)": "kPa·s", "peak p_wall": "GPa",
         "arrival": "µs", "-σ_rr max at 2.5R": "MPa", "v_r max at 2.5R": "m/s"}


def table(res: dict) -> str:
    lines = []
    for series, sres in res["series"].items():
        qs = sres["quantities"]
        lines.append(f"### {SERIES_LABEL[series]}")
        lines.append("")
        head = ["case", "cells", "h [mm]"] + [f"{q} [{UNITS[q]}]" for q in qs] + \
               [f"max err {w} vs {next(iter(v))}" for w, v in sres["windows"].items() if v] + \
               ["particles", "grid nodes", "elements", "steps", "run [s]"]
        lines.append("| " + " | ".join(head) + " |")
        lines.append("|" + "---|" * len(head))
        for k in sres["levels"]:
            c = res["cases"][k]
            row = [k, str(c["cells"]), f"{c['h'] * 1e3:.4g}"]
            for q, ex in qs.items():
                if k in ex["values"]:
                    e = ex["errors"][k]
                    row.append(_fmt(q, ex["values"][k]) + (f" ({e * 100:+.1f} %)" if k != ex["reference"] else " (ref)"))
                else:
                    row.append("–")
            for w, v in sres["windows"].items():
                if not v:
                    continue
                e = v[next(iter(v))].get(k)
                row.append(f"{e * 100:.1f} %" if e is not None else "–")
            row += [str(c["particles"]), str(c["grid_nodes"]), str(c["elements"]), str(c["steps"]), f"{c['wall_s']:.0f}"]
            lines.append("| " + " | ".join(row) + " |")
        lines.append("")
        lines.append(f"| quantity | reference | observed order (Richardson, 3 finest up to {sres['reference_early']}) "
                     "| fitted order (errors, log-log) |")
        lines.append("|---|---|---|---|")
        for q, ex in qs.items():
            ref = (f"{_fmt(q, ex['extrapolated'])} {UNITS[q]} (Richardson)" if ex["monotone"]
                   else f"{_fmt(q, ex['extrapolated'])} {UNITS[q]} ({ex['reference']}; differences not monotone)")
            lines.append(f"| {q} | {ref} | {ex['order']:.2f} |" if ex["order"] is not None else f"| {q} | {ref} | – |")
            lines[-1] += f" {ex['fitted_order']:.2f} |" if ex["fitted_order"] is not None else " – |"
        for w, v in sres["windows"].items():
            for rname, errs in v.items():
                lines.append(f"| max over {w} of abs(I_N/I_{rname} − 1) | " + ", ".join(
                    f"{res['cases'][k]['cells']}: {e * 100:.2f} %" for k, e in errs.items() if e is not None) + " | | |")
        hs = sres.get("history")
        if hs:
            lines.append(f"| wall-pressure history 0–10 µs, ∫abs(p_N − p_ref)dt / ∫p_ref dt vs {hs['reference']} | "
                         + ", ".join(f"{res['cases'][k]['cells']}: {e * 100:.1f} %" for k, e in hs["l1"].items() if e is not None)
                         + " | same after 0.5 µs running means: " + ", ".join(
                             f"{res['cases'][k]['cells']}: {e * 100:.1f} %" for k, e in hs["l1_0.5us_means"].items()
                             if e is not None) + " | |")
        lines.append("")
    if res.get("variants"):
        lines.append("### Variants (relative change against the base case)")
        lines.append("")
        qn = ["I(2 µs)", "I(5 µs)", "I(10 µs)", "I(20 µs)", "peak p_wall", "-σ_rr max at 2.5R", "max 5-10 µs"]
        lines.append("| case | against | " + " | ".join(qn) + " | run [s] |")
        lines.append("|" + "---|" * (len(qn) + 3))
        for k, v in res["variants"].items():
            lines.append(f"| {k} | {v['against']} | " + " | ".join(
                ("–" if v.get(q) is None else f"{v[q] * 100:.2f} %" if q.startswith("max") else f"{v[q] * 100:+.2f} %")
                for q in qn) +
                f" | {res['cases'][k]['wall_s']:.0f} |")
        lines.append("")
    qsd = res["cases"].get("n40", {}).get("quasi_static")
    if qsd:
        lines.append("### Quasi-static check (n40)")
        lines.append("")
        lines.append("| window | p_wall mean | V = A/πR² | E_gas/πR² | JWL p(V, E_gas) | isentrope p_isen(V) from (1, E0) | Σ V_p / A |")
        lines.append("|---|---|---|---|---|---|---|")
        for q in qsd:
            lines.append(f"| {q['window_us'][0]:g}–{q['window_us'][1]:g} µs | {q['p_wall'] * 1e-9:.3f} GPa | {q['V']:.4f} | "
                         f"{q['E_gas'] * 1e-9:.3f} GPa | {q['p_jwl_VE'] * 1e-9:.3f} GPa | {q['p_isentrope_E0'] * 1e-9:.3f} GPa | "
                         f"{q['gas_volume_over_hole']:.4f} |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--out", type=Path, default=Path("out/charge_resolution"))
    ap.add_argument("--cases", nargs="*", default=None, help=f"cases to run (default: all of {list(CASES)})")
    ap.add_argument("--end", type=float, default=None, help="end time [s] (default: 25 µs, n160 10 µs)")
    ap.add_argument("--reuse", action="store_true", help="skip finished runs (case.json present)")
    ap.add_argument("--figures", action="store_true", help="copy the figures and results.json into "
                    "examples/charge_resolution/")
    a = ap.parse_args(argv)
    a.out.mkdir(parents=True, exist_ok=True)
    for name in a.cases if a.cases is not None else list(CASES):
        if a.reuse and (a.out / name / "case.json").exists():
            continue
        run_case(name, a.out, a.end)
    res, cases = analyse(a.out)
    paths = figures(res, cases, a.out)
    (a.out / "results.json").write_text(json.dumps(res, indent=1))
    tab = table(res)
    (a.out / "table.md").write_text(tab + "\n")
    print(tab)
    if a.figures:
        for p in [*paths, a.out / "results.json"]:
            shutil.copy(p, HERE / p.name)
    return 0


if __name__ == "__main__":
    sys.exit(main())
