"""Heterogeneous rock: interface-by-interface Weibull scatter of the spring properties, i.i.d. or spatially
correlated.

Each interior interface q (one potential crack, both of its springs) gets a factor w_q on the scenario's
value of each listed property (``rock.heterogeneity.fields``):

    T_q = T̄·w_q,   c_q = c̄·w_q,   (k_n, k_s)_q = (k̄_n, k̄_s)_q·w_q,

with w_q drawn from the Weibull distribution of modulus m and unit mean,

    F(w) = 1 − exp(−(w/λ)^m),   λ = 1/Γ(1 + 1/m),
    E[w] = 1,   CV(m) = √(Γ(1 + 2/m) − Γ(1 + 1/m)²) / Γ(1 + 1/m)

(m = 2: CV 0.523, m = 5: 0.229, m = 10: 0.120), so the scenario's ``tensile_strength``, ``cohesion`` and
spring stiffness are the means. The draws are i.i.d. per interface, in the topology's interface order,
from NumPy's PCG64 seeded by ``SeedSequence([STREAM, simulation.seed, field])``: the same seed gives the
same field, each property has its own stream (adding ``stiffness`` to the list leaves the T draw as it
was), and ``correlated = true`` gives every listed property the ``tensile_strength`` stream's draw (one
weak interface is weak in tension and shear alike; switching correlation leaves T unchanged).

Weakest-link size scaling (``reference_length`` L_ref, off by default): the strength factors of an interface
of length L_q (``tensile_strength`` and ``cohesion``, not ``stiffness``) are multiplied by

    s_q = (L_ref/L_q)^(1/m),

so that interface q survives a uniform stress σ with P_q = exp(−(L_q/L_ref)(σ/(λ·T̄))^m) and a crack path
of interfaces survives with P_s = exp(−Σ L_q/L_ref·(σ/(λ·T̄))^m): a function of the path's length alone,
however many interfaces it is cut into. ``tensile_strength`` and ``cohesion`` are then the mean strengths of
an interface of length L_ref (an interface of length L has mean T̄·(L_ref/L)^(1/m)).

Spatially correlated field (``correlation_length`` ℓ, off by default): instead of one independent draw per
interface, w is a function of position, sampled at the interface's midpoint x_q,

    w(x) = F_W⁻¹(Φ(g(x))),   g(x) = √(2/N) Σ_j cos(k_j·x + φ_j),   k_j ~ N(0, I/ℓ²),  φ_j ~ U(0, 2π),

a unit-variance Gaussian random field of covariance E[g(x)g(x + r)] = exp(−|r|²/(2ℓ²)) (random Fourier
features, N = ``FOURIER_MODES``; Shinozuka's spectral method) mapped point by point onto the unit-mean
Weibull marginal. The field is drawn once per seed and property stream and is independent of the mesh: two
meshes of one domain get the same strength at the same place, so a mesh refinement compares like with like,
and the spacing of weak spots (the crack nucleation sites) is set by ℓ in metres, not by the element.
Mutually exclusive with ``reference_length`` (an interface shorter than ℓ is not an independent link).

Consequences handled in the builder (model/builder.py, docs/heterogeneity.md):
- fracture energies: the spring kernels take one softening rate per model, so the rate is the homogeneous
  rule at the area-weighted rms strength, s = T_rms²/(2(G_f − T_rms²/(2k_min))). Interface q then dissipates
  G_f·(T_q/T_rms)² per unit area (exactly, at the softest nominal spring), area-weighted mean G_f: the mean
  is kept, each interface's energy scales with its strength squared;
- stiffness: the stable step is the Gershgorin bound of the per-pair stiffnesses (the stiffest draw sets it),
  and the compliance compensation uses the per-interface sum Σ L_q/k_q, i.e. the harmonic (series) mean of
  the drawn stiffness, E[1/w] = Γ(1 − 1/m)·Γ(1 + 1/m) (finite for m > 1 only, hence m > 1 for stiffness).
"""

from __future__ import annotations

import math

import numpy as np

