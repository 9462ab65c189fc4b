"""``blastfrac calibrate SCENARIO``: simulated UCS and Brazilian tests of a scenario's rock, and an
optional automatic fit of the micro-parameters to macro targets (docs/calibration.md)."""

from __future__ import annotations

import json
from pathlib import Path

from .common import add_scenario_args, check_output_dir, load


def add_parser(sub) -> None:
    p = sub.add_parser("calibrate", help="simulated UCS and Brazilian tests; fit micro-parameters",
                       description="Run simulated UCS (54×108 mm) and Brazilian (54 mm) tests with the rock of a "
                                   "scenario and write calibration.json and figures; with --fit, find kn, ks, "
                                   "T, c that reproduce target E, ν, σt, UCS.")
    add_scenario_args(p)
    p.add_argument("--out", default=None, help="output directory (default: <output.directory>/calibration)")
    p.add_argument("--fit", default=None, metavar="TARGETS.toml", help="fit micro-parameters to these targets")
    p.add_argument("--budget", type=int, default=40,
                   help="most quasi-static runs the fit may make (default 40; static elastic solves are free)")
    p.add_argument("--search-mesh-size", type=float, default=None, metavar="H",
                   help="fit: element size [m] of both specimens for the strength search and the sensitivities; "
                        "the search result is then refined on the final meshes (default: search on the final meshes)")
    p.add_argument("--no-refine", action="store_true",
                   help="fit: stop after the search meshes (the final tests then only verify the result)")
    p.add_argument("--mesh-size", type=float, default=None, metavar="H",
                   help="element size of both specimens [m] (default: sizes giving the paper's 3734/2167 elements)")
    p.add_argument("--ucs-mesh-size", type=float, default=None, metavar="H", help="element size of the UCS prism [m]")
    p.add_argument("--brazilian-mesh-size", type=float, default=None, metavar="H", help="element size of the disc [m]")
    p.add_argument("--speed", type=float, default=None, help="platen speed, each platen [m/s] (default 0.05)")
    p.add_argument("--damping", type=float, default=None, help="Cundall local damping α (default 0: undamped, see docs)")
    p.add_argument("--platens", choices=("frictionless", "bonded"), default="frictionless",
                   help="UCS platen condition: free lateral slip (default) or no-slip")
    p.add_argument("--loading-arc", type=float, default=None, metavar="DEG",
                   help="Brazilian loading arc 2α [deg] (default 15; 0 with --jaw-ratio for curved jaws)")
    p.add_argument("--jaw-ratio", type=float, default=None,
                   help="Brazilian jaw radius / disc radius (default 1.0, conforming; 0 flat platens)")
    p.add_argument("--only", choices=("ucs", "brazilian"), default=None, help="run only one test")
    p.add_argument("--check-speed", action="store_true",
                   help="repeat each test at half the platen speed and report the change of the strengths")
    p.add_argument("--no-figures", action="store_true", help="no PNG figures")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.set_defaults(func=run)


def _settings(args):
    from ..calibration.quasistatic import LoadSettings
    from ..scenario import ScenarioError

    common = {}
    if args.speed is not None:
        if args.speed <= 0:
            raise ScenarioError("--speed must be positive [m/s]")
        common["speed"] = args.speed
    if args.damping is not None:
        if not 0 <= args.damping < 1:
            raise ScenarioError("--damping must be in [0, 1)")
        common["damping"] = args.damping
    for name in ("mesh_size", "ucs_mesh_size", "brazilian_mesh_size", "search_mesh_size", "loading_arc", "jaw_ratio"):
        v = getattr(args, name)
        if v is not None and v < 0 or (v is not None and v == 0 and "mesh" in name):
            raise ScenarioError(f"--{name.replace('_', '-')} must be positive")
    if args.budget <= 0:
        raise ScenarioError("--budget must be a positive integer")
    us = LoadSettings(**common, bonded=args.platens == "bonded")
    from dataclasses import replace

    from ..calibration.brazilian import brazilian_settings

    bs = replace(brazilian_settings(), **common)
    if args.jaw_ratio is not None:
        bs = replace(bs, jaw_ratio=args.jaw_ratio)
    if args.loading_arc is not None:
        bs = replace(bs, loading_arc=args.loading_arc)
    return us, bs


class _Progress:
    """A rich progress bar fed by the tests' on_sample callback."""

    def __init__(self, enabled: bool):
        self.enabled = enabled

    def run(self, label: str, fn, *a, **kw):
        if not self.enabled:
            return fn(*a, **kw)
        from rich.progress import BarColumn, Progress, TextColumn, TimeElapsedColumn

        with Progress(TextColumn("{task.description}"), BarColumn(), TextColumn("{task.fields[stress]}"),
                      TimeElapsedColumn(), transient=True) as prog:
            task = prog.add_task(label, total=1.0, stress="")

            def cb(frac, stress):
                prog.update(task, completed=frac, stress=f"σ {stress / 1e6:7.2f} MPa")

            return fn(*a, on_sample=cb, **kw)


