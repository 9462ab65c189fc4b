"""``blastfrac check SCENARIO``: validate and report what would run, without running."""

from __future__ import annotations

import math

from .common import add_force_arg, add_scenario_args, check_output_dir, load, resolve_device


STEPS_WARNING = 10_000_000    # check warns above this many steps to the end time
# check warns when a charge has fewer MPM cells than this across its width (circle: 2r/h; charge_width). From the
# study examples/charge_resolution (README.md: a 5 mm emulsion charge filling its hole in elastic Table 2 rock, 10 to
# 80 cells across), with the 0.2 gas defaults: the wall impulse over 5-10 µs (detonation and first reverberations)
# is off by up to 3.6 % at 10 cells, 1.8 % at 20 and 1.1 % at 40 against 80 cells; the 10-20 µs impulse
# (quasi-static gas pressure) within 1.1 % of 40 cells already at 10. 20 is the coarsest level that keeps the early
# impulse within 2 %. (With pure FLIP and q2 = 0.06, the defaults before 0.2: 7.3 / 3.7 / 1.6 %.)
CHARGE_CELLS_ACROSS_MIN = 20


def _blocks_alone(m) -> str:
    """What the blocks alone would allow (the Gershgorin bound of their CST rows, no springs) beside the rock's step,
    and whether the springs set it: with the stiff penalty springs they do, by a factor of ~6 on the demo's mesh
    (docs/rock_fronts.md, "Why the spring penalty stays at β = 20")."""
    import numpy as np

    from ..model.builder import element_row_sums

    row = element_row_sums(m.host["node_X"], m.lam, m.mu)
    dt = 2.0 / math.sqrt(float(np.max(row / m.host["node_mass_dt"][:, None])))
    if dt > 1.2 * m.stable_dt:
        return f" (the blocks alone would allow {dt:.4e} s: the springs set the step, docs/rock_fronts.md)"
    return f" (the blocks alone: {dt:.4e} s)"


def add_parser(sub) -> None:
    p = sub.add_parser("check", help="validate a scenario and print what would run")
    add_scenario_args(p)
    add_force_arg(p)
    p.set_defaults(func=run)


def model_bytes(model) -> int:
    import warp as wp

    total = 0
    for v in vars(model).values():
        if isinstance(v, wp.array):
            total += v.capacity
    return total


