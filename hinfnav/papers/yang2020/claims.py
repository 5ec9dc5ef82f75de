"""The paper's claims, each with the statistic that tests it, our number and a verdict.

:func:`evaluate_claims` reads the numbers ``reproduce`` computed (a dict
shaped like ``summary.json``) and returns one record per claim:
``{"claim", "figure", "statistic", "number", "verdict", "note"}``. A verdict
is ``"holds"``, ``"does not hold"``, ``"holds in part"`` (some of the claim's parts or of the printed
experiment's parts hold, others do not) or ``"holds under some readings"``; the note says which part or
reading decides it. Each record quotes the paper (``quote``, Section 3 in the original Chinese, and
``quote_en``, an English rendering made for this workbook).
"""

__all__ = ["evaluate_claims", "format_claims", "QUOTES", "VERDICTS", "OVERSHOOT_LIMIT"]

VERDICTS = ("holds", "does not hold", "holds in part", "holds under some readings")

#: The claims' ids, in order.
CLAIM_IDS = ("fig5_l3_vs_l1", "fig5_l1_vs_l2", "fig6", "fig7", "fig8", "fig9", "fig11", "fig12", "asd_vs_pid")
#: Fig 11: "reaches the desired attitude well" read as settling within this time (s) after each edge ...
SETTLING_LIMIT_S = 3000.0
#: ... with an overshoot of at most this fraction of the step.
OVERSHOOT_LIMIT = 0.3

