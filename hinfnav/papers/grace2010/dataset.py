"""The GRACE-A/B data of 27 July 2010: loader, Earth-fixed to inertial, and the Hill-frame truth.

Files (vendored, gzip; :data:`.constants.DATA_FILES`, see ``data/ATTRIBUTION.md``):
``date (d/m/yyyy), time (hh:mm:ss), x, y, z [km], vx, vy, vz [dm/s]`` Earth-fixed (ITRF) from precise
orbit determination, and ``date, time, range [m]`` from the K-band ranging system. The units are
converted here to m and m/s (checked in the tests: the velocity equals the finite difference of the
position, and the orbit radius is 6831–6853 km).

Earth-fixed to inertial (eq. G1)::

    r_I = R₃(θ(t)) r_E,     v_I = R₃(θ(t)) (v_E + ω_E × r_E),     θ(t) = ω_E t,

with ``t`` the seconds since the first epoch and ``R₃`` the rotation about the Earth's z axis. The
"inertial" frame is therefore the Earth-fixed frame of 00:00:00 frozen in space. Left out: polar motion
(≈ 0.3″, 1.5 µrad), precession and nutation (the frame's true orientation; their *rates* are ≈ 10⁻¹¹
rad/s), the variation of the length of day (≈ 10⁻⁸ ω_E) and the unknown time scale of the files. A
constant rotation of the inertial frame does not change a Hill-frame state; the neglected rates ε change
the relative velocity by at most ε·|ρ| ≈ 10⁻¹¹ × 2.3·10⁵ m ≈ 2·10⁻⁶ m/s and tilt the Hill frame by
≈ ε|r|/|v| ≈ 10⁻⁸ rad (2 mm at 227 km): far below the truth's own ≈ 2 cm. For J2, whose axis is the
Earth's z axis, the frozen frame is exact up to polar motion and precession since the epoch.

Hill frame of the chief c (GRACE-B), paper 000's axes (eq. G2)::

    x̂ = r_c/|r_c| (radial),  ẑ = h/|h| (orbit normal, h = r_c × v_c),  ŷ = ẑ × x̂ (along-track),
    ρ = M (r_d − r_c),       ρ̇ = M (v_d − v_c) − ω_H × ρ,   ω_H = (0, 0, |h|/|r_c|²),

with ``M`` the rows x̂, ŷ, ẑ: the velocity of the deputy (GRACE-A) seen in the rotating frame.
"""

import gzip
import zlib
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources

import numpy as np

from ...core.exceptions import InputError
from ...systems.attitude import cross  # a × b, the arithmetic of numpy.cross (same numbers), ~7x faster on (3,) vectors
from .constants import DATA_FILES, DT_S, OMEGA_EARTH

__all__ = [
    "GraceData",
    "read_orbit_file",
    "read_range_file",
    "load",
    "ecef_to_inertial",
    "inertial_to_ecef",
    "hill_basis",
    "inertial_to_hill",
    "hill_to_inertial",
]


def _data_path(name):
    return resources.files(__package__).joinpath("data", name)


def _line_seconds(source, lineno, d, t):
    """Seconds since 2010-07-27 00:00:00 of one line's ``d/m/yyyy`` and ``hh:mm:ss`` fields (errors name the line)."""
    try:
        dd, mm, yy = (int(v) for v in d.split("/"))
        h, mi, s = (float(v) for v in t.split(":"))
        day = np.datetime64(f"{yy:04d}-{mm:02d}-{dd:02d}")
        if not (0 <= h < 24 and 0 <= mi < 60 and 0 <= s < 61):
            raise ValueError("time of day out of range")
    except ValueError as exc:
        raise InputError(f"{source}: line {lineno}: date {d!r} and time {t!r} are not d/m/yyyy and hh:mm:ss "
                         f"({exc})") from None
    return (day - _DAY0).astype("timedelta64[D]").astype(float) * 86400.0 + 3600.0 * h + 60.0 * mi + s


_DAY0 = np.datetime64("2010-07-27")


