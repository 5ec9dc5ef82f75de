"""Measurements on closed-loop results: disturbance-estimation errors, spectra, step response, periodic rejection.

Every statistic names its window and units. The residual-acceleration
spectrum is Welch's (``scipy.signal.welch``: Hann window, 50 % overlap,
one-sided density), averaged over runs, as an amplitude spectral density in
m·s⁻²/√Hz.
"""

import dataclasses

import numpy as np
from scipy.signal import welch

from ...core.exceptions import InputError
from ...core.validation import as_int_at_least
from .constants import ACTUATOR_BOUND, REQUIREMENT_ASD, REQUIREMENT_BAND_HZ, STEP_COMMAND
from .filters import build_alg1, build_alg2
from .loop import Alg2Bank, residual_acceleration

__all__ = [
    "NPERSEG",
    "amplitude_spectral_density",
    "band_statistics",
    "residual_spectrum",
    "disturbance_errors",
    "estimation_errors",
    "periodic_amplitude",
    "step_response",
    "saturation_summary",
    "linear_loop_radius",
    "truncated",
    "asd_sensitivity",
    "SENSITIVITY_NPERSEG",
    "theta_readings_study",
]

#: The readings of θ the L1/L3 comparison is run under: name → (factor on Algorithm 2's θ* = √(4q/tr P₀),
#: or "alg1" for Algorithm 1's θ*, or None for the plain Kalman prediction, which is not the paper's).
THETA_READINGS = {"theta_star": 1.0, "theta_star_x0.1": 0.1, "theta_star_x10": 10.0, "theta_alg1": "alg1",
                  "kalman_prediction": None}

#: Welch segment lengths of the sensitivity table (2^13 … 2^15 samples: 819 s … 3277 s).
SENSITIVITY_NPERSEG = (2**13, 2**14, 2**15)

#: Welch segment length: 2^15 samples = 3277 s, resolution 0.31 mHz (four bins per mHz at the band's low edge).
NPERSEG = 2**15


def amplitude_spectral_density(a, dt, nperseg=NPERSEG):
    """One-sided amplitude spectral density of ``a`` (runs, n, c) along time, PSD averaged over runs.

    Returns
    -------
    f : ndarray, shape (n_f,)
        Frequency, Hz.
    asd : ndarray, shape (n_f, c)
        unit/√Hz.
    """
    a = np.asarray(a, dtype=float)
    if a.ndim != 3:
        raise InputError(f"a must have shape (runs, n_samples, channels); got {a.shape}")
    nperseg = as_int_at_least("nperseg", nperseg, 16)
    if a.shape[1] < nperseg:
        raise InputError(f"the record ({a.shape[1]} samples) is shorter than nperseg = {nperseg}")
    f, P = welch(a, fs=1.0 / dt, nperseg=nperseg, axis=1, window="hann", detrend="constant", scaling="density")
    return f, np.sqrt(P.mean(axis=0))


def band_statistics(f, asd, band=REQUIREMENT_BAND_HZ, line_hz=None, guard_bins=3):
    """Largest and median ASD in a band, with and without the bins next to a known line.

    Parameters
    ----------
    f : ndarray, shape (n_f,)
    asd : ndarray, shape (n_f,) or (n_f, c)
        The largest over channels is taken.
    band : (float, float)
        Hz, inclusive.
    line_hz : float, optional
        Frequency of a deterministic line (the disturbance's ω_d/2π).
    guard_bins : int
        Bins on each side of the line left out of ``floor_max`` (a Hann window's main lobe is ±2 bins).

    Returns
    -------
    dict
        ``max``, ``f_at_max_hz``, ``median``, ``floor_max`` (line bins excluded), ``requirement``,
        ``below_requirement`` (max), ``floor_below_requirement``.
    """
    asd = np.asarray(asd, dtype=float)
    A = asd.max(axis=1) if asd.ndim == 2 else asd
    inb = (f >= band[0]) & (f <= band[1])
    if not inb.any():
        raise InputError(f"no frequency bin in the band {band} Hz")
    i = np.argmax(np.where(inb, A, -np.inf))
    keep = inb.copy()
    if line_hz is not None:
        df = f[1] - f[0]
        keep &= np.abs(f - line_hz) > guard_bins * df
    floor = float(A[keep].max()) if keep.any() else None
    return {"max": float(A[i]), "f_at_max_hz": float(f[i]), "median": float(np.median(A[inb])), "floor_max": floor,
            "requirement": REQUIREMENT_ASD, "below_requirement": bool(A[i] < REQUIREMENT_ASD),
            "floor_below_requirement": None if floor is None else bool(floor < REQUIREMENT_ASD), "band_hz": list(band),
            "line_hz": line_hz, "guard_bins": guard_bins}


