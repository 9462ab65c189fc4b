"""User-facing scenario errors: one clear message naming the key path, no traceback."""

from __future__ import annotations

from pydantic import ValidationError


class ScenarioError(Exception):
    """A problem with the user's input (bad key, value, file). The CLI prints it and exits with 2."""


_UNION_TAGS = {"rectangle", "disc", "polygon", "constant", "exponential", "triangle", "table", "annulus", "sector", "circle"}


def format_validation_error(err: ValidationError, source: str = "scenario") -> str:
    """Turn a pydantic ValidationError into lines 'source: key.path: message (got value)'."""
    lines = []
    for e in err.errors():
        # pydantic inserts union tags ('rectangle', ...) and validator names into the path: drop them
        loc = ".".join(str(p) for p in e["loc"] if not (isinstance(p, str) and (p in _UNION_TAGS or "[" in p)))
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] == "extra_forbidden":
            msg = "unknown key (not part of the scenario schema; check the spelling)"
        got = e.get("input")
        shown = "" if e["type"] in ("missing", "extra_forbidden", "value_error") or isinstance(got, dict) else f" (got {got!r})"
        lines.append(f"{source}: {loc + ': ' if loc else ''}{msg}{shown}")
    return "\n".join(lines)
