"""Gas in cracks: with, without, and driven by the wall-pressure history (issue 13, item 1).

For two shipped examples (circular_rock/scenario.toml and confined_blast/scenario_P0.toml) this runs

    a  crack gas off (the example as shipped)
    b  crack gas on (``[crack_gas] enabled = true``)
    c  rock only, the borehole wall loaded by the wall-pressure history that run b produced
       (its ``borehole_pressure.csv`` as a ``table`` pulse in ``[[borehole_pressure]]``)
    d  rock only, driven by run a's borehole_pressure.csv (separates "gas in cracks" from "another wall history")
    e  rock only, driven by every gas-particle load of run a on the rock (radial sum / G, gas_load.csv below)
    f  the same from run b

b against c is the paper's comparison (Yue et al. 2022, Secs. 3.1 and 4): the same wall history, with and
without the gas that enters the cracks. d against a checks that a rock-only run driven by a coupled run's
wall history reproduces that run; it does not (borehole_pressure.csv records the gas load on the nodes of the
wall edges only, and once the wall is crushed 10–60 % more acts on the other blocks at the wall vertices), so
e and f repeat c and d with every particle load, and b against f is the crack-gas effect at the best wall
history. ``--perturbed`` adds a, b, c on a second mesh of the same size (``mesh_size_near`` × 1.01:
``simulation.seed`` does not change a gmsh mesh) for the mesh-realisation scatter.

All cases share output-only changes to the shipped files: ``output.monitor_interval`` = 0.1 µs (the wall
history then resolves the ~1 µs loading; the default end/200 is 0.3–0.45 µs) and four monitors at r = 8 mm
(averaging radius 2 mm) on the axes, whose mean radial stress compares the near-wall response. Each run is
``Simulation.run`` in a child process (``--worker``, the same as ``blastfrac run``) that also writes
``gas_load.csv``: where the loads act on the rock and the work they do (worker()).

    python examples/crack_gas/study.py --out out/crack_gas --perturbed          # 18 runs, one at a time
    python examples/crack_gas/study.py --out out/crack_gas --perturbed --reuse  # analysis of finished runs

Writes into examples/crack_gas/ (``--figures``): crack_gas_patterns_<example>.png, crack_gas_wall_pressure.png,
crack_gas_lengths.png, crack_gas_growth.png and results.json (``--cases`` and ``--examples`` select).
"""

from __future__ import annotations

import argparse
import csv
import json
import os
import subprocess
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent

EXAMPLES = {
    "circular_rock": {"file": ROOT / "examples/circular_rock/scenario.toml", "zoom": 0.04, "label": "circular rock"},
    "confined_blast": {"file": ROOT / "examples/confined_blast/scenario_P0.toml", "zoom": 0.06,
                       "label": "confined blast P = 0"},
}
CASES = {
    "a": "crack gas off (shipped)",
    "b": "crack gas on",
    "c": "rock only, wall history of b",
    "d": "rock only, wall history of a",
    "e": "rock only, all particle loads of a",
    "f": "rock only, all particle loads of b",
}
#: rock-only cases: (source case, history): "csv" = its borehole_pressure.csv, "all" = every gas-particle load
#: on the rock, radial / G (gas_load.csv: wall + wall_other + beyond)
DRIVEN = {"c": ("b", "csv"), "d": ("a", "csv"), "e": ("a", "all"), "f": ("b", "all")}
STYLE = {"a": ("C0", "-"), "b": ("C3", "-"), "c": ("k", "--"), "d": ("C2", ":"), "e": ("C9", "--"),
         "f": ("C1", "--"), "a_p": ("C0", "-."), "b_p": ("C3", "-."), "c_p": ("0.4", "-.")}
MONITOR_INTERVAL = 1e-7        # s
NEAR_R = 0.008                 # m: near-wall monitors (crushed zone: r_c ≈ 9–11 mm)
NEAR_AVG = 0.002               # m: their averaging radius
TABLE_DENSE = 10e-6            # s: the wall table keeps every sample before this time
TABLE_MAX = 300                # points in the table at most


# ----------------------------------------------------------------------------------------------- scenarios
def near_monitors() -> list[dict]:
    out = []
    for name, (cx, cy) in {"w0": (1, 0), "w90": (0, 1), "w180": (-1, 0), "w270": (0, -1)}.items():
        out.append({"name": name, "position": [NEAR_R * cx, NEAR_R * cy], "quantities": ["sxx", "syy", "sxy"],
                    "radius": NEAR_AVG})
    return out


