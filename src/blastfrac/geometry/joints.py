"""Pre-existing joints: given traces and seeded discrete fracture networks (DFN), clipped, trimmed and split
into the planar line network that gmsh embeds in the rock (geometry/mesh.py, docs/joints.md).

Pipeline (:func:`joint_network`):

1. every set's traces: the given segments, or a DFN drawn from the set's seed (:func:`generate_dfn`);
   each is clipped to its region (DFN) and to the domain, and cut back to ``borehole_clearance`` from every
   borehole wall (DFN; a given segment that comes closer is an error);
2. the DFN keeps the network meshable: a trace that comes within ``min_gap`` of another trace without meeting
   it, that crosses one at less than ``min_angle``, or that would leave a piece shorter than ``min_gap``, is
   redrawn; an end within ``min_gap`` of the domain boundary or of another trace is extended to meet it, a tail
   shorter than ``min_gap`` beyond a crossing is cut off;
3. all pieces of all sets are split at their mutual crossings and T-junctions: the result is a list of
   points (merged within ``1e-9`` of the domain size) and straight edges, each edge tagged with its set.

Points on the domain boundary are returned apart so that the mesher can split the boundary curves there.
Everything is NumPy and deterministic: the same scenario and seed give the same network bit for bit
(PCG64 from ``SeedSequence([0x6A6F696E, seed, set index])``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .shapes import REL_TOL, Shape, _point_seg_dist, _points_in_polygon, _signed_area, subtract_disc  # noqa: F401

#: a DFN gives up when one trace finds no place in this many draws
MAX_TRIES_PER_TRACE = 250
#: a trace's orientation and length are drawn again after this many rejected positions
MARK_REDRAW = 50


# ----------------------------------------------------------------------------- results
@dataclass
class JointSetTraces:
    """The traces of one joint set after clipping (and, for a DFN, the checks of step 2).

    pieces: [K, 2, 2] segment ends [m]; trace: index of the drawn trace each piece comes from [K];
    angles: orientation of every drawn trace [deg] (in (angle − 90, angle + 90]), lengths: its drawn length
    [m] (inf for persistent traces), asked: the number of traces the intensity asks for; redrawn: candidate
    positions rejected by the checks; remarked: traces whose orientation and length were drawn again after
    MARK_REDRAW rejected positions (the only source of bias in the distributions of the accepted traces).
    """

    name: str
    pieces: np.ndarray
    trace: np.ndarray
    angles: np.ndarray = field(default_factory=lambda: np.zeros(0))
    lengths: np.ndarray = field(default_factory=lambda: np.zeros(0))
    asked: int = 0
    redrawn: int = 0
    remarked: int = 0
    region_area: float = 0.0

    @property
    def total_length(self) -> float:
        return float(np.linalg.norm(self.pieces[:, 1] - self.pieces[:, 0], axis=1).sum()) if len(self.pieces) else 0.0


@dataclass
class JointNetwork:
    """The planar network gmsh embeds: points [M, 2] [m], edges [J, 2] (point indices), edge_set [J].

    boundary_points: indices of the points on the domain boundary (the boundary curves are split there).
    sets: the per-set traces before splitting (JointSetTraces).
    """

    points: np.ndarray
    edges: np.ndarray
    edge_set: np.ndarray
    boundary_points: np.ndarray
    sets: list[JointSetTraces]

    def set_length(self, s: int) -> float:
        m = self.edge_set == s
        d = self.points[self.edges[m, 1]] - self.points[self.edges[m, 0]]
        return float(np.linalg.norm(d, axis=1).sum())


# ----------------------------------------------------------------------------- config checks
def check_joint_config(geom) -> None:
    """Checks of ``geom.joints`` that need no seed (called by GeometryConfig's validator); raises ValueError
    with the key path relative to the geometry ('joints[0].segments[1]: ...')."""
    if geom.mesh_file is not None:
        raise ValueError("joints: pre-existing joints need gmsh meshing; they are not available with geometry.mesh_file")
    shape = Shape(geom.domain)
    names: dict[str, int] = {}
    given: dict[tuple[int, int], list] = {}                # clipped pieces of the given segments so far
    for i, js in enumerate(geom.joints):
        key = f"joints[{i}]"
        name = geom.joint_name(i)
        if name in names:
            raise ValueError(f"{key}.name: '{name}' is already used by joints[{names[name]}]; names must be unique")
        names[name] = i
        h = geom.joint_mesh_size(i)
        if js.mesh_size is not None and js.mesh_size > geom.mesh_size:
            raise ValueError(f"{key}.mesh_size: must not exceed geometry.mesh_size ({js.mesh_size} > {geom.mesh_size} m)")
        clear = clearance(geom, i)
        if js.segments is not None:
            for k, (a, b) in enumerate(js.segments):
                a, b = np.asarray(a, float), np.asarray(b, float)
                _check_segment(f"{key}.segments[{k}]", a, b, shape, geom, clear)
                pieces = shape.clip(a, b)
                for (i2, k2), other in given.items():
                    if any(_collinear_overlap(p, q, p2, q2, shape.tol) for p, q in pieces for p2, q2 in other):
                        raise ValueError(f"{key}.segments[{k}]: overlaps joints[{i2}].segments[{k2}] along a stretch; "
                                         "joints may cross or meet but not run together")
                given[i, k] = pieces
        else:
            dfn = js.dfn
            dk = f"{key}.dfn"
            region = Shape(dfn.region) if dfn.region is not None else None
            if region is not None and not _overlap(region, shape):
                raise ValueError(f"{dk}.region: does not overlap the domain; the traces would all be clipped away")
            gap = dfn.min_gap if dfn.min_gap is not None else h
            if dfn.length is None and dfn.spacing is not None and dfn.spacing < gap:
                raise ValueError(f"{dk}.spacing: {dfn.spacing} m is below min_gap = {gap} m (the closest approach of "
                                 "two traces the mesh can resolve); raise the spacing or lower min_gap")
            if dfn.length is not None and dfn.length.distribution != "fixed":
                lmax = dfn.length.max
                if lmax is not None and lmax < gap:
                    raise ValueError(f"{dk}.length.max: {lmax} m is below min_gap = {gap} m; no trace is long enough")
            elif dfn.length is not None and dfn.length.mean < gap:
                raise ValueError(f"{dk}.length.mean: {dfn.length.mean} m is below min_gap = {gap} m; "
                                 "traces shorter than min_gap are not kept")


def clearance(geom, i: int) -> float:
    js = geom.joints[i]
    return js.borehole_clearance if js.borehole_clearance is not None else geom.joint_mesh_size(i)


def _check_segment(key: str, a: np.ndarray, b: np.ndarray, shape: Shape, geom, clear: float) -> None:
    L = float(np.linalg.norm(b - a))
    if L <= shape.tol:
        raise ValueError(f"{key}: zero length (ends {_fmt(a)} and {_fmt(b)}); a joint segment needs two distinct ends")
    if shape.along_boundary(a, b):
        raise ValueError(f"{key}: runs along the domain boundary; a joint must cross the rock (the boundary is already "
                         "a free surface)")
    if not shape.clip(a, b):
        raise ValueError(f"{key}: {_fmt(a)}–{_fmt(b)} lies outside the domain")
    for j, bh in enumerate(geom.boreholes):
        c = np.asarray(bh.center, float)
        d = float(_point_seg_dist(c, a, b))
        if d < bh.radius:
            raise ValueError(f"{key}: {_fmt(a)}–{_fmt(b)} passes through borehole geometry.boreholes[{j}] (centre "
                             f"{_fmt(c)}, radius {bh.radius:.6g} m); joints must keep clear of boreholes")
        if d < bh.radius + clear:
            raise ValueError(f"{key}: {_fmt(a)}–{_fmt(b)} comes within {d - bh.radius:.3g} m of the wall of "
                             f"geometry.boreholes[{j}], closer than borehole_clearance = {clear:.6g} m")


def _collinear_overlap(a, b, c, d, tol: float) -> bool:
    """True when segments ab and cd lie on one line and share a stretch longer than tol."""
    u = b - a
    L = float(np.linalg.norm(u))
    u = u / L
    off = lambda p: abs(float((p - a)[0] * u[1] - (p - a)[1] * u[0]))   # distance from the line ab
    if off(c) > tol or off(d) > tol:
        return False
    s0, s1 = sorted((float((c - a) @ u), float((d - a) @ u)))
    return min(L, s1) - max(0.0, s0) > tol


def _overlap(region: Shape, domain: Shape) -> bool:
    n = 64
    xs = np.linspace(region.lo[0], region.hi[0], n + 2)[1:-1]
    ys = np.linspace(region.lo[1], region.hi[1], n + 2)[1:-1]
    P = np.stack(np.meshgrid(xs, ys), -1).reshape(-1, 2)
    return bool(np.any(region.contains(P) & domain.contains(P)))


def _fmt(p) -> str:
    return f"({p[0]:.6g}, {p[1]:.6g})"


# ----------------------------------------------------------------------------- trace lengths
def mean_length(cfg) -> float:
    """Mean of a (truncated) trace-length distribution [m]."""
    d, lo, hi = cfg.distribution, cfg.min, cfg.max
    if d == "fixed":
        return cfg.mean
    if d == "uniform":
        return 0.5 * (lo + hi)
    if d == "power_law":
        a = cfg.exponent
        if abs(a - 2.0) < 1e-12:
            return math.log(hi / lo) / (1 / lo - 1 / hi)
        return (1 - a) / (2 - a) * (hi ** (2 - a) - lo ** (2 - a)) / (hi ** (1 - a) - lo ** (1 - a))
    if lo is None and hi is None:
        return cfg.mean
    from scipy import integrate

    pdf = _pdf(cfg)
    a, b = lo or 0.0, hi or math.inf
    z = integrate.quad(pdf, a, b, limit=200)[0]
    return integrate.quad(lambda x: x * pdf(x), a, b, limit=200)[0] / z


def _pdf(cfg):
    if cfg.distribution == "exponential":
        m = cfg.mean
        return lambda x: math.exp(-x / m) / m
    mu, s = _lognormal_params(cfg.mean, cfg.std)
    return lambda x: 0.0 if x <= 0 else math.exp(-((math.log(x) - mu) ** 2) / (2 * s * s)) / (x * s * math.sqrt(2 * math.pi))


def _lognormal_params(mean: float, std: float) -> tuple[float, float]:
    s2 = math.log(1.0 + (std / mean) ** 2)
    return math.log(mean) - 0.5 * s2, math.sqrt(s2)


def draw_length(cfg, rng: np.random.Generator) -> float:
    d = cfg.distribution
    if d == "fixed":
        return float(cfg.mean)
    if d == "uniform":
        return float(rng.uniform(cfg.min, cfg.max))
    if d == "power_law":
        a, lo, hi = cfg.exponent, cfg.min, cfg.max
        u = rng.uniform()
        if abs(a - 1.0) < 1e-12:
            return float(lo * (hi / lo) ** u)
        e = 1.0 - a
        return float((lo**e + u * (hi**e - lo**e)) ** (1.0 / e))
    lo, hi = cfg.min or 0.0, cfg.max or math.inf
    for _ in range(10_000):
        if d == "exponential":
            x = rng.exponential(cfg.mean)
        else:
            mu, s = _lognormal_params(cfg.mean, cfg.std)
            x = rng.lognormal(mu, s)
        if lo <= x <= hi:
            return float(x)
    raise ValueError("length: the truncation [min, max] keeps almost none of the distribution")


# ----------------------------------------------------------------------------- DFN
#: why candidates were redrawn (reset for each set; the most frequent reason is named when a set fails)
_REASONS: dict[str, int] = {}


def _reject(reason: str):
    _REASONS[reason] = _REASONS.get(reason, 0) + 1
    return None


class _Placed:
    """Traces placed so far (all sets): segment ends, and for each the parameters of its crossings/junctions.

    ``mark()`` / ``rollback(mark)`` undo the pieces and junctions added since the mark (a rejected candidate)."""

    def __init__(self):
        self._A = np.zeros((64, 2))
        self._B = np.zeros((64, 2))
        self.n = 0
        self.junctions: list[list[float]] = []
        self._log: list[int] = []                       # traces that got a junction, in order

    def arrays(self):
        return self._A[: self.n], self._B[: self.n]

    def add(self, a, b, junctions=()):
        if self.n == len(self._A):
            self._A = np.concatenate([self._A, np.zeros_like(self._A)])
            self._B = np.concatenate([self._B, np.zeros_like(self._B)])
        self._A[self.n], self._B[self.n] = a, b
        self.n += 1
        self.junctions.append(list(junctions))

    def add_junction(self, j: int, w: float) -> None:
        self.junctions[j].append(w)
        self._log.append(j)

    def mark(self) -> tuple[int, int]:
        return self.n, len(self._log)

    def rollback(self, mark: tuple[int, int]) -> None:
        n, nlog = mark
        while len(self._log) > nlog:
            self.junctions[self._log.pop()].pop()
        del self.junctions[n:]
        self.n = n


def _seg_intersections(p, q, A, B):
    """Parameters (t on p→q, u on A→B) and the validity mask of the intersections of one segment with many."""
    d = q - p
    e = B - A
    den = d[0] * e[:, 1] - d[1] * e[:, 0]
    ok = np.abs(den) > 1e-300 * (1 + np.abs(d).sum())
    w = A - p
    safe = np.where(ok, den, 1.0)
    t = (w[:, 0] * e[:, 1] - w[:, 1] * e[:, 0]) / safe
    u = (w[:, 0] * d[1] - w[:, 1] * d[0]) / safe
    return t, u, ok


def _seg_seg_dist(p, q, A, B):
    return np.minimum.reduce([_point_seg_dist(p[None], A, B), _point_seg_dist(q[None], A, B),
                              _point_seg_dist(A, p[None], q[None]), _point_seg_dist(B, p[None], q[None])])


def _extend_end(end: np.ndarray, u: np.ndarray, reach: float, shape: Shape, A, B, tol: float):
    """Extend a free end along the unit direction u to the nearest boundary or trace within ``reach``."""
    best = None
    h = shape.ray_hit(end, u, reach)
    if h is not None:
        best = h
    if len(A):
        t, w, ok = _seg_intersections(end, end + reach * u, A, B)
        hit = ok & (t * reach > tol) & (t <= 1) & (w >= 0) & (w <= 1)
        if hit.any():
            s = float(t[hit].min() * reach)
            best = s if best is None else min(best, s)
    return None if best is None else end + best * u


def _place(p, q, shape: Shape, placed: _Placed, gap: float, min_angle: float, holes) -> tuple | None:
    """Try to place the piece p→q: returns (p, q, junction parameters on it, [(index, u) on placed traces]) or
    None when the piece must be redrawn."""
    tol = shape.tol
    A, B = placed.arrays()
    u_dir = (q - p) / np.linalg.norm(q - p)
    # 1. free ends close to the boundary or to another trace: extend them to meet it
    ends = [p, q]
    if len(A):                                           # traces it crosses do not count: their tails are cut
        t, w, ok = _seg_intersections(p, q, A, B)
        free = ~(ok & (t >= 0) & (t <= 1) & (w >= 0) & (w <= 1))
        A, B = A[free], B[free]
    for k, sgn in ((0, -1.0), (1, 1.0)):
        e = ends[k]
        if shape.boundary_distance(e[None])[0] <= tol:
            continue
        near_b = shape.boundary_distance(e[None])[0] < gap
        near_t = len(A) and np.min(_point_seg_dist(e[None], A, B)) < gap
        if near_b or near_t:
            x = _extend_end(e, sgn * u_dir, 2.0 * gap, shape, A, B, tol)
            if x is None:
                return _reject("an end close to the boundary or a trace cannot be extended to meet it")
            ends[k] = x
    p, q = ends
    if float(np.linalg.norm(q - p)) < gap:
        return _reject("shorter than min_gap")
    for c, r in holes:                                   # an extension must not reach into a borehole's clearance
        if float(_point_seg_dist(c, p, q)) < r * (1 - 1e-12):
            return _reject("extended into a borehole's clearance")
    return _finish(p, q, shape, placed, gap, min_angle, depth=0)


def _finish(p, q, shape: Shape, placed: _Placed, gap: float, min_angle: float, depth: int):
    """Check the crossings of p→q with the placed traces, cut off tails shorter than min_gap beyond its first
    and last crossing (then check again), and check its ends (:func:`_check_ends`)."""
    tol = shape.tol
    A, B = placed.arrays()
    L = float(np.linalg.norm(q - p))
    if L < gap:
        return _reject("shorter than min_gap")
    if not len(A):
        return _check_ends(p, q, shape, gap, min_angle, [], [])
    u_dir = (q - p) / L
    t, w, ok = _seg_intersections(p, q, A, B)
    le = np.linalg.norm(B - A, axis=1)
    cross = ok & (t >= -tol / L) & (t <= 1 + tol / L) & (w >= -tol / le) & (w <= 1 + tol / le)
    if np.any(~cross & (_seg_seg_dist(p, q, A, B) < gap)):
        return _reject("closer than min_gap to a trace it does not meet")
    idx = np.flatnonzero(cross)
    ts = np.clip(t[idx], 0.0, 1.0)
    ws = np.clip(w[idx], 0.0, 1.0)
    for j, wj in zip(idx, ws):
        e = (B[j] - A[j]) / le[j]
        if math.degrees(math.acos(min(1.0, abs(float(u_dir @ e))))) < min_angle - 1e-9:
            return _reject("crosses a trace at less than min_angle")
        if min(wj, 1 - wj) * le[j] < gap:
            return _reject("meets a trace within min_gap of its end")
        if any(abs(wj - w0) * le[j] < gap for w0 in placed.junctions[j]):
            return _reject("meets a trace within min_gap of another junction on it")
    if len(ts) and depth == 0:
        t0 = ts.min() if tol < ts.min() * L < gap else 0.0
        t1 = ts.max() if tol < (1 - ts.max()) * L < gap else 1.0
        if t0 > 0.0 or t1 < 1.0:                          # tails shorter than min_gap: cut off
            return _finish(p + t0 * (q - p), p + t1 * (q - p), shape, placed, gap, min_angle, depth=1)
    order = np.argsort(ts)
    ts, ws, idx = ts[order], ws[order], idx[order]
    if len(ts) > 1 and np.min(np.diff(ts)) * L < gap:
        return _reject("two of its crossings closer than min_gap")
    return _check_ends(p, q, shape, gap, min_angle, list(ts), [(int(j), float(x)) for j, x in zip(idx, ws)])


def _check_ends(p, q, shape, gap, min_angle, junctions, touched):
    """Ends on the boundary must meet it at min_angle or more and away from its corners; the others must be
    min_gap away from it, as must every crossing."""
    tol = shape.tol
    if float(np.linalg.norm(q - p)) < gap:
        return _reject("shorter than min_gap")
    u = (q - p) / np.linalg.norm(q - p)
    for e in (p, q):
        db = shape.boundary_distance(e[None])[0]
        if db <= tol:
            ang = math.degrees(math.acos(min(1.0, abs(float(u @ shape.tangent(e))))))
            if ang < min_angle - 1e-9 or shape.corner_distance(e) < gap:
                return _reject("meets the boundary at less than min_angle or near a corner")
        elif db < gap:
            return _reject("ends closer than min_gap to the boundary")
    for tj in junctions:
        x = p + tj * (q - p)
        if tol < shape.boundary_distance(x[None])[0] < gap:
            return _reject("crosses a trace closer than min_gap to the boundary")
    return p, q, junctions, touched


def _trace_pieces(c, theta, length, region: Shape | None, shape: Shape, holes, tol):
    """Clip the trace of centre c, direction theta [rad], length [m] (inf: a line across the region)."""
    u = np.array([math.cos(theta), math.sin(theta)])
    if math.isinf(length):
        reach = 2.0 * (shape.scale + (region.scale if region is not None else 0.0)) + float(np.linalg.norm(c - shape.lo))
        p, q = c - reach * u, c + reach * u
    else:
        p, q = c - 0.5 * length * u, c + 0.5 * length * u
    pieces = region.clip(p, q) if region is not None else [(p, q)]
    out = []
    for a, b in pieces:
        out += shape.clip(a, b)
    for hc, hr in holes:
        nxt = []
        for a, b in out:
            nxt += subtract_disc(a, b, hc, hr, tol)
        out = nxt
    return out


def generate_dfn(geom, i: int, seed: int, placed: _Placed) -> JointSetTraces:
    """Draw the network of joint set i (a DFN) with the given seed, placing its traces among ``placed``."""
    dfn = geom.joints[i].dfn
    key = f"geometry.joints[{i}].dfn"
    shape = Shape(geom.domain)
    region = Shape(dfn.region) if dfn.region is not None else None
    box = region if region is not None else _BoxShape(shape)
    area = box.area
    gap = dfn.min_gap if dfn.min_gap is not None else geom.joint_mesh_size(i)
    clear = clearance(geom, i)
    holes = [(np.asarray(b.center, float), b.radius + clear) for b in geom.boreholes]
    s = dfn.seed if dfn.seed is not None else seed
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([0x6A6F696E, int(s), i])))
    theta0 = math.radians(dfn.angle)
    spread = math.radians(dfn.angle_spread)
    n_hat = np.array([-math.sin(theta0), math.cos(theta0)])
    persistent = dfn.length is None
    if persistent:
        corners = _corners(box)
        proj = corners @ n_hat
        o0 = proj.min() + rng.uniform(0.0, dfn.spacing)
        offsets = np.arange(o0, proj.max(), dfn.spacing)
        n_ask = len(offsets)
        centre = 0.5 * (box.lo + box.hi)
        centre = centre - (centre @ n_hat) * n_hat
    else:
        lm = mean_length(dfn.length)
        expect = area / (dfn.spacing * lm) if dfn.spacing is not None else dfn.density * area
        n_ask = int(round(expect))
        if n_ask < 1:
            raise ValueError(f"{key}: the intensity asks for {expect:.3g} traces in a region of {area:.4g} m² "
                             "(fewer than one); raise the density or lower the spacing")
    pieces, trace_of, angles, lengths = [], [], [], []
    redrawn = remarked = 0
    theta, length = theta0, math.inf
    _REASONS.clear()
    k = 0
    tries = 0                                            # draws for trace k so far
    while k < n_ask:
        tries += 1
        if tries > MAX_TRIES_PER_TRACE:
            why = max(_REASONS, key=_REASONS.get) if _REASONS else "?"
            raise ValueError(f"{key}: placed only {k} of {n_ask} traces: trace {k + 1} found no place in "
                             f"{MAX_TRIES_PER_TRACE} draws (min_gap {gap:.4g} m, min_angle {dfn.min_angle:g}°; most "
                             f"redraws: {why}); lower the intensity, min_gap or min_angle")
        if (tries - 1) % MARK_REDRAW == 0:
            # the trace's marks (orientation, length) are drawn once and kept while only its position is
            # redrawn, so that the accepted traces follow the asked distributions; new marks only after
            # MARK_REDRAW positions failed
            theta = theta0 + spread * rng.standard_normal() if spread > 0 else theta0
            theta = _wrap(theta, theta0)
            length = math.inf if persistent else draw_length(dfn.length, rng)
            remarked += tries > 1
        if persistent:
            jitter = 0.0 if tries == 1 else 0.25 * dfn.spacing * rng.uniform(-1, 1)
            c = centre + (offsets[k] + jitter) * n_hat
        else:
            c = _draw_point(box, rng)
        cand = _trace_pieces(c, theta, length, region, shape, holes, shape.tol)
        results = []
        ok = True
        mark = placed.mark()
        for a, b in cand:
            if float(np.linalg.norm(b - a)) < gap:
                continue                                  # a clipped remnant shorter than min_gap: not kept
            r = _place(a, b, shape, placed, gap, dfn.min_angle, holes)
            if r is None:
                ok = False
                break
            pa, pb, junc, touched = r
            for j, w in touched:
                placed.add_junction(j, w)
            placed.add(pa, pb, junc)
            results.append((pa, pb))
        if not ok:
            placed.rollback(mark)
            redrawn += 1
            continue
        for pa, pb in results:
            pieces.append(np.stack([pa, pb]))
            trace_of.append(k)
        angles.append(math.degrees(theta))
        lengths.append(length)
        k += 1
        tries = 0
    return JointSetTraces(name=geom.joint_name(i), pieces=np.array(pieces).reshape(-1, 2, 2),
                          trace=np.array(trace_of, np.int64), angles=np.array(angles), lengths=np.array(lengths),
                          asked=n_ask, redrawn=redrawn, remarked=remarked, region_area=area)


class _BoxShape(Shape):
    """The domain's bounding box (the default DFN region)."""

    def __init__(self, shape: Shape):
        lo, hi = shape.lo, shape.hi
        self.kind = "poly"
        self.v = np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]])
        self.lo, self.hi = lo.copy(), hi.copy()
        self.scale = shape.scale
        self.tol = shape.tol