def run(args) -> int:
    import sys

    from ..calibration import run_brazilian, run_ucs
    from ..calibration.report import write_report

    sc = load(args)
    us, bs = _settings(args)
    out = Path(args.out) if args.out else Path(sc.output.directory) / "calibration"
    check_output_dir(out, "--out" if args.out else "output.directory")
    out.mkdir(parents=True, exist_ok=True)
    hu = args.ucs_mesh_size or args.mesh_size
    hb = args.brazilian_mesh_size or args.mesh_size
    dev, seed = sc.simulation.device, sc.simulation.seed
    prog = _Progress(not args.no_progress and sys.stderr.isatty())
    rock = sc.rock
    extra: dict = {}
    if args.fit:
        rock, extra["fit"] = _fit(args, rock, us, bs, hu, hb, seed, dev, out)
    ucs = braz = None
    if args.only != "brazilian":
        ucs = prog.run("UCS test", run_ucs, rock, us, hu, seed, dev, reference=True)
        print(f"UCS test ({ucs.specimen.element_count} elements, {ucs.run.steps} steps, {ucs.run.wall_s:.0f} s): "
              f"E = {ucs.youngs_modulus / 1e9:.2f} GPa, ν = {ucs.poisson_ratio:.3f} (plane strain E' = "
              f"{ucs.youngs_modulus_ps / 1e9:.2f} GPa, ν' = {ucs.poisson_ratio_ps:.3f}), UCS = {ucs.ucs / 1e6:.1f} MPa")
        ref = ucs.reference
        print("  elastic references, plane strain: " + ", ".join(
            f"{k} E' = {ref[k]['youngs_modulus_ps'] / 1e9:.2f} GPa, ν' = {ref[k]['poisson_ratio_ps']:.3f}"
            for k in ("blocks", "analytic", "static") if k in ref))
    if args.only != "ucs":
        braz = prog.run("Brazilian test", run_brazilian, rock, bs, hb, seed, dev)
        print(f"Brazilian test ({braz.specimen.element_count} elements, {braz.run.steps} steps, "
              f"{braz.run.wall_s:.0f} s): σt = {braz.tensile_strength / 1e6:.2f} MPa, first tensile failures at "
              f"median r/R = {braz.initiation_radius:.2f}")
    if args.check_speed:
        extra["speed_check"] = _speed_check(prog, rock, us, bs, hu, hb, seed, dev, ucs, braz)
    title = sc.title + (" — fitted micro-parameters" if args.fit else "")
    data = write_report(out, rock, ucs, braz, extra, figures=not args.no_figures, title=title)
    print(f"results in {out}/calibration.json" + ("" if args.no_figures else " (+ stress_strain.png, failed_specimens.png)"))
    if "speed_check" in data:
        for k, v in data["speed_check"].items():
            print(f"half speed: {k} {v['full_speed']:.4g} → {v['half_speed']:.4g} ({v['relative_change']:+.2%})")
    return 0


def _speed_check(prog, rock, us, bs, hu, hb, seed, dev, ucs, braz) -> dict:
    from dataclasses import replace

    from ..calibration import run_brazilian, run_ucs

    res = {}
    if ucs is not None:
        half = prog.run("UCS test, half speed", run_ucs, rock, replace(us, speed=us.speed / 2), hu, seed, dev)
        for k in ("ucs", "youngs_modulus", "poisson_ratio"):
            a, b = getattr(ucs, k), getattr(half, k)
            res[k] = {"full_speed": a, "half_speed": b, "relative_change": (b - a) / a}
    if braz is not None:
        half = prog.run("Brazilian test, half speed", run_brazilian, rock, replace(bs, speed=bs.speed / 2), hb, seed, dev)
        a, b = braz.tensile_strength, half.tensile_strength
        res["tensile_strength"] = {"full_speed": a, "half_speed": b, "relative_change": (b - a) / a}
    return res


def _fit(args, rock, us, bs, hu, hb, seed, dev, out: Path):
    import tomli_w

    from ..calibration.fit import Lab, fit, load_targets, sensitivity_table

    cfg = load_targets(args.fit)
    print(f"fitting {sorted(cfg.targets)} with a budget of {args.budget} quasi-static runs")
    budget = [args.budget, 0]
    lab = Lab(budget, us, bs, hu, hb, seed, dev, name="final")
    search = None
    if args.search_mesh_size:
        search = Lab(budget, us, bs, args.search_mesh_size, args.search_mesh_size, seed, dev, name="search")
    rep = fit(rock, cfg, lab, search, refine=not args.no_refine)
    (out / "fit.json").write_text(json.dumps(rep, indent=2, default=float))
    fitted = type(rock).model_validate(rep["fitted"])
    keep = {k: v for k, v in fitted.model_dump().items() if v is not None}
    (out / "fitted_rock.toml").write_text(tomli_w.dumps({"rock": keep}))
    print("fitted: kn = {kn:.4g} Pa/m, ks = {ks:.4g} Pa/m, T = {t:.4g} MPa, c = {c:.4g} MPa, φ = {p:g}° "
          "({n} runs, {s} static solves, {w:.0f} s)".format(
              kn=fitted.kn or float("nan"), ks=fitted.ks or float("nan"), t=fitted.tensile_strength / 1e6,
              c=fitted.cohesion / 1e6, p=fitted.friction_angle, n=rep["simulations"], s=rep["static_solves"],
              w=rep["wall_s"]))
    if "stopped" in rep:
        print(f"  fit stopped early: {rep['stopped']}")
    for k, e in rep["relative_error"].items():
        print(f"  {k}: achieved {rep['achieved'][k]:.4g}, target {cfg.targets[k]:.4g} ({e:+.2%}) "
              f"[{rep['achieved_on']} meshes]")
    sens = rep.get("sensitivity", {})
    if "base" in sens:
        print(f"sensitivities d ln(macro)/d ln(micro) on the {sens['mesh']} meshes:")
        print(sensitivity_table(sens))
    ident = rep.get("identifiability", {})
    if "parameters" in ident:
        print(f"identifiability (first order, {ident['mesh']} meshes; threshold {ident['threshold']:g}):")
        for p in ident["parameters"].values():
            print("  " + p["statement"])
    elif ident:
        print(f"identifiability: {ident.get('skipped')}")
    keys = ("targets", "fitted", "achieved", "achieved_on", "relative_error", "simulations", "static_solves",
            "identifiability", "wall_s")
    return fitted, {k: rep[k] for k in keys if k in rep}
