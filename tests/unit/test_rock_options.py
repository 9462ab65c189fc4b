"""The rock options of 0.2: spring-compliance compensation and the block mass matrix.

Defaults resolve by stiffness mode and appear in resolved.toml; bad values are refused naming the key; the
compensation inverts the compliance formula of METHOD §1.2 exactly; the mass matrix's rigid-body mass is ρA and
its smallest eigen-mass is the one the stable step uses.
"""

import math
import subprocess
import sys

import numpy as np
import pytest

from blastfrac.cdem.kernels_integrate import block_kinetic_energy
from blastfrac.model.compliance import assembly_moduli, compensated_block_moduli
from blastfrac.scenario import ScenarioError, scenario_from_dict
from blastfrac.scenario.load import write_resolved


def _sc(**rock):
    return scenario_from_dict({"rock": rock, "geometry": {"domain": {"type": "rectangle", "width": 0.02,
                                                                         "height": 0.02}, "mesh_size": 0.005}})


def test_compensation_default_follows_the_stiffness_mode_and_is_written_out(tmp_path):
    assert _sc().rock.compensate_spring_compliance is True
    assert _sc(stiffness_mode="per_area", kn=1e15, ks=1e15).rock.compensate_spring_compliance is False
    assert _sc(stiffness_mode="per_area", kn=1e15, ks=1e15,
               compensate_spring_compliance=True).rock.compensate_spring_compliance is True
    sc = _sc()
    write_resolved(sc, tmp_path / "resolved.toml")
    text = (tmp_path / "resolved.toml").read_text()
    assert "compensate_spring_compliance = true" in text
    assert 'mass_matrix = "averaged"' in text


def test_bad_mass_matrix_is_refused_naming_the_key():
    with pytest.raises(ScenarioError, match="rock.mass_matrix"):
        _sc(mass_matrix="diagonal")


def test_compensation_inverts_the_compliance_formula():
    """assembly(compensated(E, ν)) = (E, ν) for normal and shear compliances of different sizes."""
    E, nu = 50e9, 0.2
    for s_n, s_s in ((1.2e-12, 1.2e-12), (2e-12, 0.5e-12), (0.3e-12, 1.5e-12)):
        Eb, nub = compensated_block_moduli(E, nu, s_n, s_s)
        Ea, nua = assembly_moduli(Eb, nub, s_n, s_s)
        assert Ea == pytest.approx(E, rel=1e-12) and nua == pytest.approx(nu, rel=1e-12)
        assert Eb > E                                   # springs only add compliance: the blocks are stiffer
    # METHOD §1.2: springs k = β·E'/a on equilateral triangles of side a (ℓ = 2√3/a) give E'/(1 + √3/β); the
    # builder's k = β·E'/h̄ with the mean height h̄ = √3a/2 gives E'/(1 + 3/(2β)), 7 % softer at β = 20
    Ep = E / (1 - nu**2)
    beta, a = 20.0, 1e-3
    ell = 2 * math.sqrt(3) / a
    for k, ratio in ((beta * Ep / a, 1 + math.sqrt(3) / beta), (beta * Ep / (math.sqrt(3) / 2 * a), 1 + 1.5 / beta)):
        Ea, nua = assembly_moduli(E, nu, ell / k, ell / k)
        assert Ea / (1 - nua**2) == pytest.approx(Ep / ratio, rel=1e-12)


def test_springs_softer_than_the_rock_cannot_be_compensated():
    with pytest.raises(ValueError, match="spring_penalty"):
        compensated_block_moduli(50e9, 0.2, 1e-10, 1e-10)


def test_too_soft_penalty_springs_end_with_a_clear_error_and_exit_2(tmp_path):
    toml = tmp_path / "s.toml"
    toml.write_text('[rock]\nspring_penalty = 0.5\n[geometry]\ndomain = { type = "rectangle", width = 0.02, '
                    'height = 0.02 }\nmesh_size = 0.005\n')
    r = subprocess.run([sys.executable, "-m", "blastfrac", "check", str(toml)], capture_output=True, text=True)
    assert r.returncode == 2, r.stderr
    assert "spring_penalty" in r.stderr and "Traceback" not in r.stderr


@pytest.mark.parametrize("theta", [0.0, 0.5, 1.0])
def test_block_mass_matrix_rigid_mass_and_smallest_eigen_mass(theta):
    """M_e = m[(1 − 3θ/4)I + (θ/4)J]: a uniform velocity carries ρA (the block's mass) and the smallest
    eigenvalue, m(1 − 3θ/4), is the node mass the stable step uses (model/builder.py node_mass_dt)."""
    m = 2.0
    M = m * ((1 - 0.75 * theta) * np.eye(3) + 0.25 * theta * np.ones((3, 3)))
    assert np.ones(3) @ M @ np.ones(3) == pytest.approx(3 * m)
    assert np.linalg.eigvalsh(M).min() == pytest.approx(m * (1 - 0.75 * theta))
    v = np.random.default_rng(1).normal(size=(3, 2))
    ke = 0.5 * sum(v[:, d] @ M @ v[:, d] for d in range(2))
    assert block_kinetic_energy(np.full(3, m), v, theta) == pytest.approx(ke, rel=1e-12)


@pytest.mark.parametrize("mass_matrix", ["lumped", "averaged"])
def test_stable_step_is_below_the_exact_critical_step(mass_matrix):
    """The builder's Gershgorin step (compensated blocks, penalty springs, the mass matrix's smallest
    eigen-mass) must not exceed 2/ω_max of the model's own generalized eigenproblem K x = ω² M x, solved
    exactly here on a small mesh; and it should not be needlessly small (> 40 % of it)."""
    import scipy.linalg as sla

    from blastfrac.calibration.elastic import stiffness_matrix
    from blastfrac.model.builder import MASS_THETA, ModelBuilder

    sc = scenario_from_dict({"rock": {"unbreakable": True, "mass_matrix": mass_matrix},
                             "geometry": {"domain": {"type": "rectangle", "width": 0.03, "height": 0.02},
                                          "mesh_size": 0.003}})
    m = ModelBuilder(sc).finalize("cpu")
    K = stiffness_matrix(m).toarray()
    theta = MASS_THETA[mass_matrix]
    mn = m.host["node_mass"]
    M = np.zeros_like(K)
    for e in range(m.element_count):
        Me = mn[3 * e] * ((1 - 0.75 * theta) * np.eye(3) + 0.25 * theta * np.ones((3, 3)))
        for d in range(2):
            idx = 2 * (3 * e + np.arange(3)) + d
            M[np.ix_(idx, idx)] = Me
    omega_max = math.sqrt(sla.eigh(K, M, eigvals_only=True, subset_by_index=[K.shape[0] - 1, K.shape[0] - 1])[0])
    dt_exact = 2.0 / omega_max
    print(f"\n  {mass_matrix}: Gershgorin {m.stable_dt:.4e} s, exact {dt_exact:.4e} s ({m.stable_dt / dt_exact:.2f})")
    assert m.stable_dt <= dt_exact
    assert m.stable_dt > 0.4 * dt_exact
