"""Checkpoint and restart: the full state of a run in one file, written atomically.

``checkpoint.npz`` in the output directory holds every time-varying array and scalar of the run: the rock
state, the solver's scratch that carries over between steps (block-contact and particle–edge contact
histories, penalty overlaps, the wake windows), the gas particles and grid, the crack gas, the wall-load
impulse, the clock, the accumulators, the histories written so far, the ParaView frame list and the
snapshots. They are found by walking the attributes of the run's stage objects (:data:`STAGES`), so that
a new scratch array of a stage is saved without touching this module: every ``wp.array``, NumPy array,
number, string and bool, also inside lists, tuples and Warp structs. Static data (model, mesh, scenario)
is rebuilt from ``resolved.toml`` by the same deterministic builder. Hash grids are rebuilt from the
saved sample points, which gives the same hash and the same step (tests/verification/test_restart.py
checks that a stopped and restarted run is bit-identical to one that ran through).

The file also records the blastfrac version and a hash of the resolved scenario, and a restart refuses a
checkpoint made from another scenario.
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path

import numpy as np
import warp as wp

from .atomic import write_atomic

FORMAT = 1
#: the run's objects whose attributes make its time-varying state, by their path from the Simulation
STAGES = ("", "state", "cdem", "cdem.contact", "coupler", "gas", "gas.grid", "crack_gas", "wall_load", "ppv")
#: attributes never saved: static data rebuilt from the scenario, handles, or the objects walked separately
SKIP = {"model", "mesh", "scenario", "topology", "builder", "config", "material", "opts", "spec", "device",
        "mpm", "monitors", "fracture", "params", "cells", "static_pairs", "static_ends", "static_dx",
        "cand_cell", "cand_end", "host_length", "out_dir", "max_steps", "contact", "snapshots", "warnings",
        "insitu_report", "gas_report", "_pool", "_fragmentation_at", "_vibration_at", "_graph", "_clock_host",
        "_rock_after", "ppv_out", "s_mesh", "s_hash", "s_cache", "s_hist", "s_marks", "s_prm", "s_rec", "_second",
        "_parallel", "rec_nodes", "rec_force", "rec_xi", "rec_energy",
        "_spring_model", "_spring_states", "_spring_scalars", "geo",
        "_prm_values", "use_graph", "coupled_graph", "graphs"}
#: the stage objects hanging from the Simulation (walked as stages, not as its attributes)
ROOT_STAGES = {"state", "cdem", "coupler", "gas", "crack_gas", "wall_load", "ppv"}


def scenario_hash(text: str) -> str:
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _resolve(sim, path: str):
    obj = sim
    for part in filter(None, path.split(".")):
        obj = getattr(obj, part, None)
        if obj is None:
            return None
    return obj


def _is_struct(v) -> bool:
    return hasattr(v, "_cls") and hasattr(v._cls, "vars")


def _walk(value, key: str, arrays: dict, scalars: dict, depth: int = 0) -> None:
    if isinstance(value, wp.array):
        arrays[key] = value.numpy().copy()
    elif isinstance(value, np.ndarray):
        arrays[key] = value.copy()
    elif isinstance(value, (bool, int, float, str, np.integer, np.floating)) or value is None:
        scalars[key] = value.item() if isinstance(value, (np.integer, np.floating)) else value
    elif depth < 3 and isinstance(value, (list, tuple)) and all(
            isinstance(v, (wp.array, np.ndarray, list, tuple)) for v in value):
        scalars[key + "#len"] = len(value)
        for i, v in enumerate(value):
            _walk(v, f"{key}[{i}]", arrays, scalars, depth + 1)
    elif depth < 3 and _is_struct(value):
        for f in value._cls.vars:
            _walk(getattr(value, f), f"{key}.{f}", arrays, scalars, depth + 1)


def collect(sim) -> tuple[dict, dict]:
    """(arrays, scalars) of the run's time-varying state, keyed ``stage:attr[.field][index]``."""
    arrays: dict = {}
    scalars: dict = {}
    for stage in STAGES:
        obj = _resolve(sim, stage)
        if obj is None:
            continue
        items = vars(obj).items() if not _is_struct(obj) else ((f, getattr(obj, f)) for f in obj._cls.vars)
        for name, value in items:
            if name in SKIP or (stage == "" and name in ROOT_STAGES) or callable(value) and not isinstance(value, wp.array):
                continue
            _walk(value, f"{stage}:{name}", arrays, scalars)
    return arrays, scalars