#: The paper's words behind each claim (Section 3, Chinese original) and an English rendering, in claim order.
QUOTES = (
    ("“L3” 给出了此时算法2的运行结果, 此时的估计出现了明显偏差. …由L1和L3的对比, 可以看出约束区间外的集值信息尽管有限但仍"
     "包含了系统的重要信息, 算法2对集值信息的利用效果明显.",
     "\"L3\" gives Algorithm 2's result in this case, and the estimate shows a clear bias. ... Comparing L1 with L3 "
     "shows that the set-valued information outside the constraint interval, although limited, still carries "
     "important information about the system: Algorithm 2 uses the set-valued information to clear effect."),
    ("由L1和L2的对比, 可以看出测量的饱和约束的确影响到了估计效果;",
     "Comparing L1 with L2 shows that the saturation constraint on the measurement does affect (degrade) the "
     "estimate;"),
    ("算法1的估计效果相对稳定; 算法2在递推次数变大时对估计误差的累积效果比较明显, 并影响对扰动的估计精度(见图7).",
     "Algorithm 1's estimates are relatively stable; as the recursion count grows, Algorithm 2 accumulates estimation "
     "error markedly, which affects its disturbance estimate (see Fig 7)."),
    ("算法2…在初始一段时间内(此时累积误差相对较小)对扰动的估计效果要优于算法1, 后来由于误差的累积致使对扰动的估计效果变差.",
     "Algorithm 2 ... estimates the disturbance better than Algorithm 1 over an initial period (while the accumulated "
     "error is still small); later the accumulated error makes its disturbance estimate worse."),
    ("整体来看, 算法1对位移和速度的估计较好, 算法2对扰动的估计较好但需要误差校正…, 这是对算法1和算法2进行融合的基本出发点. "
     "图8展示了融合算法3对扰动的估计效果.",
     "Overall, Algorithm 1 estimates displacement and velocity better, Algorithm 2 the disturbance but it needs error "
     "correction ...; this is the starting point for fusing them. Fig 8 shows the fused Algorithm 3's disturbance "
     "estimate."),
    ("从图中可以看出ADRC算法较PID控制算法能更好地抑制周期性扰动.",
     "The figure shows that ADRC suppresses the periodic disturbance better than the PID law."),
    ("加入阶跃指令(在 k = 1×10^5 时, 给定 φ_sc,pitch = 0.01, φ_sc,yaw = 0.02, φ_sc,roll = 0.03 /rad 控制指令; 并在 "
     "k = 2×10^5 时回到原姿态)后, 图11显示卫星本体姿态控制回路能够较好地达到期望姿态, 同时可以看到卫星本体姿态的调整会对卫星与"
     "测试质量间的相对姿态产生影响, 不过相对姿态控制回路能够迅速地进行调整.",
     "After a step command (at k = 1×10^5 the command phi_sc = 0.01, 0.02, 0.03 rad in pitch, yaw, roll, and at "
     "k = 2×10^5 back to the original attitude), Fig 11 shows that the spacecraft attitude loop reaches the desired "
     "attitude well; adjusting the spacecraft attitude disturbs the relative attitude between spacecraft and test "
     "mass, but the relative-attitude loop readjusts quickly."),
    ("图12是在ADRC下测试质量上平动残余加速度的功率谱密度曲线, 可以看出作用在检测质量上的非保守力加速度的功率谱密度(PSD)在测量"
     "带宽(1 mHz ~ 30 mHz)内, 优于LISA pathfinder探测器的 3×10^-14 m·s^-2·Hz^-1/2 技术指标.",
     "Fig 12 is the PSD of the translational residual acceleration on the test mass under ADRC: the PSD of the "
     "non-conservative acceleration on the test mass is, over the measurement band (1-30 mHz), better than LISA "
     "Pathfinder's 3e-14 m s^-2 Hz^-1/2 specification."),
    ("从图中可以看出ADRC算法较PID控制算法能更好地抑制周期性扰动. … 图12是在ADRC下测试质量上平动残余加速度的功率谱密度曲线",
     "ADRC suppresses the periodic disturbance better than PID (Fig 9) ... Fig 12 is the residual-acceleration PSD "
     "under ADRC (the comparison with PID in 1-30 mHz is this workbook's, from Figs 9 and 12)."),
)


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
    worse = b["L1"] > b["L2"] and est["L1"]["disturbance_rms"] > est["L2"]["disturbance_rms"]
    out.append({
        "claim": "comparing L1 with the ideal L2 shows that the saturation does degrade the estimate (L1 worse than L2)",
        "figure": "Fig 5",
        "statistic": "|mean error| and RMS error of the x-axis disturbance estimate, L1 against L2, N, " + est["setting"],
        "number": {f"{k}_{q}": est[k][f"disturbance_{q}"] for k in ("L1", "L2") for q in ("bias", "rms")},
        "verdict": _v(worse),
        "note": f"|bias| L1 {_fmt(b['L1'])} N against L2 {_fmt(b['L2'])} N, RMS {_fmt(est['L1']['disturbance_rms'])} "
                f"against {_fmt(est['L2']['disturbance_rms'])} N: the saturation costs L1 accuracy, as the paper "
                "says. (Before 0.3 this record stated the claim as 'L1 is close to the ideal L2' and found it not to "
                "hold: a misreading of the paper.)",
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
    out.append(_fig11(st))
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
    for c, cid, (zh, en) in zip(out, CLAIM_IDS, QUOTES):
        c["id"], c["quote"], c["quote_en"] = cid, zh, en
    return out


def _edge_ok(axes):
    return all(a["settling_s"] < SETTLING_LIMIT_S and a["overshoot"] <= OVERSHOOT_LIMIT for a in axes.values())


def _fig11(st):
    """Fig 11 from both edges of the printed experiment (the command on at k = 1e5, back at 2e5)."""
    axes = st.get("axes", {})
    back = st.get("return_edge", {}).get("axes", {})
    on_ok, back_ok = bool(axes) and _edge_ok(axes), bool(back) and _edge_ok(back)
    desc = lambda ax: "; ".join(f"{k} overshoot {v['overshoot'] * 100:.0f} %, settles in {v['settling_s']:.0f} s, "
                                f"torque on its bound {v.get('torque_saturated_steps', float('nan')):.0f} steps"
                                for k, v in ax.items())
    verdict = ("holds" if on_ok and back_ok else "holds in part" if on_ok or back_ok else "does not hold")
    return {
        "claim": "the attitude loop reaches the commanded attitude well, on the step at k = 1e5 and on the return "
                 "at k = 2e5; the relative attitude is disturbed and readjusts quickly",
        "figure": "Fig 11",
        "statistic": f"per edge and axis: 5 % settling time (s, limit {SETTLING_LIMIT_S:g}), overshoot (fraction of "
                     f"the step, limit {OVERSHOOT_LIMIT:g}), steps with the attitude torque on its bound; peak |phi_rel| "
                     "after the edge against before (rad)",
        "number": {"step_on": axes, "return": back},
        "verdict": verdict,
        "note": (f"step on ({'holds' if on_ok else 'fails'}): {desc(axes)}. Return ("
                 + (f"{'holds' if back_ok else 'fails'}): {desc(back)}." if back else "not in this run).")),
    }


def format_claims(claims):
    """A readable table of :func:`evaluate_claims`' records: verdict, figure, claim, then the note."""
    lines = []
    for c in claims:
        lines.append(f"[{c['verdict']}] {c['figure']}: {c['claim']}")
        if c.get("quote"):
            lines.append(f"    paper:     {c['quote']}")
            lines.append(f"               ({c['quote_en']})")
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
