"""Side-by-side measurement of treatments for steep fronts in the block lattice (docs/rock_fronts.md).

Each candidate is a set of rock options; each is measured on the same uniaxial-strain strips of the Table 2
rock (tests/verification/front_helpers.py) against the 1D continuum answers:
  * overshoot of a ramp front (amplitude 200 MPa) rising over 4 element transits at h = 1 mm and over the same
    rise time at h = 0.5 mm, and of a step (0.01 µs rise);
  * broken springs under a compressive triangle pulse of 20 T (200 MPa; 0.2 and 0.5 µs rise, 4 µs long) that
    cannot fail the continuum, brittle law and with fracture energies;
  * the peak 40–80 mm in (the damping must not eat the pulse);
  * the first spall of a 50 MPa triangle (0.2 µs rise, 10 µs) at a free end against Rinehart's 1D theory
    (h = 1 mm, and its time at h = 0.5 mm).

Run: python examples/rock_fronts/candidates.py [--out DIR]   (about 4 minutes on 2 cores)
Writes candidates.json and candidates.md (the table of docs/rock_fronts.md).
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE.parents[1] / "tests" / "verification"), str(HERE.parents[1] / "tests")]

from front_helpers import ROCK, p_wave_speed, run_front  # noqa: E402
from test_fronts import spall  # noqa: E402

C_P = p_wave_speed()
S = 20 * ROCK["tensile_strength"]
SOFT = {"tensile_fracture_energy": 50.0, "shear_fracture_energy": 500.0}
CANDIDATES = {
    "A paper: lumped, undamped": {"mass_matrix": "lumped"},
    "B v0.1 examples: lumped, q(0.5, 1.5), ζ 0.1": {"mass_matrix": "lumped", "bulk_viscosity_linear": 0.5,
                                                    "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.1},
    "C averaged mass, undamped": {"mass_matrix": "averaged"},
    "D averaged, q(0.03, 1.5), ζ 0.1 (chosen until 0.2)": {"mass_matrix": "averaged", "bulk_viscosity_linear": 0.03,
                                                           "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.1},
    "E lumped, q(0.03, 1.5), ζ 0.1": {"mass_matrix": "lumped", "bulk_viscosity_linear": 0.03,
                                      "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.1},
    "F averaged, q(0.06, 1.5), ζ 0.1": {"mass_matrix": "averaged", "bulk_viscosity_linear": 0.06,
                                        "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.1},
    "G averaged, q(0.02, 1.5), ζ 0.1": {"mass_matrix": "averaged", "bulk_viscosity_linear": 0.02,
                                        "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.1},
    "H averaged, q(0.02, 1.5), ζ 0.15 (chosen since 0.2)": {"mass_matrix": "averaged", "bulk_viscosity_linear": 0.02,
                                                            "bulk_viscosity_quadratic": 1.5, "spring_damping": 0.15},
}


def ramp(rise):
    return {"type": "table", "times": [0.0, rise, 1.0], "values": [0.0, S, S]}


def measure(opts: dict) -> dict:
    el = {**opts, "unbreakable": True}
    rise4 = 4 * 0.001 / C_P
    out = {"overshoot_ramp4_h1": run_front(0.001, ramp(rise4), S, 0.1 / C_P, el)["overshoot_max"],
           "overshoot_ramp4_h0.5": run_front(0.0005, ramp(rise4), S, 0.1 / C_P, el)["overshoot_max"],
           "overshoot_step_h1": run_front(0.001, ramp(0.01e-6), S, 0.1 / C_P, el)["overshoot_max"]}
    for rise in (0.2e-6, 0.5e-6):
        pulse = {"type": "triangle", "peak": S, "rise_time": rise, "duration": 4e-6}
        r = run_front(0.001, pulse, S, 0.1 / C_P + 4e-6, opts)
        out[f"broken_brittle_rise{rise * 1e6:.1f}"] = r["broken"]
        out[f"peak_rise{rise * 1e6:.1f}"] = 1 + r["overshoot_max"]
        out[f"broken_softening_rise{rise * 1e6:.1f}"] = run_front(0.001, pulse, S, 0.1 / C_P + 4e-6,
                                                                  {**opts, **SOFT})["broken"]
    sp = spall(0.001, extra=opts)
    out.update(spall_depth_err_elements=(sp["depth"] - sp["xs"]) / 0.001,
               spall_time_err_transits=(sp["t"] - sp["ts"]) * C_P / 0.001, spall_velocity_err=sp["v"] / sp["vs"] - 1)
    sp = spall(0.0005, extra=opts)
    out.update(spall_time_err_transits_h05=(sp["t"] - sp["ts"]) * C_P / 0.0005)
    return out


def table(res: dict) -> str:
    rows = ["| candidate | overshoot, 4-transit rise: h 1 mm / 0.5 mm | step | broken of 5322, brittle, rise 0.2 / 0.5 µs "
            "| softening | peak 40–80 mm in (0.5 µs rise) | first spall: depth [elements] / time [transits] / velocity "
            "| spall time at h 0.5 mm [transits] |",
            "|---|---|---|---|---|---|---|---|"]
    for name, r in res.items():
        rows.append(f"| {name} | {r['overshoot_ramp4_h1']:+.1%} / {r['overshoot_ramp4_h0.5']:+.1%} | "
                    f"{r['overshoot_step_h1']:+.1%} | {r['broken_brittle_rise0.2']} / {r['broken_brittle_rise0.5']} | "
                    f"{r['broken_softening_rise0.2']} / {r['broken_softening_rise0.5']} | {r['peak_rise0.5']:.3f} S | "
                    f"{r['spall_depth_err_elements']:+.1f} / {r['spall_time_err_transits']:+.1f} / "
                    f"{r['spall_velocity_err']:+.1%} | {r['spall_time_err_transits_h05']:+.1f} |")
    return "\n".join(rows)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(HERE))
    args = ap.parse_args()
    res = {}
    for name, opts in CANDIDATES.items():
        res[name] = measure(opts)
        print(name, json.dumps(res[name]), flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "candidates.json").write_text(json.dumps({"candidates": CANDIDATES, "results": res}, indent=2))
    (out / "candidates.md").write_text(table(res) + "\n")
    print(table(res))


if __name__ == "__main__":
    main()
