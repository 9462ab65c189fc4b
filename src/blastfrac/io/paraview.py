"""ParaView time series of the rock: one VTU per frame (via meshio) and a PVD index.

Each frame holds the deformed blocks (triangles, with displacement and velocity at nodes and
the stress tensor per element) and the cracks as line cells on the broken interfaces, with
``crack_mode`` 1 = tensile, 2 = shear (mode of the first spring of the edge that broke).

Both cell fields exist on both cell blocks, so that no reader sees a hole or a NaN: ``crack_mode``
is 0 on the triangles, ``stress`` is 0 on the crack lines (a crack carries no stress tensor; select
the blocks with ``crack_mode == 0``). The stress is the full 3×3 plane-strain tensor [Pa], tension
positive, with σ_zz = ν(σ_xx + σ_yy), ν = λ/(2(λ + μ)) the Poisson ratio of the blocks (ε_zz = 0).
Point field ``ppv``: the peak particle velocity of each node so far [m/s]. With gas in cracks, the crack lines also carry ``crack_gas_pressure`` [Pa] and ``crack_opening`` [m] (0 on the
triangles and on cracks with one spring broken). Every file is written atomically (io/atomic.py): a killed run leaves whole frames only.
In a model with pre-existing joints (geometry.joints) the cells also carry ``joint``: on a crack line on a joint
the joint set's index + 1 (an open joint is a crack line from the first frame), 0 on blast cracks and triangles.
"""

from __future__ import annotations

from pathlib import Path
from xml.sax.saxutils import quoteattr

import meshio
import numpy as np

from .atomic import write_atomic, write_text_atomic


def block_poisson_ratio(model) -> float:
    """ν of the blocks, λ/(2(λ + μ)) from their Lamé constants (model.lam, model.mu)."""
    return float(model.lam) / (2.0 * (float(model.lam) + float(model.mu)))


def stress_tensor(sig: np.ndarray, nu: float) -> np.ndarray:
    """[E, 9] row-major 3×3 plane-strain tensors from (σxx, σyy, σxy) rows; σzz = ν(σxx + σyy)."""
    stress = np.zeros((len(sig), 9))
    stress[:, 0], stress[:, 4], stress[:, 1], stress[:, 3] = sig[:, 0], sig[:, 1], sig[:, 2], sig[:, 2]
    stress[:, 8] = nu * (sig[:, 0] + sig[:, 1])
    return stress


def _write_mesh(path: Path, mesh: meshio.Mesh) -> None:
    write_atomic(path, lambda tmp: meshio.write(tmp, mesh, file_format="vtu", binary=True))


