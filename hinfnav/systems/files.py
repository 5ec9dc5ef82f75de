"""A system of one's own from a TOML file: nominal, norm-bounded or polytopic.

Format (nested lists of numbers; ``x⁺ = A x + B w``, ``y = C x + D v``,
``z = L x``, w and v separate noise inputs as everywhere in hinfnav)::

    dt = 0.1                       # sampling time, s (dt = 0: continuous time, below)
    [nominal]
    A = [[1.0, 0.1], [0.0, 1.0]]
    B = [[0.005], [0.1]]
    C = [[1.0, 0.0]]
    D = [[0.1]]
    L = [[1.0, 0.0], [0.0, 1.0]]
    [uncertainty]                  # optional
    kind = "norm-bounded"          # A + H F E, FᵀF ≤ I
    H = [[0.0], [0.01]]
    E = [[1.0, 0.0]]
    # or: kind = "polytope" and [[uncertainty.vertices]] tables, each giving
    # any of A, B, C, D, L that differ from [nominal]; optional
    # cells = [[0, 1, 2, 3], [2, 3, 4, 5]]: the family is the union of the
    # hulls of these groups of vertices (0-based), not the hull of all

``dt = 0`` reads the same tables as a continuous-time plant
(``ẋ = A x + B w``): a :class:`~hinfnav.systems.continuous.ContinuousPolytope`
(nominal, or ``kind = "polytope"`` without cells; norm-bounded uncertainty
is refused: write its vertices ``A ± H E`` as a polytope).

Every error names the key in the file.
"""

from __future__ import annotations

import os

from ..core.exceptions import InputError
from ..core.tomlfile import check_schema, read_toml
from ..core.validation import as_matrix, as_positive
from .continuous import ContinuousPolytope
from .polytopic import MATRIX_KEYS, PolytopicSystem
from .uncertain import UncertainSystem

__all__ = ["read_system_file", "SYSTEM_SCHEMA"]

#: Every key a system file may hold, with its kind (:func:`hinfnav.core.tomlfile.check_schema`); any other key, at
#: any level, is refused naming it. A new key is one line here (and its use in :func:`read_system_file`).
SYSTEM_SCHEMA = {
    "dt": "number",
    "nominal": {key: "matrix" for key in MATRIX_KEYS},
    "uncertainty": {
        "kind": "string",
        "H": "matrix",
        "E": "matrix",
        "vertices": [{key: "matrix" for key in MATRIX_KEYS}],
        "cells": "any",  # checked by read_system_file: groups of vertex indices: the family is the union of their hulls
    },
}

#: The keys of [uncertainty] each kind uses (the others do not apply to it and are refused).
UNCERTAINTY_KEYS = {"norm-bounded": ("kind", "H", "E"), "polytope": ("kind", "vertices", "cells")}


def _matrix(where, table, key, required=True):
    if key not in table:
        if required:
            raise InputError(f"{where}: missing key {key!r} (a matrix as nested lists)")
        return None
    try:
        return as_matrix(f"{where}.{key}", table[key])
    except InputError as exc:
        raise InputError(f"{where}.{key}: {exc}") from None


def _vertices(verts):
    if not isinstance(verts, list) or not verts or not all(isinstance(v, dict) for v in verts):
        raise InputError("[uncertainty] kind = 'polytope' needs 'vertices', an array of tables "
                         "([[uncertainty.vertices]]) each with any of A, B, C, D, L")
    for i, v in enumerate(verts):
        bad = sorted(set(v) - set(MATRIX_KEYS))
        if bad:
            raise InputError(f"[uncertainty].vertices[{i}] has unknown key(s) {bad}; allowed: "
                             f"{', '.join(MATRIX_KEYS)}")
    return [{k: _matrix(f"[uncertainty].vertices[{i}]", v, k) for k in v} for i, v in enumerate(verts)]


