"""Figs 1–9 of paper 002, reproduced, and the figures of the sweeps behind its claims.

Each function returns a :class:`matplotlib.figure.Figure` (no pyplot state);
the panel functions take ``ax=``. Error curves are run 0 of the Monte Carlo
set (as a paper's single-run figure) unless a label says "mean" (the
ensemble mean over runs, the oscillating error of :mod:`.studies`).
"""

import numpy as np

from ...plotting.errors import new_figure
from .constants import PAPER_Q_ASTEKF, PAPER_Q_BEST_AEKF
from .studies import EPSILON_FACTORS

__all__ = [
    "fig1",
    "fig2",
    "fig3",
    "fig4",
    "fig5",
    "fig6",
    "fig7",
    "fig8",
    "fig9",
    "fig_error_vs_rate",
    "fig_fading",
    "fig_q_sweep",
    "fig_tuning",
    "plot_torque",
]

#: Points drawn per curve at most (every k-th sample beyond).
MAX_POINTS = 3000
#: The Q values drawn in Figs 2–5, (N·m)²/s.
FIG_Q = (1e-16, 1e-14, 1e-12)
AXES = ("x (roll φ)", "y (pitch θ)", "z (yaw ψ)")
_DEG = np.degrees(1.0)


def plot_torque(scenario, *, ax, t=None):
    """T_d(t) of the three axes, N·m (Fig 1)."""
    t = scenario.time if t is None else t
    T = scenario.torque(t)
    artists = []
    for i, name in enumerate(("T_dx", "T_dy", "T_dz")):
        artists += ax.plot(t, T[:, i] * 1e6, lw=1.0, label=f"${name}$")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("disturbance torque (µN·m)")
    ax.legend(loc="upper right")
    ax.grid(True, alpha=0.3)
    return artists


