"""The paper's claims, each with the statistic that tests it, our number and a verdict.

:func:`evaluate_claims` reads the numbers ``reproduce`` computed (a dict
shaped like ``summary.json``) and returns one record per claim:
``{"claim", "figure", "statistic", "number", "verdict", "note"}``. A verdict
is ``"holds"``, ``"does not hold"`` or ``"holds under some readings"``; the
note says which reading decides it.
"""

__all__ = ["evaluate_claims", "format_claims", "VERDICTS"]

VERDICTS = ("holds", "does not hold", "holds under some readings")


def _v(ok):
    return "holds" if ok else "does not hold"


def _fmt(x):
    return f"{x:.3g}"


def _l1_cause(est):
    """Why L1 is biased, from ``estimation.theta_readings``
    (:func:`~hinfnav.papers.yang2020.studies.theta_readings_study`)."""
    th = est.get("theta_readings")
    if not th:
        return ""
    d = th["theta_star"]["L1"]
    printed = {k: v for k, v in th.items() if isinstance(v, dict) and k != "kalman_prediction"}
    l1_worse = [k for k, v in printed.items() if abs(v["L1"]["disturbance_bias"]) > abs(v["L3"]["disturbance_bias"])]
    kal = th.get("kalman_prediction")
    text = (f"Cause: the first clipped update (step {th['first_saturated_step']}), with P0 spreading the disturbance "
            f"by {_fmt(th['p0_disturbance_std_N'] * 1e3)} mN, throws L1's estimate to "
            f"{_fmt(d['first_update_N'] * 1e3)} mN "
            f"(truth {_fmt(d['truth_first_N'] * 1e3)} mN); Algorithm 2 alone sees the displacement only through the "
            f"test-mass stiffness (K_trans/m_tm ~ 1e-6 s^-2), so the disturbance error integrates into displacement "
            f"error (mean {_fmt(d['r_error_mean_m'])} m, {_fmt(d['r_error_end_m'])} m at the end) that keeps it off. "
            f"L1 is more biased than L3 under {len(l1_worse)} of the {len(printed)} readings of theta that keep the "
            f"printed prediction ({', '.join(printed)}).")
    if kal:
        text += (" With a plain Kalman prediction (not printed) L1's bias is "
                 f"{_fmt(kal['L1']['disturbance_bias'] * 1e3)} mN against L3's {_fmt(kal['L3']['disturbance_bias'] * 1e3)} mN (RMS "
                 f"{_fmt(kal['L1']['disturbance_rms'] * 1e3)} against {_fmt(kal['L3']['disturbance_rms'] * 1e3)} mN).")
    return text


def _asd_note(asd):
    """The 3e-14 margin of each reading against the statistic's own scatter (record length and nperseg)."""
    sens = asd.get("sensitivity")
    if not sens:
        return ""
    req = asd["requirement"]
    rows = {}
    for k, v in asd["by_reading"].items():
        spread = list(v.get("max_by_nperseg", {}).values()) or [v["max"]]
        lo, hi = min(spread + [v["max"]]), max(spread + [v["max"]])
        rows[k] = ("below" if hi < req else "above" if lo > req else "straddles")
    lengths = sorted({r["n_steps"] for r in sens["rows"]})
    npers = sorted({r["nperseg"] for r in sens["rows"]})
    return (f" All readings at {asd['record_steps']} steps, one-sided Welch ASD. The default reading's band maximum "
            f"ranges {_fmt(sens['min'])}-{_fmt(sens['max'])} (spread {sens['spread'] * 100:.0f} %) over record lengths "
            f"{lengths} steps and nperseg {npers} (asd.sensitivity), so a margin smaller than that is inside the "
            "statistic's scatter. Against 3e-14 over nperseg " + str(npers) + ": " +
            ", ".join(f"{k} {v}" for k, v in rows.items()) + ".")


