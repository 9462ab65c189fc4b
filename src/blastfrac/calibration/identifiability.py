"""Identifiability of fitted micro-parameters from the fit's sensitivities (docs/calibration.md).

A micro-parameter is *identifiable* from the targets only if some targeted macro property responds
to it. With the sensitivities s_kj = d ln(macro_k)/d ln(micro_j) (:func:`.fit.sensitivity`) and the
relative tolerance tol_k of each targeted macro (the fit's own tolerances):

- **status** ``not identifiable`` when max_k |s_kj| < ``threshold`` (default 0.1, the same bound at
  which the 1-D strength stages call a response flat): the targets cannot pin micro j down.
- **alone**: the first-order range of micro j, the others held, over which every targeted macro
  stays within its tolerance: |ln(x/x_fit)| ≤ w_j = min_k tol_k/|s_kj|. Any value in [a, b] then
  reproduces the fitted point's macro values within tolerance (to first order; w is capped at
  ln ``cap``, and an interval at the cap is open-ended).
- **jointly**: the same range when the other free micro-parameters may move too (a linear program
  on |Σ_i s_ki δ_i| ≤ tol_k, |δ_i| ≤ ln cap). A parameter that responds on its own but trades off
  against others (e.g. kn against T for σt) gets a wide joint range; if that range reaches the cap
  the status is ``not identifiable jointly``.

The sensitivities are one-sided differences (+5 %), so the range is a local, first-order statement:
a response with a kink (σt flat in T above the point where Mohr–Coulomb takes over, linear below)
can make the range on the far side of the kink too wide, and a noisy response (the UCS of a brittle
lattice jumps with small changes of kn, ks) can hide a real dependence. The fit therefore *measures*
the range of every parameter it finds not identifiable (:func:`probe_interval`); if targets leave
their tolerance on both sides, the status becomes ``identifiable (measured)``.
"""

from __future__ import annotations

import math

THRESHOLD = 0.1     # |d ln macro / d ln micro| below this for every targeted macro: not identifiable
CAP = 10.0          # intervals are not extended beyond ×/÷ CAP (then reported as open-ended)
SYMBOL = {"kn": "kn", "ks": "ks", "tensile_strength": "T", "cohesion": "c", "friction_angle": "φ",
          "youngs_modulus": "E", "poisson_ratio": "ν", "ucs": "UCS"}
MACRO_SYMBOL = {"youngs_modulus": "E", "poisson_ratio": "ν", "tensile_strength": "σt", "ucs": "UCS"}


def relative_tolerances(targets: dict, rtol_modulus: float, atol_poisson: float, rtol_strength: float) -> dict:
    """Relative tolerance of each targeted macro property, as the fit uses them (ν: atol / target)."""
    tol = {}
    for k, v in targets.items():
        if k == "youngs_modulus":
            tol[k] = rtol_modulus
        elif k == "poisson_ratio":
            tol[k] = atol_poisson / v
        elif k in ("tensile_strength", "ucs"):
            tol[k] = rtol_strength
    return tol


def _joint_half_widths(S, tol, cap_ln):
    """For each column j: max |δ_j| subject to |S δ| ≤ tol (row-wise), |δ| ≤ cap_ln (linear programs)."""
    import numpy as np
    from scipy.optimize import linprog

    S = np.asarray(S, float)
    tol = np.asarray(tol, float)
    m, n = S.shape
    A = np.vstack([S, -S])
    b = np.concatenate([tol, tol])
    out = []
    for j in range(n):
        best = 0.0
        for sign in (1.0, -1.0):
            cvec = np.zeros(n)
            cvec[j] = -sign                      # maximise sign·δ_j
            res = linprog(cvec, A_ub=A, b_ub=b, bounds=[(-cap_ln, cap_ln)] * n, method="highs")
            if res.status == 0:
                best = max(best, float(sign * res.x[j]))
        out.append(best)
    return out


