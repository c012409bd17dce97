"""A user's JSON file checked against its schema before any of it is used.

Schemas are plain dicts in a small subset of JSON Schema's words: `type` (a name or a list
of names: object, array, number, integer, string, boolean, null), `const`, `enum`,
`properties`, `additionalProperties` (the schema of every other key's value; without it
unknown keys are allowed: newer files add fields), `required`, `items`, `minItems`,
`maxItems`, `minimum`, `maximum`, `exclusiveMinimum`, `exclusiveMaximum`; plus `shape`, a
numeric array of that shape (None: any length), checked with numpy in one step (drawings
hold hundreds of thousands of numbers). Numbers are finite: JSON's NaN and Infinity
spellings, which Python's reader takes, are refused.
"""

from __future__ import annotations

import json
import math

from onestroke.errors import InputError

_TYPES = {"object": dict, "array": list, "string": str, "boolean": bool, "null": type(None)}


def _is(value, name: str) -> bool:
    if name == "number":
        return isinstance(value, (int, float)) and not isinstance(value, bool)
    if name == "integer":
        return isinstance(value, int) and not isinstance(value, bool)
    return isinstance(value, _TYPES[name])


def _describe(value) -> str:
    if isinstance(value, bool) or value is None:
        return json.dumps(value)
    kinds = {dict: "an object", list: "a list", str: "a string", int: "a number", float: "a number"}
    shown = repr(value) if isinstance(value, (int, float)) or (isinstance(value, str) and len(value) < 40) else ""
    return kinds.get(type(value), type(value).__name__) + (f" ({shown})" if shown else "")


def _holds_boolean(value) -> bool:
    """True if nested lists hold true or false (numpy would read them as 1 and 0)."""
    stack = [value]
    while stack:
        item = stack.pop()
        if isinstance(item, list):
            stack.extend(item)
        elif isinstance(item, bool):
            return True
    return False


def _check_shape(value, shape: list, where: str) -> str | None:
    import numpy as np

    try:
        array = np.asarray(value)
    except ValueError:  # ragged lists
        array = None
    dims = ", ".join("K" if d is None else str(d) for d in shape)
    if array is None or array.ndim != len(shape) or any(d is not None and d != n for d, n in zip(shape, array.shape)) \
            or (array.size and array.dtype.kind not in "if") or _holds_boolean(value):
        return f"{where}: expected numbers in an array of shape ({dims})"
    if array.size and not np.isfinite(array).all():
        return f"{where}: holds a number that is not finite"
    return None


def problem(value, schema: dict, where: str = "$") -> str | None:
    """The first way `value` does not follow `schema`, as "where: what", or None."""
    if "shape" in schema:
        return _check_shape(value, schema["shape"], where)
    types = schema.get("type")
    if types is not None:
        names = [types] if isinstance(types, str) else types
        if not any(_is(value, name) for name in names):
            return f"{where}: expected {' or '.join(names)}, got {_describe(value)}"
    if "const" in schema and value != schema["const"]:
        return f"{where}: expected {json.dumps(schema['const'])}, got {_describe(value)}"
    if "enum" in schema and value not in schema["enum"]:
        return f"{where}: expected one of {', '.join(json.dumps(v) for v in schema['enum'])}, got {_describe(value)}"
    if _is(value, "number"):
        if not math.isfinite(value):
            return f"{where}: {value!r} is not a finite number"
        bounds = (("minimum", lambda v, b: v >= b, "at least"), ("maximum", lambda v, b: v <= b, "at most"),
                  ("exclusiveMinimum", lambda v, b: v > b, "above"), ("exclusiveMaximum", lambda v, b: v < b, "below"))
        for key, holds, words in bounds:
            if key in schema and not holds(value, schema[key]):
                return f"{where}: {value!r} must be {words} {schema[key]:g}"
    if isinstance(value, list):
        if len(value) < schema.get("minItems", 0) or len(value) > schema.get("maxItems", math.inf):
            low, high = schema.get("minItems", 0), schema.get("maxItems")
            wanted = f"{low}" if low == high else f"at least {low}" if high is None else f"{low} to {high}"
            return f"{where}: expected {wanted} items, got {len(value)}"
        if "items" in schema:
            for index, item in enumerate(value):
                found = problem(item, schema["items"], f"{where}[{index}]")
                if found:
                    return found
    if isinstance(value, dict):
        for key in schema.get("required", ()):
            if key not in value:
                return f"{where}: \"{key}\" is missing"
        properties, rest = schema.get("properties", {}), schema.get("additionalProperties")
        for key, item in value.items():
            sub = properties.get(key, rest)
            found = problem(item, sub, f"{where}.{key}") if sub is not None else None
            if found:
                return found
    return None


def _not_finite(word: str):
    raise ValueError(f"{word} is not a number JSON allows")


def parse_json(text: str | bytes, schema: dict, *, what: str) -> object:
    """The value of JSON `text` if it follows `schema`; else `InputError` "WHAT: where: what
    is wrong" on one line (`what` names the file, e.g. "drawing 'a.json'")."""
    try:
        value = json.loads(text, parse_constant=_not_finite)
    except UnicodeDecodeError:
        raise InputError(f"{what} is not UTF-8 text, so not JSON") from None
    except (json.JSONDecodeError, ValueError, RecursionError) as error:
        raise InputError(f"{what} is not JSON ({error})") from None
    found = problem(value, schema)
    if found:
        raise InputError(f"{what}: {found}")
    return value
