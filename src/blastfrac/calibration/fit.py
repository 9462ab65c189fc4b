"""Automatic fit of the CDEM micro-parameters to macro targets (E, ν, σt, UCS).

Staged; each stage is a small, documented scipy problem (METHOD §5.4):

1. **Elastic** (E, ν) ← two of {kn, ks, block E, block ν} (default kn, ks). The elastic response does
   not depend on the strengths, so it is measured by the exact linear static solve of the UCS prism
   (:func:`.elastic.static_moduli`, < 1 s; the undamped quasi-static test reproduces it to ~0.1 %).
   Defect correction: ``scipy.optimize.least_squares`` inverts the analytic model A of METHOD §1.2
   plus a bias b = M − A (M: the last static solve), the solve is repeated and b updated (2–3
   solves). kn, ks are searched within ``stiffness_bounds`` [Pa/m], by default the range of penalty
   ratios β = k·h̄/E' in ``penalty_range`` = (1, 100) with h̄ = 2/ℓ (the paper's Table 3 springs
   are β ≈ 40 on its meshes): stiffer springs change E by < 1 % but shrink the stable time step as
   1/√k, softer ones would carry most of the compliance. Springs only *add* compliance, so a
   target E above the blocks' (or ν below the blocks' with ks ≤ kn) is unreachable with kn, ks
   alone: the stage reports ``reachable = false`` and keeps the closest point (residuals scaled by
   ``rtol_modulus``·E and ``atol_poisson``).
2. **σt ← spring tensile strength T** (Brazilian runs): 1-D safeguarded secant on ln T ↔ ln σt
   (:func:`fit_scalar`), first step from σt ∝ T.
3. **UCS ← cohesion c** at fixed friction angle φ (UCS runs), the same secant. One UCS value cannot
   separate c from φ (a triaxial test would): φ is held at ``[fit] friction_angle`` (or the
   scenario's) and reported.
4. A Brazilian run at the new (T, c): c moves σt a little; if σt is off by more than
   ``rtol_strength``, stages 2–3 are repeated from there (at most ``strength_rounds`` rounds).
5. **Two meshes** (optional ``refine``): stages 2–4 run first on the cheap *search* meshes, then
   continue on the *final* meshes from the search result (strengths of strength-only springs
   depend on the mesh, so the search result is a starting point, not the answer there).
6. **Sensitivities** d ln(macro)/d ln(micro) by one-sided differences (+5 %; φ: +2°) on the search
   meshes: kn, ks, T, c, φ against E, ν (static solves) and σt, UCS (runs).
7. **Identifiability** of every fitted micro-parameter from those sensitivities
   (:mod:`.identifiability`): ``not identifiable`` when no targeted macro responds to it
   (max |d ln macro/d ln micro| < ``identifiability_threshold``), with the range of values that
   reproduce the targets within tolerance (alone and with the others re-adjusted).

Every quasi-static run counts against ``budget``; static solves do not (they are counted apart).
When the budget runs out the best point so far is returned.
"""

from __future__ import annotations

import math
import time
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..scenario.errors import ScenarioError
from ..scenario.schema import RockConfig
from .brazilian import run_brazilian
from .curves import plane_strain_to_3d
from .elastic import edge_density, effective_moduli, static_moduli
from .identifiability import identifiability_of_report
from .quasistatic import LoadSettings
from .specimens import ucs_specimen
from .ucs import run_ucs

TARGET_KEYS = ("youngs_modulus", "poisson_ratio", "tensile_strength", "ucs")
ELASTIC_KEYS = ("kn", "ks", "youngs_modulus", "poisson_ratio")
MICRO_KEYS = ("kn", "ks", "tensile_strength", "cohesion", "friction_angle")


class BudgetExhausted(Exception):
    pass


