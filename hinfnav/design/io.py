"""Designs as files: save a certified filter with the system it was designed for, load it back.

A design file (JSON) holds the filter (A_F, B_F, C_F), its certified γ and the
solver's γ, the certification numbers, the system it was designed for
(norm-bounded ψ_d or a polytope of vertices), the LMI witness (the Lyapunov
and slack variables the certificate was evaluated at), the options and
provenance, and a SHA-256 fingerprint of the filter, the certificate, the
system and the witness together: a file with any of them edited is refused
(:func:`design_from_dict`). :func:`recertify` re-checks a file without a
solver. :func:`load_design` refuses a file whose system does
not match the one it is loaded for, naming what differs (another T, another
B …), so a filter is never run on a system it was not designed and certified
for.

The certificate of a norm-bounded design holds the uncertainty bound and the
parameter value of each sample as ``uncertainty_bound`` and ``sample_values``;
files written before version 0.3 name them ``delta_bar`` and ``deltas`` (Sun
et al. 2011's δ), in the same format ``hinfnav-design/2``, and load the same.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..core.exceptions import InputError
from ..io.outputs import atomic_write_text
from ..io.provenance import provenance
from ..core.validation import as_path, check_new_file
from ..systems.polytopic import MATRIX_KEYS, PolytopicSystem
from ..systems.uncertain import UncertainSystem
from .result import COVERS_NOMINAL, COVERS_NORM_BOUNDED, DesignResult

__all__ = ["system_fingerprint", "content_fingerprint", "save_design", "load_design",
           "check_design_system", "check_design_path"]

#: Identifier and version of the file format.
FORMAT = "hinfnav-design/2"

_MATRICES = ("A", "B", "C", "D", "L", "H", "E")


def _system_dict(system, dt):
    out = {k: (None if getattr(system, k) is None else np.asarray(getattr(system, k)).tolist()) for k in _MATRICES}
    out["dt"] = float(dt)
    return out


def system_fingerprint(system: UncertainSystem | PolytopicSystem, dt: float) -> str:
    """SHA-256 of the system's matrices (rounded to 12 significant digits) and its sampling time."""
    h = hashlib.sha256()
    for k in _MATRICES:
        M = getattr(system, k)
        h.update(k.encode())
        if M is not None:
            h.update(np.array2string(np.asarray(M, dtype=float), precision=12, floatmode="maxprec",
                                     threshold=10**9, max_line_width=10**9).encode())
    h.update(f"dt={float(dt):.12g}".encode())
    return h.hexdigest()


def _plain(v):
    """JSON-ready copy of a witness entry (arrays to nested lists)."""
    if isinstance(v, np.ndarray):
        return v.tolist()
    if isinstance(v, (list, tuple)):
        return [_plain(x) for x in v]
    if isinstance(v, (np.floating, np.integer)):
        return v.item()
    return v


def content_fingerprint(d):
    """SHA-256 of a design file's filter, certificate, system and witness (canonical JSON; floats exact)."""
    body = {k: d.get(k) for k in ("format", "filter", "certificate", "system", "witness")}
    return hashlib.sha256(json.dumps(body, sort_keys=True, allow_nan=True).encode()).hexdigest()


def _same_system(a, b):
    """True when two systems have the same kind, dt and matrices (bitwise: a certificate holds for those only)."""
    if type(a) is not type(b) or float(a.dt) != float(b.dt):
        return False
    if isinstance(a, PolytopicSystem):
        return a.n_vertices == b.n_vertices and all(
            np.array_equal(getattr(u, k), getattr(v, k)) for u, v in zip(a.vertices, b.vertices) for k in MATRIX_KEYS)
    keys = ("A", "B", "C", "D", "L", "H", "E")
    return all((getattr(a, k, None) is None and getattr(b, k, None) is None)
               or (getattr(a, k, None) is not None and getattr(b, k, None) is not None
                   and np.array_equal(getattr(a, k), getattr(b, k))) for k in keys)