def crack_segments(model, mode: np.ndarray, tbreak: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Broken interfaces as node index pairs on the e1 side, and their mode, shapes [K, 2], [K]."""
    pm = mode.reshape(-1, 2)
    tb = tbreak.reshape(-1, 2)
    broken = np.flatnonzero((pm > 0).any(axis=1))
    first = np.where((pm[broken, 0] > 0) & ((pm[broken, 1] == 0) | (tb[broken, 0] <= tb[broken, 1])), 0, 1)
    crack_mode = pm[broken, first]
    pn = model.topology.pair_nodes
    seg = np.stack([pn[2 * broken, 0], pn[2 * broken + 1, 0]], 1)
    return seg, crack_mode


def joint_segments(model) -> np.ndarray:
    """Every interface on a pre-existing joint, broken or not, as node index pairs on the e1 side (the same
    convention as :func:`crack_segments`), shape [J, 2]; empty without joints."""
    jq = model.host.get("iface_joint")
    if jq is None:
        return np.zeros((0, 2), np.int64)
    q = np.flatnonzero(jq >= 0)
    pn = model.topology.pair_nodes
    return np.stack([pn[2 * q, 0], pn[2 * q + 1, 0]], 1)


def crack_joint_field(model, mode: np.ndarray) -> np.ndarray | None:
    """The ``joint`` value of each crack line of :func:`crack_segments` (set index + 1, 0 off joints), or None
    for a model without joints."""
    jq = model.host.get("iface_joint")
    if jq is None or not np.any(jq >= 0):
        return None
    broken = np.flatnonzero((mode.reshape(-1, 2) > 0).any(axis=1))
    return (jq[broken] + 1).astype(np.int32)


class ParaviewSeries:
    def __init__(self, directory: Path, name: str = "rock"):
        self.dir = Path(directory)
        self.name = name
        self.frames: list[tuple[float, str]] = []

    def write(self, model, state, t: float, crack_gas=None, ppv=None) -> None:
        """One frame; with ``crack_gas`` (coupling.crack_gas.CrackGas) the crack lines also carry
        ``crack_gas_pressure`` [Pa] and ``crack_opening`` (the larger end opening) [m], 0 on the triangles."""
        x = state.x.numpy()
        X = model.node_X.numpy()
        v = state.v.numpy()
        sig = state.sigma.numpy()
        seg, cmode = crack_segments(model, state.pair_mode.numpy(), state.pair_tbreak.numpy())
        pts = np.c_[x, np.zeros(len(x))]
        tri = np.arange(len(x)).reshape(-1, 3)
        cells = [("triangle", tri)]
        n_e, n_c = len(tri), len(seg)
        stress = stress_tensor(sig, block_poisson_ratio(model))
        cell_data = {"stress": [stress], "crack_mode": [np.zeros(n_e, np.int32)]}
        joint = crack_joint_field(model, state.pair_mode.numpy())
        if joint is not None:
            cell_data["joint"] = [np.zeros(n_e, np.int32)]
        if crack_gas is not None:
            cell_data["crack_gas_pressure"] = [np.zeros(n_e)]
            cell_data["crack_opening"] = [np.zeros(n_e)]
        if n_c:
            cells.append(("line", seg))
            cell_data["stress"].append(np.zeros((n_c, 9)))
            cell_data["crack_mode"].append(cmode.astype(np.int32))
            if joint is not None:
                cell_data["joint"].append(joint)
            if crack_gas is not None:
                broken = np.flatnonzero((state.pair_mode.numpy().reshape(-1, 2) > 0).any(axis=1))
                cell_data["crack_gas_pressure"].append(crack_gas.gas.pres.numpy()[broken])
                cell_data["crack_opening"].append(crack_gas.gas.gap.numpy()[broken].max(axis=1))
        u = x - X
        mesh = meshio.Mesh(
            pts, cells,
            point_data={"displacement": np.c_[u, np.zeros(len(u))], "velocity": np.c_[v, np.zeros(len(v))],
                        "displacement_magnitude": np.linalg.norm(u, axis=1),
                        **({"ppv": np.asarray(ppv, float)} if ppv is not None else {})},
            cell_data=cell_data,
        )
        fname = f"{self.name}_{len(self.frames):04d}.vtu"
        _write_mesh(self.dir / fname, mesh)
        self.frames.append((t, fname))
        self._write_pvd()

    def _write_pvd(self) -> None:
        rows = "\n".join(f'    <DataSet timestep="{t:.9e}" file={quoteattr(f)}/>' for t, f in self.frames)
        write_text_atomic(self.dir / f"{self.name}.pvd",
            '<?xml version="1.0"?>\n<VTKFile type="Collection" version="0.1">\n  <Collection>\n'
            f"{rows}\n  </Collection>\n</VTKFile>\n"
        )


class GasSeries(ParaviewSeries):
    """ParaView series of the gas particles (vertex cells): velocity, pressure, density, burn fraction."""

    def __init__(self, directory: Path, name: str = "gas"):
        super().__init__(directory, name)

    def write(self, gas, t: float) -> None:  # type: ignore[override]
        f = gas.particle_fields()
        x = f["position"]
        pts = np.c_[x, np.zeros(len(x))]
        cells = [("vertex", np.arange(len(x)).reshape(-1, 1))] if len(x) else []
        v = f["velocity"]
        mesh = meshio.Mesh(
            pts, cells,
            point_data={"velocity": np.c_[v, np.zeros(len(v))], "pressure": f["pressure"], "density": f["density"],
                        "burn_fraction": f["burn_fraction"], "relative_volume": f["relative_volume"]},
        )
        fname = f"{self.name}_{len(self.frames):04d}.vtu"
        _write_mesh(self.dir / fname, mesh)
        self.frames.append((t, fname))
        self._write_pvd()
