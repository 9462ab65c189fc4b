"""Interface springs: frame, incremental forces, failure, softening and post-break contact.

One thread per interface q updates its two node pairs 2q and 2q+1. Intact springs share a frame:
t̂ runs from the midpoint of pair A to that of pair B, n̂ = (t̂y, −t̂x) points from e1 into e2.
A broken pair is a node-to-face contact of its e2 node against the current e1 edge, so it takes
that edge's frame (the midpoint frame turns with the other pair once that one opens: a bogus
normal then read a 0.2 mm "penetration" and fired two fragments at 8 km/s in the single-hole
example). A broken pair closed by more than L0/2 is dropped like a separated one.
The spring law itself is in :mod:`blastfrac.materials.interface`.
"""

from __future__ import annotations

import warp as wp

from ..materials.interface import spring_dashpot_of, spring_update_broken, spring_update_intact

wp.set_module_options({"enable_backward": False})     # no adjoint code: nothing here is differentiated


@wp.func
def stored_spring_energy(fn: wp.float64, fs: wp.float64, kn: wp.float64, ks: wp.float64):
    """Elastic energy of a spring ½Fn²/Kn + ½Fs²/Ks [J/m]."""
    half = wp.float64(0.5)
    return half * fn * fn / kn + half * fs * fs / ks


@wp.func
def inelastic_work(f0: wp.vec2d, fn: wp.float64, fs: wp.float64, dn: wp.float64, ds: wp.float64,
                   kn: wp.float64, ks: wp.float64):
    """Work done on a spring over an increment beyond the change of its stored energy [J/m]: the trapezoidal work
    −½(Fn0 + Fn)·Δd_n − ½(Fs0 + Fs)·Δd_s minus (stored(Fn, Fs) − stored(Fn0, Fs0)). Zero, up to round-off, for an
    elastic increment (Fn = Fn0 − Kn·Δd_n, Fs = Fs0 − Ks·Δd_s)."""
    half = wp.float64(0.5)
    w = -half * ((f0[0] + fn) * dn + (f0[1] + fs) * ds)
    return w - (stored_spring_energy(fn, fs, kn, ks) - stored_spring_energy(f0[0], f0[1], kn, ks))


@wp.func
def list_change(changes: wp.array(dtype=wp.int32), change_count: wp.array(dtype=wp.int32), slot: wp.int32,
                k: wp.int32):
    """Append spring k, whose mode or dropped flag this step changed, to slot's list (changes[slot·cap …], cap =
    half the array, counted in change_count[slot]): block contact's pass reads these springs instead of scanning
    every spring's state (contact_fan.mark_listed_changes). A spring changes at most twice over a run (it breaks,
    it is dropped), so a list of twice the springs never fills, even if no pass reads it."""
    cap = changes.shape[0] // 2
    changes[slot * cap + wp.atomic_add(change_count, slot, 1)] = k


@wp.struct
class SpringModel:
    """The springs' fixed data (cdem/kernels_spring.py): the nodes of each pair, per interface the stiffness Kn, Ks
    [N/m per m], area A_c [m] and rest length L0 [m] of each of its two pairs and the law (tanφ, tanφ_r, slope_t,
    slope_c; read when per_pair_law = 1), per pair the dashpot roots (√(m_eff·Kn), √(m_eff·Ks)), and the model's
    scalars."""

    pair_i: wp.array(dtype=wp.int32)
    pair_j: wp.array(dtype=wp.int32)
    spring: wp.array(dtype=wp.vec4d)            # per interface: Kn, Ks, A_c, L0 (both pairs alike)
    law: wp.array(dtype=wp.vec4d)              # per interface (Model.iface_law)
    dashpot: wp.array(dtype=wp.vec2d)           # per pair: √(m_eff·Kn), √(m_eff·Ks) [kg/s per m]
    tan_phi: wp.float64
    tan_phi_r: wp.float64
    slope_t: wp.float64
    slope_c: wp.float64
    zeta: wp.float64                            # spring dashpot damping ratio [-]
    crush: wp.float64                           # compressive cap σ_cr [Pa], 0: none
    per_pair_law: wp.int32
    breakable: wp.int32


@wp.struct
class SpringState:
    """Each spring's state (a State's pair_* arrays): force (Fn, Fs) [N/m], strengths, mode, dropped, gap at
    break g0 [m], break time [s], work beyond the stored energy (pair_inelastic), fracture energy and dashpot work
    [J/m], and the force on its j node [N/m]; and the lists of the springs whose mode or dropped flag changed
    (``list_change``: two slots of 2P entries, the counts; the solver's, read by block contact)."""

    F: wp.array(dtype=wp.vec2d)
    strength: wp.array(dtype=wp.vec2d)
    mode: wp.array(dtype=wp.int32)
    dropped: wp.array(dtype=wp.int32)
    g0: wp.array(dtype=wp.float64)
    tbreak: wp.array(dtype=wp.float64)
    inelastic: wp.array(dtype=wp.float64)
    efrac: wp.array(dtype=wp.float64)
    damp: wp.array(dtype=wp.float64)
    force: wp.array(dtype=wp.vec2d)
    changes: wp.array(dtype=wp.int32)
    change_count: wp.array(dtype=wp.int32)