def residual_spectrum(result, reading="test_mass", settle_s=2000.0, nperseg=NPERSEG):
    """Welch ASD of the residual acceleration of a loop after ``settle_s``, with band statistics.

    Returns
    -------
    dict
        ``f`` (Hz), ``asd`` (n_f, 3), ``stats`` (see :func:`band_statistics`, the line at ω_d/2π),
        ``reading``, ``window_s``, ``nperseg``.
    """
    k0 = int(round(settle_s / result.settings["dt"]))
    a = residual_acceleration(result, reading)[:, k0:]
    nper = min(nperseg, a.shape[1])
    f, asd = amplitude_spectral_density(a, result.settings["dt"], nper)
    w_d = result.settings.get("w_d")
    stats = band_statistics(f, asd, line_hz=None if w_d is None else w_d / (2 * np.pi))
    return {"f": f, "asd": asd, "stats": stats, "reading": reading,
            "window_s": [float(result.t[k0]), float(result.t[-1])], "nperseg": nper}


def disturbance_errors(estimate, truth, *, axis=0, window=None):
    """Bias and RMS of one axis's disturbance estimate (N), over runs and a window of samples.

    Parameters
    ----------
    estimate, truth : ndarray, shape (runs, n, 9)
        Drag-free blocks ``[r, ṙ, F_Dsc]``.
    axis : int
        0, 1, 2 for x, y, z.
    window : (int, int), optional
        Sample indices [k0, k1); default all.
    """
    k0, k1 = (0, estimate.shape[1]) if window is None else window
    e = estimate[:, k0:k1, 6 + axis] - truth[:, k0:k1, 6 + axis]
    return {"disturbance_bias": float(e.mean()), "disturbance_rms": float(np.sqrt(np.mean(e**2))),
            "window_steps": [int(k0), int(k1)]}


def estimation_errors(result, *, axis=0, windows=None):
    """Disturbance errors of every estimator of a loop (Algorithm 3, Algorithm 1, L1, L2, L3) per window.

    Parameters
    ----------
    result : LoopResult
    axis : int
    windows : dict, optional
        Name → (k0, k1) sample window; default ``{"all": whole passive span}``.

    Returns
    -------
    dict
        Estimator → window name → :func:`disturbance_errors`; also ``r_error_end_m`` (the
        standalone filters' final displacement error) for Fig 6.
    """
    truth = result.dragfree_truth()
    n_p = next(iter(result.passive.values())).shape[1] if result.passive else truth.shape[1]
    windows = windows or {"all": (0, n_p)}
    out = {}
    fused = result.xhat[..., 9:18]
    for name, est in [("fused", fused[:, :n_p])] + list(result.passive.items()):
        tr = truth[:, : est.shape[1]]
        out[name] = {w: disturbance_errors(est, tr, axis=axis, window=win) for w, win in windows.items()}
        out[name]["r_error_end_m"] = float(np.abs(est[:, -1, axis] - tr[:, -1, axis]).mean())
    return out


def periodic_amplitude(signal, t, w):
    """Amplitude of the component at ω (rad/s) of ``signal`` (runs, n) by least squares, averaged over runs."""
    M = np.column_stack([np.sin(w * t), np.cos(w * t), np.ones_like(t)])
    coef, *_ = np.linalg.lstsq(M, np.asarray(signal).T, rcond=None)
    return float(np.hypot(coef[0], coef[1]).mean())


