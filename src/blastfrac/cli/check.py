"""``blastfrac check SCENARIO``: validate and report what would run, without running."""

from __future__ import annotations

import math

from .common import add_force_arg, add_scenario_args, check_output_dir, load, resolve_device


STEPS_WARNING = 10_000_000    # check warns above this many steps to the end time


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
                   ("gas particles", f"{sim.gas.n}")]
        limit = min((("rock", sc.simulation.dt_safety * m.stable_dt), ("contact", dt_c), ("MPM", dt_g)),
                    key=lambda kv: kv[1])[0]
        dt_rows.append(("step limited by", limit))
    el = m.elastic
    cp, cs = el.assembly_speeds
    cp0, _ = el.speeds(el.input_E, el.input_nu, el.density)
    steps = math.ceil(sc.simulation.end_time / dt)
    insitu_text = "no"
    if sc.insitu.active:
        import numpy as np

        span = float(np.ptp(m.host["node_X"], axis=0).max())
        lo = int(2 * span / sc.rock.p_wave_speed / (sc.simulation.dt_safety * m.stable_dt)) + 1
        insitu_text = (f"{sc.insitu.method}: {'no relaxation' if sc.insitu.method == 'initial' else f'{lo:,} to {sc.insitu.max_steps:,} steps'}"
                       f" (at least two P-wave transits, then until KE/U < {sc.insitu.tolerance:g})")
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
        ("stable dt rock (Gershgorin)", f"{m.stable_dt:.4e} s"),
        *dt_rows,
        ("dt used", f"{dt:.4e} s"),
        ("end time", f"{sc.simulation.end_time:.4e} s"),
        ("steps to end time", f"{steps:,}" + (f" (capped at {sc.simulation.max_steps})" if sc.simulation.max_steps else "")),
        ("in-situ stage", insitu_text),
        ("memory (model + state)", f"{(model_bytes(m) + state_bytes) / 2**20:.1f} MiB"),
        ("output directory", sc.output.directory),
    ]
    if sc.explosive is not None:
        from ..explosives.library import cj_report

        rep = cj_report(sc.explosive.jwl(), sc.explosive.name or "custom")
        rows.append(("explosive CJ check", rep["message"]))
    w = max(len(k) for k, _ in rows)
    print(f"scenario {args.scenario}: valid")
    for k, v in rows:
        print(f"  {k:<{w}}  {v}")
    if steps > STEPS_WARNING:
        import sys

        print(f"warning: {steps:,} steps to the end time (more than {STEPS_WARNING:,}); the step is set by "
              f"{dt_rows[-1][1] if dt_rows else 'the rock'}: check coupling.contact_stiffness, the mesh size near "
              "the holes and simulation.end_time", file=sys.stderr)
    return 0