@dataclass
class FitConfig:
    """Targets and options of a fit (SI units). Read from a TOML file by :func:`load_targets`."""

    targets: dict = field(default_factory=dict)
    elastic_parameters: tuple = ("kn", "ks")
    friction_angle: float | None = None
    stiffness_bounds: tuple | None = None    # Pa/m, search range of kn and ks (default: penalty_range)
    penalty_range: tuple = (1.0, 100.0)      # default range of k·h̄/E' (h̄ = 2/ℓ), see fit_elastic
    rtol_modulus: float = 0.01
    atol_poisson: float = 0.005
    rtol_strength: float = 0.02
    elastic_iterations: int = 4
    strength_iterations: int = 5
    strength_rounds: int = 2
    sensitivity: bool = True
    sensitivity_step: float = 0.05
    identifiability_threshold: float = 0.1   # |d ln macro/d ln micro| below this: not identifiable
    identifiability_cap: float = 10.0        # identifiability intervals are capped at ×/÷ this factor
    identifiability_probe: int = 2           # runs per side measuring the range of a non-identifiable one (0: off)


def load_targets(path: str | Path) -> FitConfig:
    """Read ``[targets]`` (youngs_modulus [Pa], poisson_ratio, tensile_strength [Pa], ucs [Pa]) and an
    optional ``[fit]`` table (see :class:`FitConfig` and docs/calibration.md)."""
    p = Path(path)
    if not p.is_file():
        raise ScenarioError(f"{p}: targets file not found")
    try:
        data = tomllib.loads(p.read_text())
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(f"{p}: {e}") from None
    unknown = set(data) - {"targets", "fit"}
    if unknown:
        raise ScenarioError(f"{p}: unknown table(s) {sorted(unknown)}; expected [targets] and [fit]")
    t = data.get("targets", {})
    bad = set(t) - set(TARGET_KEYS)
    if bad or not t:
        raise ScenarioError(f"{p}: [targets] needs some of {list(TARGET_KEYS)} (unknown: {sorted(bad)})")
    for k, v in t.items():
        if not isinstance(v, (int, float)) or v <= 0 or (k == "poisson_ratio" and v >= 0.5):
            raise ScenarioError(f"{p}: targets.{k} = {v!r} is not a valid positive value")
    cfg = FitConfig(targets={k: float(v) for k, v in t.items()})
    f = data.get("fit", {})
    allowed = set(FitConfig.__dataclass_fields__) - {"targets"}
    if set(f) - allowed:
        raise ScenarioError(f"{p}: unknown [fit] key(s) {sorted(set(f) - allowed)}; allowed {sorted(allowed)}")
    for k, v in f.items():
        setattr(cfg, k, tuple(v) if k in ("elastic_parameters", "stiffness_bounds", "penalty_range") else v)
    ep = cfg.elastic_parameters
    if len(ep) != 2 or len(set(ep)) != 2 or not set(ep) <= set(ELASTIC_KEYS):
        raise ScenarioError(f"{p}: fit.elastic_parameters must be two of {list(ELASTIC_KEYS)}, got {list(ep)}")
    if not cfg.identifiability_threshold > 0 or not cfg.identifiability_cap > 1:
        raise ScenarioError(f"{p}: fit.identifiability_threshold must be > 0 and fit.identifiability_cap > 1")
    for name in ("stiffness_bounds", "penalty_range"):
        b = getattr(cfg, name)
        if b is not None and (len(b) != 2 or not 0 < b[0] < b[1]):
            raise ScenarioError(f"{p}: fit.{name} must be [low, high] with 0 < low < high")
    return cfg