def design_to_dict(result, system, *, options=None, extra=None):
    """JSON-ready dict of a certified discrete-time design (a :class:`DesignResult`) and its system."""
    if not isinstance(result, DesignResult):
        raise InputError(f"result must be a hinfnav DesignResult; got {type(result).__name__}")
    if result.domain != "discrete":
        raise InputError(f"a design file carries discrete-time certificates only; this design is {result.domain} "
                         "time: it cannot be saved")
    polytopic = result.uncertainty == "polytope"
    want = PolytopicSystem if polytopic else UncertainSystem
    if not isinstance(system, want):
        raise InputError(f"system must be the {want.__name__} the filter was designed for; got {type(system).__name__}")
    dt = 1.0 if result.dt is True else float(result.dt)
    designed_for = getattr(result, "system", None)
    if designed_for is not None and designed_for is not system and not _same_system(designed_for, system):
        raise InputError("system is not the system this filter was designed for (its matrices or dt differ): a "
                         "design file pairs a filter with the system it was certified on; pass result.system")
    cert = {
        "gamma": result.gamma,
        "lmi_gamma": result.lmi_gamma,
        "verified_norm": result.verified_norm,
        "spectral_radius": result.spectral_radius,
        "sample_norms": np.asarray(result.sample_norms).tolist(),
        "worst_sample": int(result.worst_sample),
        "solver": result.solver,
        "form": result.form,
        "solve_time_s": result.solve_time_s,
        "total_time_s": result.total_time_s,
    }
    if polytopic:
        cert.update(lyapunov=result.lyapunov, covers=result.covers, alphas=np.asarray(result.alphas).tolist(),
                    method="minimize", objective=result.objective)
        sysd = {"kind": "polytope", "dt": dt, "labels": list(system.labels),
                "vertices": [{k: getattr(v, k).tolist() for k in MATRIX_KEYS} for v in system.vertices]}
        if system.cells:
            sysd["cells"] = [list(c) for c in system.cells]
        witness = {k: _plain(v) for k, v in result.witness.items()}
    else:
        cert.update(
            method=result.method, structure=result.structure,
            uncertainty_bound=None if result.uncertainty_bound is None else float(result.uncertainty_bound),
            sample_values=None if result.sample_values is None else np.asarray(result.sample_values).tolist(),
            covers=result.covers if system.H is not None else COVERS_NOMINAL,
        )
        sysd = dict(_system_dict(system, dt), kind="norm-bounded")
        witness = {k: _plain(v) for k, v in result.witness.items()}
    out = {
        "format": FORMAT,
        "filter": {"A_F": result.A_F.tolist(), "B_F": result.B_F.tolist(), "C_F": result.C_F.tolist(), "dt": dt},
        "certificate": cert,
        "system": sysd,
        "witness": witness,
        "options": dict(options or {}),
        "extra": dict(extra or {}),
        "provenance": provenance(),
    }
    out["fingerprint"] = content_fingerprint(out)
    out["system_fingerprint"] = None if polytopic else system_fingerprint(system, dt)
    return out


def _matrix(d, key, path):
    try:
        M = np.array(d[key], dtype=float)
    except (KeyError, TypeError, ValueError):
        raise InputError(f"design file {path}: missing or malformed {key!r}") from None
    if M.ndim != 2 or not np.all(np.isfinite(M)):
        raise InputError(f"design file {path}: {key!r} must be a finite matrix")
    return M


def design_from_dict(d, path="<dict>"):
    """Rebuild ``(result, system, dict)`` from :func:`design_to_dict`'s output; refuse an edited file."""
    if isinstance(d, dict) and d.get("format") == "hinfnav-design/1":
        raise InputError(f"{path} is a design file of format hinfnav-design/1, whose fingerprint did not cover the "
                         "filter and certificate (it cannot be trusted); design again and save with this version")
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise InputError(f"{path} is not a hinfnav design file (format {FORMAT!r} expected)")
    f, c, s = d.get("filter", {}), d.get("certificate", {}), d.get("system", {})
    if not all(isinstance(x, dict) for x in (f, c, s)):
        raise InputError(f"design file {path}: 'filter', 'certificate' and 'system' must be JSON objects")
    if content_fingerprint(d) != d.get("fingerprint"):
        raise InputError(f"design file {path}: its filter, certificate, system or witness does not match its "
                         "fingerprint (the file was edited); refused")
    A_F, B_F, C_F = (_matrix(f, k, path) for k in ("A_F", "B_F", "C_F"))
    try:
        if s.get("kind") == "polytope":
            return _rebuild_polytopic(d, f, c, s, A_F, B_F, C_F, path)
        mats = {k: (None if s.get(k) is None else _matrix(s, k, path)) for k in _MATRICES}
        return _rebuild(d, f, c, s, mats, A_F, B_F, C_F, path)
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"design file {path}: missing or malformed entry ({type(exc).__name__}: {exc})") from None