#: the properties a field can scale, in their canonical (stream) order
FIELDS = ("tensile_strength", "cohesion", "stiffness")
#: first word of the seed sequence of every heterogeneity stream ("hete"), so that other random fields
#: seeded by simulation.seed get other streams
STREAM = 0x68657465


def weibull_scale(m: float) -> float:
    """λ = 1/Γ(1 + 1/m): the scale of the unit-mean Weibull distribution of modulus m [-]."""
    return math.exp(-math.lgamma(1.0 + 1.0 / m))


def weibull_cv(m: float) -> float:
    """Coefficient of variation √(Γ(1+2/m) − Γ(1+1/m)²)/Γ(1+1/m) of a Weibull variable of modulus m [-]."""
    return math.sqrt(math.expm1(math.lgamma(1.0 + 2.0 / m) - 2.0 * math.lgamma(1.0 + 1.0 / m)))


def weibull_cdf(w: np.ndarray, m: float) -> np.ndarray:
    """CDF of the unit-mean Weibull distribution of modulus m at w ≥ 0."""
    w = np.asarray(w, float)
    return -np.expm1(-np.power(np.maximum(w, 0.0) / weibull_scale(m), m))


def mean_inverse(m: float) -> float:
    """E[1/w] = Γ(1 − 1/m)·Γ(1 + 1/m) of the unit-mean Weibull variable (m > 1; ∞ otherwise) [-]."""
    if m <= 1.0:
        return math.inf
    return math.exp(math.lgamma(1.0 - 1.0 / m) + math.lgamma(1.0 + 1.0 / m))


def stream(seed: int, field: str) -> np.random.Generator:
    """The generator of one property's draw for simulation.seed ``seed``."""
    return np.random.Generator(np.random.PCG64(np.random.SeedSequence([STREAM, int(seed), FIELDS.index(field)])))


def draw(m: float, n: int, seed: int, field: str = "tensile_strength") -> np.ndarray:
    """``n`` unit-mean Weibull factors of modulus m from the stream of ``field`` [-]."""
    return stream(seed, field).weibull(m, n) * weibull_scale(m)


#: the properties that are strengths: the weakest-link size scaling applies to these only
STRENGTH_FIELDS = ("tensile_strength", "cohesion")


def size_factor(lengths: np.ndarray, reference_length: float, m: float) -> np.ndarray:
    """Weakest-link strength scale (L_ref/L_q)^(1/m) of interfaces of length L_q [m] [-]."""
    lengths = np.asarray(lengths, float)
    return np.power(float(reference_length) / lengths, 1.0 / float(m))


def weakest_link_survival(stress: float, total_length: float, mean_strength: float, m: float,
                          reference_length: float) -> float:
    """P_s = exp(−(ℓ/L_ref)(σ/(λ·T̄))^m): survival of a path of total length ℓ [m] under a uniform stress σ
    when interfaces of length L_ref have unit-mean Weibull strengths of mean T̄ (size-scaled field) [-]."""
    return math.exp(-(total_length / reference_length) * (stress / (weibull_scale(m) * mean_strength)) ** m)


#: number of random Fourier modes of a correlated field (the marginal's departure from Gaussian and the
#: covariance's sampling error both fall as 1/√N; 1024 keeps them at ~3 %, at ~1 s per 100 k interfaces)
FOURIER_MODES = 1024


class GaussianField:
    """One realisation of a stationary, unit-variance Gaussian random field on the plane with the squared-
    exponential covariance exp(−|r|²/(2ℓ²)), ℓ = ``correlation_length`` [m]: N random Fourier modes drawn
    from ``rng`` (module doc, "Spatially correlated field"). Evaluating it at a point depends on the point
    alone, not on which other points are asked."""

    def __init__(self, correlation_length: float, rng: np.random.Generator, modes: int = FOURIER_MODES):
        if not correlation_length > 0.0:
            raise ValueError(f"correlation_length must be > 0 m, got {correlation_length}")
        self.correlation_length = float(correlation_length)
        self.k = rng.standard_normal((modes, 2)) / self.correlation_length      # wave vectors [1/m]
        self.phase = rng.uniform(0.0, 2.0 * math.pi, modes)
        self.amplitude = math.sqrt(2.0 / modes)

    def __call__(self, points: np.ndarray, chunk: int = 4096) -> np.ndarray:
        """g at ``points`` [m], shape [n, 2] → [n] (unit variance, zero mean)."""
        points = np.asarray(points, float).reshape(-1, 2)
        out = np.empty(len(points))
        for a in range(0, len(points), chunk):
            arg = points[a:a + chunk] @ self.k.T + self.phase
            out[a:a + chunk] = self.amplitude * np.cos(arg).sum(axis=1)
        return out