class Lab:
    """Runs the simulated tests for a rock on one pair of meshes, counting runs against a shared budget.

    budget: a one-element list shared by the labs of a two-mesh fit (runs left); static solves of the
    elastic stage are counted in ``static_solves`` and do not use the budget.
    """

    def __init__(self, budget, ucs_settings: LoadSettings, braz_settings: LoadSettings,
                 ucs_mesh: float | None, braz_mesh: float | None, seed: int = 0, device: str = "cpu",
                 log=print, name: str = "final"):
        self.budget = budget if isinstance(budget, list) else [int(budget), 0]
        self.us, self.bs = ucs_settings, braz_settings
        self.ucs_mesh, self.braz_mesh, self.seed, self.device = ucs_mesh, braz_mesh, seed, device
        self.log, self.name = log, name
        self.history: list[dict] = []
        self.static_solves = 0
        self.wall_s = 0.0

    @property
    def used(self) -> int:
        return self.budget[1]

    def _spend(self) -> None:
        if self.budget[1] >= self.budget[0]:
            raise BudgetExhausted(f"simulation budget of {self.budget[0]} used up")
        self.budget[1] += 1

    def _record(self, kind: str, rock: RockConfig, result: dict, wall: float) -> dict:
        row = {"run": self.budget[1] if kind != "static" else None, "mesh": self.name, "test": kind,
               "kn": rock.kn, "ks": rock.ks, "block_E": rock.youngs_modulus, "block_nu": rock.poisson_ratio,
               "tensile_strength": rock.tensile_strength, "cohesion": rock.cohesion,
               "friction_angle": rock.friction_angle, **result, "wall_s": wall}
        self.history.append(row)
        self.wall_s += wall
        shown = ", ".join(f"{k} {v:.4g}" for k, v in result.items())
        tag = f"[{self.budget[1]}/{self.budget[0]}]" if kind != "static" else "[static]"
        self.log(f"  {tag} {self.name} {kind}: T {rock.tensile_strength / 1e6:.4g} MPa, c {rock.cohesion / 1e6:.4g} "
                 f"MPa, φ {rock.friction_angle:g}°, kn {rock.kn:.3g}, ks {rock.ks:.3g} → {shown} ({wall:.0f} s)")
        return row

    def elastic(self, rock: RockConfig) -> tuple[float, float, float]:
        """(E, ν, ℓ) of the rock's UCS prism from the exact static solve (3D-equivalent E, ν)."""
        t0 = time.perf_counter()
        spec = ucs_specimen(rock.model_copy(update={"unbreakable": True}), self.ucs_mesh, self.seed, self.device)
        E, nu = plane_strain_to_3d(*static_moduli(spec))
        self.static_solves += 1
        self._record("static", rock, {"E": E, "nu": nu}, time.perf_counter() - t0)
        return E, nu, edge_density(spec.model)

    def brazilian(self, rock: RockConfig) -> float:
        self._spend()
        t0 = time.perf_counter()
        res = run_brazilian(rock, self.bs, self.braz_mesh, self.seed, self.device)
        r0 = res.initiation_radius
        self._record("brazilian", rock, {"sigma_t": res.tensile_strength, "r_over_R": r0}, time.perf_counter() - t0)
        if not r0 < 0.6:
            self.log(f"  warning: the first tensile failures lie at r/R = {r0:.2f}: the disc did not split from the "
                     "centre (mesh too coarse for the loading arc?); σt is not a valid splitting strength")
        return res.tensile_strength

    def ucs(self, rock: RockConfig) -> tuple[float, float, float]:
        self._spend()
        t0 = time.perf_counter()
        res = run_ucs(rock, self.us, self.ucs_mesh, self.seed, self.device)
        self._record("ucs", rock, {"UCS": res.ucs, "E": res.youngs_modulus, "nu": res.poisson_ratio},
                     time.perf_counter() - t0)
        return res.ucs, res.youngs_modulus, res.poisson_ratio


def _with(rock: RockConfig, **kw) -> RockConfig:
    return rock.model_copy(update=kw)


def per_area(rock: RockConfig, ell: float) -> RockConfig:
    """The rock in 'per_area' stiffness mode (penalty mode: kn = ks = β·E'/h̄, with the mean h̄ taken
    as 2/ℓ for a mesh whose interior edge density is ℓ)."""
    if rock.stiffness_mode == "per_area":
        return rock
    k = rock.spring_penalty * rock.plane_strain_modulus * ell / 2.0
    return _with(rock, stiffness_mode="per_area", kn=k, ks=k)


