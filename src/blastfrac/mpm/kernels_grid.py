"""Grid-node updates (METHOD §2.2 steps 2, 3 and the remap velocity), owner-computes, and the image-wall
fold (atomic adds onto image nodes) and ghost update; see :mod:`blastfrac.mpm.grid`.

Every node kernel runs over the grid's active box (launch size ``Grid.box_node_count``, arguments
``Grid.box_args()``): launch index t is node :func:`box_node` (t).
"""

from __future__ import annotations

import warp as wp

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated

F64 = wp.float64


@wp.func
def apply_bc(v: wp.vec2d, mask: int, v_bc: wp.vec2d):
    """Prescribe the masked velocity components (bit 1: x, bit 2: y) [m/s]."""
    out = v
    if (mask & 1) != 0:
        out[0] = v_bc[0]
    if (mask & 2) != 0:
        out[1] = v_bc[1]
    return out


@wp.func
def box_node(t: int, i0: int, j0: int, bw: int, nx: int):
    """Flat index of node t of the active box (row-major, width bw nodes, origin node (i0, j0)) [-]."""
    return (j0 + t // bw) * nx + i0 + t % bw


@wp.kernel
def clear_grid_box(
    i0: int,
    j0: int,
    bw: int,
    nx: int,
    with_mass_force: int,
    g_mass: wp.array(dtype=wp.float64),
    g_mom: wp.array(dtype=wp.vec2d),
    g_force: wp.array(dtype=wp.vec2d),
):
    """Zero the momentum (and mass and force) of the active box's nodes before a P2G."""
    n = box_node(wp.tid(), i0, j0, bw, nx)
    g_mom[n] = wp.vec2d()
    if with_mass_force != 0:
        g_mass[n] = F64(0.0)
        g_force[n] = wp.vec2d()


@wp.kernel
def update_grid_momentum(
    i0: int,
    j0: int,
    bw: int,
    nx: int,
    g_mass: wp.array(dtype=wp.float64),
    bc_mask: wp.array(dtype=wp.int32),
    bc_vel: wp.array(dtype=wp.vec2d),
    g_force: wp.array(dtype=wp.vec2d),
    dt: wp.float64,
    m_cut: wp.float64,
    g_mom: wp.array(dtype=wp.vec2d),
    g_vel: wp.array(dtype=wp.vec2d),
    g_dvel: wp.array(dtype=wp.vec2d),
):
    """p_I += dt f_I on nodes above the mass cut-off m_cut [kg/m]; writes v_I and the increment dv_I.

    A node at or below the cut-off takes no force (dv_I = 0: its tiny mass would turn a force into a huge
    acceleration) but keeps its velocity p_I/m_I, a weighted mean of its points' velocities, so that the PIC share
    of the blend and the points' motion see the gas's own velocity there, not a node at rest (which lost momentum
    at the fringe of expanding gas)."""
    n = box_node(wp.tid(), i0, j0, bw, nx)
    m = g_mass[n]
    if m <= m_cut:
        v_keep = wp.vec2d()
        if m > wp.float64(0.0):
            v_keep = apply_bc(g_mom[n] / m, bc_mask[n], bc_vel[n])
        g_vel[n] = v_keep
        g_dvel[n] = wp.vec2d()
        g_mom[n] = m * v_keep
        return
    v_old = g_mom[n] / m
    v_new = apply_bc((g_mom[n] + dt * g_force[n]) / m, bc_mask[n], bc_vel[n])
    g_vel[n] = v_new
    g_dvel[n] = v_new - v_old
    g_mom[n] = m * v_new


@wp.kernel
def velocity_from_momentum(
    i0: int,
    j0: int,
    bw: int,
    nx: int,
    g_mass: wp.array(dtype=wp.float64),
    bc_mask: wp.array(dtype=wp.int32),
    bc_vel: wp.array(dtype=wp.vec2d),
    g_mom: wp.array(dtype=wp.vec2d),
    g_vel: wp.array(dtype=wp.vec2d),
):
    """v_I = p_I / m_I after the MUSL remap (0 on empty nodes), boundary conditions applied."""
    n = box_node(wp.tid(), i0, j0, bw, nx)
    m = g_mass[n]
    if m <= wp.float64(0.0):
        g_vel[n] = wp.vec2d()
        return
    g_vel[n] = apply_bc(g_mom[n] / m, bc_mask[n], bc_vel[n])


@wp.func
def cmul(a: wp.vec2d, b: wp.vec2d):
    """Component-wise product."""
    return wp.vec2d(a[0] * b[0], a[1] * b[1])


@wp.kernel
def fold_wall_images(
    i0: int,
    j0: int,
    bw: int,
    nx: int,
    mirror: wp.array(dtype=wp.int32),
    sign: wp.array(dtype=wp.vec2d),
    with_mass_force: int,
    g_mass: wp.array(dtype=wp.float64),
    g_mom: wp.array(dtype=wp.vec2d),
    g_force: wp.array(dtype=wp.vec2d),
):
    """Image walls, after a P2G: a ghost node adds its momentum (and mass and force) to its image, signed.

    A node on the wall is its own image (its odd components cancel, its mass doubles).  No race:
    a ghost is never an image, and a wall node is the image of itself only.
    """
    n = box_node(wp.tid(), i0, j0, bw, nx)
    k = mirror[n]
    if k < 0:
        return
    sg = sign[n]
    if k == n:
        g_mom[n] = g_mom[n] + cmul(sg, g_mom[n])
        if with_mass_force != 0:
            g_mass[n] = g_mass[n] + g_mass[n]
            g_force[n] = g_force[n] + cmul(sg, g_force[n])
        return
    wp.atomic_add(g_mom, k, cmul(sg, g_mom[n]))
    if with_mass_force != 0:
        wp.atomic_add(g_mass, k, g_mass[n])
        wp.atomic_add(g_force, k, cmul(sg, g_force[n]))


@wp.kernel
def set_wall_ghosts(
    i0: int,
    j0: int,
    bw: int,
    nx: int,
    mirror: wp.array(dtype=wp.int32),
    sign: wp.array(dtype=wp.vec2d),
    g_mass: wp.array(dtype=wp.float64),
    with_dvel: int,
    g_vel: wp.array(dtype=wp.vec2d),
    g_dvel: wp.array(dtype=wp.vec2d),
    g_mom: wp.array(dtype=wp.vec2d),
):
    """Image walls, after the node update: a ghost takes its image's velocity (and increment), signed [m/s]."""
    n = box_node(wp.tid(), i0, j0, bw, nx)
    k = mirror[n]
    if k < 0 or k == n:
        return
    sg = sign[n]
    v = cmul(sg, g_vel[k])
    g_vel[n] = v
    g_mom[n] = g_mass[k] * v
    if with_dvel != 0:
        g_dvel[n] = cmul(sg, g_dvel[k])
