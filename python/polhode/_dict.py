"""Writes a scenario given as a Python dict as block-style YAML text for the CLI's loader.

``Scenario.from_dict`` calls :func:`to_yaml` and validates the text with the same loader as
``polhode check``, so a dict gets the same checks and messages as a file. Values are written
so that the loader sees what Python holds:

- text always double-quoted (``"1e2"`` stays text), keys plain when they are identifiers;
- floats in their shortest round-trip form, NaN and infinities as ``.nan``, ``.inf`` and
  ``-.inf`` (so the loader's own finiteness checks report them, naming the field);
- numpy arrays as (nested) lists, numpy scalars as numbers, tuples as lists;
- mappings as indented blocks, lists of numbers as ``[a, b, c]``, lists of mappings as
  ``- `` items, so the loader can name the field of an error (``effectors[0].mass``).

Anything else (a set, bytes, a complex number, an arbitrary object) raises ``ScenarioError``
naming its field; a ``d`` that is not a mapping at all raises ``TypeError``.
"""

import json
import math
import re
from collections.abc import Mapping

from ._args import type_error
from ._polhode import ScenarioError

__all__ = ["to_yaml"]

# Keys written without quotes: identifiers the YAML core schema does not read as anything else.
_PLAIN_KEY = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_RESERVED = {"true", "false", "null", "yes", "no", "on", "off", "y", "n"}
_MAX_DEPTH = 64


def _error(field, message):
    """A ScenarioError about ``field`` of the dict (no line or column: the text is generated)."""
    text = f"<dict>: field `{field}`: {message}" if field else f"<dict>: {message}"
    e = ScenarioError(text)
    e.path = "<dict>"
    e.line = None
    e.column = None
    e.field = field or None
    e.message = message
    return e


def _join(field, key):
    return f"{field}.{key}" if field else str(key)


def _plain(value):
    """numpy arrays and scalars as Python lists and numbers; tuples as lists."""
    if hasattr(value, "dtype") and hasattr(value, "tolist"):
        return value.tolist()
    if isinstance(value, tuple):
        return list(value)
    return value


def _scalar(value, field):
    """The YAML text of a scalar, or None when ``value`` is a list or a mapping."""
    if value is None:
        return "null"
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return ".nan"
        if math.isinf(value):
            return ".inf" if value > 0 else "-.inf"
        return repr(value)
    if isinstance(value, str):
        return json.dumps(value, ensure_ascii=False)
    if isinstance(value, (list, Mapping)):
        return None
    raise _error(
        field,
        f"expected a number, text, true/false, a list or a mapping, got a "
        f"{type(value).__name__} ({value!r:.60})",
    )


def _key(key, field):
    if not isinstance(key, str):
        raise _error(field, f"keys must be text, got the {type(key).__name__} {key!r:.60}")
    if _PLAIN_KEY.match(key) and key.lower() not in _RESERVED:
        return key
    return json.dumps(key, ensure_ascii=False)


def _has_mapping(value):
    value = _plain(value)
    if isinstance(value, Mapping):
        return True
    if isinstance(value, list):
        return any(_has_mapping(v) for v in value)
    return False


def _flow(value, field, depth):
    """A list without mappings as one line: ``[1.0, [2, 3], "x"]``."""
    value = _plain(value)
    if depth > _MAX_DEPTH:
        raise _error(field, f"nested deeper than {_MAX_DEPTH} levels")
    if isinstance(value, list):
        items = [_flow(v, f"{field}[{i}]", depth + 1) for i, v in enumerate(value)]
        return "[" + ", ".join(items) + "]"
    return _scalar(value, field)


def _inline(value, field, depth):
    """One-line text of ``value``, or None when it needs a block."""
    value = _plain(value)
    if isinstance(value, Mapping):
        return None if value else "{}"
    if isinstance(value, list):
        return None if _has_mapping(value) else _flow(value, field, depth)
    return _scalar(value, field)


def _block(value, field, depth, lines, fields):
    """Appends the lines of a mapping or list ``value``, and the field each line holds."""
    if depth > _MAX_DEPTH:
        raise _error(field, f"nested deeper than {_MAX_DEPTH} levels")
    value = _plain(value)
    if isinstance(value, Mapping):
        for key, item in value.items():
            name = _join(field, key) if isinstance(key, str) else field
            text = _key(key, name)
            one_line = _inline(item, name, depth + 1)
            if one_line is not None:
                lines.append(f"{text}: {one_line}")
                fields.append(name)
            else:
                lines.append(f"{text}:")
                fields.append(name)
                sub, sub_fields = [], []
                _block(item, name, depth + 1, sub, sub_fields)
                lines.extend("  " + s for s in sub)
                fields.extend(sub_fields)
        return
    for i, item in enumerate(value):
        name = f"{field}[{i}]"
        one_line = _inline(item, name, depth + 1)
        if one_line is not None:
            lines.append(f"- {one_line}")
            fields.append(name)
            continue
        sub, sub_fields = [], []
        _block(item, name, depth + 1, sub, sub_fields)
        if not sub:
            lines.append("- []")
            fields.append(name)
            continue
        lines.append("- " + sub[0])
        lines.extend("  " + s for s in sub[1:])
        fields.extend(sub_fields)


def to_yaml(scenario):
    """``(text, fields)``: the scenario dict as YAML, and the dotted field of each line."""
    scenario = _plain(scenario)
    if not isinstance(scenario, Mapping):
        raise type_error(
            "Scenario.from_dict",
            "d",
            "a dict of the scenario's top-level keys (name, body, initial, duration, ...)",
            scenario,
        )
    lines, fields = [], []
    _block(scenario, "", 0, lines, fields)
    return "\n".join(lines) + "\n", fields