def spring_model(model, sm: SpringModel | None = None) -> SpringModel:
    """The SpringModel of ``model``; with ``sm``, only its scalars are set again (they can change during a run:
    ``breakable`` during an in-situ stage)."""
    if sm is None:
        sm = SpringModel()
        sm.pair_i, sm.pair_j, sm.spring = model.pair_i, model.pair_j, model.iface_spring
        sm.law, sm.dashpot = model.iface_law, model.pair_dashpot
    sm.tan_phi, sm.tan_phi_r, sm.slope_t, sm.slope_c = model.tan_phi, model.tan_phi_r, model.slope_t, model.slope_c
    sm.zeta, sm.per_pair_law, sm.breakable = model.spring_damping, int(model.per_pair_law), int(model.breakable)
    sm.crush = model.crush
    return sm


def spring_scalars(model) -> tuple:
    """The model scalars a SpringModel holds (a change means spring_model must set them again)."""
    return (model.tan_phi, model.tan_phi_r, model.slope_t, model.slope_c, model.spring_damping,
            int(model.per_pair_law), int(model.breakable), model.crush)


def change_lists(pair_count: int, device) -> tuple:
    """(changes, change_count) for ``list_change``: two slots of 2·pair_count entries each, and their counts."""
    return (wp.zeros(4 * max(1, pair_count), dtype=wp.int32, device=device),
            wp.zeros(2, dtype=wp.int32, device=device))


def spring_state(state, changes: tuple | None = None) -> SpringState:
    """The SpringState of a State (the same arrays); changes: (changes, change_count) of ``change_lists`` (the
    solver's, which block contact reads), or None for lists of its own."""
    ss = SpringState()
    ss.changes, ss.change_count = changes if changes is not None else change_lists(len(state.pair_mode),
                                                                                   state.pair_mode.device)
    ss.F, ss.strength, ss.mode, ss.dropped = state.pair_F, state.pair_str, state.pair_mode, state.pair_dropped
    ss.g0, ss.tbreak, ss.inelastic, ss.efrac, ss.force = (state.pair_g0, state.pair_tbreak, state.pair_inelastic,
                                                    state.pair_efrac, state.pair_force)
    ss.damp = state.pair_damp
    return ss