def _continuous(mats, unc):
    """``dt = 0``: a nominal plant or a polytope without cells, in continuous time."""
    if unc is None:
        return ContinuousPolytope.from_matrices(mats)
    if not isinstance(unc, dict):
        raise InputError("key 'uncertainty' must be a table [uncertainty]")
    kind = unc.get("kind")
    if kind != "polytope":
        raise InputError(f"dt = 0 (continuous time): [uncertainty] kind must be \"polytope\"; got {kind!r} "
                         "(norm-bounded uncertainty is not carried in continuous time: write the vertices "
                         "A ± H E as a polytope)")
    if "cells" in unc:
        raise InputError("dt = 0 (continuous time): [uncertainty] key 'cells' is not supported in continuous time "
                         "(the continuous design certifies the hull of all vertices)")
    return ContinuousPolytope.from_matrices(mats, _vertices(unc.get("vertices")))


def read_system_file(path: str | os.PathLike[str]) -> UncertainSystem | PolytopicSystem | ContinuousPolytope:
    """Read a system TOML file.

    Returns
    -------
    UncertainSystem or PolytopicSystem or ContinuousPolytope
        Nominal or norm-bounded (``UncertainSystem``), or a polytope;
        ``dt = 0``: a continuous-time ``ContinuousPolytope``.

    Raises
    ------
    InputError
        Missing file, not UTF-8, not TOML, a missing or malformed key (named).
    """
    d = read_toml(path, "system file")
    where = str(path)
    try:
        check_schema(d, SYSTEM_SCHEMA)
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
    if "dt" not in d:
        raise InputError(f"{where}: missing key 'dt' (the sampling time, s; 0 for continuous time)")
    continuous = isinstance(d["dt"], (int, float)) and not isinstance(d["dt"], bool) and d["dt"] == 0
    try:
        dt = 0.0 if continuous else as_positive("dt", d["dt"])
    except InputError as exc:
        raise InputError(f"{where}: key 'dt': {exc}") from None
    nom = d.get("nominal")
    if not isinstance(nom, dict):
        raise InputError(f"{where}: missing table [nominal] with A, B, C, D, L")
    bad = sorted(set(nom) - set(MATRIX_KEYS))
    if bad:
        raise InputError(f"{where}: [nominal] has unknown key(s) {bad}; allowed: {', '.join(MATRIX_KEYS)}")
    mats = {k: _matrix("[nominal]", nom, k) for k in MATRIX_KEYS}
    unc = d.get("uncertainty")
    try:
        if continuous:
            return _continuous(mats, unc)
        if unc is None:
            return UncertainSystem(mats["A"], mats["B"], mats["C"], mats["D"], mats["L"], dt=dt)
        if not isinstance(unc, dict):
            raise InputError("key 'uncertainty' must be a table [uncertainty]")
        kind = unc.get("kind")
        stray = sorted(set(unc) - set(UNCERTAINTY_KEYS.get(kind, unc)))
        if stray:
            raise InputError(f"[uncertainty] key(s) {stray} do not apply to kind = {kind!r} (it uses "
                             f"{', '.join(UNCERTAINTY_KEYS[kind])})")
        if kind == "norm-bounded":
            H, E = _matrix("[uncertainty]", unc, "H"), _matrix("[uncertainty]", unc, "E")
            return UncertainSystem(mats["A"], mats["B"], mats["C"], mats["D"], mats["L"], H, E, dt=dt)
        if kind == "polytope":
            verts = _vertices(unc.get("vertices"))
            try:  # [nominal] must be a system on its own, even where every vertex replaces one of its matrices
                UncertainSystem(mats["A"], mats["B"], mats["C"], mats["D"], mats["L"], dt=dt)
            except InputError as exc:
                raise InputError(f"[nominal]: {exc}") from None
            poly = PolytopicSystem.from_matrices(mats, verts, dt)
            cells = unc.get("cells")  # optional: groups of vertex indices; the family is the union of their hulls
            if cells is None:
                return poly
            if not (isinstance(cells, list) and cells and all(isinstance(c, list) and c and
                                                              all(isinstance(i, int) for i in c) for c in cells)):
                raise InputError("[uncertainty] key 'cells' must be a list of lists of vertex indices (0-based)")
            return PolytopicSystem(poly.vertices, poly.dt, poly.labels, tuple(tuple(c) for c in cells))
        raise InputError(f"[uncertainty] key 'kind' must be \"norm-bounded\" or \"polytope\"; got {kind!r}")
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from None
