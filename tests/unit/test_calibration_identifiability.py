"""Identifiability of fitted micro-parameters (issue 5, item 2): a parameter that no targeted macro
responds to must be reported as not identifiable, with the range of values that reproduce the targets;
a parameter that responds must not be.

The feature test runs the real staged fit (`fit.fit`) on a *model* laboratory whose strengths follow
the continuum limits measured in examples/calibration/README.md ("Why the strengths differ"):
σt = min(0.94·T, 0.93·c·cosφ/(2 − sinφ)) and UCS = 0.63·2c·cosφ/(1 − sinφ). With the Table 3
targets (σt set by Mohr–Coulomb) T must come out not identifiable; with the Table 4 targets (σt
set by T) it must come out identifiable.
"""

from __future__ import annotations

import math

import pytest

from blastfrac.calibration.fit import FitConfig, Lab, fit
from blastfrac.calibration.identifiability import identifiability, identifiability_of_report, relative_tolerances
from blastfrac.calibration.quasistatic import LoadSettings
from blastfrac.scenario.schema import RockConfig

TOL = {"tensile_strength": 0.02, "ucs": 0.02}


def test_flat_parameter_is_not_identifiable_and_its_interval_is_reported():
    sens = {"tensile_strength": {"tensile_strength": 0.005, "ucs": 0.0},
            "cohesion": {"tensile_strength": 0.93, "ucs": 1.17}}
    res = identifiability(sens, TOL, {"tensile_strength": 11.7e6, "cohesion": 26.7e6})
    t, c = res["tensile_strength"], res["cohesion"]
    assert t["status"] == "not identifiable"
    assert t["max_response"] == pytest.approx(0.005) and t["governing_macro"] == "tensile_strength"
    # 0.02/0.005 = 4 in ln exceeds the cap ×10: open-ended interval [T/10, 10 T]
    assert t["interval_alone"] == pytest.approx([1.17e6, 1.17e8]) and t["interval_alone_open"]
    assert "not identifiable" in t["statement"] and "any value in" in t["statement"]
    assert c["status"] == "identifiable"
    # alone: the tighter of σt (0.02/0.93) and UCS (0.02/1.17)
    w = 0.02 / 1.17
    assert c["interval_alone"] == pytest.approx([26.7e6 * math.exp(-w), 26.7e6 * math.exp(w)])
    assert not c["interval_alone_open"]


def test_threshold_separates_identifiable_from_not():
    sens = {"a": {"ucs": 0.099}, "b": {"ucs": 0.101}}
    res = identifiability(sens, {"ucs": 0.02}, {"a": 1.0, "b": 1.0}, threshold=0.1)
    assert res["a"]["status"] == "not identifiable"
    assert res["b"]["status"] != "not identifiable"


def test_parameters_that_trade_off_are_not_identifiable_jointly():
    """kn and T both move only σt: each responds on its own, but together one target cannot fix both."""
    sens = {"kn": {"tensile_strength": 0.3}, "tensile_strength": {"tensile_strength": 1.0},
            "cohesion": {"tensile_strength": 0.0, "ucs": 1.2}}
    tol = {"tensile_strength": 0.02, "ucs": 0.02}
    res = identifiability(sens, tol, {"kn": 1e15, "tensile_strength": 8e6, "cohesion": 40e6})
    assert res["kn"]["status"] == "not identifiable jointly"
    assert res["kn"]["interval_alone"] == pytest.approx([1e15 * math.exp(-0.02 / 0.3), 1e15 * math.exp(0.02 / 0.3)])
    # T can absorb kn's whole range (×/÷10 → σt ×/÷10^0.3) plus its own tolerance: joint range ×/÷ 10^0.3·e^0.02
    f = 10**0.3 * math.exp(0.02)
    assert res["tensile_strength"]["interval_jointly"] == pytest.approx([8e6 / f, 8e6 * f], rel=1e-6)
    assert res["cohesion"]["status"] == "identifiable"
    # c alone and jointly: only the UCS pins it, and nothing else moves the UCS
    assert res["cohesion"]["interval_jointly"] == pytest.approx(res["cohesion"]["interval_alone"], rel=1e-6)


def test_probe_confirms_flat_side_and_brackets_the_kink():
    from blastfrac.calibration.identifiability import probe_interval

    def measure(T):          # σt flat above T = 10, ∝ T below
        return {"tensile_strength": min(T, 10.0)}

    res = probe_interval(measure, 12.0, {"tensile_strength": 10.0}, {"tensile_strength": 0.02}, (9.0, 120.0),
                         tries=3, log=lambda *_: None)
    # 9 is out (−10 %), the ln-midpoint √(9·12) = 10.39 is in; 120 is in at the first try
    assert res["measured_interval"] == pytest.approx([math.sqrt(9 * 12), 120.0])
    assert [p["within_tolerance"] for p in res["probe_points"]] == [False, True, True]
    # no confirmed point on a side: the interval stops at the fitted value
    res = probe_interval(measure, 12.0, {"tensile_strength": 10.0}, {"tensile_strength": 0.02}, (1.2, 120.0),
                         tries=2, log=lambda *_: None)
    assert res["measured_interval"] == pytest.approx([12.0, 120.0])


