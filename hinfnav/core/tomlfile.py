"""TOML files read strictly, against one schema per file kind (issue 36).

:func:`read_toml` names the file and what is wrong with its bytes: a missing
file, a byte-order mark (UTF-8 or UTF-16: TOML is UTF-8 without one), text
that is not UTF-8 (the byte, its offset and its line), invalid TOML (tomllib's
message, with its line; a key or table given twice is invalid TOML).

:func:`check_schema` checks the parsed tables against a schema written as one
dict, so a new key is one line where the schema is defined::

    SCHEMA = {
        "dt": "number",                      # a real number (not a boolean)
        "continuous": "bool",                # True or False
        "nominal": {"A": "matrix", ...},     # a sub-table: its own keys, checked the same way
        "uncertainty": {"kind": "string", "vertices": [{"A": "matrix", ...}]},  # an array of tables
    }

Kinds: ``"number"``, ``"integer"``, ``"bool"``, ``"string"``, ``"matrix"``
(nested lists of numbers, rectangular: a boolean inside is refused, never read
as 0/1), ``"any"`` (left to the caller), a dict (a table) and a one-element
list (an array of tables). Unknown keys are refused at every level, naming
the key, where it is and the keys allowed there.
"""

from __future__ import annotations

import numbers
import tomllib
from typing import Any

from .exceptions import InputError
from .validation import as_path

__all__ = ["read_toml", "check_schema"]


_BOMS = {b"\xef\xbb\xbf": "UTF-8", b"\xff\xfe": "UTF-16 (little-endian)", b"\xfe\xff": "UTF-16 (big-endian)"}


def read_toml(path: Any, what: str = "file") -> dict[str, Any]:
    """Parse the TOML file at ``path``; every error is an InputError naming ``what`` and the file.

    Parameters
    ----------
    path : str or path-like
    what : str
        What the file is, for messages ("system file", "campaign spec" …).
    """
    path = as_path(what, path)
    if not path.is_file():
        raise InputError(f"{what} {path} does not exist (or is not a file)")
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise InputError(f"{what} {path} cannot be read ({exc.strerror})") from None
    for bom, enc in _BOMS.items():
        if raw.startswith(bom):
            raise InputError(f"{what} {path} starts with a {enc} byte-order mark (BOM); TOML files are UTF-8 "
                             "without one: re-save it as 'UTF-8' (not 'UTF-8 with BOM' or UTF-16)")
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise InputError(f"{what} {path} is not UTF-8 text, as TOML requires: byte {raw[exc.start]:#04x} at "
                         f"offset {exc.start} (line {line}); save it as UTF-8 (it may be Latin-1 or "
                         "Windows-1252)") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{what} {path} is not valid TOML ({exc}; a key or table given twice is refused)") from None


def _is_number(v):
    return isinstance(v, numbers.Real) and not isinstance(v, bool)


def _check_matrix(where, value):
    if not isinstance(value, list) or not value:
        raise InputError(f"{where} must be a matrix, a non-empty list of rows (lists of numbers); got {value!r}")
    rows = value if all(isinstance(r, list) for r in value) else [value]
    width = len(rows[0])
    for i, row in enumerate(rows):
        if not isinstance(row, list) or len(row) != width:
            raise InputError(f"{where}: row {i} has {len(row) if isinstance(row, list) else 'no'} entries, row 0 "
                             f"has {width}; a matrix is rectangular")
        for j, v in enumerate(row):
            if isinstance(v, bool):
                raise InputError(f"{where}[{i}][{j}] is the boolean {str(v).lower()}; a matrix holds numbers "
                                 "(write 1.0 or 0.0)")
            if not _is_number(v):
                raise InputError(f"{where}[{i}][{j}] must be a number; got {v!r}")


def check_schema(data: dict[str, Any], schema: dict[str, Any], where: str = "") -> None:
    """Check ``data`` against ``schema`` (see the module docstring); raise naming the key and where it is."""
    label = where or "the top level"
    if not isinstance(data, dict):
        raise InputError(f"{label} must be a table; got {type(data).__name__}")
    unknown = sorted(set(data) - set(schema))
    if unknown:
        raise InputError(f"{label}: unknown key {', '.join(map(repr, unknown))}; allowed here: "
                         f"{', '.join(schema) or 'none'}")
    for key, value in data.items():
        kind, at = schema[key], f"{where}.{key}" if where else key
        if isinstance(kind, dict):
            check_schema(value, kind, at)
        elif isinstance(kind, list):
            if not isinstance(value, list) or not all(isinstance(v, dict) for v in value):
                raise InputError(f"{at} must be an array of tables ([[{key}]] entries)")
            for i, v in enumerate(value):
                check_schema(v, kind[0], f"{at}[{i}]")
        elif kind == "matrix":
            _check_matrix(at, value)
        elif kind == "number" and not _is_number(value):
            raise InputError(f"{at} must be a number; got {value!r}")
        elif kind == "integer" and (isinstance(value, bool) or not isinstance(value, int)):
            raise InputError(f"{at} must be an integer; got {value!r}")
        elif kind == "bool" and not isinstance(value, bool):
            raise InputError(f"{at} must be true or false; got {value!r}")
        elif kind == "string" and not isinstance(value, str):
            raise InputError(f"{at} must be a string; got {value!r}")