def evaluate_claims(s):
    """Claims of Section 3 against the numbers of a reproduction (see the module docstring).

    Parameters
    ----------
    s : dict
        With ``estimation``, ``algorithms``, ``periodic``, ``step_response`` and ``asd`` as written by
        :func:`hinfnav.papers.yang2020.reproduce`.

    Returns
    -------
    list of dict
    """
    out = []
    est = s["estimation"]
    b = {k: abs(est[k]["disturbance_bias"]) for k in ("L1", "L2", "L3")}
    out.append({
        "claim": "L3 (updates skipped while saturated) is clearly biased, more than L1 (Algorithm 2)",
        "figure": "Fig 5",
        "statistic": "|mean error| of the x-axis disturbance estimate, N, " + est["setting"],
        "number": {k: est[k]["disturbance_bias"] for k in ("L1", "L2", "L3")},
        "verdict": _v(b["L3"] > b["L1"]),
        "note": f"|bias| L1 {_fmt(b['L1'])}, L2 {_fmt(b['L2'])}, L3 {_fmt(b['L3'])} N. " + _l1_cause(est) +
                " In the closed loop the accelerometers saturate only in the first steps and the three "
                "coincide afterwards (estimation.closed_loop).",
    })
    close = abs(est["L1"]["disturbance_bias"] - est["L2"]["disturbance_bias"]) < abs(
        est["L3"]["disturbance_bias"] - est["L2"]["disturbance_bias"])
    out.append({
        "claim": "L1 is close to the ideal L2: the set-valued information beyond the range is used well",
        "figure": "Fig 5",
        "statistic": "|bias L1 - bias L2| against |bias L3 - bias L2| and the RMS errors, N",
        "number": {k: est[k]["disturbance_rms"] for k in ("L1", "L2", "L3")},
        "verdict": _v(close and est["L1"]["disturbance_rms"] < est["L3"]["disturbance_rms"]),
        "note": "the truncated mean E[y | y <= lower] of a wide predicted normal lies far below the bound: "
                "with theta* the predicted variance of f grows by (1 + 1/theta*) 4 q per step, so long "
                "saturation drives L1 away from the truth",
    })
    al = s["algorithms"]
    out.append({
        "claim": "Algorithm 1's displacement and velocity estimates stay stable; Algorithm 2's accumulate errors",
        "figure": "Fig 6",
        "statistic": "x-axis displacement error at the end of the standalone run, m",
        "number": {"algorithm1": al["alg1"]["r_error_end_m"], "algorithm2": al["L1"]["r_error_end_m"]},
        "verdict": _v(al["L1"]["r_error_end_m"] > 10 * al["alg1"]["r_error_end_m"]),
        "note": "closed loop (ADRC), the filters run standalone on its readings",
    })
    e1, e2 = al["alg1"], al["L1"]
    early_ok = e2["early"]["disturbance_rms"] < e1["early"]["disturbance_rms"]
    late_ok = e2["late"]["disturbance_rms"] > e1["late"]["disturbance_rms"]
    out.append({
        "claim": "Algorithm 2 estimates the disturbance better than Algorithm 1 at first, worse later",
        "figure": "Fig 7",
        "statistic": "RMS x-axis disturbance error, N, early and late windows (steps " +
                     f"{e1['early']['window_steps']} and {e1['late']['window_steps']})",
        "number": {"algorithm1": {"early": e1["early"]["disturbance_rms"], "late": e1["late"]["disturbance_rms"]},
                   "algorithm2": {"early": e2["early"]["disturbance_rms"], "late": e2["late"]["disturbance_rms"]}},
        "verdict": "holds" if early_ok and late_ok else ("holds under some readings" if early_ok or late_ok
                                                          else "does not hold"),
        "note": f"early: better {early_ok}; late: worse {late_ok}",
    })
    fu = al["fused"]["all"]["disturbance_rms"]
    out.append({
        "claim": "the fusion (Algorithm 3) estimates the disturbance better than either algorithm",
        "figure": "Fig 8",
        "statistic": "RMS x-axis disturbance error over the standalone span, N",
        "number": {"fused": fu, "algorithm1": al["alg1"]["all"]["disturbance_rms"],
                   "algorithm2": al["L1"]["all"]["disturbance_rms"]},
        "verdict": _v(fu < min(al["alg1"]["all"]["disturbance_rms"], al["L1"]["all"]["disturbance_rms"])),
        "note": "",
    })
    per = s["periodic"]
    out.append({
        "claim": "ADRC rejects the periodic disturbance better than the tuned PID (K_P 5.55, K_I 0, K_D 9)",
        "figure": "Fig 9",
        "statistic": "amplitude of r_rel,x at omega_d after 2000 s, m",
        "number": per,
        "verdict": _v(per["adrc_pid"] < per["pid"] and per["adrc"] < per["pid"]),
        "note": f"PID/ADRC ratio {_fmt(per['pid'] / max(per['adrc_pid'], 1e-300))} (same PID + compensation)",
    })
    st = s["step_response"]
    ok = bool(st) and all(a["settling_s"] < 3000.0 for a in st["axes"].values())
    out.append({
        "claim": "the attitude follows the step command; the relative attitude is disturbed and recovers",
        "figure": "Fig 11",
        "statistic": "5 % settling time (s), overshoot, peak |phi_rel| after the step against before (rad)",
        "number": st.get("axes", {}),
        "verdict": _v(ok),
        "note": "",
    })
    asd = s["asd"]
    by = asd["by_reading"]
    passes = {k: v["max"] < asd["requirement"] for k, v in by.items()}
    n_pass = sum(passes.values())
    out.append({
        "claim": "the residual acceleration ASD stays below 3e-14 m s^-2/sqrt(Hz) over 1-30 mHz under ADRC",
        "figure": "Fig 12",
        "statistic": "largest one-sided Welch ASD in 1-30 mHz, any axis (nperseg " + str(asd["nperseg"]) + ", "
                     + str(asd.get("record_steps", "")) + " steps)",
        "number": {"default": asd["adrc_max_1_30mHz"], **{k: v["max"] for k, v in by.items()}},
        "verdict": ("holds" if n_pass == len(passes) else "does not hold" if n_pass == 0
                    else "holds under some readings"),
        "note": "readings that pass: " + (", ".join(k for k, p in passes.items() if p) or "none") +
                f"; default ({asd['reading']}, {asd['noise']} noise) {_fmt(by['default']['max'])} at "
                f"{by['default']['n_steps']} steps ({_fmt(asd['adrc_max_1_30mHz'])} over the full run)."
                + _asd_note(asd),
    })
    out.append({
        "claim": "ADRC's residual-acceleration ASD in 1-30 mHz is below PID's",
        "figure": "Figs 9, 12",
        "statistic": "largest and median Welch ASD in 1-30 mHz",
        "number": {"adrc": asd["adrc_max_1_30mHz"], "adrc_pid": asd["adrc_pid_max_1_30mHz"],
                   "pid": asd["pid_max_1_30mHz"], "adrc_median": asd["adrc_median_1_30mHz"],
                   "pid_median": asd["pid_median_1_30mHz"]},
        "verdict": _v(asd["adrc_max_1_30mHz"] < asd["pid_max_1_30mHz"]),
        "note": "",
    })
    return out


def format_claims(claims):
    """A readable table of :func:`evaluate_claims`' records: verdict, figure, claim, then the note."""
    lines = []
    for c in claims:
        lines.append(f"[{c['verdict']}] {c['figure']}: {c['claim']}")
        lines.append(f"    statistic: {c['statistic']}")
        lines.append(f"    number:    {_short(c['number'])}")
        if c.get("note"):
            lines.append(f"    note:      {c['note']}")
    return "\n".join(lines)


def _short(obj):
    if isinstance(obj, dict):
        return "{" + ", ".join(f"{k}: {_short(v)}" for k, v in obj.items()) + "}"
    if isinstance(obj, float):
        return f"{obj:.3g}"
    return str(obj)