def write(path: Path, sim, run_state: dict, scenario_text: str, version: str, extra: dict | None = None) -> None:
    """Write ``path`` atomically: the stages' state, ``run_state`` (JSON-able: histories, counters) and
    ``extra`` arrays (kept under their own keys)."""
    arrays, scalars = collect(sim)
    arrays.update(extra or {})
    meta = {"format": FORMAT, "version": version, "scenario_hash": scenario_hash(scenario_text),
            "time": sim.time, "steps": sim.steps, "scalars": scalars, "run": run_state}
    payload = {f"a/{k}": v for k, v in arrays.items()}
    payload["meta"] = np.frombuffer(json.dumps(meta).encode(), dtype=np.uint8)

    def save(tmp: Path) -> None:
        with open(tmp, "wb") as fh:
            np.savez(fh, **payload)

    write_atomic(Path(path), save)


def read(path: Path) -> tuple[dict, dict]:
    """(arrays, meta) of a checkpoint file."""
    with np.load(Path(path), allow_pickle=False) as z:
        meta = json.loads(bytes(z["meta"]).decode())
        arrays = {k[2:]: z[k] for k in z.files if k.startswith("a/")}
    return arrays, meta


def _target(sim, key: str):
    """(container, attribute or index) of a saved key, or None when the run has no such place."""
    stage, rest = key.split(":", 1)
    obj = _resolve(sim, stage)
    if obj is None:
        return None
    parts = rest.replace("]", "").replace("[", ".").split(".")
    for p in parts[:-1]:
        obj = obj[int(p)] if p.isdigit() else getattr(obj, p, None)
        if obj is None:
            return None
    if not parts[-1].isdigit() and not hasattr(obj, parts[-1]):
        return None                               # an attribute this version does not have (renamed or removed)
    return obj, parts[-1]


def restore(sim, arrays: dict, scalars: dict) -> None:
    """Copy a checkpoint into a freshly built run of the same scenario (arrays in place, so that structs and
    launch arguments that share them see the restored values), then rebuild the hash grids."""
    for key, val in scalars.items():
        if key.endswith("#len"):
            continue
        t = _target(sim, key)
        if t is not None:
            setattr(t[0], t[1], val)
    for key, val in arrays.items():
        t = _target(sim, key)
        if t is None:
            raise ValueError(f"checkpoint: the run has no place for '{key}' (a checkpoint of another version?)")
        obj, name = t
        cur = obj[int(name)] if name.isdigit() else getattr(obj, name)
        if isinstance(cur, wp.array):
            if tuple(cur.shape) != tuple(val.shape[: len(cur.shape)]) or cur.size * _width(cur) != val.size:
                raise ValueError(f"checkpoint: '{key}' has shape {val.shape}, the run {cur.shape}")
            cur.assign(val)
        elif name.isdigit():
            obj[int(name)] = val
        else:
            setattr(obj, name, val)
    _rebuild_hashes(sim)


def _width(a: wp.array) -> int:
    n = 1
    for d in getattr(a.dtype, "_shape_", ()) or ():
        n *= d
    return n


def _rebuild_hashes(sim) -> None:
    c = getattr(getattr(sim, "cdem", None), "contact", None)
    if c is not None and getattr(c, "_built", False) and getattr(c, "_grid_kind", -1) == 0:
        c.grid.build(c.points, c.radius)                  # wp.HashGrid (fan_cache off); the cell grid is saved
    cp = getattr(sim, "coupler", None)
    if cp is not None and cp._since < cp.rebuild_interval:
        cp._count_stale = True                            # captured steps may have changed the counts
        cp._read_count()
        cp.build_hash()