def weibull_from_gaussian(g: np.ndarray, m: float) -> np.ndarray:
    """The unit-mean Weibull factor of modulus m with the same quantile as the standard normal value g:
    F_W⁻¹(Φ(g)) = λ·(−ln(1 − Φ(g)))^(1/m), evaluated through Φ(−g) for accuracy in the upper tail [-]."""
    from scipy.special import log_ndtr

    return weibull_scale(m) * np.power(-log_ndtr(-np.asarray(g, float)), 1.0 / float(m))


def correlated_draw(m: float, points: np.ndarray, correlation_length: float, seed: int,
                    field: str = "tensile_strength") -> np.ndarray:
    """Unit-mean Weibull factors of modulus m at ``points`` [m] from the correlated field of ``field``'s
    stream (module doc) [-]."""
    return weibull_from_gaussian(GaussianField(correlation_length, stream(seed, field))(points), m)


def interface_factors(cfg, n_interfaces: int, seed: int, lengths: np.ndarray | None = None,
                      midpoints: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Factor per interface [Q] for each listed property of a ``HeterogeneityConfig``; {} when homogeneous
    (``weibull_modulus`` None). The unit-mean factor w_q, drawn per interface or, with ``correlation_length``,
    sampled from the correlated field at the interface ``midpoints`` [m], [Q, 2]; times the weakest-link
    scale (L_ref/L_q)^(1/m) on the strengths when ``reference_length`` is set (then ``lengths`` [m], [Q])."""
    if cfg is None or cfg.weibull_modulus is None:
        return {}
    m = float(cfg.weibull_modulus)
    l_ref = getattr(cfg, "reference_length", None)
    ell = getattr(cfg, "correlation_length", None)
    scale = None
    if l_ref is not None:
        if lengths is None or len(lengths) != n_interfaces:
            raise ValueError("reference_length: the size scaling needs the interface lengths")
        scale = size_factor(lengths, l_ref, m)
    if ell is not None and (midpoints is None or len(midpoints) != n_interfaces):
        raise ValueError("correlation_length: the correlated field needs the interface midpoints")

    def one(f: str) -> np.ndarray:
        if ell is not None:
            return correlated_draw(m, midpoints, ell, seed, f)
        return draw(m, n_interfaces, seed, f)

    out: dict[str, np.ndarray] = {}
    shared = one(FIELDS[0]) if cfg.correlated else None
    for f in FIELDS:
        if f in cfg.fields:
            w = shared if shared is not None else one(f)
            out[f] = w * scale if (scale is not None and f in STRENGTH_FIELDS) else w
    return out


def rms(values: np.ndarray, weights: np.ndarray) -> float:
    """Weighted root mean square √(Σ w·v²/Σ w)."""
    values, weights = np.asarray(values, float), np.asarray(weights, float)
    return float(math.sqrt(np.sum(weights * values**2) / np.sum(weights)))


def fracture_energy_per_area(strength: np.ndarray, k: np.ndarray, slope: float) -> np.ndarray:
    """Energy [J/m²] a softening spring of strength [Pa] and per-area stiffness k [Pa/m] dissipates with the
    softening rate ``slope`` [Pa/m]: s²/(2·slope) + s²/(2k) (materials.interface.softening_slope)."""
    strength = np.asarray(strength, float)
    return strength**2 / (2.0 * slope) + strength**2 / (2.0 * np.asarray(k, float))
