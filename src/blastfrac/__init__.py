"""blastfrac: blast-induced rock fracture with breakable-spring blocks (CDEM) and MPM explosives."""

__version__ = "0.1.0"

from .scenario import Scenario, ScenarioError, load_scenario, scenario_from_dict  # noqa: E402
from .simulation import Simulation, SimulationError  # noqa: E402

__all__ = ["Scenario", "ScenarioError", "Simulation", "SimulationError", "load_scenario", "scenario_from_dict",
           "__version__"]
