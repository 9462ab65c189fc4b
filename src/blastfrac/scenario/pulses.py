"""Scenario loads: pressure pulses p(t) on borehole walls and boundary sides (``[[borehole_pressure]]``,
``boundaries.<side>.pulse``). Part of the scenario schema (schema.py re-exports every name)."""

from __future__ import annotations

import math
from typing import Annotated, Literal, Union

from pydantic import Field, model_validator

from ._base import _Strict


class ConstantPulse(_Strict):
    type: Literal["constant"] = "constant"
    value: float = Field(description="Pressure [Pa] (positive pushes on the surface).")

    def __call__(self, t: float) -> float:
        return self.value


class ExponentialPulse(_Strict):
    """p(t) = p0·(exp(-a t) - exp(-b t)) normalised so that its peak equals ``peak``."""

    type: Literal["exponential"] = "exponential"
    peak: float = Field(gt=0, description="Peak pressure [Pa].")
    rise_time: float = Field(gt=0, description="Time to peak [s].")
    decay_time: float = Field(gt=0, description="e-folding decay time after the peak [s] (must exceed rise_time: "
                              "p0·(exp(-a t) - exp(-b t)) peaks before 1/a).")

    @model_validator(mode="after")
    def _decay_after_rise(self) -> "ExponentialPulse":
        if not self.decay_time > self.rise_time:
            raise ValueError(f"decay_time: must exceed rise_time ({self.decay_time} <= {self.rise_time} s); "
                             "p0·(exp(-t/decay_time) - exp(-b t)) cannot peak later than decay_time")
        return self

    def __call__(self, t: float) -> float:
        if t <= 0:
            return 0.0
        a = 1.0 / self.decay_time
        b = _rise_rate(a, self.rise_time)
        tp = math.log(b / a) / (b - a)
        norm = math.exp(-a * tp) - math.exp(-b * tp)
        return self.peak * (math.exp(-a * t) - math.exp(-b * t)) / norm


def _rise_rate(a: float, tr: float) -> float:
    """Solve ln(b/a)/(b-a) = tr for b > a (bisection on a monotone function)."""
    lo, hi = a * (1 + 1e-9), a * 1e9
    if math.log(hi / a) / (hi - a) > tr:
        return hi
    for _ in range(200):
        mid = math.sqrt(lo * hi)
        if math.log(mid / a) / (mid - a) > tr:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


class TrianglePulse(_Strict):
    type: Literal["triangle"] = "triangle"
    peak: float = Field(gt=0, description="Peak pressure [Pa].")
    rise_time: float = Field(gt=0, description="Linear rise to the peak [s].")
    duration: float = Field(gt=0, description="Total duration (linear decay to zero at this time) [s].")

    @model_validator(mode="after")
    def _order(self) -> "TrianglePulse":
        if self.duration <= self.rise_time:
            raise ValueError("duration must exceed rise_time")
        return self

    def __call__(self, t: float) -> float:
        if t <= 0 or t >= self.duration:
            return 0.0
        if t < self.rise_time:
            return self.peak * t / self.rise_time
        return self.peak * (self.duration - t) / (self.duration - self.rise_time)


class TablePulse(_Strict):
    type: Literal["table"] = "table"
    times: list[float] = Field(min_length=2, description="Times [s], increasing.")
    values: list[float] = Field(min_length=2, description="Pressures [Pa] at those times (linear in between, 0 outside).")

    @model_validator(mode="after")
    def _same_length(self) -> "TablePulse":
        if len(self.times) != len(self.values):
            raise ValueError("times and values must have the same length")
        if any(b <= a for a, b in zip(self.times, self.times[1:])):
            raise ValueError("times must be strictly increasing")
        return self

    def __call__(self, t: float) -> float:
        if t < self.times[0] or t > self.times[-1]:
            return 0.0
        for i in range(len(self.times) - 1):
            if t <= self.times[i + 1]:
                w = (t - self.times[i]) / (self.times[i + 1] - self.times[i])
                return self.values[i] + w * (self.values[i + 1] - self.values[i])
        return self.values[-1]


Pulse = Annotated[
    Union[ConstantPulse, ExponentialPulse, TrianglePulse, TablePulse], Field(discriminator="type")
]


class BoreholePressure(_Strict):
    """A prescribed pressure history on a borehole wall (rock-only blast loading)."""

    borehole: int = Field(0, ge=0, description="Index into geometry.boreholes.")
    pulse: Pulse = Field(description="Pressure history p(t).")
