"""Rigid loading platens for the laboratory tests: frictionless penalty contact.

A platen is a rigid body that moves along y toward the specimen. Its surface is either flat
(radius 0) or a concave circular jaw of radius R (ISRM Brazilian jaws, R = 1.5 × disc radius).
A specimen node that penetrates the platen by d > 0 receives the force F = −Kp·d along the
platen's inward surface normal [N/m per unit thickness]; Kp [N/m per m] is a node penalty.
The contact is frictionless (free lateral slip) unless ``bonded`` is set, in which case a
tangential penalty ties the node's x to its position at first contact (no-slip platen).

The platen reaction [N/m] is the sum of the contact forces on its nodes; the axial stress in
the specimen is that reaction divided by the loaded width (unit thickness).

Forces are added to ``state.f`` after the CDEM force stage and before integration (the
solver's own boundary conditions are not used, so the blast code is untouched).
"""

from __future__ import annotations

import numpy as np
import warp as wp

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.func
def platen_contact_force(x: wp.vec2d, apex_y: wp.float64, side: wp.float64, radius: wp.float64,
                         kp: wp.float64):
    """Contact force [N/m] of a rigid platen on a node at x [m].

    apex_y: y of the platen surface at x = 0 [m]; side: +1 top platen (pushes −y), −1 bottom;
    radius: jaw radius [m], 0 for a flat platen; kp: node penalty stiffness [N/m per m].
    Returns (Fx, Fy, penetration) packed as a vec3d.
    """
    zero = wp.float64(0.0)
    if radius <= zero:
        d = side * (x[1] - apex_y)
        if d > zero:
            return wp.vec3d(zero, -side * kp * d, d)
        return wp.vec3d(zero, zero, zero)
    c = wp.vec2d(zero, apex_y - side * radius)
    r = x - c
    rl = wp.length(r)
    d = rl - radius
    if d > zero and side * r[1] > zero:
        fr = -kp * d / rl
        return wp.vec3d(fr * r[0], fr * r[1], d)
    return wp.vec3d(zero, zero, zero)


def platen_contact_force_np(x: np.ndarray, apex_y: float, side: float, radius: float, kp: float) -> np.ndarray:
    """NumPy twin of :func:`platen_contact_force` for points x of shape [n, 2]; returns [n, 3]."""
    x = np.atleast_2d(np.asarray(x, float))
    out = np.zeros((len(x), 3))
    if radius <= 0.0:
        d = side * (x[:, 1] - apex_y)
        hit = d > 0
        out[hit, 1] = -side * kp * d[hit]
        out[hit, 2] = d[hit]
        return out
    r = x - np.array([0.0, apex_y - side * radius])
    rl = np.hypot(r[:, 0], r[:, 1])
    d = rl - radius
    hit = (d > 0) & (side * r[:, 1] > 0)
    fr = -kp * d[hit] / rl[hit]
    out[hit, 0], out[hit, 1], out[hit, 2] = fr * r[hit, 0], fr * r[hit, 1], d[hit]
    return out


@wp.kernel
def apply_platens(
    plat_nodes: wp.array(dtype=wp.int32),
    plat_start: wp.array(dtype=wp.int32),
    apex_top: wp.float64,
    apex_bottom: wp.float64,
    radius: wp.float64,
    kp: wp.float64,
    bonded: wp.int32,
    x: wp.array(dtype=wp.vec2d),
    x_stick: wp.array(dtype=wp.float64),
    f: wp.array(dtype=wp.vec2d),
    reaction: wp.array(dtype=wp.float64),
):
    """One thread per platen p: add contact forces to its candidate nodes, sum the reaction [N/m].

    plat_nodes[plat_start[p]:plat_start[p+1]] are the candidate nodes of platen p (a gather
    over a fixed list: deterministic, no atomics). reaction[p] = Σ |Fy| over its nodes.
    x_stick: x of a node at first contact (bonded mode), NaN while never in contact.
    """
    p = wp.tid()
    side = wp.float64(1.0)
    apex = apex_top
    if p == 1:
        side = wp.float64(-1.0)
        apex = apex_bottom
    total = wp.float64(0.0)
    for k in range(plat_start[p], plat_start[p + 1]):
        n = plat_nodes[k]
        xn = x[n]
        r = platen_contact_force(xn, apex, side, radius, kp)
        fx = r[0]
        if bonded != 0:
            if r[2] > wp.float64(0.0):
                if wp.isnan(x_stick[k]):
                    x_stick[k] = xn[0]
                fx = fx - kp * (xn[0] - x_stick[k])
        f[n] = f[n] + wp.vec2d(fx, r[1])
        total = total - side * r[1]
    reaction[p] = total


class Platens:
    """Two rigid platens (top, bottom) closing on a specimen at a prescribed displacement history.

    nodes_top, nodes_bottom: candidate node indices; apex0: initial surface y of (top, bottom) [m];
    radius: jaw radius [m] (0 flat); kp: node penalty stiffness [N/m per m].
    Buffers are allocated here once; :meth:`apply` allocates nothing.
    """

    def __init__(self, model, nodes_top, nodes_bottom, apex0, radius: float, kp: float, bonded: bool = False):
        d = model.device
        self.model = model
        nodes = np.concatenate([nodes_top, nodes_bottom]).astype(np.int32)
        self.nodes = nodes
        self.n_top = len(nodes_top)
        self.apex0 = np.asarray(apex0, float)
        self.radius, self.kp, self.bonded = float(radius), float(kp), bool(bonded)
        self._nodes = wp.array(nodes, dtype=wp.int32, device=d)
        self._start = wp.array(np.array([0, len(nodes_top), len(nodes)], np.int32), dtype=wp.int32, device=d)
        self._stick = wp.full(len(nodes), np.nan, dtype=wp.float64, device=d)
        self.reaction = wp.zeros(2, dtype=wp.float64, device=d)

    def apply(self, state, u: float) -> None:
        """Move each platen by u [m] toward the specimen and add the contact forces to state.f."""
        wp.launch(apply_platens, dim=2,
                  inputs=[self._nodes, self._start, wp.float64(self.apex0[0] - u), wp.float64(self.apex0[1] + u),
                          wp.float64(self.radius),
                          wp.float64(self.kp), wp.int32(1 if self.bonded else 0), state.x, self._stick],
                  outputs=[state.f, self.reaction], device=self.model.device)


def ramped_displacement(t: float, speed: float, t_ramp: float) -> float:
    """Platen displacement [m] at time t [s]: speed [m/s] reached smoothly over t_ramp [s].

    u = v·t²/(2·t_ramp) for t < t_ramp, then v·(t − t_ramp/2): the velocity is continuous, so
    loading starts without a velocity jump (no shock wave into the specimen).
    """
    if t <= 0.0:
        return 0.0
    if t < t_ramp:
        return speed * t * t / (2.0 * t_ramp)
    return speed * (t - 0.5 * t_ramp)
