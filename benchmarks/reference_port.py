"""The compiled reference's CDEM and MPM loops written as Warp kernels: what Warp's code generation costs, apart from
the algorithm.

    python benchmarks/reference_port.py [--reference ../shared/bench-reference] [--steps 50] [--reps 5]

``../shared/bench-reference/bench_cpp.cpp`` (namespace ``cdem``) steps 199,712 CST triangles that own their nodes,
two total-displacement springs per interface with tension / Mohr–Coulomb failure and frictional contact after it,
and local damping. blastfrac's own step does more (an incremental spring with a stored force, strengths, work and
fracture accounts and a broken-pair frame, a separate owner-computes gather, an updated-Lagrangian Jaumann CST with
bulk viscosity, a block mass matrix, block contact), so blastfrac ÷ C++ mixes algorithm and code generation. This
module runs *the reference's algorithm* in three Warp kernels (float64, one launch per interface colour, so a colour
writes each node once and needs no atomics on a GPU either), on the reference's own initial state
(``common.cdem_init()`` of a scratch copy), and checks its end state against the C++ run's ``checks`` (momentum,
kinetic energy, broken springs, stress sums): the same algorithm to round-off. Then

    blastfrac ÷ C++ = (blastfrac ÷ Warp port) × (Warp port ÷ C++),

the first factor being the extra work of blastfrac's algorithm, the second Warp's code against g++ -O3 -march=native.

The same for the MPM loop (namespace ``mpm``: MLS-MPM with APIC and the quadratic B-spline, a JWL pressure from J in
the P2G, one P2G, grid update and G2P a step, 512² grid; ``MPMPort``, ``run_mpm``). blastfrac's MPM step does more:
a MUSL step (P2G of mass, momentum and force; grid update; G2P of the velocity; a second P2G of the momentum, the
remap; velocity gradient, volume and motion from the remapped grid in a pass of its own), a stencil that serves the
B-spline and uGIMP and periodic axes, and a products' update per point with programmed burn, bulk viscosity, the
energy update implicit in p and two JWL sound speeds (the viscosity's and the time step's).
``run(ref_dir)`` and ``run_mpm(ref_dir, n)`` need a built copy (``bench_coupled.run_reference`` makes one); ``main``
builds one itself.
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import warp as wp

F64 = wp.float64


@wp.kernel
def ref_cst(elem: wp.array2d(dtype=F64), u: wp.array(dtype=wp.vec2d), lam: F64, mu: F64,
            sigma: wp.array(dtype=wp.vec3d), f: wp.array(dtype=wp.vec2d)):
    """Small-strain CST of triangle t (elem row: b0 b1 b2 c0 c1 c2 A, B already divided by 2A); assigns f of its
    three nodes."""
    t = wp.tid()
    n0 = 3 * t
    exx = F64(0.0)
    eyy = F64(0.0)
    gxy = F64(0.0)
    for k in range(3):
        uk = u[n0 + k]
        exx += elem[t, k] * uk[0]
        eyy += elem[t, 3 + k] * uk[1]
        gxy += elem[t, 3 + k] * uk[0] + elem[t, k] * uk[1]
    two = F64(2.0)
    sxx = (lam + two * mu) * exx + lam * eyy
    syy = lam * exx + (lam + two * mu) * eyy
    sxy = mu * gxy
    sigma[t] = wp.vec3d(sxx, syy, sxy)
    a = elem[t, 6]
    for k in range(3):
        bk = elem[t, k]
        ck = elem[t, 3 + k]
        f[n0 + k] = wp.vec2d(-a * (bk * sxx + ck * sxy), -a * (ck * syy + bk * sxy))


@wp.kernel
def ref_springs(first: int, ifc: wp.array(dtype=wp.vec4i), X0: wp.array(dtype=wp.vec2d), u: wp.array(dtype=wp.vec2d),
                L0: wp.array(dtype=F64), kn: F64, ks: F64, ten: F64, coh: F64, tphi: F64, muc: F64,
                broken: wp.array(dtype=wp.vec2i), f: wp.array(dtype=wp.vec2d)):
    """Both springs of interface first + tid (nodes a0 a1 of one triangle, b0 b1 of the other): total-displacement
    forces in the frame of edge a0→a1, failure, frictional contact once broken; scattered to the four nodes (within
    one colour no node appears twice)."""
    i = wp.tid() + first
    q = ifc[i]
    d = (X0[q[1]] + u[q[1]]) - (X0[q[0]] + u[q[0]])
    t = d / wp.sqrt(wp.dot(d, d))
    n = wp.vec2d(t[1], -t[0])
    area = F64(0.5) * L0[i]
    br = broken[i]
    for k in range(2):
        na = q[k]
        nb = q[2 + k]
        du = u[nb] - u[na]
        fn = kn * area * wp.dot(du, n)
        fs = ks * area * wp.dot(du, t)
        b = br[k]
        if b == 0 and (fn > ten * area or wp.abs(fs) > coh * area + tphi * wp.max(-fn, F64(0.0))):
            b = 1
            br[k] = 1
        if b == 1:
            fn = wp.min(fn, F64(0.0))
            lim = muc * wp.abs(fn)
            fs = wp.min(wp.max(fs, -lim), lim)
        fv = fn * n + fs * t
        f[na] = f[na] + fv
        f[nb] = f[nb] - fv
    broken[i] = br


@wp.kernel
def ref_integrate(f: wp.array(dtype=wp.vec2d), inv_mass: wp.array(dtype=F64), alpha: F64, dt: F64,
                  v: wp.array(dtype=wp.vec2d), u: wp.array(dtype=wp.vec2d)):
    """Local damping f − α|f|·sign(v) per component, then v += Δt·f/m, u += Δt·v."""
    i = wp.tid()
    fi = f[i]
    vi = v[i]
    w = wp.vec2d()
    for dd in range(2):
        sg = F64(0.0)                     # sign(v) with sign(0) = 0, as the C++ has it (wp.sign(0) is 1)
        if vi[dd] > F64(0.0):
            sg = F64(1.0)
        elif vi[dd] < F64(0.0):
            sg = F64(-1.0)
        fd = fi[dd] - alpha * wp.abs(fi[dd]) * sg
        w[dd] = vi[dd] + dt * fd * inv_mass[i]
    v[i] = w
    u[i] = u[i] + dt * w


# ----------------------------------------------------------------------------- the reference's MPM loop
@wp.func
def ref_weights(fx: F64):
    """Quadratic B-spline weights of the three nodes from the particle's offset fx in its base cell."""
    return wp.vec3d(F64(0.5) * (F64(1.5) - fx) * (F64(1.5) - fx), F64(0.75) - (fx - F64(1.0)) * (fx - F64(1.0)),
                    F64(0.5) * (fx - F64(0.5)) * (fx - F64(0.5)))


