"""Designs as files: save a certified filter with the system it was designed for, load it back.

A design file (JSON) holds the filter (A_F, B_F, C_F), its certified γ and the
solver's γ, the certification numbers, the uncertain system ψ_d it was
designed for with a fingerprint of its matrices and sampling time, the
options and provenance. :func:`load_design` refuses a file whose system does
not match the one it is loaded for, naming what differs (another T, another
B …), so a filter is never run on a system it was not designed and certified
for.
"""

import hashlib
import json

import numpy as np

from ..core.exceptions import InputError
from ..core.provenance import provenance
from ..core.validation import as_path, check_new_file
from ..systems.uncertain import UncertainSystem
from .result import SynthesisResult

__all__ = ["FORMAT", "system_fingerprint", "design_to_dict", "design_from_dict", "save_design", "load_design",
           "check_design_system", "check_design_path"]

#: Identifier and version of the file format.
FORMAT = "hinfnav-design/1"

_MATRICES = ("A", "B", "C", "D", "L", "H", "E")


def _system_dict(system, dt):
    out = {k: (None if getattr(system, k) is None else np.asarray(getattr(system, k)).tolist()) for k in _MATRICES}
    out["dt"] = float(dt)
    return out


def system_fingerprint(system, dt):
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


def design_to_dict(result, system, *, options=None, extra=None):
    """JSON-ready dict of a :class:`SynthesisResult` and the system it was designed for."""
    if not isinstance(result, SynthesisResult):
        raise InputError(f"result must be a hinfnav SynthesisResult; got {type(result).__name__}")
    if not isinstance(system, UncertainSystem):
        raise InputError(f"system must be the UncertainSystem the filter was designed for; got {type(system).__name__}")
    dt = 1.0 if result.dt is True else float(result.dt)
    return {
        "format": FORMAT,
        "filter": {"A_F": result.A_F.tolist(), "B_F": result.B_F.tolist(), "C_F": result.C_F.tolist(), "dt": dt},
        "certificate": {
            "gamma": result.gamma,
            "lmi_gamma": result.lmi_gamma,
            "verified_norm": result.verified_norm,
            "spectral_radius": result.spectral_radius,
            "sample_norms": np.asarray(result.sample_norms).tolist(),
            "worst_sample": int(result.worst_sample),
            "solver": result.solver,
            "method": result.method,
            "structure": result.structure,
            "form": result.form,
            "delta_bar": None if result.delta_bar is None else float(result.delta_bar),
            "deltas": None if result.deltas is None else np.asarray(result.deltas).tolist(),
            "solve_time_s": result.solve_time_s,
            "total_time_s": result.total_time_s,
        },
        "system": _system_dict(system, dt),
        "fingerprint": system_fingerprint(system, dt),
        "options": dict(options or {}),
        "extra": dict(extra or {}),
        "provenance": provenance(),
    }


def _matrix(d, key, path):
    try:
        M = np.array(d[key], dtype=float)
    except (KeyError, TypeError, ValueError):
        raise InputError(f"design file {path}: missing or malformed {key!r}") from None
    if M.ndim != 2 or not np.all(np.isfinite(M)):
        raise InputError(f"design file {path}: {key!r} must be a finite matrix")
    return M


def design_from_dict(d, path="<dict>"):
    """Rebuild ``(SynthesisResult, UncertainSystem, dict)`` from :func:`design_to_dict`'s output."""
    if not isinstance(d, dict) or d.get("format") != FORMAT:
        raise InputError(f"{path} is not a hinfnav design file (format {FORMAT!r} expected)")
    f, c, s = d.get("filter", {}), d.get("certificate", {}), d.get("system", {})
    if not all(isinstance(x, dict) for x in (f, c, s)):
        raise InputError(f"design file {path}: 'filter', 'certificate' and 'system' must be JSON objects")
    A_F, B_F, C_F = (_matrix(f, k, path) for k in ("A_F", "B_F", "C_F"))
    mats = {k: (None if s.get(k) is None else _matrix(s, k, path)) for k in _MATRICES}
    try:
        return _rebuild(d, f, c, s, mats, A_F, B_F, C_F, path)
    except (KeyError, TypeError, ValueError) as exc:
        if isinstance(exc, InputError):
            raise
        raise InputError(f"design file {path}: missing or malformed entry ({type(exc).__name__}: {exc})") from None


def _rebuild(d, f, c, s, mats, A_F, B_F, C_F, path):
    system = UncertainSystem(mats["A"], mats["B"], mats["C"], mats["D"], mats["L"], mats["H"], mats["E"], float(s["dt"]))
    result = SynthesisResult(
        A_F=A_F, B_F=B_F, C_F=C_F, gamma=float(c["gamma"]), lmi_gamma=float(c["lmi_gamma"]),
        verified_norm=float(c["verified_norm"]), sample_norms=np.asarray(c.get("sample_norms", []), dtype=float),
        worst_sample=int(c.get("worst_sample", 0)), spectral_radius=float(c["spectral_radius"]),
        solver=str(c.get("solver")), solve_time_s=float(c.get("solve_time_s", 0.0)),
        total_time_s=float(c.get("total_time_s", 0.0)), method=str(c.get("method")), dt=float(f["dt"]),
        structure=str(c.get("structure")), delta_bar=c.get("delta_bar"),
        deltas=None if c.get("deltas") is None else np.asarray(c["deltas"], dtype=float), form=str(c.get("form")),
    )
    if system_fingerprint(system, float(s["dt"])) != d.get("fingerprint"):
        raise InputError(f"design file {path}: its system does not match its fingerprint (the file was edited)")
    return result, system, d


def check_design_path(path):
    """Check, before any work, that a design file can be written at ``path``; returns it as a Path."""
    return check_new_file("path", path, example="design.json")


def save_design(result, system, path, *, options=None, extra=None):
    """Write a design file (JSON); returns the path. The file is written whole or not at all."""
    path = check_design_path(path)
    text = json.dumps(design_to_dict(result, system, options=options, extra=extra), indent=2) + "\n"
    tmp = path.with_name(f".{path.name}.tmp")
    tmp.write_text(text)
    tmp.replace(path)
    return path


def load_design(path):
    """Read a design file; returns ``(SynthesisResult, UncertainSystem, dict)``."""
    path = as_path("path", path)
    if not path.is_file():
        raise InputError(f"design file {path} does not exist (or is not a file)")
    try:
        d = json.loads(path.read_text())
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"design file {path} is not valid JSON ({exc})") from None
    return design_from_dict(d, path)


def check_design_system(stored, stored_dt, system, dt, *, what="the scenario"):
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
