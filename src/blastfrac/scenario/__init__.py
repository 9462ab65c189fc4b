"""Scenario files: schema (pydantic), loading with overrides, resolved output."""

from .errors import ScenarioError
from .load import load_scenario, scenario_from_dict, write_resolved
from .schema import Scenario

__all__ = ["Scenario", "ScenarioError", "load_scenario", "scenario_from_dict", "write_resolved"]