@wp.func
def ref_stencil(xp: wp.vec2d, inv_dx: F64):
    """The particle's base node (b0, b1), its offsets in that cell (fx0, fx1) and its weights along each axis."""
    X = xp * inv_dx
    b0 = int(wp.floor(X[0] - F64(0.5)))
    b1 = int(wp.floor(X[1] - F64(0.5)))
    fx0 = X[0] - F64(b0)
    fx1 = X[1] - F64(b1)
    return b0, b1, fx0, fx1, ref_weights(fx0), ref_weights(fx1)


@wp.kernel
def ref_mpm_p2g(x: wp.array(dtype=wp.vec2d), v: wp.array(dtype=wp.vec2d), C: wp.array(dtype=wp.mat22d),
                J: wp.array(dtype=F64), e: wp.array(dtype=F64), ng: int, inv_dx: F64, dx: F64, stress_k: F64,
                p_mass: F64, ja: F64, jb: F64, r1: F64, r2: F64, om: F64,
                pres: wp.array(dtype=F64), grid: wp.array(dtype=wp.vec3d)):
    """JWL pressure of particle p, then its APIC momentum, MLS stress impulse and mass onto its 3 × 3 nodes
    (grid: momentum x, y and mass per node; one thread on a CPU, so the adds need no atomics there)."""
    p = wp.tid()
    b0, b1, fx0, fx1, w0, w1 = ref_stencil(x[p], inv_dx)
    V = J[p]
    one = F64(1.0)
    pr = ja * (one - om / (r1 * V)) * wp.exp(-r1 * V) + jb * (one - om / (r2 * V)) * wp.exp(-r2 * V) + om * e[p] / V
    pres[p] = pr
    st = stress_k * V * pr
    Cp = C[p]
    a00 = st + p_mass * Cp[0, 0]
    a01 = p_mass * Cp[0, 1]
    a10 = p_mass * Cp[1, 0]
    a11 = st + p_mass * Cp[1, 1]
    mvx = p_mass * v[p][0]
    mvy = p_mass * v[p][1]
    di = F64(0.0)                  # the node offsets i, j as floats (F64(i) would retype the loop's int)
    for i in range(3):
        dpx = (di - fx0) * dx
        dj = F64(0.0)
        for j in range(3):
            dpy = (dj - fx1) * dx
            wt = w0[i] * w1[j]
            gi = (b0 + i) * ng + (b1 + j)
            grid[gi] = grid[gi] + wp.vec3d(wt * (mvx + a00 * dpx + a01 * dpy), wt * (mvy + a10 * dpx + a11 * dpy),
                                           wt * p_mass)
            dj += F64(1.0)
        di += F64(1.0)


