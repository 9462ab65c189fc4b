"""Calibration of the CDEM rock: simulated UCS and Brazilian tests and a staged micro-parameter fit.

See docs/calibration.md. All quantities SI; the tests are 2D plane strain with unit thickness.
"""

from .brazilian import BrazilianResult, run_brazilian
from .fit import FitConfig, Lab, fit, load_targets
from .quasistatic import LoadSettings, run_loading
from .specimens import disc_specimen, ucs_specimen
from .ucs import UCSResult, run_ucs

__all__ = ["BrazilianResult", "FitConfig", "Lab", "LoadSettings", "UCSResult", "disc_specimen", "fit",
           "load_targets", "run_brazilian", "run_loading", "run_ucs", "ucs_specimen"]