def _edge(phi, target, step, torque, bound, dt, tolerance):
    """Settling, overshoot and torque saturation of one edge of the step, per axis.

    ``phi`` (n, 3) is the run-averaged attitude from the edge on, ``target`` (3,) what it is commanded to,
    ``step`` (3,) the signed change of the command at the edge (target minus the command before),
    ``torque`` (runs, n, 3) the applied attitude torques, N m. The overshoot is how far ``phi`` goes past
    ``target`` in the direction of the step, as a fraction of ``|step|``; ``settling_s`` the time from the
    edge after which ``|phi - target|`` stays within ``tolerance |step|``; ``torque_saturated_steps`` the
    steps (run-averaged) with ``|u| >= bound`` (the clip (13) active).
    """
    out = {}
    for a, name in enumerate(("pitch", "yaw", "roll")):
        err = phi[:, a] - target[a]
        outside = np.nonzero(np.abs(err) > tolerance * abs(step[a]))[0]
        past = np.sign(step[a]) * err
        out[name] = {
            "settling_s": float((outside[-1] + 1) * dt) if outside.size else 0.0,
            "overshoot": float(max(0.0, past.max() / abs(step[a]))),
            "torque_saturated_steps": float(np.mean(np.sum(np.abs(torque[:, :, a]) >= bound * (1 - 1e-12), axis=1))),
        }
    return out


def step_response(result, *, tolerance=0.05, bound=ACTUATOR_BOUND):
    """The attitude step of Fig 11, both edges: settling, overshoot, torque saturation, relative-attitude excursion.

    The paper commands φ_sc = (0.01, 0.02, 0.03) rad at k = 1×10⁵ **and returns to the original attitude at
    k = 2×10⁵**; both edges are measured, each from its own command change.

    Returns
    -------
    dict
        ``axes``: per axis (pitch, yaw, roll) of the first edge (command on): ``settling_s`` (to within
        ``tolerance`` of the step, after the command), ``overshoot`` (fraction of the step),
        ``rel_attitude_peak_rad`` (largest ``|φ_rel|`` in the 1000 s after the command),
        ``rel_attitude_before_rad`` (largest ``|φ_rel|`` in the 1000 s before) and ``torque_saturated_steps``
        (steps with the attitude torque on its bound ``bound``, N m, between the two edges).
        ``return_edge``: the same for the return to zero at ``step_off_s`` (overshoot past zero as a fraction
        of the step; settling and saturation counted from the return to the end of the run; the
        relative-attitude peak in the 1000 s after it); absent when the run ends before the return.
    """
    ref = result.reference
    on = np.nonzero(np.any(ref != 0, axis=1))[0]
    if on.size == 0:
        return {}
    k_on = int(on[0])
    k_off = int(on[-1]) + 1
    dt = result.settings["dt"]
    win = int(1000.0 / dt)
    phi = result.x[:, k_on:k_off, 0:3].mean(axis=0)
    out = {"step_on_s": float(result.t[k_on]), "step_off_s": float(result.t[min(k_off, len(result.t) - 1)]), "axes": {}}
    first = _edge(phi, STEP_COMMAND, STEP_COMMAND, result.u[:, k_on:k_off, 0:3], bound, dt, tolerance)
    for a, name in enumerate(("pitch", "yaw", "roll")):
        err = np.abs(phi[:, a] - STEP_COMMAND[a])
        outside = np.nonzero(err > tolerance * STEP_COMMAND[a])[0]
        settle = float((outside[-1] + 1) * dt) if outside.size else 0.0
        rel = result.x[:, :, 12 + a].mean(axis=0)
        out["axes"][name] = {
            "settling_s": settle,
            "overshoot": float(max(0.0, (phi[:, a].max() - STEP_COMMAND[a]) / STEP_COMMAND[a])),
            "rel_attitude_peak_rad": float(np.abs(rel[k_on:k_on + win]).max()),
            "rel_attitude_before_rad": float(np.abs(rel[max(0, k_on - win):k_on]).max()),
            "torque_saturated_steps": first[name]["torque_saturated_steps"],
        }
    if k_off < len(result.t):
        back = _edge(result.x[:, k_off:, 0:3].mean(axis=0), np.zeros(3), -STEP_COMMAND, result.u[:, k_off:, 0:3],
                     bound, dt, tolerance)
        for a, name in enumerate(("pitch", "yaw", "roll")):
            rel = result.x[:, :, 12 + a].mean(axis=0)
            back[name]["rel_attitude_peak_rad"] = float(np.abs(rel[k_off:k_off + win]).max())
        out["return_edge"] = {"time_s": float(result.t[k_off]), "axes": back}
    return out


