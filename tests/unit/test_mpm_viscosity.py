"""The products' artificial viscosity uses the products' own sound speed (docs/explosive.md, "Artificial viscosity").

q = ρ l (Q1 l (tr D)² − Q2 c tr D) in compression, with c the sound speed of the burnt share at the start of the
step, c² = F·c²_JWL: for the γ-law gas of Sod's tube (JWL A = B = 0, ω = γ − 1) c² = γ p/ρ. It is not the time
step's signal speed (which adds q's own augmentation and the burn front's floor D(1 − F)), and unburnt explosive
(F = 0, no pressure) gets no linear term. The expected q is computed here from the state read out between two steps.
"""

import numpy as np
import pytest

from blastfrac.materials.jwl import JWLParams
from blastfrac.mpm import MPMOptions, MPMSolver
from blastfrac.mpm.seeding import slab_1d

G = 1.4
GAS = JWLParams(rho0=1.0, D=1.0, A=0.0, B=0.0, R1=1.0, R2=1.0, omega=G - 1.0, E0=1e5 / (G - 1.0))
RATE = 200.0        # uniform compression v_x = −RATE (x − 1/2) [1/s]


def compressed_slab(q1, q2, light_time=None):
    spec, x, vol = slab_1d(1.0, 40)
    v = np.zeros_like(x)
    v[:, 0] = -RATE * (x[:, 0] - 0.5)
    s = MPMSolver.from_arrays(x, vol, spec, GAS, MPMOptions(q1=q1, q2=q2), v=v, light_time=light_time)
    return s, x


@pytest.mark.parametrize("q1,q2", [(0.0, 1.0), (1.5, 0.06), (1.5, 2.0)])
def test_viscosity_uses_the_gas_sound_speed(q1, q2):
    s, x = compressed_slab(q1, q2)
    s.set_gas_state(np.full(len(x), 1.0), np.full(len(x), 1e5), v=s.v.numpy())
    dt = 0.2 * s.spec.h / 400.0
    s.step(dt, 0.0)
    f = s.particle_fields()
    c_old = np.sqrt(G * f["pressure"] / f["density"])             # γ-law sound speed at the step's start
    s.step(dt, dt)
    trD = np.array([g[0, 0] + g[1, 1] for g in s.grad_v.numpy()])
    rho, l = s.rho.numpy(), np.sqrt(s.vol.numpy())
    expected = rho * l * (q1 * l * trD**2 - q2 * c_old * trD)
    inner = (x[:, 0] > 0.2) & (x[:, 0] < 0.8)                     # away from the open ends
    assert np.all(trD[inner] < 0)
    assert np.allclose(trD[inner], -RATE, rtol=1e-2)               # the grid carries the linear field
    q = s.q.numpy()
    assert np.max(np.abs(q[inner] / expected[inner] - 1)) < 1e-9
    # the time step's signal speed is larger than c (it carries q), and is not what q used
    assert np.all(s.cs.numpy()[inner] > 1.01 * np.sqrt(G * s.p.numpy()[inner] / rho[inner]))


def test_unburnt_explosive_gets_no_linear_viscosity():
    """The linear term scales with c, which is 0 for F = 0 (before, the floor c = D put it at ρ l D |tr D|)."""
    s, x = compressed_slab(0.0, 1.0, light_time=np.full(len(slab_1d(1.0, 40)[1]), 1.0))   # lit at 1 s: unburnt
    dt = 0.2 * s.spec.h / 400.0
    for k in range(3):
        s.step(dt, k * dt)
    trD = np.array([g[0, 0] + g[1, 1] for g in s.grad_v.numpy()])
    inner = (x[:, 0] > 0.2) & (x[:, 0] < 0.8)
    assert np.all(trD[inner] < -0.5 * RATE)                        # it is being compressed
    assert np.all(s.burn.numpy() == 0.0)
    assert np.all(s.q.numpy() == 0.0)