def case_dict(example: str, case: str, table: tuple[list, list] | None = None, perturbed: bool = False,
              end_time: float | None = None) -> dict:
    """The scenario of one case as a plain dict (the shipped file with the changes of the module docstring)."""
    data = tomllib.loads(EXAMPLES[example]["file"].read_text())
    data["rock"].pop("fracture_band_width", None)  # as measured (README), before the confined example's fracture band
    if end_time is not None:
        data["simulation"]["end_time"] = end_time
        data["output"]["interval"] = end_time / 2
        data["output"]["snapshot_times"] = [end_time / 2, end_time]
    data["simulation"]["progress"] = False
    data["output"]["monitor_interval"] = MONITOR_INTERVAL
    data["output"].pop("directory", None)
    if perturbed:
        data["geometry"]["mesh_size_near"] = round(data["geometry"]["mesh_size_near"] * 1.01, 9)
    mons = [m for m in data.get("monitors", []) if not m["name"].startswith("w")]
    if case == "b":
        data["crack_gas"] = {"enabled": True}
    if case in DRIVEN:
        assert table is not None
        for key in ("explosive", "coupling", "crack_gas"):
            data.pop(key, None)
        mons = [dict(m, quantities=[q for q in m.get("quantities", ["sxx"]) if q != "gas_pressure"]) for m in mons]
        mons = [m for m in mons if m["quantities"]]
        data["borehole_pressure"] = [{"borehole": 0, "pulse": {"type": "table", "times": list(table[0]),
                                                                "values": list(table[1])}}]
    data["monitors"] = mons + near_monitors()
    return data


def read_csv(path: Path) -> tuple[list[str], np.ndarray]:
    with open(path) as f:
        rows = [r for r in csv.reader(f) if r and not r[0].startswith("#")]
    return rows[0], np.array([[float(v) for v in r] for r in rows[1:]])


def load_history(run_dir: Path, kind: str = "csv") -> tuple[np.ndarray, np.ndarray]:
    """A coupled run's wall history [s], [Pa]: "csv" its borehole_pressure.csv, "all" every gas-particle load on
    the rock, radial / G (gas_load.csv → wall + wall_other + beyond, worker())."""
    if kind == "csv":
        _, a = read_csv(run_dir / "borehole_pressure.csv")
        return a[:, 0], a[:, 1]
    _, g = read_csv(run_dir / "gas_load.csv")
    return g[:, 0], g[:, 1] + g[:, 2] + g[:, 3]


def wall_table(run_dir: Path, end_time: float, kind: str = "csv") -> tuple[list, list, dict]:
    """The table pulse from a coupled run's wall history (load_history): every sample before TABLE_DENSE, then
    every k-th so that at most TABLE_MAX points remain, the peak always kept; (0, 0) first and (end, last) last."""
    t, p = load_history(run_dir, kind)
    keep = t <= TABLE_DENSE
    rest = np.flatnonzero(~keep)
    room = max(1, TABLE_MAX - 2 - int(keep.sum()))
    step = max(1, int(np.ceil(len(rest) / room)))
    keep[rest[::step]] = True
    keep[int(np.argmax(p))] = True
    keep[-1] = True
    tt, pp = list(t[keep]), list(p[keep])
    if tt[0] > 0:
        tt, pp = [0.0] + tt, [0.0] + pp
    if tt[-1] < end_time:
        tt, pp = tt + [end_time * (1 + 1e-9)], pp + [pp[-1]]
    dt_int = np.diff(np.r_[0.0, 0.5 * (t[1:] + t[:-1]), 2 * t[-1] - 0.5 * (t[-1] + t[-2])])
    info = {"source": str(run_dir / ("borehole_pressure.csv" if kind == "csv" else "gas_load.csv")),
            "history": kind, "samples": int(len(t)), "points": len(tt),
            "peak_pa": float(p.max()), "peak_time_s": float(t[int(np.argmax(p))]),
            "table_peak_pa": float(max(pp)), "min_pa": float(p.min()),
            "impulse_csv_pa_s": float(np.sum(p * dt_int)), "impulse_table_pa_s": float(np.trapezoid(pp, tt)),
            "final_pa": float(p[-1])}
    return [float(v) for v in tt], [float(v) for v in pp], info


def write_toml(data: dict, path: Path) -> None:
    import tomli_w

    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(tomli_w.dumps(data))


def run(scenario: Path, out_dir: Path, reuse: bool, nice: int) -> float:
    """Run one scenario in a child process (this script's --worker); returns the wall time [s] of the process."""
    if reuse and (out_dir / "summary.json").is_file():
        return float("nan")
    cmd = [sys.executable, str(Path(__file__).resolve()), "--worker", str(scenario), str(out_dir)]
    print("$", " ".join(cmd), flush=True)
    t0 = time.perf_counter()
    subprocess.run(cmd, check=True, preexec_fn=(lambda: os.nice(nice)) if nice else None)
    dt = time.perf_counter() - t0
    print(f"  done in {dt:.0f} s", flush=True)
    return dt