@wp.kernel
def eval_spring_forces(
    sm: SpringModel,
    ss: SpringState,
    x: wp.array(dtype=wp.vec2d),
    v: wp.array(dtype=wp.vec2d),
    dt: wp.float64,
    clock: wp.array(dtype=wp.float64),
    first: wp.int32,
    slot: wp.int32,
):
    """Update both springs of interface q; write the force on each pair's j node (global axes) [N/m]; list the
    springs whose mode or dropped flag changes in ss.changes' slot (``list_change``; 0 for the first or only part of
    the interfaces, 1 for the second).

    With zeta > 0 a dashpot (materials.interface.spring_dashpot) acts beside each spring that carries
    load (intact, or broken and closed); its force is not part of the stored spring force, so it never
    enters the failure criteria, and its work goes to the pair's own dashpot account ss.damp (no two threads
    write one address, so the launch can be split or run on a GPU without atomics on a shared total).

    With per_pair_law = 1 (a model with joints or a fracture band) each interface takes its friction and softening
    (tanφ, tanφ_r, slope_t, slope_c) from iface_law; otherwise every spring takes the scalars.

    Bytes per interface are what this kernel costs (it is the largest of the step): the law is read once per
    interface, ``dropped`` only for a broken pair, and the work account (pair_inelastic, the work beyond the stored
    energy) only where the increment was not elastic.

    Thread i updates interface first + i (a launch may cover part of the interfaces: two threads, see
    CDEMSolver.forces_springs).
    """
    q = wp.tid() + first
    half = wp.float64(0.5)
    pa = 2 * q
    pb = 2 * q + 1
    # the interface's constants (Kn, Ks [N/m per m], Ac, L0 [m]; the same for both pairs) and its four nodes
    c = sm.spring[q]
    kn = c[0]
    ks = c[1]
    ac = c[2]
    l0 = c[3]
    ia = sm.pair_i[pa]
    ja = sm.pair_j[pa]
    ib = sm.pair_i[pb]
    jb = sm.pair_j[pb]
    xia = x[ia]
    xib = x[ib]
    t = wp.normalize(half * (xib + x[jb]) - half * (xia + x[ja]))
    n = wp.vec2d(t[1], -t[0])
    law = wp.vec4d(sm.tan_phi, sm.tan_phi_r, sm.slope_t, sm.slope_c)
    if sm.per_pair_law != 0:
        law = sm.law[q]
    for s in range(2):
        k = pa + s
        mode = ss.mode[k]
        if mode != 0:                                   # only a broken pair can have been dropped
            if ss.dropped[k] != 0:
                ss.force[k] = wp.vec2d(wp.float64(0.0), wp.float64(0.0))
                continue
        i = ia
        j = ja
        if s == 1:
            i = ib
            j = jb
        dv = v[j] - v[i]
        dd = dv * dt
        dn = wp.dot(dd, n)
        ds = wp.dot(dd, t)
        nn = n
        tt = t
        f0 = ss.F[k]
        fn = wp.float64(0.0)
        fs = wp.float64(0.0)
        if mode == 0:
            st = ss.strength[k]
            r = spring_update_intact(f0[0], f0[1], st[0], st[1], dn, ds, kn, ks, ac,
                                     law[0], law[1], law[2], law[3], sm.breakable, sm.crush)
            fn = r[0]
            fs = r[1]
            if r[2] != st[0] or r[3] != st[1]:           # softening or broken: most springs keep their strength
                ss.strength[k] = wp.vec2d(r[2], r[3])
            new_mode = wp.int32(r[4])
            # an elastic increment (the trial forces kept) does work equal to its change of stored energy, so
            # pair_inelastic (work − stored) stays as it is: most springs neither read nor write it
            if new_mode != 0 or fn != f0[0] - kn * dn or fs != f0[1] - ks * ds:
                w = ss.inelastic[k] + inelastic_work(f0, fn, fs, dn, ds, kn, ks)
                ss.inelastic[k] = w
                if new_mode != 0:
                    ss.mode[k] = new_mode
                    ss.tbreak[k] = clock[0]
                    ss.efrac[k] = w
                    list_change(ss.changes, ss.change_count, slot, k)
        else:
            # frame of a broken pair: the e1 face (node-to-face contact of j against the edge i_a→i_b of e1).
            # The midpoint frame is meaningless once the other pair has opened or the blocks have turned.
            tt = wp.normalize(xib - xia)
            nn = wp.vec2d(tt[1], -tt[0])
            dn = wp.dot(dd, nn)
            ds = wp.dot(dd, tt)
            rel = x[j] - x[i]
            gap = wp.dot(rel, nn)
            g0 = ss.g0[k]
            # separated (open by more than L0, slid by L0/2), or crossed by more than L0/2: leave it to §1.5
            if wp.abs(gap - g0) > half * l0 and gap - g0 < wp.float64(0.0):
                ss.dropped[k] = 1
                list_change(ss.changes, ss.change_count, slot, k)
            elif gap - g0 > l0 or wp.abs(wp.dot(rel, tt)) > half * l0:
                ss.dropped[k] = 1
                list_change(ss.changes, ss.change_count, slot, k)
            else:
                r2 = spring_update_broken(f0[1], gap, g0, ds, kn, ks, law[1])
                fn = r2[0]
                fs = r2[1]
            ss.inelastic[k] = ss.inelastic[k] + inelastic_work(f0, fn, fs, dn, ds, kn, ks)
        ss.F[k] = wp.vec2d(fn, fs)
        fv = fn * nn + fs * tt
        if sm.zeta > wp.float64(0.0) and (mode == 0 or fn > wp.float64(0.0)):
            cd = spring_dashpot_of(dv, nn, tt, sm.dashpot[k], sm.zeta)
            fv = fv + cd
            ss.damp[k] = ss.damp[k] - wp.dot(cd, dv) * dt
        ss.force[k] = fv


def launch_spring_forces(model, state, dt: float, clock: wp.array, launch=wp.launch, first: int = 0,
                         count: int | None = None, key=None, structs: tuple | None = None) -> None:
    """Interfaces first … first + count − 1 (all by default). clock: [1] the time at the start of the step [s], on
    the device (set before the step, and before each replay of a captured one); structs: (SpringModel,
    SpringState) of model and state, if the caller keeps them (CDEMSolver does), else built here."""
    count = model.interface_count - first if count is None else count
    if count <= 0:
        return
    sm, ss = structs if structs is not None else (spring_model(model), spring_state(state))
    site = {} if key is None else {"key": key}        # a Launcher's call site (the plain wp.launch has none)
    launch(eval_spring_forces, dim=count,
           inputs=[sm, ss, state.x, state.v, wp.float64(dt), clock, first, int(first > 0)],
           device=model.device, **site)
