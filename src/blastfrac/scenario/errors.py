"""User-facing scenario errors: one clear message naming the key path, no traceback."""

from __future__ import annotations

import re

from pydantic import ValidationError


class ScenarioError(Exception):
    """A problem with the user's input (bad key, value, file). The CLI prints it and exits with 2."""


_UNION_TAGS = {"rectangle", "disc", "polygon", "constant", "exponential", "triangle", "table", "annulus", "sector", "circle"}

# a validator's message may start with a key path relative to the model it checks ('vertices[2]: ...'); it is
# then joined to the location of that model ('explosive.charges[0]' + '.vertices[2]')
_REL_PATH = re.compile(r"^([A-Za-z_]\w*(?:\[\d+\])*(?:\.[A-Za-z_]\w*(?:\[\d+\])*)*): (.*)$", re.S)


def key_path(parts) -> str:
    """'explosive.charges[0].radius' from ('explosive', 'charges', 0, 'radius')."""
    out = ""
    for p in parts:
        if isinstance(p, int):
            out += f"[{p}]"
        else:
            out += f".{p}" if out else str(p)
    return out


def format_validation_error(err: ValidationError, source: str = "scenario") -> str:
    """Turn a pydantic ValidationError into lines 'source: key.path: message (got value)'."""
    lines = []
    for e in err.errors():
        # pydantic inserts union tags ('rectangle', ...) and validator names into the path: drop them
        loc = key_path(p for p in e["loc"] if not (isinstance(p, str) and (p in _UNION_TAGS or "[" in p)))
        msg = e["msg"].removeprefix("Value error, ")
        if e["type"] in ("value_error", "assertion_error"):
            m = _REL_PATH.match(msg)
            if m:
                rel, msg = m.groups()
                loc = f"{loc}.{rel}" if loc else rel
        if e["type"] == "extra_forbidden":
            msg = "unknown key (not part of the scenario schema; check the spelling)"
        elif e["type"] == "finite_number":
            msg = "must be a finite number (NaN and ±inf are not allowed)"
        got = e.get("input")
        shown = "" if e["type"] in ("missing", "extra_forbidden", "value_error") or isinstance(got, dict) else f" (got {got!r})"
        lines.append(f"{source}: {loc + ': ' if loc else ''}{msg}{shown}")
    return "\n".join(lines)