def fit_elastic(lab: Lab, rock: RockConfig, cfg: FitConfig, report: dict) -> RockConfig:
    """Stage 1: defect-corrected least squares on two elastic parameters (module doc)."""
    from scipy.optimize import least_squares

    tE, tnu = cfg.targets.get("youngs_modulus"), cfg.targets.get("poisson_ratio")
    if tE is None and tnu is None:
        return rock
    names = list(cfg.elastic_parameters)
    E_m, nu_m, ell = lab.elastic(rock)
    rock = per_area(rock, ell)

    def params(r):
        return {"kn": r.kn, "ks": r.ks, "youngs_modulus": r.youngs_modulus, "poisson_ratio": r.poisson_ratio}

    def model(p):
        return np.array(effective_moduli(p["youngs_modulus"], p["poisson_ratio"], ell, p["kn"], p["ks"]))

    def to_x(p):
        return np.array([math.log(p[n]) if n != "poisson_ratio" else p[n] for n in names])

    def from_x(x, base):
        p = dict(base)
        for n, xi in zip(names, x):
            p[n] = math.exp(xi) if n != "poisson_ratio" else float(xi)
        return p

    kb = cfg.stiffness_bounds or tuple(b * rock.plane_strain_modulus * ell / 2.0 for b in cfg.penalty_range)
    klo, khi = (math.log(b) for b in kb)
    bounds = {"kn": (klo, khi), "ks": (klo, khi), "youngs_modulus": (math.log(1e8), math.log(1e13)),
              "poisson_ratio": (0.0, 0.499)}
    lo = [bounds[n][0] for n in names]
    hi = [bounds[n][1] for n in names]
    target = np.array([tE if tE is not None else np.nan, tnu if tnu is not None else np.nan])
    scale = np.array([cfg.rtol_modulus * (tE or 1.0), cfg.atol_poisson])
    sel = ~np.isnan(target)
    meas = np.array([E_m, nu_m])
    steps, reachable = [], True
    for it in range(cfg.elastic_iterations):
        p0 = params(rock)
        bias = meas - model(p0)
        steps.append({"iteration": it, "measured": meas.tolist(), "bias": bias.tolist(), **{n: p0[n] for n in names}})
        err = np.abs(np.nan_to_num((meas - target) / scale))
        if np.all(err <= 1.0):
            reachable = True
            break

        def resid(x):
            return ((model(from_x(x, p0)) + bias - target) / scale)[sel]

        x0 = np.clip(to_x(p0), lo, hi)
        sol = least_squares(resid, x0, bounds=(lo, hi), xtol=1e-12, ftol=1e-12)
        new = from_x(sol.x, p0)
        reachable = bool(np.all(np.abs(sol.fun) <= 1.0))
        rock = _with(rock, kn=new["kn"], ks=new["ks"], youngs_modulus=new["youngs_modulus"],
                     poisson_ratio=new["poisson_ratio"])
        E_m, nu_m, _ = lab.elastic(rock)
        meas = np.array([E_m, nu_m])
        if not reachable and it >= 1:
            break
    at_bound = [n for n in names if n in ("kn", "ks") and
                min(abs(math.log(params(rock)[n]) - klo), abs(math.log(params(rock)[n]) - khi)) < 1e-3]
    if not reachable:
        Ep_max = rock.youngs_modulus / (1 - rock.poisson_ratio**2)
        lab.log(f"  elastic targets not reachable with {names} free: springs only add compliance (block "
                f"E = {rock.youngs_modulus / 1e9:.4g} GPa, ν = {rock.poisson_ratio:.3g}, E' = {Ep_max / 1e9:.4g} GPa); "
                f"closest point kept{' (at the stiffness bound: ' + ', '.join(at_bound) + ')' if at_bound else ''}")
    report["elastic"] = {"parameters": names, "edge_density_per_m": ell, "stiffness_bounds": list(kb), "iterations": steps,
                         "reachable": reachable, "at_stiffness_bound": at_bound,
                         "final_measured": {"youngs_modulus": float(meas[0]), "poisson_ratio": float(meas[1])}}
    return rock


MAX_STEP = 3.0          # a secant step changes a strength by at most this factor
MIN_RESPONSE = 0.1      # |d ln(macro)/d ln(micro)| below this: the macro value does not respond


