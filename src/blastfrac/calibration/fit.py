"""Automatic fit of the CDEM micro-parameters to macro targets (E, ν, σt, UCS).

Staged, each stage a small, documented scipy problem (METHOD §5.4):

1. Elastic (E, ν) ← two of {kn, ks, block E, block ν} (default kn, ks). E and ν do not depend
   on strengths, so they are measured on a short elastic UCS run with unbreakable springs.
   Defect correction: scipy.optimize.least_squares inverts the analytic model A of METHOD §1.2
   plus a bias b = M − A (M: the last simulated moduli), then the simulation is rerun and b
   updated. The analytic model carries the derivatives, the simulation the accuracy.
2. σt ← spring tensile strength T (Brazilian test). 1-D secant root (scipy.optimize.root_scalar,
   method 'secant'), first step from strength ∝ T.
3. UCS ← spring cohesion c at fixed friction angle φ (UCS test), the same 1-D secant.
   A single UCS target cannot separate c from φ: φ is held at its given value ([fit]
   friction_angle, or the scenario's); c0 = UCS·(1−sinφ)/(2cosφ) is not used because the
   2D spring UCS is not the continuum Mohr–Coulomb one.
4. A final Brazilian run at the fitted point (c can move σt) and, if the budget allows,
   finite-difference sensitivities d ln(macro)/d ln(micro) (+5 % steps; φ: +2°).

Every simulation counts against ``budget``; when it runs out the best point so far is returned.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..scenario.errors import ScenarioError
from ..scenario.schema import RockConfig
from .brazilian import run_brazilian
from .elastic import edge_density, effective_moduli
from .quasistatic import LoadSettings
from .specimens import ucs_specimen
from .ucs import analyse_ucs, run_ucs
from .quasistatic import run_loading

TARGET_KEYS = ("youngs_modulus", "poisson_ratio", "tensile_strength", "ucs")
ELASTIC_KEYS = ("kn", "ks", "youngs_modulus", "poisson_ratio")
ELASTIC_SPEED = 0.025   # m/s, platen speed of the elastic runs


class BudgetExhausted(Exception):
    pass


class _Converged(Exception):
    pass


@dataclass
class FitConfig:
    """Targets and options of a fit (SI units). Read from a TOML file by :func:`load_targets`."""

    targets: dict = field(default_factory=dict)
    elastic_parameters: tuple = ("kn", "ks")
    friction_angle: float | None = None
    rtol_modulus: float = 0.01
    atol_poisson: float = 0.005
    rtol_strength: float = 0.02
    elastic_iterations: int = 4
    strength_iterations: int = 6
    sensitivity: bool = True
    sensitivity_step: float = 0.05


def load_targets(path: str | Path) -> FitConfig:
    """Read ``[targets]`` (youngs_modulus [Pa], poisson_ratio, tensile_strength [Pa], ucs [Pa]) and an
    optional ``[fit]`` table (elastic_parameters, friction_angle, tolerances, sensitivity)."""
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
    allowed = {"elastic_parameters", "friction_angle", "rtol_modulus", "atol_poisson", "rtol_strength",
               "elastic_iterations", "strength_iterations", "sensitivity", "sensitivity_step"}
    if set(f) - allowed:
        raise ScenarioError(f"{p}: unknown [fit] key(s) {sorted(set(f) - allowed)}; allowed {sorted(allowed)}")
    for k, v in f.items():
        setattr(cfg, k, tuple(v) if k == "elastic_parameters" else v)
    ep = cfg.elastic_parameters
    if len(ep) != 2 or len(set(ep)) != 2 or not set(ep) <= set(ELASTIC_KEYS):
        raise ScenarioError(f"{p}: fit.elastic_parameters must be two of {list(ELASTIC_KEYS)}, got {list(ep)}")
    return cfg


class Lab:
    """Runs the simulated tests for a rock, counting simulations against a budget."""

    def __init__(self, budget: int, ucs_settings: LoadSettings, braz_settings: LoadSettings,
                 ucs_mesh: float | None, braz_mesh: float | None, seed: int = 0, device: str = "cpu", log=print):
        self.budget, self.used = budget, 0
        self.us, self.bs = ucs_settings, braz_settings
        self.ucs_mesh, self.braz_mesh, self.seed, self.device = ucs_mesh, braz_mesh, seed, device
        self.log = log
        self.history: list[dict] = []

    def _spend(self, kind: str, rock: RockConfig) -> None:
        if self.used >= self.budget:
            raise BudgetExhausted(f"simulation budget of {self.budget} used up")
        self.used += 1

    def _record(self, kind: str, rock: RockConfig, result: dict) -> dict:
        row = {"run": self.used, "test": kind, "kn": rock.kn, "ks": rock.ks, "block_E": rock.youngs_modulus,
               "block_nu": rock.poisson_ratio, "tensile_strength": rock.tensile_strength,
               "cohesion": rock.cohesion, "friction_angle": rock.friction_angle, **result}
        self.history.append(row)
        shown = ", ".join(f"{k} {v:.4g}" for k, v in result.items())
        self.log(f"  [{self.used}/{self.budget}] {kind}: {shown}")
        return row

    def elastic(self, rock: RockConfig) -> tuple[float, float, float]:
        """(E, ν, ℓ) from a short elastic UCS run with unbreakable springs."""
        self._spend("elastic", rock)
        r = rock.model_copy(update={"unbreakable": True})
        # elastic runs are short: always at a slow, quasi-static speed (≤ 0.025 m/s)
        s = LoadSettings(**{**self.us.as_dict(), "max_strain": 4e-4, "sample_strain": 1e-5,
                            "speed": min(self.us.speed, ELASTIC_SPEED)})
        spec = ucs_specimen(r, self.ucs_mesh, self.seed, self.device)
        res = analyse_ucs(spec, run_loading(spec, s), s)
        self._record("elastic", rock, {"E": res.youngs_modulus, "nu": res.poisson_ratio})
        return res.youngs_modulus, res.poisson_ratio, edge_density(spec.model)

    def brazilian(self, rock: RockConfig) -> float:
        self._spend("brazilian", rock)
        res = run_brazilian(rock, self.bs, self.braz_mesh, self.seed, self.device)
        self._record("brazilian", rock, {"sigma_t": res.tensile_strength})
        return res.tensile_strength

    def ucs(self, rock: RockConfig) -> tuple[float, float, float]:
        self._spend("ucs", rock)
        res = run_ucs(rock, self.us, self.ucs_mesh, self.seed, self.device)
        self._record("ucs", rock, {"UCS": res.ucs, "E": res.youngs_modulus, "nu": res.poisson_ratio})
        return res.ucs, res.youngs_modulus, res.poisson_ratio


def _with(rock: RockConfig, **kw) -> RockConfig:
    return rock.model_copy(update=kw)


def per_area(rock: RockConfig, ell: float) -> RockConfig:
    """The rock in 'per_area' stiffness mode (penalty mode: kn = ks = β·E'/h̄ with h̄ ≈ 2/ℓ... taken as
    β·E'·ℓ/2, the mean over a mesh whose interior edge density is ℓ)."""
    if rock.stiffness_mode == "per_area":
        return rock
    k = rock.spring_penalty * rock.plane_strain_modulus * ell / 2.0
    return _with(rock, stiffness_mode="per_area", kn=k, ks=k)


def fit_elastic(lab: Lab, rock: RockConfig, cfg: FitConfig, report: dict) -> RockConfig:
    """Stage 1: defect-corrected least squares on two elastic parameters (see module doc)."""
    from scipy.optimize import least_squares

    tE, tnu = cfg.targets.get("youngs_modulus"), cfg.targets.get("poisson_ratio")
    if tE is None and tnu is None:
        return rock
    names = list(cfg.elastic_parameters)
    E_m, nu_m, ell = lab.elastic(rock)
    rock = per_area(rock, ell)

    def params(r):
        return {"kn": r.kn, "ks": r.ks, "youngs_modulus": r.youngs_modulus, "poisson_ratio": r.poisson_ratio}

    def model(r_params):
        return np.array(effective_moduli(r_params["youngs_modulus"], r_params["poisson_ratio"], ell,
                                         r_params["kn"], r_params["ks"]))

    def to_x(p):
        return np.array([math.log(p[n]) if n != "poisson_ratio" else p[n] for n in names])

    def from_x(x, base):
        p = dict(base)
        for n, xi in zip(names, x):
            p[n] = math.exp(xi) if n != "poisson_ratio" else float(xi)
        return p

    lo = [math.log(1e9) if n in ("kn", "ks") else (math.log(1e8) if n == "youngs_modulus" else 0.0) for n in names]
    hi = [math.log(1e19) if n in ("kn", "ks") else (math.log(1e13) if n == "youngs_modulus" else 0.499) for n in names]
    target = np.array([tE if tE is not None else np.nan, tnu if tnu is not None else np.nan])
    scale = np.array([tE or 1.0, 0.1])
    meas = np.array([E_m, nu_m])
    steps = []
    for it in range(cfg.elastic_iterations):
        p0 = params(rock)
        bias = meas - model(p0)
        steps.append({"iteration": it, "measured": meas.tolist(), "bias": bias.tolist(), **{n: p0[n] for n in names}})
        err = np.nan_to_num((meas - target) / scale)
        if abs(err[0]) <= cfg.rtol_modulus and abs(err[1]) * 0.1 <= cfg.atol_poisson:
            break
        sel = ~np.isnan(target)

        def resid(x):
            return ((model(from_x(x, p0)) + bias - target) / scale)[sel]

        sol = least_squares(resid, to_x(p0), bounds=(lo, hi), x_scale=1.0, xtol=1e-12, ftol=1e-12)
        new = from_x(sol.x, p0)
        if np.any(np.abs(sol.fun) > 1e-3):
            lab.log(f"  elastic targets not reachable with {names} free (analytic residual {sol.fun}); "
                    "taking the closest point")
        rock = _with(rock, kn=new["kn"], ks=new["ks"], youngs_modulus=new["youngs_modulus"],
                     poisson_ratio=new["poisson_ratio"])
        try:
            E_m, nu_m, _ = lab.elastic(rock)
        except BudgetExhausted:
            break
        meas = np.array([E_m, nu_m])
    report["elastic"] = {"parameters": names, "edge_density_per_m": ell, "iterations": steps,
                         "final_measured": {"youngs_modulus": float(meas[0]), "poisson_ratio": float(meas[1])}}
    return rock


def fit_scalar(evaluate, x0: float, target: float, rtol: float, max_evals: int) -> tuple[float, float, list]:
    """Solve evaluate(x) = target for x > 0 by the secant method (scipy root_scalar), first step
    x1 = x0·target/evaluate(x0) (response ∝ x). Returns (best x, its value, [(x, value), ...])."""
    from scipy.optimize import root_scalar

    seen: dict[float, float] = {}

    def f(x):
        x = float(max(x, 1e-6 * x0))
        if x not in seen:
            if len(seen) >= max_evals:
                raise BudgetExhausted("stage iterations used up")
            seen[x] = evaluate(x)
            if abs(seen[x] - target) <= rtol * target:
                raise _Converged
        return seen[x] - target

    try:
        f0 = f(x0) + target
        x1 = x0 * target / f0 if f0 > 0 else 2 * x0
        root_scalar(f, method="secant", x0=x0, x1=x1, xtol=1e-6 * x0, maxiter=max_evals)
    except (_Converged, BudgetExhausted, ValueError, RuntimeError):
        pass
    if not seen:
        raise BudgetExhausted("no evaluation possible")
    best = min(seen, key=lambda x: abs(seen[x] - target))
    return best, seen[best], sorted(seen.items())


def fit(rock: RockConfig, cfg: FitConfig, lab: Lab) -> dict:
    """Run the staged fit; returns a JSON-ready report with the fitted micro-parameters."""
    report: dict = {"targets": cfg.targets, "start": rock.model_dump(), "budget": lab.budget}
    if cfg.friction_angle is not None:
        rock = _with(rock, friction_angle=float(cfg.friction_angle))
    achieved: dict = {}
    try:
        rock = fit_elastic(lab, rock, cfg, report)
        tt = cfg.targets.get("tensile_strength")
        if tt is not None:
            x, val, pts = fit_scalar(lambda T: lab.brazilian(_with(rock, tensile_strength=T)),
                                     rock.tensile_strength, tt, cfg.rtol_strength, cfg.strength_iterations)
            rock = _with(rock, tensile_strength=x)
            achieved["tensile_strength"] = val
            report["tensile"] = {"points": pts}
        tu = cfg.targets.get("ucs")
        if tu is not None:
            last: dict = {}

            def ucs_of(c):
                u, E, nu = lab.ucs(_with(rock, cohesion=c))
                last[c] = (E, nu)
                return u

            x, val, pts = fit_scalar(ucs_of, rock.cohesion, tu, cfg.rtol_strength, cfg.strength_iterations)
            rock = _with(rock, cohesion=x)
            achieved["ucs"] = val
            achieved["youngs_modulus"], achieved["poisson_ratio"] = last[x]
            report["ucs"] = {"points": pts}
        if tt is not None and tu is not None:
            achieved["tensile_strength"] = lab.brazilian(rock)
    except BudgetExhausted as e:
        report["stopped"] = str(e)
    report["fitted"] = rock.model_dump()
    report["achieved"] = achieved
    report["relative_error"] = {k: (achieved[k] - v) / v for k, v in cfg.targets.items() if k in achieved}
    if cfg.sensitivity:
        try:
            report["sensitivity"] = sensitivity(lab, rock, cfg.sensitivity_step, achieved)
        except BudgetExhausted as e:
            report["sensitivity"] = {"skipped": str(e)}
    report["simulations"] = lab.used
    report["history"] = lab.history
    return report


def sensitivity(lab: Lab, rock: RockConfig, step: float, base: dict) -> dict:
    """d ln(macro)/d ln(micro) by one-sided finite differences at ``rock`` (φ in degrees: +2°).

    kn, ks: elastic runs (E, ν); T, c, φ: Brazilian + UCS runs (σt, UCS). Base values come from
    ``base`` (the fit's last runs) or are measured here.
    """
    out: dict = {}
    if "youngs_modulus" not in base:
        base["youngs_modulus"], base["poisson_ratio"], _ = lab.elastic(rock)
    if "tensile_strength" not in base:
        base["tensile_strength"] = lab.brazilian(rock)
    if "ucs" not in base:
        base["ucs"] = lab.ucs(rock)[0]
    if rock.stiffness_mode == "per_area":
        for name in ("kn", "ks"):
            E, nu, _ = lab.elastic(_with(rock, **{name: getattr(rock, name) * (1 + step)}))
            d = math.log(1 + step)
            out[name] = {"youngs_modulus": math.log(E / base["youngs_modulus"]) / d,
                         "poisson_ratio": math.log(nu / base["poisson_ratio"]) / d}
    for name, new in (("tensile_strength", rock.tensile_strength * (1 + step)),
                      ("cohesion", rock.cohesion * (1 + step)),
                      ("friction_angle", rock.friction_angle + 2.0)):
        r = _with(rock, **{name: new})
        st = lab.brazilian(r)
        u = lab.ucs(r)[0]
        d = math.log(new / getattr(rock, name))
        out[name] = {"tensile_strength": math.log(st / base["tensile_strength"]) / d,
                     "ucs": math.log(u / base["ucs"]) / d}
    return out
