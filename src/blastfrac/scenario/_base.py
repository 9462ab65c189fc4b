"""Base model and shared types of the scenario schema (split from schema.py so that sections can live in their
own modules without importing each other in a circle)."""

from __future__ import annotations

from pydantic import BaseModel, ConfigDict

Point = tuple[float, float]


class _Strict(BaseModel):
    # allow_inf_nan=False: every float, also inside tuples, lists and nested models, must be finite
    model_config = ConfigDict(extra="forbid", validate_assignment=True, allow_inf_nan=False)
