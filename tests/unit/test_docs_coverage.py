"""Every scenario option is documented: each field of every scenario model appears as a `key` row in
docs/scenario.md (the brief: every user-facing option is documented, validated and resolved)."""

import inspect
from pathlib import Path

from pydantic import BaseModel

import blastfrac.scenario.explosive as explosive
import blastfrac.scenario.geometry_config as geometry_config
import blastfrac.scenario.pulses as pulses
import blastfrac.scenario.schema as schema

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenario.md"


def test_every_scenario_field_has_a_row_in_docs_scenario_md():
    text = DOC.read_text()
    missing = []
    for mod in (schema, geometry_config, pulses, explosive):
        for name, cls in vars(mod).items():
            if not (inspect.isclass(cls) and issubclass(cls, BaseModel) and cls.__module__ == mod.__name__):
                continue
            if name.startswith("_") or name == "Scenario":      # Scenario's fields are the section headings
                continue
            missing += [f"{name}.{f}" for f in cls.model_fields if f"| `{f}` |" not in text]
    assert not missing, f"undocumented in docs/scenario.md: {missing}"