@wp.kernel
def ref_mpm_grid(grid: wp.array(dtype=wp.vec3d), ng: int, bound: int, gv: wp.array(dtype=wp.vec2d),
                 gm: wp.array(dtype=F64)):
    """Grid velocity = momentum / mass with the reference's sticky-slip walls; the accumulator is zeroed."""
    gi = wp.tid()
    i = gi / ng
    j = gi % ng
    g = grid[gi]
    grid[gi] = wp.vec3d()
    gm[gi] = g[2]
    vx = F64(0.0)
    vy = F64(0.0)
    if g[2] > F64(0.0):
        vx = g[0] / g[2]
        vy = g[1] / g[2]
    if i < bound and vx < F64(0.0):
        vx = F64(0.0)
    if i > ng - bound - 1 and vx > F64(0.0):
        vx = F64(0.0)
    if j < bound and vy < F64(0.0):
        vy = F64(0.0)
    if j > ng - bound - 1 and vy > F64(0.0):
        vy = F64(0.0)
    gv[gi] = wp.vec2d(vx, vy)


@wp.kernel
def ref_mpm_g2p(gv: wp.array(dtype=wp.vec2d), pres: wp.array(dtype=F64), ng: int, inv_dx: F64, dt: F64, lo: F64,
                hi: F64, x: wp.array(dtype=wp.vec2d), v: wp.array(dtype=wp.vec2d), C: wp.array(dtype=wp.mat22d),
                J: wp.array(dtype=F64), e: wp.array(dtype=F64)):
    """Velocity and affine matrix from the 3 × 3 nodes, motion (clamped to the box), J and the pdV energy."""
    p = wp.tid()
    b0, b1, fx0, fx1, w0, w1 = ref_stencil(x[p], inv_dx)
    nv = wp.vec2d()
    c00 = F64(0.0)
    c01 = F64(0.0)
    c10 = F64(0.0)
    c11 = F64(0.0)
    di = F64(0.0)                  # the node offsets i, j as floats (F64(i) would retype the loop's int)
    for i in range(3):
        dpx = di - fx0
        dj = F64(0.0)
        for j in range(3):
            dpy = dj - fx1
            wt = w0[i] * w1[j]
            u = gv[(b0 + i) * ng + (b1 + j)]
            nv = nv + wt * u
            sc = F64(4.0) * inv_dx * wt
            c00 += sc * u[0] * dpx
            c01 += sc * u[0] * dpy
            c10 += sc * u[1] * dpx
            c11 += sc * u[1] * dpy
            dj += F64(1.0)
        di += F64(1.0)
    v[p] = nv
    xp = x[p]
    x[p] = wp.vec2d(wp.min(wp.max(xp[0] + dt * nv[0], lo), hi), wp.min(wp.max(xp[1] + dt * nv[1], lo), hi))
    Jo = J[p]
    Jn = Jo * (F64(1.0) + dt * (c00 + c11))
    e[p] = e[p] - pres[p] * (Jn - Jo)
    J[p] = Jn
    C[p] = wp.mat22d(c00, c01, c10, c11)