def _rows(source, n_numbers):
    """Date and time strings and the numbers of a CSV file (gzip when its name ends in .gz).

    Every error names the file and, for its content, the line (issue 36): a file that cannot be read, a
    gzip file that is truncated or is not gzip, text that is not ASCII, a line with the wrong number of
    fields, a bad date or number, NaN or inf, time not increasing, no data at all.
    """
    try:
        if hasattr(source, "read_bytes"):
            raw = source.read_bytes()
        else:
            with open(source, "rb") as fh:
                raw = fh.read()
    except (OSError, TypeError) as exc:
        raise InputError(f"source must be a readable file; {source!r}: {exc}") from None
    if str(source).endswith(".gz"):
        try:
            raw = gzip.decompress(raw)
        except (OSError, EOFError, zlib.error) as exc:
            raise InputError(f"{source}: not a complete gzip file ({type(exc).__name__}: {exc or 'truncated'}); "
                             "download or copy it again") from None
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError as exc:
        line = raw[:exc.start].count(b"\n") + 1
        raise InputError(f"{source}: line {line}: byte {raw[exc.start]:#04x} is not ASCII (these files are plain "
                         "ASCII CSV: date, time, numbers)") from None
    t, nums = [], []
    for i, line in enumerate(text.splitlines()):
        if not line.strip():
            continue
        parts = line.split(",")
        if len(parts) != 2 + n_numbers:
            raise InputError(f"{source}: line {i + 1} has {len(parts)} fields; expected {2 + n_numbers}")
        try:
            row = [float(p) for p in parts[2:]]
        except ValueError as exc:
            raise InputError(f"{source}: line {i + 1}: {exc}") from None
        if not all(np.isfinite(row)):
            raise InputError(f"{source}: line {i + 1} has NaN or inf among its numbers; the files hold measured "
                             "values only")
        ti = _line_seconds(source, i + 1, parts[0].strip(), parts[1].strip())
        if t and ti <= t[-1]:
            raise InputError(f"{source}: line {i + 1}: time {parts[0]} {parts[1]} is not after the previous line's")
        t.append(ti)
        nums.append(row)
    if not nums:
        raise InputError(f"{source}: no data lines (the file is empty)")
    return np.asarray(t), np.asarray(nums)


def read_orbit_file(source):
    """One orbit file: ``(t [s since 2010-07-27 00:00], r [m] (n, 3), v [m/s] (n, 3))``, Earth-fixed.

    Converts the files' km to m and dm/s to m/s.
    """
    t, nums = _rows(source, 6)
    return t, nums[:, :3] * 1e3, nums[:, 3:] * 0.1


def read_range_file(source):
    """The K-band file: ``(t [s], range [m])``."""
    t, nums = _rows(source, 1)
    return t, nums[:, 0]


def _rot3(theta):
    c, s = np.cos(theta), np.sin(theta)
    R = np.zeros(np.shape(theta) + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1], R[..., 2, 2] = c, -s, s, c, 1.0
    return R


def ecef_to_inertial(t, r, v, omega_earth=OMEGA_EARTH):
    """Earth-fixed to the frozen inertial frame, eq. (G1); ``t`` (n,) s, ``r``, ``v`` (n, 3) m, m/s."""
    t, r, v = np.asarray(t, float), np.asarray(r, float), np.asarray(v, float)
    R = _rot3(omega_earth * t)
    w = np.array([0.0, 0.0, omega_earth])
    return np.einsum("...ij,...j->...i", R, r), np.einsum("...ij,...j->...i", R, v + cross(w, r))


def inertial_to_ecef(t, r, v, omega_earth=OMEGA_EARTH):
    """Inverse of :func:`ecef_to_inertial`."""
    t, r, v = np.asarray(t, float), np.asarray(r, float), np.asarray(v, float)
    Rt = np.swapaxes(_rot3(omega_earth * t), -1, -2)
    r_e = np.einsum("...ij,...j->...i", Rt, r)
    w = np.array([0.0, 0.0, omega_earth])
    return r_e, np.einsum("...ij,...j->...i", Rt, v) - cross(w, r_e)


def hill_basis(r_c, v_c):
    """Rows x̂ (radial), ŷ (along-track), ẑ (normal) of the chief's Hill frame, and its rate ``|h|/|r|²``, eq. (G2).

    Returns
    -------
    M : ndarray, shape (..., 3, 3)
    omega : ndarray, shape (...,), rad/s
    """
    r_c, v_c = np.asarray(r_c, float), np.asarray(v_c, float)
    h = cross(r_c, v_c)
    xh = r_c / np.linalg.norm(r_c, axis=-1, keepdims=True)
    zh = h / np.linalg.norm(h, axis=-1, keepdims=True)
    yh = cross(zh, xh)
    return np.stack([xh, yh, zh], axis=-2), np.linalg.norm(h, axis=-1) / np.sum(r_c * r_c, axis=-1)