def worker(scenario: str, out_dir: str) -> int:
    """``blastfrac run`` of one scenario (the same Simulation.run), which also writes ``gas_load.csv``: where the
    loads on the rock act, as radial force / G about the hole centre (G of analysis/wall_load.py, so the first
    column is borehole_pressure.csv itself), each 0.1 µs interval, and the work each part did on the rock:

    * ``wall``: gas particles (coupled runs) or the table pulse (rock-only runs) on the nodes of the wall edges:
      what borehole_pressure.csv records;
    * ``wall_other``: gas particles on the other blocks' nodes at wall vertices (exposed when the wall is crushed);
    * ``beyond``: gas particles on nodes off the wall (crack faces, fragments);
    * ``cells``: the crack-gas cells' face loads (their radial sum is small: a crack's faces are pushed apart).

    The work columns [J/m] are Σ f·v Δt with this step's force and the velocity after the step (v^{n+1/2}).
    """
    import numpy as np
    from blastfrac.analysis.wall_load import WallLoad
    from blastfrac.scenario import load_scenario
    from blastfrac.simulation import Simulation

    sc = load_scenario(scenario)
    sc.output.directory = out_dir
    sim = Simulation(sc)
    wl = sim.wall_load if sim.wall_load is not None else WallLoad(sim.model, sc.geometry.boreholes, sim.device)
    X = sim.model.host["node_X"]
    c = np.asarray(sc.geometry.boreholes[0].center, float)
    r_b = sc.geometry.boreholes[0].radius
    d = X - c
    r = np.linalg.norm(d, axis=1)
    rhat = d / np.maximum(r, 1e-300)[:, None]
    wall = np.zeros(len(X), bool)
    wall[wl.nodes.numpy()] = True
    rhat_w = rhat.copy()
    rhat_w[wl.nodes.numpy()] = wl.rhat.numpy()          # exactly WallLoad's directions
    other = (~wall) & (r <= r_b * (1 + 1e-6))
    beyond = (~wall) & ~other
    G = float(wl.perimeter[0])
    parts = {"wall": wall, "wall_other": other, "beyond": beyond}
    acc = dict.fromkeys([*parts, "cells"], 0.0)
    work = dict.fromkeys([*parts, "cells"], 0.0)
    rows: list[list[float]] = []
    t_last = [0.0]
    next_t = [1e-7]
    cell_f = [None]
    if sim.crack_gas is not None:
        cg_apply = sim.crack_gas.apply

        def apply(state, dt):
            f0 = state.f.numpy().copy()
            cg_apply(state, dt)
            cell_f[0] = state.f.numpy() - f0

        sim.crack_gas.apply = apply
    if sim.model.loaded_edge_count:
        n0, n1 = sim.model.ledge_n0.numpy(), sim.model.ledge_n1.numpy()
    step = sim.step

    def stepped(gas: bool = True):
        dt = sim.dt
        step(gas)
        if sim.coupler is not None:
            f = sim.coupler.f_react.numpy()
        else:
            f = np.zeros_like(X)
            if sim.model.loaded_edge_count:
                fp = sim.state.ledge_fprev.numpy()
                np.add.at(f, n0, fp[0::2])
                np.add.at(f, n1, fp[1::2])
        v = sim.state.v.numpy()
        fr = np.einsum("ij,ij->i", f, rhat_w)
        fv = np.einsum("ij,ij->i", f, v)
        for k, m in parts.items():
            acc[k] += dt * float(fr[m].sum())
            work[k] += dt * float(fv[m].sum())
        if cell_f[0] is not None:
            acc["cells"] += dt * float(np.einsum("ij,ij->i", cell_f[0], rhat).sum())
            work["cells"] += dt * float(np.einsum("ij,ij->i", cell_f[0], v).sum())
            cell_f[0] = None
        if sim.time >= next_t[0] - 1e-15:
            span = sim.time - t_last[0]
            rows.append([0.5 * (t_last[0] + sim.time), *(acc[k] / span / G for k in acc), *work.values()])
            for k in acc:
                acc[k] = 0.0
            t_last[0] = sim.time
            next_t[0] += 1e-7

    sim.step = stepped
    s = sim.run(progress=False)
    head = ["time [s]"] + [f"{k} [Pa]" for k in acc] + [f"work_{k} [J/m]" for k in work]
    with open(Path(out_dir) / "gas_load.csv", "w") as fh:
        fh.write(",".join(head) + "\n")
        for row in rows:
            fh.write(",".join(f"{v:.9g}" for v in row) + "\n")
    b = s["broken_springs"]
    print(f"{s['steps']} steps, t = {s['simulated_time'] * 1e6:.2f} µs, wall {s['wall_time_s']:.1f} s; "
          f"broken springs {b['total']} (tensile {b['tensile']}, shear {b['shear']}); results in {out_dir}", flush=True)
    return 0


