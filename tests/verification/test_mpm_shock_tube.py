"""Sod's shock tube in the MPM gas: APIC against FLIP and PIC, measured on the exact Riemann solution.

Ideal gas gamma = 1.4 written as JWL with A = B = 0, omega = gamma - 1: p = omega E / V with E = ie/V_p0 and
V = V_p/V_p0, i.e. p = (gamma - 1) ie/V_p = (gamma - 1) rho e.  Left rho = 1 kg/m^3, p = 1e5 Pa; right
rho = 0.125 kg/m^3, p = 1e4 Pa; at rest; diaphragm at x = 0.5 m of a 1 m tube (slip walls at both ends, a
strip one cell wide, periodic across); measured at t = 0.2 L / sqrt(p_L/rho_L) (Sod's t = 0.2), when the
rarefaction head is at 0.26 m and the shock at 0.85 m.  The exact solution (Toro, ch. 4: Newton on the
pressure function) is computed here.

Measured on the particles (not smoothed): plateau means of p*, u* (between the rarefaction tail and the
shock, 4 cells clear of the tail, the contact and the shock), rho*_L (tail to contact), rho*_R (contact to
shock); the velocity overshoot max(u)/u* - 1 from the contact to 3 cells ahead of the shock; the scatter,
std(u)/u* over the plateau; the shock position, where p crosses (p* + p_R)/2, minus the exact one, in cells;
the change of the total energy (exactly conserved in the closed tube) over the final kinetic energy.
Each of APIC, pure FLIP and PIC (FLIP fraction 0) is run with the v0.1 viscosity (q1 = 1.5, q2 = 0.06) and with
q2 = 2; the default (1 % PIC with blend heating, q2 = 2, explosive.flip / q2 in docs/scenario.md) must meet
issue 12's targets: plateaus within 2 %, velocity overshoot at most 5 %, shock within 2 cells.
"""

import numpy as np

from blastfrac.materials.jwl import JWLParams
from blastfrac.mpm import MPMOptions, MPMSolver
from blastfrac.mpm.seeding import slab_1d

G = 1.4
RL, PL, RR, PR = 1.0, 1.0e5, 0.125, 1.0e4  # kg/m^3, Pa
L, X0 = 1.0, 0.5  # tube length and diaphragm [m]
T_END = 0.2 * L / np.sqrt(PL / RL)  # [s]
NCELL = 400
# rho0 is the reference density of V = rho0/rho; D only times the (already complete) burn
GAS = JWLParams(rho0=1.0, D=1.0, A=0.0, B=0.0, R1=1.0, R2=1.0, omega=G - 1.0, E0=PL / (G - 1.0))


# ----------------------------------------------------------------------------- exact Riemann solver (Toro ch. 4)
def _f(p, rk, pk, g=G):
    """Toro's f_K(p) and f_K'(p) for the left or right state (rk, pk) at rest-frame pressure p."""
    ck = np.sqrt(g * pk / rk)
    if p > pk:  # shock
        A, B = 2.0 / ((g + 1) * rk), (g - 1) / (g + 1) * pk
        q = np.sqrt(A / (p + B))
        return (p - pk) * q, q * (1.0 - 0.5 * (p - pk) / (p + B))
    return 2 * ck / (g - 1) * ((p / pk) ** ((g - 1) / (2 * g)) - 1.0), (p / pk) ** (-(g + 1) / (2 * g)) / (rk * ck)


def star_state(rl, ul, pl, rr, ur, pr, g=G):
    """(p*, u*) by Newton iteration on f_L(p) + f_R(p) + u_R - u_L = 0."""
    p = 0.5 * (pl + pr)
    for _ in range(50):
        fl, dl = _f(p, rl, pl, g)
        fr, dr = _f(p, rr, pr, g)
        dp = (fl + fr + ur - ul) / (dl + dr)
        p = max(p - dp, 1e-8 * min(pl, pr))
        if abs(dp) < 1e-15 * p:
            break
    return p, 0.5 * (ul + ur) + 0.5 * (_f(p, rr, pr, g)[0] - _f(p, rl, pl, g)[0])