def plot_error_axes(t, series, *, axes, what="torque", styles=None):
    """Error curves on three axes (one per component).

    Parameters
    ----------
    t : ndarray, shape (n,)
    series : list of (label, ndarray (n, 9))
        Error histories in error coordinates.
    axes : sequence of 3 Axes
    what : {"torque", "euler"}
        Torque error (drawn in µN·m) or Euler-angle error (deg).
    styles : list of dict, optional

    Curves are drawn with the first series on top (``zorder``), and thinned to
    at most :data:`MAX_POINTS` points.
    """
    sl, scale, unit = (slice(6, 9), 1e6, "µN·m") if what == "torque" else (slice(0, 3), _DEG, "deg")
    artists = []
    step = max(1, t.size // MAX_POINTS)
    for j, (label, err) in enumerate(series):
        st = {"lw": 0.6, "color": f"C{j}"} if styles is None else styles[j]
        for i, ax in enumerate(axes):
            artists += ax.plot(t[::step], err[::step, sl][:, i] * scale, label=label if i == 0 else None,
                               zorder=len(series) - j, **st)
    for i, ax in enumerate(axes):
        ax.set_ylabel(f"{'ΔT' if what == 'torque' else 'Δ angle'} {AXES[i]} ({unit})")
        ax.grid(True, alpha=0.3)
    axes[-1].set_xlabel("time t (s)")
    axes[0].legend(loc="upper right", fontsize=7, ncol=2)
    return artists


def fig1(scenario):
    """Fig 1: the disturbance torque used in the simulation."""
    fig, axes = new_figure(1, 1, figsize=(9, 3.6))
    plot_torque(scenario, ax=axes[0, 0])
    axes[0, 0].set_title("Fig 1 — disturbance torque T_d(t), T₀ = 1e-5 N m at 6, 4, 8 ω_e")
    return fig


def _pick(study, name, Qs):
    sw = study.q_sweep
    out = []
    for Q in Qs:
        i = int(np.argmin(np.abs(np.log10(sw["Q"]) - np.log10(Q))))
        out.append((f"Q = {sw['Q'][i]:.0e}", sw[name][i]))
    return out


def fig_filter(stats, title, what, *, t_from=None, styles=None):
    """Three stacked axes with each (label, FilterStats)'s run-0 error (``styles``: see :func:`plot_error_axes`)."""
    fig, axes = new_figure(3, 1, figsize=(10, 7.5), sharex=True)
    t = stats[0][1].t
    m = slice(None) if t_from is None else t >= t_from
    plot_error_axes(t[m], [(lab, s.run0[m]) for lab, s in stats], axes=axes[:, 0], what=what, styles=styles)
    fig.suptitle(title)
    return fig


def fig2(study):
    """Fig 2: AEKF torque error at several Q."""
    return fig_filter(_pick(study, "aekf", FIG_Q), "Fig 2 — AEKF torque estimation error (run 0) for several Q", "torque",
                      t_from=study.scenario.dt * 200)


def fig3(study):
    """Fig 3: AEKF Euler-angle error at several Q."""
    return fig_filter(_pick(study, "aekf", FIG_Q), "Fig 3 — AEKF Euler-angle error (3-2-1, run 0) for several Q", "euler",
                      t_from=study.scenario.dt * 200)


def fig4(study):
    """Fig 4: ASTEKF torque error at several Q."""
    return fig_filter(_pick(study, "astekf", FIG_Q), "Fig 4 — ASTEKF torque estimation error (run 0) for several Q",
                      "torque", t_from=study.scenario.dt * 200)


def fig5(study):
    """Fig 5: ASTEKF Euler-angle error at several Q."""
    return fig_filter(_pick(study, "astekf", FIG_Q), "Fig 5 — ASTEKF Euler-angle error (run 0) for several Q", "euler",
                      t_from=study.scenario.dt * 200)


def _aaekf_fig(study, what, title):
    aa = study.main["aaekf"]
    fig, axes = new_figure(4, 1, figsize=(10, 9), sharex=True)
    t = aa.t
    m = t >= study.scenario.dt * 200
    plot_error_axes(t[m], [("AAEKF run 0", aa.run0[m]), ("AAEKF mean over runs", aa.mean[m])], axes=axes[:3, 0],
                    what=what, styles=[{"lw": 0.5, "color": "C2"}, {"lw": 1.4, "color": "k"}])
    q = aa.diagnostics.get("q_adapted")
    ax = axes[3, 0]
    if q is not None:
        step = max(1, int(m.sum()) // MAX_POINTS)
        for i in range(3):
            ax.semilogy(t[m][::step], q[m][::step, i], lw=0.7, label=f"Q_{'xyz'[i]}")
        ax.legend(loc="upper right", fontsize=7)
    ax.set_ylabel("adapted Q ((N m)²/s)")
    ax.set_xlabel("time t (s)")
    ax.grid(True, alpha=0.3)
    fig.suptitle(title)
    return fig


def fig6(study):
    """Fig 6: AAEKF torque error (run 0, mean over runs) and its adapted Q."""
    return _aaekf_fig(study, "torque", "Fig 6 — AAEKF torque estimation error and adapted Q (run 0)")


def fig7(study):
    """Fig 7: AAEKF Euler-angle error and its adapted Q."""
    return _aaekf_fig(study, "euler", "Fig 7 — AAEKF Euler-angle error and adapted Q (run 0)")


def _three(study):
    """The three filters of Figs 8-9, the AAEKF first (drawn on top: it nearly coincides with the AEKF), the noisy
    ASTEKF last (underneath, faded)."""
    m = study.main
    return [("AAEKF", m["aaekf"]), (f"AEKF, Q = {PAPER_Q_BEST_AEKF:.0e}", m["aekf"]),
            (f"ASTEKF, Q = {PAPER_Q_ASTEKF:.0e}", m["astekf"])]


#: Line styles of Figs 8-9 (in :func:`_three`'s order): every curve stays visible.
THREE_STYLES = ({"lw": 1.1, "color": "k", "ls": "--"}, {"lw": 1.4, "color": "C0"},
                {"lw": 0.5, "color": "C1", "alpha": 0.55})


def fig8(study):
    """Fig 8: torque error of the three filters at the paper's settings."""
    return fig_filter(_three(study), "Fig 8 — torque estimation error of the three filters (run 0)", "torque",
                      t_from=study.scenario.dt * 200, styles=THREE_STYLES)


def fig9(study):
    """Fig 9: Euler-angle error of the three filters at the paper's settings."""
    return fig_filter(_three(study), "Fig 9 — Euler-angle error of the three filters (run 0)", "euler",
                      t_from=study.scenario.dt * 200, styles=THREE_STYLES)


def fig_q_sweep(study):
    """RMS error (last orbit) against Q for the AEKF and the ASTEKF, split into oscillating and random parts."""
    sw = study.q_sweep
    Q = np.array(sw["Q"])
    fig, axes = new_figure(1, 2, figsize=(12, 4.4))
    r = lambda v: np.sqrt(np.mean(np.square(v)))
    for col, (what, unit) in enumerate((("euler", "deg"), ("torque", "N m"))):
        ax = axes[0, col]
        for name, color in (("aekf", "C0"), ("astekf", "C3")):
            if name not in sw:
                continue
            tot = [s.euler_deg if what == "euler" else s.torque_Nm for s in sw[name]]
            bias = [r(s.euler_bias_deg if what == "euler" else s.torque_bias_Nm) for s in sw[name]]
            rnd = [r(s.euler_random_deg if what == "euler" else s.torque_random_Nm) for s in sw[name]]
            pos = lambda v: np.where(np.asarray(v) > 0, v, np.nan)
            ax.loglog(Q, tot, "o-", color=color, label=f"{name.upper()} total")
            ax.loglog(Q, pos(bias), "--", color=color, lw=0.9, label=f"{name.upper()} oscillating (mean over runs)")
            ax.loglog(Q, pos(rnd), ":", color=color, lw=0.9, label=f"{name.upper()} random")
        ax.axvline(PAPER_Q_BEST_AEKF, color="k", lw=0.6, ls="-.", label="paper's best AEKF Q")
        ax.set_xlabel("Q ((N m)²/s)")
        ax.set_ylabel(f"RMS {'Euler-angle' if what == 'euler' else 'torque'} error ({unit})")
        ax.grid(True, which="both", alpha=0.3)
    axes[0, 0].legend(fontsize=7)
    fig.suptitle("The Q trade-off (claims 2-3): RMS over the last orbit, " + " vs ".join(k.upper() for k in sw if k != "Q"))
    return fig


def fig_error_vs_rate(study, Q=PAPER_Q_BEST_AEKF, name="aekf"):
    """Claim 1: the oscillating torque error |b(t)| beside the torque's |dT_d/dt| and |T_d| (scaled), last orbit."""
    i = int(np.argmin(np.abs(np.log10(study.q_sweep["Q"]) - np.log10(Q))))
    s = study.q_sweep[name][i]
    sc = study.scenario
    m = s.t >= sc.rms_window_s[0]
    t = s.t[m]
    fig, axes = new_figure(3, 1, figsize=(10, 7), sharex=True)
    rate, torque = np.abs(sc.torque_rate(t)), np.abs(sc.torque(t))
    b = np.abs(s.mean[m, 6:9]) * 1e6  # µN·m
    for k, ax in enumerate(axes[:, 0]):
        ax.plot(t, b[:, k], color="C0", lw=1.0, label="|oscillating torque error| (mean over runs)")
        ax.plot(t, rate[:, k] * b[:, k].max() / rate[:, k].max(), "C1--", lw=0.8, label="|dT_d/dt| (scaled)")
        ax.plot(t, torque[:, k] * b[:, k].max() / torque[:, k].max(), "C2:", lw=0.8, label="|T_d| (scaled)")
        ax.set_ylabel(f"|ΔT| {AXES[k]} (µN·m)")
        ax.grid(True, alpha=0.3)
    axes[-1, 0].set_xlabel("time t (s)")
    axes[0, 0].legend(loc="upper right", fontsize=7)
    fig.suptitle(f"Claim 1 — {name.upper()} at Q = {study.q_sweep['Q'][i]:.0e}: the error follows the torque's rate")
    return fig


def fig_fading(study, mean_steps=300):
    """The ASTEKF's fading factor λ (run 0; all λᵢ equal with aᵢ = 1) and its moving mean over ``mean_steps`` steps.
    """
    st = study.main["astekf"]
    lam = st.diagnostics["fading"][:, 0]
    fig, axes = new_figure(1, 1, figsize=(10, 3.6))
    ax = axes[0, 0]
    step = max(1, lam.size // MAX_POINTS)
    ax.semilogy(st.t[::step], lam[::step], lw=0.4, color="0.6", label="λ (run 0)")
    mov = np.convolve(lam, np.ones(mean_steps) / mean_steps, mode="same")
    ax.semilogy(st.t, mov, color="C3", lw=1.2, label=f"moving mean over {mean_steps} steps")
    ax.set_xlabel("time t (s)")
    ax.set_ylabel("fading factor λ (–)")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(loc="upper right", fontsize=7)
    ax.set_title(f"ASTEKF fading factor, Q = {PAPER_Q_ASTEKF:.0e}, ρ = {st.params.get('rho')}, β = {st.params.get('beta')}")
    return fig


def fig_tuning(study):
    """The ASTEKF over (ρ, β) and the AAEKF over ε and the rate memory m (steps): RMS Euler and torque errors."""
    fig, axes = new_figure(1, 2, figsize=(12, 4.2))
    ax = axes[0, 0]
    labels = [s.label for s in study.st_grid]
    x = np.arange(len(labels))
    ax.bar(x - 0.2, [s.euler_deg * 1e4 for s in study.st_grid], 0.4, label="Euler (1e-4 deg)")
    ax.bar(x + 0.2, [s.torque_Nm * 1e6 for s in study.st_grid], 0.4, label="torque (µN·m)")
    ax.set_xticks(x, labels, rotation=45, ha="right", fontsize=7)
    ax.set_ylabel("RMS error (1e-4 deg; µN·m)")
    ax.set_title("ASTEKF at Q = 1e-16 over (ρ, β)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, axis="y", alpha=0.3)
    ax = axes[0, 1]
    f = np.array(EPSILON_FACTORS)
    ax.loglog(f, [s.euler_deg for s in study.epsilon_sweep], "o-", label="Euler RMS (deg)")
    ax.loglog(f, [s.torque_Nm * 1e2 for s in study.epsilon_sweep], "s-", label="torque RMS (1e-2 N m)")
    for s in study.window_sweep:
        ax.plot([1.0], [s.euler_deg], "x", ms=8, label=f"Euler, {s.label}")
    ax.set_xlabel("ε / default ε (–)")
    ax.set_ylabel("RMS error (deg, 1e-2 N m)")
    ax.set_title("AAEKF over its compression factor ε (m = 60) and rate memory m (steps)", fontsize=9)
    ax.legend(fontsize=7)
    ax.grid(True, which="both", alpha=0.3)
    fig.suptitle("What the two ideas' own parameters do (claims 3 and 5)")
    return fig
