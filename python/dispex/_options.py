"""Keyword arguments to the JSON values the library takes, by the library's option table.

Each extract option is declared once, in the library (src/extract/io/option_table.cpp): its name
(the keyword), its command-line flag, the kind of value it takes. A value of the wrong type
raises TypeError; a value of the right type is handed to the library as JSON, which checks its
range (ValueError). NumPy scalars count as the numbers they hold, os.PathLike as paths, and
numbers may be given as the text the command line takes ("0.001").
"""

import json
import math
import numbers
import operator
import os
from typing import Any, Dict

from . import _dispex
from ._errors import shown

SPECS: Dict[str, Dict[str, Any]] = {s["name"]: s for s in _dispex._extract_option_specs()}


def _flag_name(spec):
    """The flag as a keyword ("--uv-maps" -> "uv_maps"); None for a negated flag."""
    flag = spec["flag"]
    return None if flag.startswith("--no-") else flag[2:].replace("-", "_")


# The command line's spelling of an option, where it differs from the field name.
ALIASES: Dict[str, str] = {
    _flag_name(s): name for name, s in SPECS.items()
    if _flag_name(s) is not None and _flag_name(s) != name}


def _type_error(name, value, what):
    return TypeError(f"{name}: {shown(value)} is not {what}")


def _integer(name, value):
    if isinstance(value, bool):
        raise _type_error(name, value, "an integer")
    if isinstance(value, str):
        try:
            return int(value)
        except ValueError:
            raise ValueError(f"{name}: {shown(value)} is not an integer") from None
    try:
        return operator.index(value)
    except TypeError:
        raise _type_error(name, value, "an integer") from None


def _number(name, value):
    if isinstance(value, bool):
        raise _type_error(name, value, "a number")
    if isinstance(value, str):
        try:
            number = float(value)
        except ValueError:
            raise ValueError(f"{name}: {shown(value)} is not a number") from None
    elif isinstance(value, numbers.Real):
        number = float(value)
    else:
        raise _type_error(name, value, "a number")
    if not math.isfinite(number):
        raise ValueError(f"{name}: {shown(value)} is not a finite number")
    return int(number) if isinstance(value, numbers.Integral) else number


def _text(name, value, what="a string"):
    if not isinstance(value, str):
        raise _type_error(name, value, what)
    return value


def _json_value(name, kind, values, value):
    if kind == "bool":
        if not isinstance(value, bool) and type(value).__name__ != "bool_":
            raise _type_error(name, value, "True or False")
        return bool(value)
    if kind == "integer":
        return _integer(name, value)
    if kind == "number":
        return _number(name, value)
    if kind == "integer_or_auto":
        return "auto" if value == "auto" else _integer(name, value)
    if kind in ("size", "distance"):
        if isinstance(value, str):
            return value
        if kind == "distance":
            return _number(name, value)
        size = _integer(name, value)
        if size < 0:
            raise ValueError(f"{name} = {size}: must be >= 0 bytes")
        return size
    if kind == "path":
        if not isinstance(value, (str, os.PathLike)):
            raise _type_error(name, value, "a path")
        return os.fsdecode(os.fspath(value))
    return _text(name, value, f"a string ({values})" if kind == "choice" else "a string")


def to_json(options: Dict[str, Any]) -> Dict[str, str]:
    """{option: JSON text} for the library, from keyword arguments (field names or the command
    line's spelling); unknown names raise ValueError listing the known ones."""
    out = {}
    for given, value in options.items():
        name = ALIASES.get(given, given)
        spec = SPECS.get(name)
        if spec is None:
            known = ", ".join(SPECS)
            raise ValueError(f"{given}: unknown option (known: {known})")
        if name in out:
            raise ValueError(f"{given}: given twice (also as {name})")
        out[name] = json.dumps(_json_value(given, spec["kind"], spec["values"], value))
    return out