def _corners(s: Shape) -> np.ndarray:
    if s.kind == "disc":
        a = np.linspace(0, 2 * np.pi, 65)[:-1]
        return s.center + s.radius * np.stack([np.cos(a), np.sin(a)], 1)
    return s.v


def _draw_point(s: Shape, rng) -> np.ndarray:
    while True:
        x = s.lo + (s.hi - s.lo) * rng.uniform(size=2)
        if s.contains(x[None])[0]:
            return x


def _wrap(theta: float, theta0: float) -> float:
    """theta folded into (theta0 − π/2, theta0 + π/2] (a trace at θ equals one at θ + π)."""
    return theta0 + ((theta - theta0 + 0.5 * math.pi) % math.pi) - 0.5 * math.pi


# ----------------------------------------------------------------------------- the network
def joint_traces(geom, seed: int = 0) -> list[JointSetTraces]:
    """The traces of every joint set: given segments clipped to the domain, then the persistent DFN sets, then the
    others (each group in list order); a DFN's traces are placed among all those placed before."""
    shape = Shape(geom.domain)
    placed = _Placed()
    out: list[JointSetTraces | None] = [None] * len(geom.joints)
    for i, js in enumerate(geom.joints):
        if js.segments is None:
            continue
        pieces, trace = [], []
        for k, (a, b) in enumerate(js.segments):
            for pa, pb in shape.clip(np.asarray(a, float), np.asarray(b, float)):
                pieces.append(np.stack([pa, pb]))
                trace.append(k)
                placed.add(pa, pb)
        d = np.array([np.asarray(b, float) - np.asarray(a, float) for a, b in js.segments])
        out[i] = JointSetTraces(name=geom.joint_name(i), pieces=np.array(pieces).reshape(-1, 2, 2),
                                trace=np.array(trace, np.int64), angles=np.degrees(np.arctan2(d[:, 1], d[:, 0])),
                                lengths=np.linalg.norm(d, axis=1), asked=len(js.segments))
    # persistent sets (lines across their region) are the hardest to fit among other traces: placed first
    dfns = [i for i, js in enumerate(geom.joints) if js.dfn is not None]
    for i in sorted(dfns, key=lambda i: geom.joints[i].dfn.length is not None):
        out[i] = generate_dfn(geom, i, seed, placed)
    return out  # type: ignore[return-value]


