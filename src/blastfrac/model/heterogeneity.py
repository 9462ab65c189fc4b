"""Heterogeneous rock: interface-by-interface Weibull scatter of the spring properties.

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


def interface_factors(cfg, n_interfaces: int, seed: int, lengths: np.ndarray | None = None) -> dict[str, np.ndarray]:
    """Factor per interface [Q] for each listed property of a ``HeterogeneityConfig``; {} when homogeneous
    (``weibull_modulus`` None). The drawn unit-mean factor w_q, times the weakest-link scale
    (L_ref/L_q)^(1/m) on the strengths when ``reference_length`` is set (then ``lengths`` [m], [Q], is needed)."""
    if cfg is None or cfg.weibull_modulus is None:
        return {}
    m = float(cfg.weibull_modulus)
    l_ref = getattr(cfg, "reference_length", None)
    scale = None
    if l_ref is not None:
        if lengths is None or len(lengths) != n_interfaces:
            raise ValueError("reference_length: the size scaling needs the interface lengths")
        scale = size_factor(lengths, l_ref, m)
    out: dict[str, np.ndarray] = {}
    shared = draw(m, n_interfaces, seed, FIELDS[0]) if cfg.correlated else None
    for f in FIELDS:
        if f in cfg.fields:
            w = shared if shared is not None else draw(m, n_interfaces, seed, f)
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