class MPMPort:
    """The reference's MPM problem (``common.mpm_init(N)``) on a Warp device, float64, one P2G and one G2P a step."""

    def __init__(self, common, n: int, device: str = "cpu"):
        c, d = common.MPM, common.mpm_init(n)
        self.device, self.n, self.common = device, n, common
        as64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)      # noqa: E731
        self.init = {k: as64(d[k]) for k in ("x", "v", "C", "J", "e")}
        self.x = wp.array(self.init["x"], dtype=wp.vec2d, device=device)
        self.v = wp.array(self.init["v"], dtype=wp.vec2d, device=device)
        self.C = wp.array(self.init["C"], dtype=wp.mat22d, device=device)
        self.J = wp.array(self.init["J"], dtype=F64, device=device)
        self.e = wp.array(self.init["e"], dtype=F64, device=device)
        self.ng = int(c["n_grid"])
        self.pres = wp.zeros(n, dtype=F64, device=device)
        self.grid = wp.zeros(self.ng * self.ng, dtype=wp.vec3d, device=device)
        self.gv = wp.zeros(self.ng * self.ng, dtype=wp.vec2d, device=device)
        self.gm = wp.zeros(self.ng * self.ng, dtype=F64, device=device)
        # the constants as the C++ f64 build computes them
        self.dx, self.inv_dx, self.dt = 1.0 / 512, 512.0, 1e-4
        p_vol = (self.dx * 0.5) * (self.dx * 0.5)
        self.p_mass = p_vol * 1.0
        self.stress_k = self.dt * 4.0 * self.inv_dx * self.inv_dx * p_vol
        self.jwl = (371.2 * 0.05, 3.231 * 0.05, 4.15, 0.95, 0.30)
        self.bound = int(c["bound"])

    def reset(self) -> None:
        for k in ("x", "v", "C", "J", "e"):
            getattr(self, k).assign(self.init[k])

    def step(self) -> None:
        dev, n, ng = self.device, self.n, self.ng
        wp.launch(ref_mpm_p2g, n, inputs=[self.x, self.v, self.C, self.J, self.e, ng, F64(self.inv_dx), F64(self.dx),
                                          F64(self.stress_k), F64(self.p_mass), *(F64(a) for a in self.jwl)],
                  outputs=[self.pres, self.grid], device=dev)
        wp.launch(ref_mpm_grid, ng * ng, inputs=[self.grid, ng, self.bound], outputs=[self.gv, self.gm], device=dev)
        wp.launch(ref_mpm_g2p, n, inputs=[self.gv, self.pres, ng, F64(self.inv_dx), F64(self.dt), F64(2.0 * self.dx),
                                          F64(1.0 - 2.0 * self.dx)],
                  outputs=[self.x, self.v, self.C, self.J, self.e], device=dev)

    def checks(self) -> dict:
        return self.common.mpm_checks(self.x.numpy(), self.v.numpy(), self.C.numpy(), self.J.numpy(), self.e.numpy(),
                                      float(self.gm.numpy().sum()))