def inertial_to_hill(r_c, v_c, r_d, v_d):
    """The deputy's state relative to the chief in the chief's Hill frame, eq. (G2), shape (..., 6) m, m/s."""
    M, w = hill_basis(r_c, v_c)
    rho = np.einsum("...ij,...j->...i", M, np.asarray(r_d, float) - r_c)
    drho = np.einsum("...ij,...j->...i", M, np.asarray(v_d, float) - v_c)
    drho = drho - cross(np.stack([np.zeros_like(w), np.zeros_like(w), w], axis=-1), rho)
    return np.concatenate([rho, drho], axis=-1)


def hill_to_inertial(r_c, v_c, x):
    """The deputy's inertial ``(r_d, v_d)`` from the chief's state and the Hill state ``x`` (inverse of (G2))."""
    M, w = hill_basis(r_c, v_c)
    x = np.asarray(x, float)
    rho, drho = x[..., :3], x[..., 3:6]
    wv = np.stack([np.zeros_like(w), np.zeros_like(w), w], axis=-1)
    Mt = np.swapaxes(M, -1, -2)
    r_d = r_c + np.einsum("...ij,...j->...i", Mt, rho)
    v_d = v_c + np.einsum("...ij,...j->...i", Mt, drho + cross(wv, rho))
    return r_d, v_d


@dataclass(frozen=True, eq=False)
class GraceData:
    """The day of data, in SI units.

    Attributes
    ----------
    t : ndarray, shape (n,)
        Seconds since 2010-07-27 00:00:00 (time scale not stated by the files), n = 8641.
    rA_ecef, vA_ecef, rB_ecef, vB_ecef : ndarray, shape (n, 3)
        Earth-fixed positions (m) and velocities (m/s) of GRACE-A and GRACE-B.
    rA, vA, rB, vB : ndarray, shape (n, 3)
        The same in the frozen inertial frame, eq. (G1).
    truth : ndarray, shape (n, 6)
        GRACE-A relative to GRACE-B in GRACE-B's Hill frame (x, y, z, ẋ, ẏ, ż), m and m/s, eq. (G2).
    t_kband, kband : ndarray, shape (n_k,)
        K-band epochs (s) and inter-satellite range (m), n_k = 8640.
    """

    t: np.ndarray
    rA_ecef: np.ndarray
    vA_ecef: np.ndarray
    rB_ecef: np.ndarray
    vB_ecef: np.ndarray
    rA: np.ndarray
    vA: np.ndarray
    rB: np.ndarray
    vB: np.ndarray
    truth: np.ndarray
    t_kband: np.ndarray
    kband: np.ndarray

    @property
    def baseline(self):
        """The POD baseline ``|r_A − r_B|`` at every epoch, m."""
        return np.linalg.norm(self.rA_ecef - self.rB_ecef, axis=-1)

    @property
    def orbital_rate(self):
        """GRACE-B's mean Hill-frame rate over the day, ``|h|/|r|²``, rad/s."""
        return float(np.mean(hill_basis(self.rB, self.vB)[1]))

    @property
    def period_s(self):
        """2π / :attr:`orbital_rate`, s."""
        return 2 * np.pi / self.orbital_rate


@lru_cache(maxsize=1)
def load():
    """Read the vendored files (cached): a :class:`GraceData` (every array read-only)."""
    tA, rA, vA = read_orbit_file(_data_path(DATA_FILES["A"]))
    tB, rB, vB = read_orbit_file(_data_path(DATA_FILES["B"]))
    tk, rng = read_range_file(_data_path(DATA_FILES["kband"]))
    if tA.shape != tB.shape or np.any(tA != tB):
        raise InputError("the GRACE-A and GRACE-B files do not share their epochs")
    if not np.allclose(np.diff(tA), DT_S) or not np.allclose(np.diff(tk), DT_S) or np.any(tk != tA[: tk.size]):
        raise InputError(f"the files are not on one {DT_S:g} s grid")
    rAi, vAi = ecef_to_inertial(tA, rA, vA)
    rBi, vBi = ecef_to_inertial(tB, rB, vB)
    truth = inertial_to_hill(rBi, vBi, rAi, vAi)
    arrays = dict(t=tA, rA_ecef=rA, vA_ecef=vA, rB_ecef=rB, vB_ecef=vB, rA=rAi, vA=vAi, rB=rBi, vB=vBi,
                  truth=truth, t_kband=tk, kband=rng)
    for a in arrays.values():
        a.setflags(write=False)
    return GraceData(**arrays)