def sample(s, rl, ul, pl, rr, ur, pr, g=G):
    """Exact (rho, u, p) at similarity coordinates s = (x - x0)/t [m/s] (array) and the waves' speeds."""
    ps, us = star_state(rl, ul, pl, rr, ur, pr, g)
    s = np.asarray(s, float)
    rho, u, p = np.empty_like(s), np.empty_like(s), np.empty_like(s)
    waves = {"contact": us}
    for side, (rk, uk, pk), sgn in (("left", (rl, ul, pl), -1.0), ("right", (rr, ur, pr), 1.0)):
        ck = np.sqrt(g * pk / rk)
        m = s <= us if sgn < 0 else s > us
        if ps > pk:  # shock
            S = uk + sgn * ck * np.sqrt((g + 1) / (2 * g) * ps / pk + (g - 1) / (2 * g))
            r_star = rk * (ps / pk + (g - 1) / (g + 1)) / ((g - 1) / (g + 1) * ps / pk + 1)
            out = sgn * (s - S) > 0
            rho[m], u[m], p[m] = np.where(out[m], rk, r_star), np.where(out[m], uk, us), np.where(out[m], pk, ps)
            waves[f"{side}_shock"] = S
        else:  # rarefaction
            r_star = rk * (ps / pk) ** (1 / g)
            c_star = ck * (ps / pk) ** ((g - 1) / (2 * g))
            head, tail = uk + sgn * ck, us + sgn * c_star
            fan_u = 2 / (g + 1) * (-sgn * ck + (g - 1) / 2 * uk + s)
            fan_c = 2 / (g + 1) * (ck - sgn * (g - 1) / 2 * (uk - s))
            fan = (rk * (fan_c / ck) ** (2 / (g - 1)), fan_u, pk * (fan_c / ck) ** (2 * g / (g - 1)))
            out, star = sgn * (s - head) > 0, sgn * (s - tail) < 0
            for arr, kv, sv, fv in ((rho, rk, r_star, fan[0]), (u, uk, us, fan[1]), (p, pk, ps, fan[2])):
                arr[m] = np.where(out, kv, np.where(star, sv, fv))[m]
            waves[f"{side}_head"], waves[f"{side}_tail"] = head, tail
        waves[f"rho_star_{side}"] = r_star
    waves["p_star"], waves["u_star"] = ps, us
    return (rho, u, p), waves


def test_exact_riemann_solver_reproduces_sod():
    """Toro's Table 4.2, test 1 (Sod): p* = 0.30313, u* = 0.92745 (normalised units)."""
    ps, us = star_state(1.0, 0.0, 1.0, 0.125, 0.0, 0.1)
    assert abs(ps - 0.30313) < 1e-5 and abs(us - 0.92745) < 1e-5
    (r, u, p), w = sample(np.array([-2.0, 0.0, 1.0, 2.0]), 1.0, 0.0, 1.0, 0.125, 0.0, 0.1)
    assert abs(w["rho_star_left"] - 0.42632) < 1e-5 and abs(w["rho_star_right"] - 0.26557) < 1e-5
    assert r[0] == 1.0 and r[-1] == 0.125 and abs(p[2] - ps) < 1e-12


# ----------------------------------------------------------------------------- the MPM run
def run_tube(ncell=NCELL, **opts):
    """Sod's tube with MPMOptions(**opts) (the defaults where not given)."""
    spec, x, vol = slab_1d(L, ncell)
    s = MPMSolver.from_arrays(x, vol, spec, GAS, MPMOptions(**opts))
    s.grid.set_walls(xmin=0.0, xmax=L, kind="slip")
    left = x[:, 0] < X0
    s.set_gas_state(np.where(left, RL, RR), np.where(left, PL, PR))
    e0 = s.energies()["total"]
    t, steps = 0.0, 0
    while t < T_END * (1 - 1e-12):
        dt = min(s.stable_dt(), T_END - t)
        s.step(dt, t)
        t += dt
        steps += 1
    return s, t, steps, e0


def measure(s, t, e0):
    f = s.particle_fields()
    o = np.argsort(f["position"][:, 0])
    x, u, p, rho = f["position"][o, 0], f["velocity"][o, 0], f["pressure"][o], f["density"][o]
    _, w = sample((x - X0) / t, RL, 0.0, PL, RR, 0.0, PR)
    h = s.spec.h
    xt, xc, xs = X0 + w["left_tail"] * t, X0 + w["u_star"] * t, X0 + w["right_shock"] * t
    cl = 4 * h
    win_l = (x > xt + cl) & (x < xc - cl)
    win_r = (x > xc + cl) & (x < xs - cl)
    plateau = win_l | win_r
    ps, us = w["p_star"], w["u_star"]
    k = np.nonzero(p > 0.5 * (ps + PR))[0].max()  # last point above the mid level
    x_shock = x[k] + (p[k] - 0.5 * (ps + PR)) / (p[k] - p[k + 1]) * (x[k + 1] - x[k])
    behind = (x > xc) & (x < xs + 3 * h)
    e = s.energies()
    return {
        "p*": p[plateau].mean() / ps - 1,
        "u*": u[plateau].mean() / us - 1,
        "rho*L": rho[win_l].mean() / w["rho_star_left"] - 1,
        "rho*R": rho[win_r].mean() / w["rho_star_right"] - 1,
        "overshoot": u[behind].max() / us - 1,
        "scatter": u[plateau].std() / us,
        "shock/h": (x_shock - xs) / h,
        "dE/KE": (e["total"] - e0) / e["kinetic"],  # the exact flow conserves the total energy
    }