class Port:
    """The reference's CDEM problem on a Warp device, from the float32 initial state of ``common.cdem_init()``."""

    def __init__(self, common, device: str = "cpu"):
        c, d = common.CDEM, common.cdem_init()
        self.c, self.device, self.common = c, device, common
        as64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)      # noqa: E731  (the C++ f64 build widens the same way)
        self.elem = wp.array(as64(d["elem"]), dtype=F64, device=device)
        self.X0 = wp.array(as64(d["X0"]), dtype=wp.vec2d, device=device)
        self.inv_mass = wp.array(as64(d["inv_mass"]), dtype=F64, device=device)
        self.ifc = wp.array(d["ifc"].astype(np.int32), dtype=wp.vec4i, device=device)
        self.L0 = wp.array(as64(d["L0"]), dtype=F64, device=device)
        self.colours = [int(x) for x in d["colour_start"]]
        self.u0, self.v0, self.broken0 = as64(d["u"]), as64(d["v"]), d["broken"].astype(np.int32)
        self.u = wp.array(self.u0, dtype=wp.vec2d, device=device)
        self.v = wp.array(self.v0, dtype=wp.vec2d, device=device)
        self.broken = wp.array(self.broken0, dtype=wp.vec2i, device=device)
        self.f = wp.zeros(len(self.u0), dtype=wp.vec2d, device=device)
        self.sigma = wp.zeros(len(self.elem), dtype=wp.vec3d, device=device)
        # the constants as the C++ f64 build computes them (float literals read as doubles)
        E, nu, h = 1.0, 0.25, 1.0 / c["nx"]
        self.lam, self.mu = E * nu / ((1 + nu) * (1 - 2 * nu)), E / (2 * (1 + nu))
        self.kn = 10.0 * E / h
        self.ks, self.dt = self.kn * 0.5, 0.1 * h
        self.ntri = len(self.elem)

    def reset(self) -> None:
        self.u.assign(self.u0)
        self.v.assign(self.v0)
        self.broken.assign(self.broken0)

    def step(self) -> None:
        dev = self.device
        wp.launch(ref_cst, self.ntri, inputs=[self.elem, self.u, F64(self.lam), F64(self.mu)],
                  outputs=[self.sigma, self.f], device=dev)
        c = self.c
        for k in range(3):
            a, b = self.colours[k], self.colours[k + 1]
            wp.launch(ref_springs, b - a, inputs=[a, self.ifc, self.X0, self.u, self.L0, F64(self.kn), F64(self.ks),
                                                  F64(c["tension"]), F64(c["cohesion"]), F64(c["tan_phi"]),
                                                  F64(c["mu_contact"])],
                      outputs=[self.broken, self.f], device=dev)
        wp.launch(ref_integrate, len(self.u0), inputs=[self.f, self.inv_mass, F64(c["alpha"]), F64(self.dt)],
                  outputs=[self.v, self.u], device=dev)

    def checks(self) -> dict:
        return self.common.cdem_checks(self.u.numpy(), self.v.numpy(), self.inv_mass.numpy(), self.broken.numpy(),
                                       self.sigma.numpy())


def _side_by_side(ref_dir: Path, cpp_args: list[str], scatter: str, kind: str, n: int, steps: int | None, reps: int,
                  device: str) -> tuple[dict, dict, float, dict]:
    """Run the built C++ f64 reference of ``ref_dir`` (``./bench_cpp_f64 *cpp_args``, one thread, ``reps``
    repetitions) and time the Warp port of the same problem (``port_timer``) as the C++ program times itself: reset,
    ``steps`` steps (the C++ run's own count by default), median over ``reps``; its checks after the first
    repetition against the C++ run's. Returns (the C++ RESULT, the port's fields of the result without its size,
    the port's seconds a step, the port's info)."""
    cpp = run_cpp(ref_dir, cpp_args, scatter, reps)
    steps = int(cpp["nsteps"]) if steps is None else steps
    info, block, checks = port_timer(ref_dir, kind, n, device)
    walls, chk = [], None
    for k in range(reps):
        walls.append(block(steps))
        if k == 0:
            chk = checks()
    step_s = float(np.median(walls)) / steps
    ref = cpp["checks"]
    rel = {k: abs(chk[k] - ref[k]) / max(abs(ref[k]), 1e-300) for k in chk}
    out = {"port_step_ms": 1e3 * step_s, "cpp_step_ms": cpp["step_ms_median"],
           "cpp_units_steps_per_s": cpp["units_steps_per_s"], "port_over_cpp": step_s * 1e3 / cpp["step_ms_median"],
           "checks": chk, "cpp_checks": ref, "checks_max_rel_diff": max(rel.values()), "device": device}
    return cpp, out, step_s, info


def _common(ref_dir: Path):
    """The reference folder's ``common`` module (constants and initial states, numpy only)."""
    sys.path.insert(0, str(ref_dir))
    try:
        import common
    finally:
        sys.path.pop(0)
    return common


def run_cpp(ref_dir: Path, cpp_args: list[str], scatter: str, reps: int = 1) -> dict:
    """The built C++ f64 reference (``./bench_cpp_f64 *cpp_args``, one thread, ``reps`` timed repetitions, their
    median its figure): its RESULT."""
    env = {**os.environ, "OMP_NUM_THREADS": "1", "SCATTER": scatter, "REPS": str(reps)}
    r = subprocess.run(["./bench_cpp_f64", *cpp_args], cwd=ref_dir, env=env, capture_output=True, text=True,
                       check=True)
    return json.loads(next(line for line in r.stdout.splitlines() if line.startswith("RESULT")).split(" ", 1)[1])