def fit_scalar(evaluate, x0: float, target: float, rtol: float, max_evals: int,
               f_x0: float | None = None, log=print, label: str = "") -> tuple[float, float, list]:
    """Solve evaluate(x) = target for x > 0: secant on ln x ↔ ln y (exact for a power law y ∝ x^a),
    first step with a = 1 (response ∝ x), each step limited to a factor MAX_STEP, and regula falsi
    once the root is bracketed. Stops when |y − target| ≤ rtol·target, after ``max_evals``
    evaluations, or when the response is flat (|a| < MIN_RESPONSE: e.g. a coarse disc that fails at
    the jaws whatever its tensile strength). ``f_x0``: evaluate(x0) if already known (no run).
    Returns (best x, its value, [(x, value), ...])."""
    pts: list[tuple[float, float]] = []
    if f_x0 is not None:
        pts.append((float(x0), float(f_x0)))
    lt = math.log(target)
    x, n_eval = float(x0), 0
    while True:
        if not pts or pts[-1][0] != x:
            if n_eval >= max_evals:
                break
            try:
                y = float(evaluate(x))
            except BudgetExhausted:
                if not pts:
                    raise
                break
            pts.append((x, y))
            n_eval += 1
        y = pts[-1][1]
        if abs(y - target) <= rtol * target or not y > 0:
            break
        below = [p for p in pts if p[1] < target]
        above = [p for p in pts if p[1] > target]
        if len(pts) == 1:
            (xb, yb), a = pts[-1], 1.0
        else:
            if below and above:      # bracketed: regula falsi between the closest points on each side
                (xa, ya), (xb, yb) = max(below, key=lambda p: p[1]), min(above, key=lambda p: p[1])
            else:
                (xa, ya), (xb, yb) = pts[-2], pts[-1]
            a = (math.log(yb) - math.log(ya)) / (math.log(xb) - math.log(xa)) if xb != xa else 0.0
            if abs(a) < MIN_RESPONSE:
                log(f"  {label}: the response is flat (d ln y/d ln x = {a:.3f}); stopping this stage")
                break
        x_new = xb * math.exp((lt - math.log(yb)) / a)
        x = min(max(x_new, pts[-1][0] / MAX_STEP), pts[-1][0] * MAX_STEP)
    best = min(pts, key=lambda p: abs(p[1] - target))
    return best[0], best[1], sorted(pts)


def fit_strengths(lab: Lab, rock: RockConfig, cfg: FitConfig, achieved: dict) -> tuple[RockConfig, dict]:
    """Stages 2–4 on one lab: T ← σt, c ← UCS, Brazilian check; repeated up to ``strength_rounds``.
    If the budget runs out, the best point so far is kept and the stage dict gets ``stopped``."""
    tt, tu = cfg.targets.get("tensile_strength"), cfg.targets.get("ucs")
    rounds: list = []
    known_st = None            # σt at the current (T, c), when measured
    stopped = None
    try:
        for _ in range(max(1, cfg.strength_rounds)):
            row: dict = {}
            rounds.append(row)
            if tt is not None:
                x, val, pts = fit_scalar(lambda T: lab.brazilian(_with(rock, tensile_strength=T)),
                                         rock.tensile_strength, tt, cfg.rtol_strength, cfg.strength_iterations,
                                         known_st, lab.log, "σt ← T")
                rock = _with(rock, tensile_strength=x)
                achieved["tensile_strength"] = known_st = val
                row["tensile"] = pts
            if tu is not None:
                last: dict = {}

                def ucs_of(c):
                    u, E, nu = lab.ucs(_with(rock, cohesion=c))
                    last[c] = (E, nu)
                    return u

                x, val, pts = fit_scalar(ucs_of, rock.cohesion, tu, cfg.rtol_strength, cfg.strength_iterations,
                                         None, lab.log, "UCS ← c")
                moved = x != rock.cohesion
                rock = _with(rock, cohesion=x)
                achieved["ucs"] = val
                achieved["youngs_modulus_run"], achieved["poisson_ratio_run"] = last[x]
                row["ucs"] = pts
                if tt is not None and moved:
                    achieved.pop("tensile_strength", None)      # c moved: σt at (T, c) is unknown until measured
                    known_st = lab.brazilian(rock)
                    achieved["tensile_strength"] = known_st
                    row["check_tensile"] = known_st
            if tt is None or tu is None or abs(achieved["tensile_strength"] - tt) <= cfg.rtol_strength * tt:
                break
    except BudgetExhausted as e:
        stopped = str(e)
    out = {"mesh": lab.name, "ucs_mesh_size": lab.ucs_mesh, "brazilian_mesh_size": lab.braz_mesh,
           "rounds": rounds, "fitted": {"tensile_strength": rock.tensile_strength, "cohesion": rock.cohesion},
           "achieved": {k: achieved.get(k) for k in ("tensile_strength", "ucs")}}
    if stopped:
        out["stopped"] = stopped
    return rock, out