# ------------------------------------------------------------------------------------------------- analysis
def vtu_frames(run_dir: Path) -> list[tuple[float, Path]]:
    import re

    txt = (run_dir / "rock.pvd").read_text()
    return [(float(t), run_dir / f) for t, f in re.findall(r'timestep="([^"]+)" file="([^"]+)"', txt)]


def read_frame(path: Path) -> dict:
    import meshio

    m = meshio.read(path)
    x = m.points[:, :2]
    X = x - m.point_data["displacement"][:, :2]
    out = {"x": x, "X": X, "tri": None, "seg": np.zeros((0, 2), int), "mode": np.zeros(0, int), "pgas": None}
    for k, blk in enumerate(m.cells):
        if blk.type == "triangle":
            out["tri"] = blk.data
        elif blk.type == "line":
            out["seg"] = blk.data
            out["mode"] = np.asarray(m.cell_data["crack_mode"][k])
            if "crack_gas_pressure" in m.cell_data:
                out["pgas"] = np.asarray(m.cell_data["crack_gas_pressure"][k])
    return out


def load_match(src: Path, run_dir: Path, end: float, kind: str = "csv") -> dict:
    """Wall load of a rock-only run (gas_load.csv → wall: its table pulse on the deformed wall edges, radial, / G)
    against the coupled run's borehole_pressure.csv that made the table: impulse ratio, peak ratio, and the rms
    difference / rms over the whole run and the first 10 µs."""
    ts, ps = load_history(src, kind)
    _, g = read_csv(run_dir / "gas_load.csv")
    n = min(len(ts), len(g))
    t, p_src, p_run = ts[:n], ps[:n], g[:n, 1]
    out = {"history": kind, "time_offset_max_s": float(np.abs(t - g[:n, 0]).max())}
    for name, sel in (("all", t <= end), ("0-10us", t <= 10e-6)):
        out[name] = {"impulse_ratio": float(np.sum(p_run[sel]) / np.sum(p_src[sel])),
                     "peak_ratio": float(p_run[sel].max() / p_src[sel].max()),
                     "rms_difference_over_rms": float(np.sqrt(np.mean((p_run[sel] - p_src[sel]) ** 2))
                                                      / np.sqrt(np.mean(p_src[sel] ** 2)))}
    return out


def load_split(run_dir: Path) -> dict:
    """Where the gas of a coupled run pushes the rock (gas_load.csv, worker()): the radial load of each part / G
    as a fraction of the wall load that borehole_pressure.csv records, averaged over time windows, and the work
    each part did on the rock [J/m], with the csv's own column checked against gas_load.csv → wall."""
    _, g = read_csv(run_dir / "gas_load.csv")
    head, _ = read_csv(run_dir / "gas_load.csv")
    col = {h.split(" [")[0]: k for k, h in enumerate(head)}
    _, a = read_csv(run_dir / "borehole_pressure.csv")
    n = min(len(a), len(g))
    t = g[:, 0]
    out = {"csv_vs_gas_load_wall_max_rel_diff": float(np.max(np.abs(a[:n, 1] - g[:n, 1]))
                                                      / max(np.abs(a[:n, 1]).max(), 1e-30))}
    wins = {}
    for lo, hi in ((0, 2e-6), (2e-6, 5e-6), (5e-6, 10e-6), (10e-6, 30e-6), (30e-6, 1.0)):
        sel = (t >= lo) & (t < hi)
        if not sel.any():
            continue
        w = g[sel, col["wall"]].sum()
        wins[f"{lo * 1e6:.0f}-{min(hi, t[-1]) * 1e6:.0f}us"] = {
            "wall_MPa_mean": float(g[sel, col["wall"]].mean() / 1e6),
            **{f"{k}_over_wall": float(g[sel, col[k]].sum() / w) for k in ("wall_other", "beyond", "cells")}}
    out["radial_load"] = wins
    out["work_J_per_m"] = {k: float(g[-1, col[f"work_{k}"]]) for k in ("wall", "wall_other", "beyond", "cells")}
    return out