def cpp_once(ref_dir: Path, cpp_args: list[str], scatter: str) -> dict:
    """One timed repetition of the built C++ f64 reference (one thread): its RESULT."""
    return run_cpp(ref_dir, cpp_args, scatter, 1)


def port_timer(ref_dir: Path, kind: str, n: int = 0, device: str = "cpu"):
    """(info, block, checks) of the Warp port of the reference's ``kind`` problem ('cdem', or 'mpm' with n points):
    ``block(steps)`` resets it and times that many steps [s] as the C++ program times a repetition; ``checks()``
    its state's checks (after a block, comparable with the C++ run's after its first repetition)."""
    from blastfrac._warp import init_warp

    init_warp()
    common = _common(ref_dir)
    p = Port(common, device) if kind == "cdem" else MPMPort(common, n, device)
    p.reset()
    p.step()                                   # load the module (kernel compile or cache read)
    wp.synchronize_device(device)

    def block(steps: int) -> float:
        p.reset()
        wp.synchronize_device(device)
        t0 = time.perf_counter()
        for _ in range(steps):
            p.step()
        wp.synchronize_device(device)
        return time.perf_counter() - t0

    units = p.ntri if kind == "cdem" else n
    return {"units": units}, block, p.checks


def run(ref_dir: Path, steps: int = 50, reps: int = 5, device: str = "cpu") -> dict:
    """Time the CDEM port as the C++ program times itself (reset, ``steps`` steps, median over ``reps``) and check
    its state after the first repetition against the built C++ f64 reference of ``ref_dir`` run on one thread.
    Returns both RESULTs, the port's checks and the largest relative difference of the checks."""
    _, out, step_s, info = _side_by_side(ref_dir, ["cdem"], "colour", "cdem", 0, steps, reps, device)
    return {"triangles": info["units"], "port_units_steps_per_s": info["units"] / step_s, **out}


def run_mpm(ref_dir: Path, n: int = 100_000, reps: int = 5, device: str = "cpu") -> dict:
    """The MPM port timed as the C++ program times its ``mpm n`` (reset, its 20 steps, median over ``reps``), its
    state after the first repetition checked against the C++ f64 run's (one thread, SCATTER=private)."""
    _, out, step_s, _ = _side_by_side(ref_dir, ["mpm", str(n)], "private", "mpm", n, None, reps, device)
    return {"particles": n, "port_units_steps_per_s": n / step_s, **out}


def build(src: Path) -> Path:
    """A built scratch copy of the reference folder ``src`` (build.sh: g++ -O3 -march=native, data files)."""
    dst = Path(tempfile.mkdtemp(prefix="bench_ref_")) / "ref"
    shutil.copytree(src, dst)
    subprocess.run(["bash", "build.sh", sys.executable], cwd=dst, check=True, capture_output=True)
    return dst


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--reference", type=Path, default=Path(__file__).resolve().parents[2] / "shared" / "bench-reference")
    ap.add_argument("--steps", type=int, default=50)
    ap.add_argument("--reps", type=int, default=5)
    ap.add_argument("--device", default="cpu")
    a = ap.parse_args(argv)
    d = build(a.reference)
    try:
        r = run(d, a.steps, a.reps, a.device)
        rm = [run_mpm(d, n, a.reps, a.device) for n in (100_000, 400_000)]
    finally:
        shutil.rmtree(d.parent, ignore_errors=True)
    print(f"CDEM {r['triangles']:,} triangles: Warp port {r['port_step_ms']:.2f} ms/step, C++ f64 1 thread "
          f"{r['cpp_step_ms']:.2f} ms/step, port / C++ = {r['port_over_cpp']:.2f}; checks agree to "
          f"{r['checks_max_rel_diff']:.1e} (relative)")
    for m in rm:
        print(f"MPM {m['particles']:,} particles: Warp port {m['port_step_ms']:.2f} ms/step, C++ f64 1 thread "
              f"{m['cpp_step_ms']:.2f} ms/step, port / C++ = {m['port_over_cpp']:.2f}; checks agree to "
              f"{m['checks_max_rel_diff']:.1e} (relative)")


if __name__ == "__main__":
    main()