PURE = {"transfer": "flip", "flip": 1.0, "blend_heating": False}
CASES = {  # v0.1's viscosity q2 = 0.06 (on the time step's signal speed then), and q2 = 2
    "APIC": {"transfer": "apic", "q2": 0.06},
    "FLIP": {**PURE, "q2": 0.06},
    "PIC": {**PURE, "flip": 0.0, "q2": 0.06},
    "APIC q2=2": {"transfer": "apic", "q2": 2.0},
    "FLIP q2=2": {**PURE, "q2": 2.0},
}
BLEND = {  # 1 % PIC: plain, with blend heating, and the default (with heating and q2 = 2)
    "blend": {"flip": 0.99, "blend_heating": False, "q2": 0.06},
    "blend+heat": {"flip": 0.99, "blend_heating": True, "q2": 0.06},
    "default": {},
}


def _table(rows, title):
    keys = [k for k in next(iter(rows.values())) if k != "steps"]
    print(f"\n  {title}")
    print("  " + " " * 12 + "".join(f"{k:>10s}" for k in keys))
    for name, r in rows.items():
        print(f"  {name:12s}" + "".join(f"{r[k]:>+10.4f}" for k in keys))


def test_sod_shock_tube_apic_flip_pic():
    rows = {}
    for name, opts in CASES.items():
        s, t, steps, e0 = run_tube(**opts)
        assert s.deactivated_count == 0
        rows[name] = measure(s, t, e0)
    _table(rows, f"Sod, {NCELL} cells, 2x2 points per cell, t = {T_END:.4e} s; relative errors against the exact solution")
    a, f, pic = rows["APIC"], rows["FLIP"], rows["PIC"]
    # weak viscosity: APIC removes most of FLIP's noise, keeps u* and p*, but rings behind the shock
    assert abs(a["p*"]) < 0.02 and abs(a["u*"]) < 0.02
    assert abs(a["rho*L"]) < 0.035 and abs(a["rho*R"]) < 0.035
    assert a["overshoot"] < 0.15 and a["overshoot"] < f["overshoot"] / 3
    assert a["scatter"] < 0.03 and a["scatter"] < f["scatter"] / 5
    assert abs(a["shock/h"]) < 3
    assert f["overshoot"] > 0.3 and f["scatter"] > 0.1  # the FLIP noise the independent checks found
    assert pic["shock/h"] < -4  # PIC's dissipation slows the shock
    # APIC and PIC lose kinetic energy in their transfers that the flow should have turned into heat; FLIP does not
    assert a["dE/KE"] < -0.05 and abs(f["dE/KE"]) < 0.02
    # q2 = 2 damps APIC's ringing but not pure FLIP's noise
    a2, f2 = rows["APIC q2=2"], rows["FLIP q2=2"]
    assert a2["overshoot"] < 0.05 and abs(a2["p*"]) < 0.02 and abs(a2["u*"]) < 0.02
    assert f2["overshoot"] > 0.1 and f2["scatter"] > 0.02


def test_sod_shock_tube_blend_with_heating_and_the_default():
    """1 % PIC with blend heating: the PIC share's kinetic energy goes into the points' internal energy, so the
    closed tube keeps its total energy as pure FLIP does, while the plain blend loses it and its shock lags; the
    default (with q2 = 2) meets the targets of issue 12."""
    rows = {name: measure(*(lambda r: (r[0], r[1], r[3]))(run_tube(**opts))) for name, opts in BLEND.items()}
    _table(rows, f"Sod, {NCELL} cells: 1 % PIC blends")
    h, b, d = rows["blend+heat"], rows["blend"], rows["default"]
    assert abs(h["dE/KE"]) < 0.01 and b["dE/KE"] < -0.03          # heating books what the plain blend loses
    assert abs(h["shock/h"]) < 0.5 and b["shock/h"] < -1.0          # and keeps the shock on time
    for k in ("p*", "u*", "rho*L", "rho*R"):
        assert abs(h[k]) < 0.035, k
        assert abs(d[k]) < 0.02, k                                  # the default: plateaus within 2 %
    assert d["overshoot"] < 0.05 and abs(d["shock/h"]) < 2 and abs(d["dE/KE"]) < 0.01
    assert d["scatter"] < 0.02