def gas_reach(fr: dict, center: np.ndarray) -> dict:
    """Where the crack gas is (p ≥ 1 MPa), from a frame's crack lines: cracked length [m] and the radii (about
    the hole centre, reference midpoints) within which 50 / 90 / 100 % of that length lies."""
    if fr["pgas"] is None or len(fr["seg"]) == 0:
        return {}
    s = fr["seg"][fr["pgas"] >= 1e6]
    if len(s) == 0:
        return {"pressurised_length": 0.0, "r50": 0.0, "r90": 0.0, "rmax": 0.0}
    X = fr["X"]
    mid = 0.5 * (X[s[:, 0]] + X[s[:, 1]])
    L = np.linalg.norm(X[s[:, 0]] - X[s[:, 1]], axis=1)
    r = np.linalg.norm(mid - center, axis=1)
    o = np.argsort(r)
    cum = np.cumsum(L[o]) / L.sum()
    return {"pressurised_length": float(L.sum()), "r50": float(r[o][np.searchsorted(cum, 0.5)]),
            "r90": float(r[o][np.searchsorted(cum, 0.9)]), "rmax": float(r.max())}


_MODELS: dict[str, object] = {}


def rebuilt_model(run_dir: Path):
    """The scenario and rock model of a finished run, rebuilt from its resolved.toml (the same gmsh mesh); one
    model per geometry and rock section, shared by the cases that use the same mesh."""
    from blastfrac.model.builder import ModelBuilder
    from blastfrac.scenario import load_scenario

    sc = load_scenario(run_dir / "resolved.toml")
    key = json.dumps([sc.geometry.model_dump(mode="json"), sc.rock.model_dump(mode="json")], sort_keys=True)
    if key not in _MODELS:
        _MODELS[key] = ModelBuilder(sc).finalize("cpu")
    return sc, _MODELS[key]