def fit(rock: RockConfig, cfg: FitConfig, lab: Lab, search: Lab | None = None, refine: bool = True) -> dict:
    """Run the staged fit; returns a JSON-ready report with the fitted micro-parameters.

    lab: the final meshes (the elastic stage always runs there: static solves are cheap);
    search: optional cheaper meshes for the strength search and the sensitivities; with
    ``refine`` the strength stages then continue on ``lab`` from the search result, without it
    the fit stops after the search (achieved strengths are then the search meshes').
    """
    t0 = time.perf_counter()
    report: dict = {"targets": cfg.targets, "start": rock.model_dump(), "budget": lab.budget[0],
                    "config": {k: getattr(cfg, k) for k in FitConfig.__dataclass_fields__ if k != "targets"}}
    if cfg.friction_angle is not None:
        rock = _with(rock, friction_angle=float(cfg.friction_angle))
    achieved: dict = {}
    stages = []
    labs = [lab] if search is None else ([search, lab] if refine else [search])
    try:
        rock = fit_elastic(lab, rock, cfg, report)
        achieved["youngs_modulus"] = report.get("elastic", {}).get("final_measured", {}).get("youngs_modulus")
        achieved["poisson_ratio"] = report.get("elastic", {}).get("final_measured", {}).get("poisson_ratio")
        if achieved["youngs_modulus"] is None:
            achieved["youngs_modulus"], achieved["poisson_ratio"], _ = lab.elastic(rock)
        for lb in labs:
            lab.log(f"strength stages on the {lb.name} meshes (UCS h = {lb.ucs_mesh or 'paper'}, "
                    f"disc h = {lb.braz_mesh or 'paper'})")
            ach: dict = {}
            rock, st = fit_strengths(lb, rock, cfg, ach)
            stages.append(st)
            if lb is labs[-1]:
                achieved.update(ach)
            if "stopped" in st:
                report["stopped"] = f"{st['stopped']} (on the {lb.name} meshes)"
                break
    except BudgetExhausted as e:
        report["stopped"] = str(e)
    report["strength_stages"] = stages
    report["fitted"] = rock.model_dump()
    report["achieved"] = {k: v for k, v in achieved.items() if v is not None}
    report["achieved_on"] = labs[-1].name
    report["relative_error"] = {k: (achieved[k] - v) / v for k, v in cfg.targets.items() if achieved.get(k) is not None}
    if cfg.sensitivity:
        lb = search or lab
        try:
            report["sensitivity"] = sensitivity(lb, rock, cfg.sensitivity_step)
        except BudgetExhausted as e:
            report["sensitivity"] = {"skipped": str(e)}
    report["identifiability"] = ident = identifiability_of_report(report, cfg.identifiability_threshold,
                                                                  cfg.identifiability_cap)
    if cfg.identifiability_probe > 0 and "parameters" in ident:
        probe_flat(search or lab, rock, ident, report["sensitivity"], cfg.identifiability_probe)
    report["simulations"] = lab.used
    report["static_solves"] = lab.static_solves + (search.static_solves if search else 0)
    report["history"] = (search.history if search else []) + lab.history
    report["wall_s"] = time.perf_counter() - t0
    return report


