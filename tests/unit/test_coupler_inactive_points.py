"""The contacts' heat goes to active gas points only (coupling.contact_heating; kernels_contact.py).

Each step the particle–edge contact pass writes every gas point's dissipation rate q_p, and heat_gas_from_contacts
hands the contacts' dissipated energy Q to the points in proportion to q_p / Σq, where Σq sums the active points.
A point that has left the grid (deactivated) must hold q_p = 0 from then on; a stale q_p would keep drawing shares
that Σq does not count, so the shares handed out would exceed Q: energy made from nothing, in a point no energy
account reads.
"""

import numpy as np
from test_coupled_graph import _scenario

from blastfrac.coupling.kernels_contact import ACC_HEATED
from blastfrac.scenario import scenario_from_dict
from blastfrac.simulation import Simulation


def test_a_deactivated_point_draws_no_contact_heat(tmp_path):
    sim = Simulation(scenario_from_dict(_scenario("off")), out_dir=tmp_path)
    cp, gas = sim.coupler, sim.gas
    while not (cp.diss_p.numpy() > 0).sum() >= 10:      # until the gas's contacts dissipate (~240 steps)
        sim.step()
        assert sim.steps < 1000
    # deactivate five of the points whose contacts dissipate now, as leaving the grid would
    gone = np.flatnonzero(cp.diss_p.numpy() > 0)[:5]
    active = gas.active.numpy()
    active[gone] = 0
    gas.active.assign(active)
    ie0 = gas.ie.numpy()[gone].copy()
    heated0 = cp.acc.numpy()[ACC_HEATED]
    for _ in range(5):
        sim.step()
    assert cp.acc.numpy()[ACC_HEATED] > heated0              # the contacts kept heating the gas ...
    assert np.all(cp.diss_p.numpy()[gone] == 0.0)          # ... but not the points that left
    assert np.array_equal(gas.ie.numpy()[gone], ie0)