def crack_history(run_dir: Path) -> list[dict]:
    """Crack statistics (analysis.cracks.crack_statistics, as in summary.json) at every ParaView frame of a run:
    the model is rebuilt from the run's resolved.toml (the same gmsh mesh) and each frame's crack lines, which are
    the broken interfaces' e1-side node pairs (io.paraview.crack_segments), are mapped back to interfaces."""
    from blastfrac.analysis.cracks import crack_statistics

    sc, model = rebuilt_model(run_dir)
    pn = model.topology.pair_nodes
    index = {(int(pn[2 * i, 0]), int(pn[2 * i + 1, 0])): i for i in range(len(pn) // 2)}
    c = np.asarray(sc.geometry.boreholes[0].center, float)
    r_b = sc.geometry.boreholes[0].radius
    out = []
    for t, f in vtu_frames(run_dir):
        fr = read_frame(f)
        mode = np.zeros((len(pn) // 2, 2), np.int32)
        for (n0, n1), m in zip(fr["seg"], fr["mode"]):
            mode[index[(int(n0), int(n1))]] = m
        st = crack_statistics(model, mode.ravel(), c, r_b)
        out.append({"t_us": round(t * 1e6, 3), "radial_crack_count": st["radial_crack_count"],
                    "mean_radial_crack_length_mm": 1e3 * st["mean_radial_crack_length"],
                    "longest_radial_crack_mm": 1e3 * st["longest_radial_crack"],
                    "radial_crack_lengths_mm": [round(1e3 * v, 2) for v in st["radial_crack_lengths"]],
                    "connected_crack_length_m": st["connected_crack_length"],
                    "crack_length_total_m": st.get("crack_length_total", 0.0),
                    "crack_extent_r50_mm": 1e3 * st.get("crack_extent_r50", 0.0),
                    "crack_extent_r90_mm": 1e3 * st.get("crack_extent_r90", 0.0),
                    "cracked_interfaces": st["cracked_interfaces"]})
    return out


ANNULI_MM = (5, 10, 20, 40, 80, 160, 400)


def annulus_lengths(run_dir: Path) -> dict:
    """Cracked length [m] of the final frame (reference midpoints about the hole centre) in the annuli ANNULI_MM,
    all cracks (tensile and shear)."""
    fr = read_frame(vtu_frames(run_dir)[-1][1])
    X, s = fr["X"], fr["seg"]
    r = 1e3 * np.linalg.norm(0.5 * (X[s[:, 0]] + X[s[:, 1]]), axis=1)
    L = np.linalg.norm(X[s[:, 0]] - X[s[:, 1]], axis=1)
    out = {}
    for lo, hi in zip(ANNULI_MM[:-1], ANNULI_MM[1:]):
        sel = (r >= lo) & (r < hi)
        out[f"{lo}-{hi}mm"] = float(L[sel].sum())
    return out


def gas_topology(run_dir: Path) -> dict:
    """Where the crack gas of a run's frames sits against the crack network (analysis.cracks.connected_network on
    the rebuilt model): cells holding gas (p > 0) and pressurised (p ≥ 1 MPa), and how many of them are not in the
    network joined to the hole (gas where none can flow) or on an interface that is not cracked."""
    from blastfrac.analysis.cracks import connected_network

    sc, model = rebuilt_model(run_dir)
    pn = model.topology.pair_nodes
    index = {(int(pn[2 * i, 0]), int(pn[2 * i + 1, 0])): i for i in range(len(pn) // 2)}
    c = np.asarray(sc.geometry.boreholes[0].center, float)
    r_b = sc.geometry.boreholes[0].radius
    out = []
    for t, f in vtu_frames(run_dir)[1:]:
        fr = read_frame(f)
        if fr["pgas"] is None:
            return {}
        ids = np.array([index[(int(a), int(b))] for a, b in fr["seg"]], int)
        cracked = np.zeros(len(pn) // 2, bool)
        cracked[ids] = True
        conn = connected_network(model, cracked, c, r_b)["connected"][ids]
        gas, loaded = fr["pgas"] > 0, fr["pgas"] >= 1e6
        out.append({"t_us": round(t * 1e6, 3), "cells_with_pressure": int(gas.sum()),
                    "pressurised": int(loaded.sum()), "with_pressure_detached": int((gas & ~conn).sum()),
                    "pressurised_detached": int((loaded & ~conn).sum()),
                    "max_pressure_MPa": float(fr["pgas"].max() / 1e6) if len(gas) else 0.0})
    return out


def near_radial_stress(run_dir: Path) -> tuple[np.ndarray, np.ndarray]:
    """Mean radial stress of the four near-wall monitors [Pa] (tension +) against time."""
    head, a = read_csv(run_dir / "monitors.csv")
    col = {h.split(" [")[0]: k for k, h in enumerate(head)}
    srr = (a[:, col["w0:sxx"]] + a[:, col["w180:sxx"]] + a[:, col["w90:syy"]] + a[:, col["w270:syy"]]) / 4
    return a[:, 0], srr


def case_metrics(run_dir: Path, wall_s: float) -> dict:
    from blastfrac.analysis.cracks import zone_radii

    s = json.loads((run_dir / "summary.json").read_text())
    c = s["cracks"][0]
    z = zone_radii(c)
    e = s["energy"]
    m = {
        "radial_crack_count": c["radial_crack_count"],
        "radial_crack_count_radius_mm": 1e3 * c["radial_crack_count_radius"],
        "mean_radial_crack_length_mm": 1e3 * c["mean_radial_crack_length"],
        "longest_radial_crack_mm": 1e3 * c["longest_radial_crack"],
        "radial_crack_lengths_mm": [round(1e3 * v, 2) for v in c["radial_crack_lengths"]],
        "crack_extent_r50_mm": 1e3 * c["crack_extent_r50"], "crack_extent_r80_mm": 1e3 * c["crack_extent_r80"],
        "crack_extent_r90_mm": 1e3 * c["crack_extent_r90"],
        "crack_length_total_m": c["crack_length_total"],
        "connected_crack_length_m": c["connected_crack_length"],
        "detached_crack_sets": c["detached_crack_sets"], "detached_crack_length_m": c["detached_crack_length"],
        "crushed_zone_radius_over_rb": z["crushed_zone_radius_over_rb"],
        # the tips' radii from the hole centre, R_k = length + r_k (the lengths start at the dense-cracking radius
        # r_k, which differs between cases; docs/results.md)
        "longest_tip_radius_mm": 1e3 * (c["longest_radial_crack"] + z["dense_cracking_radius"]),
        "mean_tip_radius_mm": 1e3 * (c["mean_radial_crack_length"] + z["dense_cracking_radius"])
        if c["radial_crack_lengths"] else 0.0,
        "dense_cracking_radius_mm": 1e3 * z["dense_cracking_radius"],
        "D": s["fracture_degree"]["D"], "D_tensile": s["fracture_degree"]["D_tensile"],
        "D_shear": s["fracture_degree"]["D_shear"],
        "budget_error_relative": e["budget_error_relative"],
        "wall_time_s": s["wall_time_s"], "process_time_s": None if np.isnan(wall_s) else wall_s,
        "steps": s["steps"], "time_step_s": s["time_step"], "elements": s["counts"]["elements"],
        "status": s.get("status"), "warnings": s.get("warnings", []),
        "crossings": {"radius_mm": [round(1e3 * r, 3) for r in c["crossings"]["radius"]],
                      "count": c["crossings"]["count"], "count_all": c["crossings"]["count_all"]},
    }
    if "explosive_released" in e:
        from blastfrac.explosives.library import get_explosive

        ex = get_explosive("emulsion")
        m["explosive_released_J_per_m"] = e["explosive_released"]
        m["gas_mass_kg_per_m"] = ex.rho0 * e["explosive_released"] / ex.E0      # fully burnt: Σ V0 = released / E0
        m["contact_energy_fraction"] = e["contact_energy"] / e["explosive_released"]
    if "crack_gas" in s:
        cg = s["crack_gas"]
        m["crack_gas"] = cg
        m["crack_gas_mass_fraction"] = cg["mass"] / m["gas_mass_kg_per_m"]
        m["crack_gas_energy_fraction"] = cg["internal_energy"] / e["explosive_released"]
        head, a = read_csv(run_dir / "energy.csv")
        col = {h.split(" [")[0]: k for k, h in enumerate(head)}
        rel = a[:, col["crack_gas"]] / np.maximum(a[:, col["explosive_released"]], 1e-30)
        k = int(np.argmax(rel))
        m["crack_gas_energy_fraction_max"] = float(rel[k])
        m["crack_gas_energy_fraction_max_time_us"] = float(1e6 * a[k, 0])
    if (run_dir / "borehole_pressure.csv").is_file():
        head, a = read_csv(run_dir / "borehole_pressure.csv")
        m["wall_pressure_peak_MPa"] = float(a[:, 1].max() / 1e6)
        m["wall_pressure_final_MPa"] = float(a[-1, 1] / 1e6)
        m["wall_impulse_kPa_s"] = float(np.trapezoid(a[:, 1], a[:, 0]) / 1e3)
    return m


# -------------------------------------------------------------------------------------------------- figures


def main(argv: list[str] | None = None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if argv[:1] == ["--worker"]:
        return worker(argv[1], argv[2])
    from study_figures import fig_growth, fig_lengths, fig_patterns, fig_wall
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default="out/crack_gas", help="run directory (one sub-folder per example and case)")
    ap.add_argument("--examples", nargs="+", default=list(EXAMPLES), choices=list(EXAMPLES))
    ap.add_argument("--cases", nargs="+", default=list(CASES), choices=list(CASES))
    ap.add_argument("--perturbed", action="store_true", help="also a, b, c on a second mesh (mesh_size_near × 1.01)")
    ap.add_argument("--reuse", action="store_true", help="skip runs whose summary.json exists")
    ap.add_argument("--nice", type=int, default=5, help="niceness of the runs (shared machine)")
    ap.add_argument("--figures", default=str(HERE), help="where the figures and results.json go")
    ap.add_argument("--end-time", type=float, default=None, help="override simulation.end_time (smoke tests)")
    args = ap.parse_args(argv)
    out = Path(args.out)
    figdir = Path(args.figures)
    figdir.mkdir(parents=True, exist_ok=True)
    import blastfrac

    src = Path(blastfrac.__file__).resolve().parents[1]
    commit, dirty = None, None
    if (src.parent / "COMMIT").is_file():                 # a `git archive` snapshot with its commit noted
        commit, dirty = (src.parent / "COMMIT").read_text().strip(), False
    elif src == ROOT / "src":
        git = ["git", "-C", str(ROOT)]
        commit = subprocess.run(git + ["rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
        dirty = bool(subprocess.run(git + ["status", "--porcelain", "src"], capture_output=True, text=True).stdout)
    results: dict = {"_meta": {"blastfrac_source": str(src), "commit": commit, "source_modified": dirty,
                               "monitor_interval_s": MONITOR_INTERVAL, "near_monitor_r_m": NEAR_R,
                               "date": time.strftime("%Y-%m-%d %H:%M:%S")}}
    all_runs: dict[str, dict[str, Path]] = {}
    for ex in args.examples:
        end = args.end_time or tomllib.loads(EXAMPLES[ex]["file"].read_text())["simulation"]["end_time"]
        runs: dict[str, Path] = {}
        wall: dict[str, float] = {}
        tables: dict[str, dict] = {}
        todo = [(k, False) for k in CASES if k in args.cases]
        if args.perturbed:
            todo += [(k, True) for k in ("a", "b", "c")]
        for k, pert in todo:
            name = k + ("_p" if pert else "")
            d = out / ex / name
            table = None
            if k in DRIVEN:
                src = runs.get(DRIVEN[k][0] + ("_p" if pert else ""))
                if src is None:
                    continue
                tt, pp, info = wall_table(src, end, DRIVEN[k][1])
                table = (tt, pp)
                tables[name] = {"times": tt, "values": pp, **info}
            sc = d.parent / f"{name}.toml"
            write_toml(case_dict(ex, k, table, pert, args.end_time), sc)
            wall[name] = run(sc, d, args.reuse, args.nice)
            runs[name] = d
        all_runs[ex] = runs
        res = {"cases": {k: case_metrics(d, wall[k]) for k, d in runs.items()}, "tables": tables}
        center = np.zeros(2)
        # wall-load check: the load the table pulse of c / d put on the wall, measured as borehole_pressure.csv
        # measures a coupled run's (gas_load.csv → wall), against the coupled run's csv it came from
        check = {}
        for k in runs:
            if k[0] in DRIVEN:
                src, kind = DRIVEN[k[0]]
                src += k[1:]
                if src in runs:
                    check[f"applied_{k}_vs_{kind}_{src}"] = load_match(runs[src], runs[k], end, kind)
        for k in ("a", "b", "a_p", "b_p"):
            if k in runs:
                check[f"gas_load_{k}"] = load_split(runs[k])
        for pair in (("b", "c"), ("a", "d"), ("a", "e"), ("b", "f"), ("b_p", "c_p")):
            if all(p in runs for p in pair):
                t1, s1 = near_radial_stress(runs[pair[0]])
                t2, s2 = near_radial_stress(runs[pair[1]])
                n = min(len(t1), len(t2))
                win = {}
                for lo, hi in ((0, 5e-6), (0, 10e-6), (0, end)):
                    sel = (t1[:n] >= lo) & (t1[:n] <= hi)
                    win[f"0-{hi * 1e6:.0f}us"] = {
                        "peak_compression_MPa": [float(-s1[:n][sel].min() / 1e6), float(-s2[:n][sel].min() / 1e6)],
                        "mean_compression_MPa": [float(-s1[:n][sel].mean() / 1e6), float(-s2[:n][sel].mean() / 1e6)],
                        "rms_difference_over_rms": float(np.sqrt(np.mean((s1[:n][sel] - s2[:n][sel]) ** 2))
                                                         / np.sqrt(np.mean(s1[:n][sel] ** 2)))}
                check[f"near_wall_{pair[0]}_vs_{pair[1]}"] = win
        res["wall_load_check"] = check
        res["crack_history"] = {k: crack_history(d) for k, d in runs.items()}
        for k, d in runs.items():
            res["cases"][k]["cracked_length_by_annulus_m"] = annulus_lengths(d)
        res["gas_topology"] = {k: gas_topology(d) for k in ("b", "b_p") if (d := runs.get(k)) is not None}
        res["gas_reach"] = {k: [{"t_us": round(t * 1e6, 3), **gas_reach(read_frame(f), center)}
                                for t, f in vtu_frames(runs[k])] for k in ("b", "b_p") if k in runs}
        results[ex] = res
        fig_patterns(ex, {k: v for k, v in runs.items() if k in CASES}, res["cases"],
                     figdir / f"crack_gas_patterns_{ex}.png")
    fig_wall({k: v for k, v in results.items() if k != "_meta"}, all_runs, figdir / "crack_gas_wall_pressure.png")
    fig_lengths({k: v for k, v in results.items() if k != "_meta"}, figdir / "crack_gas_lengths.png")
    fig_growth({k: v for k, v in results.items() if k != "_meta"}, figdir / "crack_gas_growth.png")
    (figdir / "results.json").write_text(json.dumps(results, indent=1))
    print(table_md(results))
    return 0


def table_md(results: dict) -> str:
    rows = ["| example | case | radial cracks | mean / longest [mm] | r50 / r80 / r90 [mm] | connected [m] | D |"
            " crack gas: mass / energy [% of released] | budget error | wall [s] |", "|" + "---|" * 10]
    for ex, res in results.items():
        if ex == "_meta":
            continue
        for k, m in res["cases"].items():
            cg = (f"{100 * m['crack_gas_mass_fraction']:.1f} / {100 * m['crack_gas_energy_fraction']:.1f}"
                  if "crack_gas_mass_fraction" in m else "–")
            rows.append(f"| {ex} | {k} | {m['radial_crack_count']} | {m['mean_radial_crack_length_mm']:.0f} / "
                        f"{m['longest_radial_crack_mm']:.0f} | {m['crack_extent_r50_mm']:.0f} / "
                        f"{m['crack_extent_r80_mm']:.0f} / {m['crack_extent_r90_mm']:.0f} | "
                        f"{m['connected_crack_length_m']:.2f} | {m['D']:.3f} | {cg} | "
                        f"{100 * m['budget_error_relative']:+.2f} % | {m['wall_time_s']:.0f} |")
    return "\n".join(rows)


if __name__ == "__main__":
    sys.exit(main())
