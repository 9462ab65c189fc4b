"""Mesh sensitivity of the calibration tests: the rock of scenario.toml (Table 3 micro-parameters) on
meshes whose element size is a factor × the paper-sized one (factor 1: 3734 / 2167 triangles aimed
at, Fig. 5), with the default quasi-static control (undamped, 0.05 m/s per platen).

    .venv/bin/python examples/calibration/mesh_study.py 2 1 0.5

prints one JSON line per specimen and mesh, then a Markdown table. Same runs as
``blastfrac calibrate examples/calibration/scenario.toml --ucs-mesh-size H --brazilian-mesh-size H'``.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

from blastfrac.calibration import LoadSettings, run_brazilian, run_ucs
from blastfrac.calibration.brazilian import brazilian_settings
from blastfrac.calibration.elastic import edge_density
from blastfrac.calibration.specimens import default_disc_mesh_size, default_ucs_mesh_size
from blastfrac.scenario import load_scenario


def main(factors: list[float]) -> None:
    rock = load_scenario(Path(__file__).with_name("scenario.toml")).rock
    rows = []
    for f in factors:
        t0 = time.perf_counter()
        h = default_disc_mesh_size() * f
        b = run_brazilian(rock, brazilian_settings(), h)
        row = {"factor": f, "disc_mesh_size_m": h, "disc_elements": b.specimen.element_count,
               "tensile_strength_Pa": b.tensile_strength, "initiation_radius_over_R": b.initiation_radius,
               "brazilian_wall_s": time.perf_counter() - t0}
        t0 = time.perf_counter()
        h = default_ucs_mesh_size() * f
        u = run_ucs(rock, LoadSettings(), h)
        row.update({"ucs_mesh_size_m": h, "ucs_elements": u.specimen.element_count,
                    "edge_density_per_m": edge_density(u.specimen.model), "youngs_modulus_Pa": u.youngs_modulus,
                    "poisson_ratio": u.poisson_ratio, "ucs_Pa": u.ucs, "ucs_wall_s": time.perf_counter() - t0})
        print(json.dumps(row), flush=True)
        rows.append(row)
    print("| size factor | prism elements | E [GPa] | ν | UCS [MPa] | disc elements | σt [MPa] |")
    print("|---|---|---|---|---|---|---|")
    for r in rows:
        print(f"| {r['factor']:g} | {r['ucs_elements']} | {r['youngs_modulus_Pa'] / 1e9:.2f} | {r['poisson_ratio']:.3f} | "
              f"{r['ucs_Pa'] / 1e6:.1f} | {r['disc_elements']} | {r['tensile_strength_Pa'] / 1e6:.2f} |")


if __name__ == "__main__":
    main([float(a) for a in sys.argv[1:]] or [2.0, 1.0])