def identifiability(sens: dict, tol: dict, values: dict, free: list[str] | None = None,
                    threshold: float = THRESHOLD, cap: float = CAP) -> dict:
    """Classify each free micro-parameter (module doc).

    sens: {micro: {macro: d ln macro/d ln micro}} (extra keys such as "base" are ignored);
    tol: {macro: relative tolerance} of the targeted macros; values: {micro: fitted value};
    free: the micro-parameters the fit moved (default: those in both ``sens`` and ``values``).
    Returns {micro: {...}} with status, max_response, governing macro, the interval alone and
    jointly, and a one-line statement.
    """
    free = [j for j in (free if free is not None else values) if j in sens and j in values]
    macros = [k for k in tol if any(k in sens[j] for j in free)]     # a missing entry is no response
    cap_ln = math.log(cap)
    S = [[float(sens[j].get(k, 0.0)) for j in free] for k in macros]
    joint = _joint_half_widths(S, [tol[k] for k in macros], cap_ln) if free and macros else [cap_ln] * len(free)
    out = {}
    for col, j in enumerate(free):
        resp = {k: abs(float(sens[j].get(k, 0.0))) for k in macros}
        kmax = max(resp, key=resp.get) if resp else None
        smax = resp[kmax] if kmax else 0.0
        w = min([tol[k] / r for k, r in resp.items() if r > 0] or [math.inf])
        w_alone = min(w, cap_ln)
        w_joint = min(joint[col], cap_ln)
        x = float(values[j])
        open_alone = bool(w >= cap_ln * (1 - 1e-9))
        open_joint = bool(w_joint >= cap_ln * (1 - 1e-6))
        if smax < threshold:
            status = "not identifiable"
        elif open_joint:
            status = "not identifiable jointly"
        else:
            status = "identifiable"
        alone = [x * math.exp(-w_alone), x * math.exp(w_alone)]
        jointly = [x * math.exp(-w_joint), x * math.exp(w_joint)]
        name = SYMBOL.get(j, j)
        gov = MACRO_SYMBOL.get(kmax, kmax)
        rng = (f"[{alone[0]:.3g}, {alone[1]:.3g}]" + (f" or wider (capped at ×/÷{cap:g})" if open_alone else ""))
        if status == "not identifiable":
            text = (f"{name} = {x:.4g}: not identifiable: max |d ln macro/d ln {name}| = {smax:.3f} ({gov}) < "
                    f"{threshold:g}; any value in {rng} reproduces the targets within tolerance (others held, "
                    "first order)")
        elif status == "not identifiable jointly":
            text = (f"{name} = {x:.4g}: responds alone (|d ln {gov}/d ln {name}| = {smax:.3f}; alone {rng}) but "
                    f"not jointly: with the other free parameters re-adjusted any value in "
                    f"[{jointly[0]:.3g}, {jointly[1]:.3g}] or wider reproduces the targets")
        else:
            text = (f"{name} = {x:.4g}: identifiable (|d ln {gov}/d ln {name}| = {smax:.3f}); within tolerance for "
                    f"{rng} alone, [{jointly[0]:.3g}, {jointly[1]:.3g}] with the others re-adjusted")
        out[j] = {"status": status, "value": x, "max_response": smax, "governing_macro": kmax,
                  "responses": resp, "interval_alone": alone, "interval_alone_open": open_alone,
                  "interval_jointly": jointly, "interval_jointly_open": open_joint, "statement": text}
    return out


def probe_interval(measure, x_fit: float, base: dict, tol: dict, ends: tuple, tries: int = 2,
                   log=print, name: str = "") -> dict:
    """Measure where a parameter stops reproducing the fitted point: for each end of ``ends`` (the
    first-order interval), evaluate ``measure(x)`` -> {macro: value}; if every targeted macro is within
    its tolerance of ``base`` the end is confirmed, otherwise the step is halved in ln x (at most
    ``tries`` evaluations per side). Returns the confirmed interval (x_fit on a side with no
    confirmed point) and every probe point."""
    points, confirmed = [], [x_fit, x_fit]
    for side, end in enumerate(ends):
        x = float(end)
        for _ in range(tries):
            vals = measure(x)
            dev = {k: float(vals[k] / base[k] - 1.0) for k in tol if k in vals}
            ok = bool(all(abs(d) <= tol[k] for k, d in dev.items()))
            points.append({"value": x, "macro": {k: float(v) for k, v in vals.items()}, "relative_change": dev,
                           "within_tolerance": ok})
            log(f"  identifiability probe {name} = {x:.4g}: " + ", ".join(
                f"{MACRO_SYMBOL.get(k, k)} {d:+.2%}" for k, d in dev.items()) + (" (within)" if ok else " (out)"))
            if ok:
                confirmed[side] = x
                break
            x = math.sqrt(x * x_fit)
    below = [p["value"] for p in points if not p["within_tolerance"] and p["value"] < x_fit]
    above = [p["value"] for p in points if not p["within_tolerance"] and p["value"] > x_fit]
    bracket = [max(below) if below else None, min(above) if above else None]
    return {"measured_interval": confirmed, "measured_bracket": bracket,
            "probe_points": sorted(points, key=lambda p: p["value"])}