def _rebuild_polytopic(d, f, c, s, A_F, B_F, C_F, path):
    verts = [UncertainSystem(*(_matrix(v, k, path) for k in MATRIX_KEYS), dt=float(s["dt"])) for v in s["vertices"]]
    system = PolytopicSystem(tuple(verts), float(s["dt"]), tuple(s.get("labels", ())),
                             tuple(tuple(c) for c in s.get("cells", ())))
    w = d.get("witness") or {}
    result = DesignResult(
        A_F=A_F, B_F=B_F, C_F=C_F, gamma=float(c["gamma"]), lmi_gamma=float(c["lmi_gamma"]), uncertainty="polytope",
        verified_norm=float(c["verified_norm"]), sample_norms=np.asarray(c.get("sample_norms", []), dtype=float),
        alphas=np.asarray(c.get("alphas", []), dtype=float), worst_sample=int(c.get("worst_sample", 0)),
        spectral_radius=float(c["spectral_radius"]), lyapunov=str(c["lyapunov"]), form=str(c["form"]),
        covers=str(c["covers"]), objective=str(c.get("objective", "hinf")),
        witness=dict({k: np.asarray(v, dtype=float) for k, v in w.items() if k != "P"},
                     P=[np.asarray(P, dtype=float) for P in w.get("P", [])]),
        solver=str(c.get("solver")), solve_time_s=float(c.get("solve_time_s", 0.0)),
        total_time_s=float(c.get("total_time_s", 0.0)), dt=float(f["dt"]), system=system,
    )
    return result, system, d


def _rebuild(d, f, c, s, mats, A_F, B_F, C_F, path):
    system = UncertainSystem(mats["A"], mats["B"], mats["C"], mats["D"], mats["L"], mats["H"], mats["E"], float(s["dt"]))
    w = d.get("witness") or {}
    # files saved before 0.3 name the bound and the sample values after Sun 2011's δ: "delta_bar", "deltas"
    bound = c.get("uncertainty_bound", c.get("delta_bar"))
    values = c.get("sample_values", c.get("deltas"))
    variables = {k: (np.asarray(v, dtype=float) if isinstance(v, list) and k != "P" else
                     [np.asarray(P, dtype=float) for P in v] if k == "P" else v) for k, v in w.items()}
    result = DesignResult(
        A_F=A_F, B_F=B_F, C_F=C_F, gamma=float(c["gamma"]), lmi_gamma=float(c["lmi_gamma"]),
        verified_norm=float(c["verified_norm"]), sample_norms=np.asarray(c.get("sample_norms", []), dtype=float),
        worst_sample=int(c.get("worst_sample", 0)), spectral_radius=float(c["spectral_radius"]),
        solver=str(c.get("solver")), solve_time_s=float(c.get("solve_time_s", 0.0)),
        total_time_s=float(c.get("total_time_s", 0.0)), method=str(c.get("method")), dt=float(f["dt"]),
        structure=str(c.get("structure")), uncertainty_bound=bound, form=str(c.get("form")),
        sample_values=None if values is None else np.asarray(values, dtype=float),
        witness=variables, system=system,
        covers=str(c.get("covers", COVERS_NOMINAL if system.H is None else COVERS_NORM_BOUNDED)),
    )
    return result, system, d


def check_design_path(path):
    """Check, before any work, that a design file can be written at ``path``; returns it as a Path."""
    return check_new_file("path", path, example="design.json")


def save_design(result: DesignResult, system: UncertainSystem | PolytopicSystem,
                path: str | os.PathLike[str], *, options: Mapping[str, Any] | None = None,
                extra: Mapping[str, Any] | None = None) -> Path:
    """Write a design file (JSON); returns the path. The file is written whole or not at all."""
    path = check_design_path(path)
    text = json.dumps(design_to_dict(result, system, options=options, extra=extra), indent=2) + "\n"
    return atomic_write_text(path, text)  # whole or nothing; no temporary file left on a failure


def load_design(path: str | os.PathLike[str]) -> tuple[DesignResult, UncertainSystem | PolytopicSystem, dict[str, Any]]:
    """Read a design file; returns ``(DesignResult, UncertainSystem or PolytopicSystem, dict)``."""
    path = as_path("path", path)
    if not path.is_file():
        raise InputError(f"design file {path} does not exist (or is not a file)")
    try:
        d = json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"design file {path} is not valid JSON ({exc})") from None
    return design_from_dict(d, path)


def check_design_system(stored: UncertainSystem | PolytopicSystem, stored_dt: float,
                        system: UncertainSystem | PolytopicSystem, dt: float, *, what: str = "the scenario") -> None:
    """Raise :class:`InputError` naming what differs when a design's system is not ``system`` at ``dt``."""
    if abs(float(stored_dt) - float(dt)) > 1e-12 * max(1.0, abs(float(dt))):
        raise InputError(f"the design was made for sampling time T = {float(stored_dt):g} s but {what} has "
                         f"T = {float(dt):g} s: a discrete filter only holds at its own T; design again at this T")
    for k in _MATRICES:
        a, b = getattr(stored, k), getattr(system, k)
        if (a is None) != (b is None) or (a is not None and (a.shape != b.shape or not np.allclose(a, b, rtol=1e-9,
                                                                                                    atol=1e-15))):
            raise InputError(f"the design was made for another system: its {k} differs from {what}'s "
                             "(design again for this system)")
