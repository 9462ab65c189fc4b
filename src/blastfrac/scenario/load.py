"""Scenario I/O: read TOML, apply ``--set`` overrides, validate, write the resolved file."""

from __future__ import annotations

import ast
import tomllib
from pathlib import Path
from typing import Any

import tomli_w
from pydantic import ValidationError

from .errors import ScenarioError, format_validation_error
from .schema import Scenario


def parse_override(text: str) -> tuple[list[str], Any]:
    """Parse ``section.key=value``; the value is read as a TOML value, else as a bare string."""
    if "=" not in text:
        raise ScenarioError(f"--set {text!r}: expected section.key=value")
    key, raw = text.split("=", 1)
    path = [p for p in key.strip().split(".") if p]
    if not path:
        raise ScenarioError(f"--set {text!r}: empty key")
    raw = raw.strip()
    try:
        value = tomllib.loads(f"v = {raw}")["v"]
    except tomllib.TOMLDecodeError:
        try:
            value = ast.literal_eval(raw)
        except (ValueError, SyntaxError):
            value = raw
    return path, value


def apply_overrides(data: dict, overrides: list[str]) -> dict:
    """Set each ``a.b.c=value`` into the nested dict ``data`` (list items by integer index)."""
    for text in overrides:
        path, value = parse_override(text)
        node: Any = data
        for i, part in enumerate(path[:-1]):
            nxt = path[i + 1]
            if isinstance(node, list):
                node = node[_index(part, text, len(node))]
            else:
                if part not in node:
                    node[part] = [] if nxt.isdigit() else {}
                node = node[part]
            if not isinstance(node, (dict, list)):
                where = ".".join(path[: i + 1])
                raise ScenarioError(f"--set {text!r}: {where} is a value ({node!r}), not a section or a list; "
                                    f"'{'.'.join(path[i + 1:])}' cannot be set inside it")
        last = path[-1]
        if isinstance(node, list):
            node[_index(last, text, len(node))] = value
        else:
            node[last] = value
    return data


def _index(part: str, text: str, n: int) -> int:
    if not part.isdigit() or int(part) >= n:
        raise ScenarioError(f"--set {text!r}: '{part}' is not a valid index (list has {n} items)")
    return int(part)


def load_scenario(path: str | Path, overrides: list[str] | None = None) -> Scenario:
    """Read, override and validate a scenario file. Raises ScenarioError with a readable message."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except FileNotFoundError:
        raise ScenarioError(f"{path}: no such file") from None
    except (OSError, UnicodeDecodeError) as e:
        raise ScenarioError(f"{path}: cannot read ({e})") from None
    except tomllib.TOMLDecodeError as e:
        raise ScenarioError(f"{path}: not valid TOML ({e})") from None
    data = apply_overrides(data, overrides or [])
    scenario = scenario_from_dict(data, source=str(path))
    if scenario.geometry.mesh_file is not None:
        mesh = Path(scenario.geometry.mesh_file)
        if not mesh.is_absolute():
            mesh = (path.parent / mesh).resolve()
        if not mesh.is_file():
            raise ScenarioError(f"{path}: geometry.mesh_file: no such file {mesh}")
        scenario.geometry.mesh_file = str(mesh)
    return scenario


def scenario_from_dict(data: dict, source: str = "scenario") -> Scenario:
    """Validate a plain dict (the Python API builds scenarios this way too)."""
    try:
        return Scenario.model_validate(data)
    except ValidationError as e:
        raise ScenarioError(format_validation_error(e, source)) from None


def resolved_dict(scenario: Scenario) -> dict:
    """All values, defaults included, as TOML-serialisable data (None entries dropped)."""
    return _drop_none(scenario.model_dump(mode="json"))


def write_resolved(scenario: Scenario, path: str | Path) -> None:
    from ..io.atomic import write_text_atomic

    write_text_atomic(
        path,
        "# blastfrac resolved scenario: every value used by the run, defaults included\n"
        + tomli_w.dumps(resolved_dict(scenario)),
    )


def _drop_none(x: Any) -> Any:
    if isinstance(x, dict):
        return {k: _drop_none(v) for k, v in x.items() if v is not None}
    if isinstance(x, list):
        return [_drop_none(v) for v in x]
    return x