def measure(lab: Lab, rock: RockConfig, keys) -> dict:
    """The macro properties ``keys`` of ``rock`` on ``lab``'s meshes: E, ν by a static solve (free),
    σt by a Brazilian run, UCS by a UCS run."""
    out: dict = {}
    if {"youngs_modulus", "poisson_ratio"} & set(keys):
        out["youngs_modulus"], out["poisson_ratio"], _ = lab.elastic(rock)
    if "tensile_strength" in keys:
        out["tensile_strength"] = lab.brazilian(rock)
    if "ucs" in keys:
        out["ucs"] = lab.ucs(rock)[0]
    return out


STRENGTH_ONLY = ("tensile_strength", "cohesion", "friction_angle")


def probe_flat(lab: Lab, rock: RockConfig, ident: dict, sens: dict, tries: int) -> None:
    """Measure the range of every 'not identifiable' parameter (:func:`.identifiability.probe_interval`)
    on ``lab``'s meshes around ``rock``: all targeted macros are measured at each probe point (strength
    parameters cannot change E, ν, which are skipped for them). Updates ``ident`` in place."""
    from .identifiability import SYMBOL, measured_status, probe_interval, probed_statement

    tol = ident["tolerances"]
    for name, entry in ident["parameters"].items():
        if entry["status"] != "not identifiable":
            continue
        keys = [k for k in tol if not (name in STRENGTH_ONLY and k in ("youngs_modulus", "poisson_ratio"))]
        ptol = {k: tol[k] for k in keys}
        try:
            res = probe_interval(lambda x: measure(lab, _with(rock, **{name: x}), keys), entry["value"],
                                 sens["base"], ptol, entry["interval_alone"], tries, lab.log, SYMBOL.get(name, name))
        except BudgetExhausted as e:
            entry["probe"] = {"skipped": str(e)}
            continue
        entry.update(res)
        entry["status"] = measured_status(entry)
        entry["statement"] = probed_statement(entry, SYMBOL.get(name, name), ptol, lab.name)


def sensitivity(lab: Lab, rock: RockConfig, step: float) -> dict:
    """d ln(macro)/d ln(micro) by one-sided finite differences at ``rock`` on ``lab``'s meshes.

    Micro: kn, ks (+step), T, c (+step), φ (+2°, reported per ln of the angle in degrees and per
    degree). Macro: E, ν from static solves; σt, UCS from one Brazilian and one UCS run each.
    Returns {"base": {...}, "mesh": name, micro: {macro: value}}.
    """
    def measure(r):
        E, nu, _ = lab.elastic(r)
        return {"youngs_modulus": E, "poisson_ratio": nu, "tensile_strength": lab.brazilian(r), "ucs": lab.ucs(r)[0]}

    base = measure(rock)
    out: dict = {"base": base, "mesh": lab.name, "step": step}
    for name in MICRO_KEYS:
        if name in ("kn", "ks") and rock.stiffness_mode != "per_area":
            continue
        old = getattr(rock, name)
        new = old + 2.0 if name == "friction_angle" else old * (1 + step)
        m = measure(_with(rock, **{name: new}))
        d = math.log(new / old)
        out[name] = {k: math.log(m[k] / base[k]) / d for k in base}
        if name == "friction_angle":
            out[name]["per_degree"] = {k: math.log(m[k] / base[k]) / 2.0 for k in base}
    return out


def sensitivity_table(sens: dict) -> str:
    """Markdown table of d ln(macro)/d ln(micro)."""
    cols = ("youngs_modulus", "poisson_ratio", "tensile_strength", "ucs")
    lines = ["| micro \\ macro | E | ν | σt | UCS |", "|---|---|---|---|---|"]
    for name in MICRO_KEYS:
        if name in sens:
            lines.append(f"| {name} | " + " | ".join(f"{sens[name][c]:+.3f}" for c in cols) + " |")
    return "\n".join(lines)