def run(args) -> int:
    from ..scenario import ScenarioError
    from ..model.builder import ModelBuilder
    from ..scenario.sizes import check_sizes

    sc = load(args)
    check_output_dir(sc.output.directory, "output.directory")
    resolve_device(sc, args)
    est = check_sizes(sc, force=args.force)
    try:
        b = ModelBuilder(sc)
    except ValueError as e:
        raise ScenarioError(str(e)) from None
    m = b.finalize("cpu")
    st = m.state()
    import warp as wp

    state_bytes = sum(v.capacity for v in vars(st).values() if isinstance(v, wp.array))
    dt = sc.simulation.dt_safety * m.stable_dt
    dt_rows = []
    if sc.explosive is not None:          # the run's step is the smallest of rock, gas-rock contact and MPM
        from ..simulation import Simulation

        try:
            sim = Simulation(sc, mesh=b.mesh)
        except ValueError as e:
            raise ScenarioError(str(e)) from None
        dt_c = sc.simulation.dt_safety * sim.coupler.stable_dt()
        dt_g = sim.gas.stable_dt()
        dt = sim.dt
        dt_rows = [("dt contact (x dt_safety)", f"{dt_c:.4e} s"),
                   ("dt MPM (CFL, at ignition)", f"{dt_g:.4e} s (changes with the gas speed during the run)"),
                   ("gas particles", f"{sim.gas.n - sim.gas.n_solid}")]
        for k, b in enumerate(sim.gas_report.get("bodies", [])):
            eb = sc.explosive.bodies[k]
            text = (f"{b['particles']} points, {b['mass']:.4g} kg/m, E {eb.youngs_modulus / 1e9:.4g} GPa, "
                    f"nu {eb.poisson_ratio:.4g}, c_p {b['p_wave_speed']:.1f} m/s, "
                    f"v ({eb.velocity[0]:.4g}, {eb.velocity[1]:.4g}) m/s")
            dt_rows.append((f"elastic body {b['name']}", text))
        limit = min((("rock", sc.simulation.dt_safety * m.stable_dt), ("contact", dt_c), ("MPM", dt_g)),
                    key=lambda kv: kv[1])[0]
        dt_rows.append(("step limited by", limit))
    el = m.elastic
    cp, cs = el.assembly_speeds
    cp0, _ = el.speeds(el.input_E, el.input_nu, el.density)
    steps = math.ceil(sc.simulation.end_time / dt)
    insitu_text = "no"
    if sc.insitu.active:
        from ..insitu_stage import relaxation_floor

        lo = relaxation_floor(m, sc, sc.simulation.dt_safety * m.stable_dt)
        insitu_text = (f"{sc.insitu.method}: {'no relaxation' if sc.insitu.method == 'initial' else f'{lo:,} to {sc.insitu.max_steps:,} steps'}"
                       f" (at least {sc.insitu.min_transits:g} P-wave transit{'' if sc.insitu.min_transits == 1 else 's'} of the domain, "
                       f"then until KE/U < "
                       f"{sc.insitu.tolerance:g})")
    rows = [
        ("title", sc.title or "-"),
        ("device", sc.simulation.device),
        *est.rows(),
        ("elements (blocks)", f"{m.element_count}"),
        ("nodes", f"{m.node_count}"),
        ("springs (node pairs)", f"{m.spring_count} on {m.interface_count} interfaces"),
        ("boreholes", f"{len(sc.geometry.boreholes)}"),
        ("rock E, nu (input)", f"{el.input_E / 1e9:.4g} GPa, {el.input_nu:.4g}"),
        ("block E, nu", f"{el.block_E / 1e9:.4g} GPa, {el.block_nu:.4g}"
         + (" (compensated for the spring compliance)" if el.compensated else " (as given)")),
        ("assembly E, nu, c_p, c_s", f"{el.assembly_E / 1e9:.4g} GPa, {el.assembly_nu:.4g}, {cp:.1f} m/s, {cs:.1f} m/s"
         + f" (c_p {cp / cp0 - 1:+.2%} against the input)"),
        ("stable dt rock (Gershgorin)", f"{m.stable_dt:.4e} s" + _blocks_alone(m)),
        *dt_rows,
        ("dt used", f"{dt:.4e} s"),
        ("end time", f"{sc.simulation.end_time:.4e} s"),
        ("steps to end time", f"{steps:,}" + (f" (capped at {sc.simulation.max_steps})" if sc.simulation.max_steps else "")),
        ("in-situ stage", insitu_text),
        ("memory (model + state)", f"{(model_bytes(m) + state_bytes) / 2**20:.1f} MiB"),
        ("output directory", sc.output.directory),
    ]
    het = sc.rock.heterogeneity
    if het.active:                            # Weibull spring properties (docs/heterogeneity.md)
        from ..model.heterogeneity import weibull_cv

        if het.correlation_length:
            scaling = f", spatially correlated over ℓ = {het.correlation_length:.4g} m"
        elif het.reference_length:
            scaling = f", weakest-link scaling to L_ref = {het.reference_length:.4g} m"
        else:
            scaling = ", i.i.d. per interface, no size scaling"
        rows.append(("heterogeneity", f"Weibull m = {het.weibull_modulus:g} (CV {weibull_cv(het.weibull_modulus):.3f}) "
                     f"on {', '.join(het.fields)}{', correlated' if het.correlated else ''}{scaling}, "
                     f"seed {sc.simulation.seed}"))
    if sc.geometry.symmetry:                  # a half or quarter model (docs/explosive.md)
        from ..analysis.symmetry import describe

        rows.append(("symmetry", describe(sc.geometry)))
    if sc.explosive is not None:
        from ..explosives.library import cj_report

        jwl = sc.explosive.jwl()
        if jwl is None:
            rows.append(("explosive CJ check", "no charges (elastic bodies only): no JWL used"))
        else:
            rep = cj_report(jwl, sc.explosive.name or "custom")
            rows.append(("explosive CJ check", rep["message"]))
    w = max(len(k) for k, _ in rows)
    print(f"scenario {args.scenario}: valid")
    for k, v in rows:
        print(f"  {k:<{w}}  {v}")
    if sc.explosive is not None:
        import sys

        for msg in charge_resolution_warnings(sc):
            print(f"warning: {msg}", file=sys.stderr)
    if steps > STEPS_WARNING:
        import sys

        print(f"warning: {steps:,} steps to the end time (more than {STEPS_WARNING:,}); the step is set by "
              f"{dt_rows[-1][1] if dt_rows else 'the rock'}: check coupling.contact_stiffness, the mesh size near "
              "the holes and simulation.end_time", file=sys.stderr)
    return 0


