"""Programmed burn: lighting times, time/volumetric burn, monotonicity; config validation; CLI."""

import argparse

import numpy as np
import pytest
import warp as wp
from pydantic import ValidationError

from blastfrac._warp import init_warp
from blastfrac.mpm.burn import BURN_MODES, burn_fraction, burn_fraction_np, lighting_times

F64 = wp.float64


def test_lighting_times_several_points_and_delays():
    X = np.array([[0.0, 0.0], [1.0, 0.0], [3.0, 4.0]])
    pts = np.array([[0.0, 0.0], [3.0, 0.0]])
    t = lighting_times(X, pts, np.array([0.0, 1e-4]), 5000.0)
    exp = [0.0, min(1 / 5000, 2 / 5000 + 1e-4), min(5 / 5000, 4 / 5000 + 1e-4)]
    np.testing.assert_allclose(t, exp, rtol=1e-14)


def test_time_burn_ramp_and_volumetric_burn():
    D, rho0, pcj, he = 8000.0, 1700.0, 30e9, 1e-3
    t_l = 1e-6
    # time burn alone: linear ramp over 1.5 h_e / D
    ts = t_l + np.array([-1e-7, 0.0, 0.5, 1.0, 2.0]) * 1.5 * he / D
    F = burn_fraction_np(np.zeros(5), ts, t_l, 1.0, he, D, rho0, pcj, 1.5, "time")
    np.testing.assert_allclose(F, [0, 0, 0.5, 1, 1], atol=1e-12)
    # volumetric burn alone
    V = np.array([1.0, 0.99, 0.96, 1 - 0.95 * pcj / (rho0 * D * D) - 1e-9])
    F = burn_fraction_np(np.zeros(4), 0.0, 1.0, V, he, D, rho0, pcj, 1.5, "volumetric")
    f2 = (1 - V) * rho0 * D * D / pcj
    np.testing.assert_allclose(F[1:3], np.where(f2[1:3] > 0.95, 1, f2[1:3]))
    assert F[0] == 0 and F[3] == 1.0
    # combined = max of both; and never decreases
    Fc = burn_fraction_np(np.array([0.7]), t_l + 0.2 * 1.5 * he / D, t_l, 1.0 + 1e-3, he, D, rho0, pcj)
    assert Fc[0] == 0.7
    assert burn_fraction_np(np.array([0.0]), 0.0, 1.0, 1.0 - 1e-9, he, D, rho0, pcj)[0] == 0.0  # below 1e-4 → 0


@wp.kernel
def _burn(a: wp.array(dtype=wp.float64, ndim=2), mode: int, out: wp.array(dtype=wp.float64)):
    i = wp.tid()
    out[i] = burn_fraction(a[i, 0], a[i, 1], a[i, 2], a[i, 3], a[i, 4], a[i, 5], a[i, 6], a[i, 7], a[i, 8], mode)


@pytest.mark.parametrize("mode", list(BURN_MODES))
def test_burn_warp_twin(mode):
    init_warp()
    rng = np.random.default_rng(4)
    n = 200
    a = np.stack(
        [rng.uniform(0, 1, n) * (rng.uniform(size=n) < 0.3), rng.uniform(0, 2e-6, n), rng.uniform(0, 2e-6, n),
         rng.uniform(0.9, 1.05, n), np.full(n, 1e-3), np.full(n, 8000.0), np.full(n, 1700.0), np.full(n, 30e9), np.full(n, 1.5)],
        axis=1,
    )
    out = wp.zeros(n, dtype=wp.float64)
    wp.launch(_burn, dim=n, inputs=[wp.array(a, dtype=F64), BURN_MODES[mode], out])
    ref = burn_fraction_np(a[:, 0], a[:, 1], a[:, 2], a[:, 3], 1e-3, 8000.0, 1700.0, 30e9, 1.5, mode)
    np.testing.assert_allclose(out.numpy(), ref, rtol=1e-14)


def test_burn_monotone_in_solver_and_center_initiation():
    """In a charge, F never decreases step to step, and ignition starts at the centre."""
    from blastfrac.mpm import MPMSolver
    from blastfrac.scenario.explosive import ExplosiveConfig

    cfg = ExplosiveConfig(name="emulsion", charges=[{"kind": "circle", "center": [0.1, 0.2], "radius": 0.01}],
                          grid={"cell_size": 1e-3, "margin": 0.01})
    s = MPMSolver(cfg)
    x = s.x.numpy()
    tl = s.light_time.numpy()
    np.testing.assert_allclose(tl, np.linalg.norm(x - [0.1, 0.2], axis=1) / 4000.0, rtol=1e-12)
    t, F_prev = 0.0, s.burn.numpy().copy()
    for _ in range(40):
        dt = s.stable_dt()
        s.step(dt, t)
        t += dt
        F = s.burn.numpy()
        assert (F >= F_prev).all()
        F_prev = F.copy()
    burnt = F > 0.5
    assert burnt.any() and not burnt.all()
    r = np.linalg.norm(x - [0.1, 0.2], axis=1)
    assert r[burnt].max() < r[~burnt].min() + 2e-3


def test_config_validation_messages():
    from blastfrac.scenario.explosive import ExplosiveConfig

    base = {"charges": [{"kind": "circle", "center": [0, 0], "radius": 0.02}], "grid": {"cell_size": 1e-3}}
    ExplosiveConfig(name="petn", **base)
    with pytest.raises(ValidationError, match="exactly one"):
        ExplosiveConfig(**base)
    with pytest.raises(ValidationError, match="unknown explosive"):
        ExplosiveConfig(name="dynamite", **base)
    with pytest.raises(ValidationError):
        ExplosiveConfig(name="petn", typo=1, **base)
    with pytest.raises(ValidationError):
        ExplosiveConfig(name="petn", charges=[{"kind": "circle", "center": [0, 0], "radius": -1}], grid={"cell_size": 1e-3})
    with pytest.raises(ValidationError):
        ExplosiveConfig(name="petn", flip=1.5, **base)
    c = ExplosiveConfig(constants=dict(rho0=1630, D=6930, A=3.712e11, B=3.231e9, R1=4.15, R2=0.95, omega=0.3, E0=7e9), **base)
    assert c.jwl().D == 6930


def _parse(argv):
    from blastfrac.cli.explosive import add_parser

    ap = argparse.ArgumentParser()
    add_parser(ap.add_subparsers(dest="cmd"))
    return ap.parse_args(argv)


def test_cli_explosive(capsys, tmp_path):
    from blastfrac.cli.explosive import run

    assert run(_parse(["explosive", "emulsion"])) == 0
    out = capsys.readouterr().out
    assert "D_CJ = 552" in out and "WARNING" in out
    assert run(_parse(["explosive", "petn"])) == 0
    assert "WARNING" not in capsys.readouterr().out
    assert run(_parse(["explosive", "nope"])) == 2
    assert "unknown explosive" in capsys.readouterr().err
    assert run(_parse(["explosive", "--file", str(tmp_path / "missing.toml")])) == 2
    f = tmp_path / "tnt.toml"
    f.write_text("[explosive.constants]\nrho0=1630.0\nD=6930.0\nA=371.2e9\nB=3.231e9\nR1=4.15\nR2=0.95\nomega=0.3\nE0=7.0e9\n")
    assert run(_parse(["explosive", "--file", str(f)])) == 0
    assert "6929" in capsys.readouterr().out
    f.write_text("rho0 = 1630.0\nD = 'fast'\n")
    assert run(_parse(["explosive", "--file", str(f)])) == 2
    assert "invalid constants" in capsys.readouterr().err