def joint_network(geom, seed: int = 0) -> JointNetwork:
    """All joint pieces split at their crossings and T-junctions into one planar network (see the module doc)."""
    sets = joint_traces(geom, seed)
    shape = Shape(geom.domain)
    tol = shape.tol
    segs, sid = [], []
    for s, ts in enumerate(sets):
        for a, b in ts.pieces:
            segs.append((a, b))
            sid.append(s)
    n = len(segs)
    if n == 0:
        return JointNetwork(np.zeros((0, 2)), np.zeros((0, 2), np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64), sets)
    A = np.array([a for a, _ in segs])
    B = np.array([b for _, b in segs])
    L = np.linalg.norm(B - A, axis=1)
    params: list[list[float]] = [[0.0, 1.0] for _ in range(n)]
    for i in range(n):
        if i + 1 >= n:
            break
        Aj, Bj = A[i + 1:], B[i + 1:]
        t, w, ok = _seg_intersections(A[i], B[i], Aj, Bj)
        et, ew = tol / L[i], tol / L[i + 1:]
        hit = ok & (t >= -et) & (t <= 1 + et) & (w >= -ew) & (w <= 1 + ew)
        for j in np.flatnonzero(hit):
            params[i].append(float(np.clip(t[j], 0, 1)))
            params[i + 1 + j].append(float(np.clip(w[j], 0, 1)))
        # collinear overlaps of two given segments: not a planar network gmsh can embed
        par = ~ok & (_seg_seg_dist(A[i], B[i], Aj, Bj) <= tol)
        for j in np.flatnonzero(par):
            raise ValueError(f"geometry.joints[{sid[i]}] and geometry.joints[{sid[i + 1 + j]}]: two joint segments "
                             f"overlap along {_fmt(A[i])}–{_fmt(B[i])}; joints may cross or meet but not run together")
    pts: list[np.ndarray] = []
    edges, eset = [], []
    grid: dict[tuple[int, int], list[int]] = {}
    cell = max(1e3 * tol, 1e-300)

    def point_id(x: np.ndarray) -> int:
        key = (int(math.floor(x[0] / cell)), int(math.floor(x[1] / cell)))
        for dx in (-1, 0, 1):
            for dy in (-1, 0, 1):
                for k in grid.get((key[0] + dx, key[1] + dy), ()):
                    if np.linalg.norm(pts[k] - x) <= 10 * tol:
                        return k
        pts.append(x)
        grid.setdefault(key, []).append(len(pts) - 1)
        return len(pts) - 1

    for i in range(n):
        ts = np.unique(np.array(params[i]))
        ids = [point_id(A[i] + t * (B[i] - A[i])) for t in ts]
        for a, b in zip(ids[:-1], ids[1:]):
            if a != b:
                edges.append((a, b))
                eset.append(sid[i])
    P = np.array(pts)
    on_b = np.flatnonzero(shape.boundary_distance(P) <= 10 * tol)
    E = np.array(edges, np.int64).reshape(-1, 2)
    # one edge may appear twice when two sets meet end to end along the same line; keep it once (first set)
    key = np.minimum(E[:, 0], E[:, 1]) * len(P) + np.maximum(E[:, 0], E[:, 1])
    _, first = np.unique(key, return_index=True)
    first.sort()
    return JointNetwork(P, E[first], np.array(eset, np.int64)[first], on_b, sets)


def check_joint_network(geom, seed: int) -> None:
    """Draw the scenario's networks once (the Scenario cross-check): raises ValueError naming the set on failure."""
    if any(js.dfn is not None for js in geom.joints):
        joint_network(geom, seed)
