"""Interface springs: frame, incremental forces, failure, softening and post-break contact.

One thread per interface q updates its two node pairs 2q and 2q+1, which share a frame:
t̂ runs from the midpoint of pair A to that of pair B, n̂ = (t̂y, −t̂x) points from e1 into e2.
The spring law itself is in :mod:`blastfrac.materials.interface`.
"""

from __future__ import annotations

import warp as wp

from ..materials.interface import spring_update_broken, spring_update_intact


@wp.func
def stored_spring_energy(fn: wp.float64, fs: wp.float64, kn: wp.float64, ks: wp.float64):
    """Elastic energy of a spring ½Fn²/Kn + ½Fs²/Ks [J/m]."""
    half = wp.float64(0.5)
    return half * fn * fn / kn + half * fs * fs / ks


@wp.kernel
def eval_spring_forces(
    pair_i: wp.array(dtype=wp.int32),
    pair_j: wp.array(dtype=wp.int32),
    pair_kn: wp.array(dtype=wp.float64),
    pair_ks: wp.array(dtype=wp.float64),
    pair_ac: wp.array(dtype=wp.float64),
    pair_l0: wp.array(dtype=wp.float64),
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    pair_F: wp.array(dtype=wp.vec2d),
    pair_str: wp.array(dtype=wp.vec2d),
    pair_mode: wp.array(dtype=wp.int32),
    pair_dropped: wp.array(dtype=wp.int32),
    pair_g0: wp.array(dtype=wp.float64),
    pair_tbreak: wp.array(dtype=wp.float64),
    pair_work: wp.array(dtype=wp.float64),
    pair_efrac: wp.array(dtype=wp.float64),
    tan_phi: wp.float64,
    tan_phi_r: wp.float64,
    slope_t: wp.float64,
    slope_c: wp.float64,
    breakable: wp.int32,
    dt: wp.float64,
    time: wp.float64,
    pair_force: wp.array(dtype=wp.vec2d),
):
    """Update both springs of interface q; write the force on each pair's j node (global axes) [N/m]."""
    q = wp.tid()
    half = wp.float64(0.5)
    pa = 2 * q
    pb = 2 * q + 1
    ma = half * (x[pair_i[pa]] + x[pair_j[pa]])
    mb = half * (x[pair_i[pb]] + x[pair_j[pb]])
    t = wp.normalize(mb - ma)
    n = wp.vec2d(t[1], -t[0])
    for s in range(2):
        k = pa + s
        if pair_dropped[k] != 0:
            pair_force[k] = wp.vec2d(wp.float64(0.0), wp.float64(0.0))
            continue
        i = pair_i[k]
        j = pair_j[k]
        dd = (v[j] - v[i]) * dt
        dn = wp.dot(dd, n)
        ds = wp.dot(dd, t)
        f0 = pair_F[k]
        kn = pair_kn[k]
        ks = pair_ks[k]
        fn = wp.float64(0.0)
        fs = wp.float64(0.0)
        mode = pair_mode[k]
        if mode == 0:
            st = pair_str[k]
            r = spring_update_intact(f0[0], f0[1], st[0], st[1], dn, ds, kn, ks, pair_ac[k],
                                     tan_phi, tan_phi_r, slope_t, slope_c, breakable)
            fn = r[0]
            fs = r[1]
            pair_str[k] = wp.vec2d(r[2], r[3])
            new_mode = wp.int32(r[4])
            w = pair_work[k] - half * ((f0[0] + fn) * dn + (f0[1] + fs) * ds)
            pair_work[k] = w
            if new_mode != 0:
                pair_mode[k] = new_mode
                pair_tbreak[k] = time
                pair_efrac[k] = w - stored_spring_energy(fn, fs, kn, ks)
        else:
            rel = x[j] - x[i]
            gap = wp.dot(rel, n)
            g0 = pair_g0[k]
            if gap - g0 > pair_l0[k] or wp.abs(wp.dot(rel, t)) > half * pair_l0[k]:
                pair_dropped[k] = 1
            else:
                r2 = spring_update_broken(f0[1], gap, g0, ds, kn, ks, tan_phi_r)
                fn = r2[0]
                fs = r2[1]
            pair_work[k] = pair_work[k] - half * ((f0[0] + fn) * dn + (f0[1] + fs) * ds)
        pair_F[k] = wp.vec2d(fn, fs)
        pair_force[k] = fn * n + fs * t


def launch_spring_forces(model, state, dt: float, time: float) -> None:
    if model.interface_count == 0:
        return
    wp.launch(
        eval_spring_forces,
        dim=model.interface_count,
        inputs=[model.pair_i, model.pair_j, model.pair_kn, model.pair_ks, model.pair_ac, model.pair_l0,
                state.x, state.v, state.pair_F, state.pair_str, state.pair_mode, state.pair_dropped,
                state.pair_g0, state.pair_tbreak, state.pair_work, state.pair_efrac,
                wp.float64(model.tan_phi), wp.float64(model.tan_phi_r), wp.float64(model.slope_t),
                wp.float64(model.slope_c), wp.int32(model.breakable), wp.float64(dt), wp.float64(time)],
        outputs=[state.pair_force],
        device=model.device,
    )