def saturation_summary(result):
    """How often the accelerometers saturated and the inputs were clipped."""
    sat = result.saturated
    any_sat = sat.any(axis=2)
    idx = np.nonzero(any_sat.any(axis=0))[0]
    return {"saturated_fraction": [float(v) for v in sat.mean(axis=(0, 1))],
            "saturated_steps": int(any_sat.any(axis=0).sum()),
            "last_saturated_step": int(idx[-1]) if idx.size else None,
            "clipped_input_steps": int(result.settings.get("clipped_input_steps", 0))}


def linear_loop_radius(kp, ki, kd, gain, integral_scale, h=0.1, slope=10.0):
    """Spectral radius of one NLPID loop in fal's linear zone, the estimate equal to the truth.

    The compensated plant is a double integrator ``ẍ = gain · u₀`` (gain 1 for
    the attitude after (44), 1/m_sc for the drag-free loop after (45)), held
    over h, with ``u₀ = slope (k_p e_p + k_i e_i + k_d e_d)``, ``e_p = −x``,
    ``e_d = −ẋ`` and ``e_i(k) = e_i(k−1) + c e_p(k)`` (c = 1 as printed, h for
    a rectangle-rule integral, ``ki = 0`` for none). Above 1: the loop diverges
    from rest until fal's square-root zone limits it.
    """
    Ad = np.array([[1.0, h], [0.0, 1.0]])
    Bd = np.array([h * h / 2, h]) * gain
    c = integral_scale
    K = slope * np.array([-kp - ki * c, -kd, ki])
    A = np.zeros((3, 3))
    A[:2, :2] = Ad + np.outer(Bd, K[:2])
    A[:2, 2] = Bd * K[2]
    A[2] = [-c, 0.0, 1.0]
    if ki == 0:
        A = A[:2, :2]
    return float(np.max(np.abs(np.linalg.eigvals(A))))


def replay_alg2(result, alg, steps=None):
    """L1, L2, L3 of an Algorithm 2 ``alg`` re-run on a loop's stored readings and inputs.

    The timing is the loop's (:func:`~hinfnav.papers.yang2020.loop.run_closed_loop`): the update is told
    the input the reading contains (u_{k−1}; u_k with ``timing="prior"``), the prediction the input the
    plant moves with (u_k). With ``alg = build_alg2(scenario)`` it gives the loop's own L1, L2, L3.

    Parameters
    ----------
    result : LoopResult
    alg : SaturatedExtendedStateFilter
    steps : int, optional
        The first ``steps`` samples (default all).

    Returns
    -------
    dict
        ``L1``, ``L2``, ``L3`` → filtered ``[r, ṙ, F_Dsc]``, shape (runs, steps, 9).
    """
    n = result.x.shape[1] if steps is None else min(as_int_at_least("steps", steps, 1), result.x.shape[1])
    prior = result.settings.get("timing") == "prior"
    u = result.u[..., 3:6]
    acc, acc_c = result.acc, result.acc_clipped
    bank = Alg2Bank(alg, result.runs)
    out = np.empty((3, result.runs, n, 9))
    zero = np.zeros_like(u[:, 0])
    for k in range(n):
        u_read = u[:, k] if prior else (u[:, k - 1] if k else zero)
        out[:, :, k] = bank.step(acc[:, k], acc_c[:, k], u_read, u[:, k])
    return {"L1": out[0], "L2": out[1], "L3": out[2]}


def truncated(result, n_steps):
    """The first ``n_steps`` steps of a loop (``n_steps + 1`` samples), as if it had been run that long.

    Every part of the loop is causal and the attitude command does not depend on the length, so this is
    the loop of ``n_steps`` with the same seed up to its last full block of noise draws (:data:`BLOCK`
    steps; for a length that is a multiple of it, all but the final sample). The standalone estimators
    are dropped.
    """
    n1 = min(as_int_at_least("n_steps", n_steps, 1) + 1, result.x.shape[1])
    cut = {k: getattr(result, k)[:, :n1] for k in ("x", "u", "drive", "acc", "xhat")}
    return dataclasses.replace(result, t=result.t[:n1], f=result.f[:n1], passive={},
                               reference=None if result.reference is None else result.reference[:n1],
                               settings=dict(result.settings, n_steps=n1 - 1), **cut)