def measured_status(entry: dict) -> str:
    """Status after a probe: ``identifiable (measured)`` when probe points on *both* sides moved a
    target out of tolerance (the parameter is bounded, the one-sided sensitivity missed it: a noisy or
    non-smooth response); otherwise ``not identifiable`` (on at least one side the range reaches the
    first-order end, ×/÷ cap for a flat response)."""
    lo, hi = entry["measured_bracket"]
    return "identifiable (measured)" if lo is not None and hi is not None else "not identifiable"


def probed_statement(entry: dict, name: str, tol: dict, mesh: str) -> str:
    a, b = entry["measured_interval"]
    out = [p for p in entry["probe_points"] if not p["within_tolerance"]]
    tols = ", ".join(f"{MACRO_SYMBOL.get(k, k)} ±{v:.1%}" for k, v in tol.items())
    if entry["status"] == "identifiable (measured)":
        lo, hi = entry["measured_bracket"]
        text = (f"{name} = {entry['value']:.4g}: identifiable (measured): the one-sided sensitivity "
                f"{entry['max_response']:.3f} is below the threshold, but runs on the {mesh} meshes bracket it: "
                f"within tolerance ({tols}) on [{a:.4g}, {b:.4g}]")
    else:
        text = (f"{name} = {entry['value']:.4g}: not identifiable (max |d ln macro/d ln {name}| = "
                f"{entry['max_response']:.3f} < threshold): measured on the {mesh} meshes, any value in "
                f"[{a:.4g}, {b:.4g}] reproduces the fitted point's macro values within tolerance ({tols})")
    if out:
        text += "; out of tolerance at " + ", ".join(
            f"{p['value']:.4g} (" + ", ".join(f"{MACRO_SYMBOL.get(k, k)} {d:+.1%}" for k, d in
                                             p["relative_change"].items() if abs(d) > tol[k]) + ")" for p in out)
    return text


def identifiability_of_report(report: dict, threshold: float = THRESHOLD, cap: float = CAP) -> dict:
    """Identifiability from a stored fit report (``fit.json``): its sensitivities, targets and tolerances.
    The free parameters are the elastic ones, T when σt is a target and c when the UCS is."""
    sens = report.get("sensitivity", {})
    if "base" not in sens:
        return {"skipped": "no sensitivities in this fit (set [fit] sensitivity = true)"}
    cfg, targets = report.get("config", {}), report["targets"]
    tol = relative_tolerances(targets, cfg.get("rtol_modulus", 0.01), cfg.get("atol_poisson", 0.005),
                              cfg.get("rtol_strength", 0.02))
    free = []
    if "youngs_modulus" in targets or "poisson_ratio" in targets:
        free += list(cfg.get("elastic_parameters", ("kn", "ks")))
    if "tensile_strength" in targets:
        free.append("tensile_strength")
    if "ucs" in targets:
        free.append("cohesion")
    values = {j: report["fitted"][j] for j in free if report["fitted"].get(j) is not None}
    res = identifiability(sens, tol, values, free, threshold, cap)
    return {"threshold": threshold, "cap": cap, "tolerances": tol, "mesh": sens.get("mesh"),
            "note": "first order, from one-sided +{:.0%} differences at the fitted point; kinks (a criterion "
                    "taking over) are not seen beyond the step".format(sens.get("step", 0.05)),
            "parameters": res}


def main(argv: list[str] | None = None) -> int:
    """``python -m blastfrac.calibration.identifiability FIT.json``: print the identifiability of a stored fit."""
    import json
    import sys
    from pathlib import Path

    args = sys.argv[1:] if argv is None else argv
    if len(args) != 1:
        print("usage: python -m blastfrac.calibration.identifiability FIT.json", file=sys.stderr)
        return 2
    rep = identifiability_of_report(json.loads(Path(args[0]).read_text()))
    if "skipped" in rep:
        print(rep["skipped"])
        return 0
    print(f"identifiability (threshold {rep['threshold']:g}, tolerances "
          + ", ".join(f"{MACRO_SYMBOL[k]} {v:.1%}" for k, v in rep["tolerances"].items()) + "):")
    for p in rep["parameters"].values():
        print("  " + p["statement"])
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