def test_probe_that_leaves_tolerance_on_both_sides_makes_the_parameter_identifiable():
    """A response that the +5 % difference misses (flat within ±6 %, then ∝ x^0.5) is bounded by the probe."""
    from blastfrac.calibration.identifiability import measured_status, probe_interval

    def measure(x):
        return {"ucs": 100.0 if abs(math.log(x)) < 0.06 else 100.0 * x**0.5}

    entry = identifiability({"ks": {"ucs": 0.0}}, {"ucs": 0.02}, {"ks": 1.0})["ks"]
    assert entry["status"] == "not identifiable"
    entry.update(probe_interval(measure, 1.0, {"ucs": 100.0}, {"ucs": 0.02}, entry["interval_alone"], tries=2,
                                log=lambda *_: None))
    # ×/÷10 and ×/÷√10 are all out of tolerance: nothing confirmed, bracketed by ÷√10 and ×√10
    assert entry["measured_interval"] == [1.0, 1.0]
    assert entry["measured_bracket"] == pytest.approx([10**-0.5, 10**0.5])
    assert measured_status(entry) == "identifiable (measured)"


def test_relative_tolerances_follow_the_fit():
    tol = relative_tolerances({"youngs_modulus": 50e9, "poisson_ratio": 0.2, "ucs": 1e8}, 0.01, 0.005, 0.02)
    assert tol == pytest.approx({"youngs_modulus": 0.01, "poisson_ratio": 0.025, "ucs": 0.02})


def test_report_without_sensitivities_says_so():
    assert "skipped" in identifiability_of_report({"targets": {"ucs": 1e8}, "fitted": {}, "sensitivity": {}})


# ----------------------------------------------------------------------------- feature test: the fit
def _sigma_t(r: RockConfig) -> float:
    p = math.radians(r.friction_angle)
    return min(0.94 * r.tensile_strength, 0.93 * r.cohesion * math.cos(p) / (2 - math.sin(p)))


def _ucs(r: RockConfig) -> float:
    p = math.radians(r.friction_angle)
    return 0.63 * 2 * r.cohesion * math.cos(p) / (1 - math.sin(p))


class ModelLab(Lab):
    """A laboratory whose tests are closed-form (no simulation): strength only, no elastic targets."""

    def __init__(self):
        super().__init__([40, 0], LoadSettings(), LoadSettings(), None, None, log=lambda *_: None, name="model")

    def elastic(self, rock):
        self.static_solves += 1
        return 49e9, 0.197, 1762.0

    def brazilian(self, rock):
        self._spend()
        return _sigma_t(rock)

    def ucs(self, rock):
        self._spend()
        return _ucs(rock), 49e9, 0.197


ROCK = RockConfig(stiffness_mode="per_area", kn=1.8e15, ks=1.6e15, tensile_strength=8e6, cohesion=40e6,
                  friction_angle=60.0)


def _fit(targets):
    import json

    rep = fit(ROCK, FitConfig(targets=targets), ModelLab())
    assert all(abs(e) <= 0.02 for e in rep["relative_error"].values()), rep["relative_error"]
    json.dumps(rep["identifiability"])          # plain JSON types (calibration.json is written without a default)
    return rep["identifiability"]["parameters"]


def test_fit_reports_T_not_identifiable_where_mohr_coulomb_sets_sigma_t():
    # the model lab's macro values at Table 3 (T 14, c 26 MPa): σt 10.66 (Mohr–Coulomb), UCS 122.3 MPa
    t3 = ROCK.model_copy(update={"tensile_strength": 14e6, "cohesion": 26e6})
    ident = _fit({"tensile_strength": _sigma_t(t3), "ucs": _ucs(t3)})
    assert ident["tensile_strength"]["status"] == "not identifiable"
    t = ident["tensile_strength"]
    lo, hi = t["interval_alone"]
    assert lo < t["value"] * 1.001 and hi > 14e6     # Table 3's T lies inside (first order)
    # measured: above the fitted T nothing changes up to the cap; below it σt falls (T sets σt there)
    a, b = t["measured_interval"]
    assert a == pytest.approx(t["value"]) and b == pytest.approx(10 * t["value"])
    assert a <= 14e6 <= b
    assert any(not p["within_tolerance"] and p["value"] < a for p in t["probe_points"])
    assert "not identifiable" in t["statement"] and "any value in" in t["statement"]
    assert ident["cohesion"]["status"] == "identifiable"
    assert ident["cohesion"]["interval_alone"][0] < 26e6 < ident["cohesion"]["interval_alone"][1]


def test_fit_reports_T_identifiable_where_tension_sets_sigma_t():
    ident = _fit({"tensile_strength": 7.4e6, "ucs": 162.3e6})
    assert ident["tensile_strength"]["status"] == "identifiable"
    assert ident["cohesion"]["status"] == "identifiable"