def asd_sensitivity(result, reading="test_mass", *, settle_s=2000.0, lengths=None, npersegs=SENSITIVITY_NPERSEG):
    """The Fig 12 statistic (largest one-sided Welch ASD in 1-30 mHz) against record length and ``nperseg``.

    Parameters
    ----------
    result : LoopResult
    reading : str
        Residual reading (:func:`~hinfnav.papers.yang2020.loop.residual_acceleration`).
    settle_s : float
        Samples before it are left out, s.
    lengths : sequence of int, optional
        Record lengths, steps (default: the loop's own length).
    npersegs : sequence of int

    Returns
    -------
    dict
        ``rows``: one dict per (length, nperseg) with ``n_steps``, ``nperseg``, ``max``, ``f_at_max_hz``
        (m s⁻²/√Hz, Hz); ``spread``: largest / smallest ``max`` − 1 over the rows (the statistic's own
        scatter with these choices); ``min``, ``max``.
    """
    lengths = [result.x.shape[1] - 1] if lengths is None else [as_int_at_least("lengths entry", n, 1) for n in lengths]
    rows = []
    for n in lengths:
        part = truncated(result, n)
        for nper in npersegs:
            st = residual_spectrum(part, reading, settle_s=settle_s, nperseg=nper)
            if any(r["n_steps"] == n and r["nperseg"] == st["nperseg"] for r in rows):
                continue  # nperseg capped at a short record
            rows.append({"n_steps": int(n), "nperseg": int(st["nperseg"]), "max": st["stats"]["max"],
                         "f_at_max_hz": st["stats"]["f_at_max_hz"]})
    values = np.array([r["max"] for r in rows])
    return {"reading": reading, "convention": "one-sided Welch ASD (Hann, 50 % overlap), PSD averaged over runs",
            "rows": rows, "min": float(values.min()), "max": float(values.max()),
            "spread": float(values.max() / values.min() - 1.0)}


def theta_readings_study(scenario, result, *, axis=0, readings=None):
    """L1, L2, L3 on one loop's readings under several readings of θ, and what drives L1's bias.

    Parameters
    ----------
    result : LoopResult
        Usually the open drag-free loop of Fig 5 (its standalone L1/L2/L3 are the θ* reading).
    scenario : Scenario
    axis : int
    readings : dict, optional
        Default :data:`THETA_READINGS`.

    Returns
    -------
    dict
        Per reading: ``theta`` (per axis), and for L1, L2, L3 the :func:`disturbance_errors` (N) plus
        ``r_error_mean_m`` / ``r_error_end_m`` (mean and final ``|displacement error|``, m); for L1 also
        ``first_update_N`` (its disturbance estimate after the first update) and ``truth_first_N``.
        Also ``first_saturated_step``, ``saturated_fraction`` and ``p0_disturbance_std_N`` (√P₀ of F).
    """
    readings = THETA_READINGS if readings is None else readings
    truth = result.dragfree_truth()
    base = build_alg2(scenario)
    sat = result.saturated[..., axis]
    first = np.argmax(sat, axis=1)
    out = {"first_saturated_step": int(first.min()) if sat.any() else None,
           "saturated_fraction": float(sat.mean()), "p0_disturbance_std_N": float(np.sqrt(base.P0[axis, 2, 2]))}
    n_p = next(iter(result.passive.values())).shape[1] if result.passive else 0
    for name, how in readings.items():
        if how == 1.0 and n_p == truth.shape[1]:
            est, theta = {k: result.passive[k] for k in ("L1", "L2", "L3")}, base.theta
        else:
            if how is None:
                alg = build_alg2(scenario, prediction="kalman")
            else:
                th = build_alg1(scenario).theta if how == "alg1" else float(how) * base.theta
                alg = build_alg2(scenario, theta=th)
            est, theta = replay_alg2(result, alg), (None if how is None else alg.theta)
        row = {"theta": None if theta is None else [float(v) for v in np.broadcast_to(theta, (3,))]}
        for k, e in est.items():
            tr = truth[:, : e.shape[1]]
            r_err = np.abs(e[:, :, axis] - tr[:, :, axis])
            row[k] = dict(disturbance_errors(e, tr, axis=axis), r_error_mean_m=float(r_err.mean()),
                          r_error_end_m=float(r_err[:, -1].mean()))
        k = out["first_saturated_step"] or 0
        row["L1"]["first_update_N"] = float(est["L1"][:, k, 6 + axis].mean())
        row["L1"]["truth_first_N"] = float(truth[:, k, 6 + axis].mean())
        out[name] = row
    return out