def charge_width(charge) -> float:
    """Width of a charge [m]: a circle's diameter; for a polygon the narrowest chord through it along an edge's inward
    normal from the edge's midpoint (the least width of a convex polygon when a side lies flush with the
    narrowest direction, the local thickness of an arm otherwise)."""
    if charge.kind == "circle":
        return 2.0 * charge.radius
    v = [tuple(map(float, p)) for p in charge.vertices]
    n = len(v)
    sign = 1.0 if sum(v[i][0] * v[(i + 1) % n][1] - v[(i + 1) % n][0] * v[i][1] for i in range(n)) > 0 else -1.0
    best = math.inf
    for i in range(n):
        (ax, ay), (bx, by) = v[i], v[(i + 1) % n]
        L = math.hypot(bx - ax, by - ay)
        mx, my = 0.5 * (ax + bx), 0.5 * (ay + by)
        nx, ny = -sign * (by - ay) / L, sign * (bx - ax) / L          # inward normal
        for j in range(n):                                            # first crossing of the ray with another edge
            if j == i:
                continue
            (cx, cy), (dx, dy) = v[j], v[(j + 1) % n]
            ex, ey = dx - cx, dy - cy
            den = nx * ey - ny * ex
            if den == 0.0:
                continue
            s = ((cx - mx) * ey - (cy - my) * ex) / den               # along the ray
            u = ((cx - mx) * ny - (cy - my) * nx) / den               # along the edge
            if s > 1e-12 * L and -1e-12 <= u <= 1 + 1e-12:
                best = min(best, s)
    if not math.isfinite(best):                                       # not reached for a simple polygon
        (x0, y0), (x1, y1) = charge.bbox
        best = min(x1 - x0, y1 - y0)
    return best


def charge_resolution_warnings(sc) -> list[str]:
    """One message per charge with fewer than CHARGE_CELLS_ACROSS_MIN grid cells across its width (charge_width)."""
    if sc.explosive is None:
        return []
    h = sc.explosive.grid.cell_size
    out = []
    for i, ch in enumerate(sc.explosive.charges):
        w = charge_width(ch)
        cells = w / h
        if cells < CHARGE_CELLS_ACROSS_MIN * (1 - 1e-9):
            what = "2r/h" if ch.kind == "circle" else "narrowest width/h"
            out.append(f"explosive.charges[{i}] ({ch.kind}, {w * 1e3:.4g} mm across): {cells:.3g} grid cells across "
                       f"({what}, explosive.grid.cell_size = {h * 1e3:.4g} mm), fewer than {CHARGE_CELLS_ACROSS_MIN}; "
                       f"its wall impulse over the first 5-10 µs is then off by more than ~2 % (3.6 % at 10 cells, "
                       f"examples/charge_resolution): cell_size <= {w / CHARGE_CELLS_ACROSS_MIN * 1e3:.3g} mm resolves it")
    return out
