"""Figures of the GRACE study: the truth, the mismatch growth, and the filters' errors against time."""

import numpy as np
from scipy.ndimage import uniform_filter1d

from ...plotting.errors import new_figure
from .constants import TRUTH_SIGMA_M

__all__ = ["truth_figure", "mismatch_figure", "errors_figure"]

#: 1σ of the truth's relative position per axis, m: two independent ≈ 2 cm orbits, √2 × 2 cm.
RELATIVE_TRUTH_SIGMA_M = float(np.sqrt(2.0) * TRUTH_SIGMA_M)


def truth_figure(data, kband_check):
    """GRACE-A in GRACE-B's Hill frame over the day, and K-band minus POD baseline."""
    fig, ax = new_figure(2, 2, figsize=(10, 6))
    t_h = data.t / 3600.0
    for i, (lab, unit, scale) in enumerate((("x (radial)", "km", 1e-3), ("y (along-track)", "km", 1e-3),
                                            ("z (normal)", "km", 1e-3))):
        a = ax.flat[i]
        a.plot(t_h, data.truth[:, i] * scale, label=f"GRACE-A {lab}")
        a.set_xlabel("time since 2010-07-27 00:00 (h)")
        a.set_ylabel(f"{lab} ({unit})")
        a.legend(loc="best", fontsize=8)
    a = ax.flat[3]
    n = data.kband.size
    a.plot(t_h[:n], (data.kband - data.baseline[:n]) * 100, label="K-band range − |r_A − r_B| (POD)")
    for s in (-1, 1):
        a.axhline(s * kband_check["tolerance_m"] * 100, color="k", ls="--", lw=0.8,
                  label="±4 cm (issue 20 check)" if s > 0 else None)
    a.set_xlabel("time since 2010-07-27 00:00 (h)")
    a.set_ylabel("difference (cm)")
    a.legend(loc="best", fontsize=8)
    fig.suptitle("GRACE-A relative to GRACE-B, 27 July 2010 (POD truth, Hill frame of GRACE-B)")
    return fig


def mismatch_figure(prop):
    """RMS position error of the three models propagating the true relative state, against time."""
    fig, ax = new_figure(1, 1, figsize=(7, 4.2))
    a = ax[0, 0]
    t = prop["growth_t_s"][1:]
    names = {"hill_cw": "Hill/CW (paper 000)", "two_body": "two-body, both spacecraft",
             "two_body_j2": "two-body + J2, both spacecraft"}
    for key, label in names.items():
        a.loglog(t, prop["growth"][key][1:], label=label)
    for i, s in enumerate(prop["horizons_s"].values()):
        a.axvline(s, color="gray", ls=":", lw=0.8, label="1/10, 1/4 and one orbit" if i == 0 else None)
    a.axhline(RELATIVE_TRUTH_SIGMA_M, color="k", ls="--", lw=0.8, label="truth's own 1σ per axis (≈ 2.8 cm)")
    a.set_xlabel("propagation time (s); dotted: 1/10, 1/4 and one orbit")
    a.set_ylabel(f"RMS position error over {prop['starts']} starts (m)")
    a.legend(loc="best", fontsize=8)
    fig.suptitle("Model mismatch on the real day: propagating the true relative state")
    return fig


def errors_figure(t, errors, variant, names=None, rms_epochs=60):
    """RMS position error per Hill axis, a moving RMS over ``rms_epochs`` epochs (10 min), log scale, against
    time, with the truth's own ≈ 2.8 cm (1σ, relative) marked. ``errors``: filter name → (n, 6) error (m, m/s).
    """
    names = list(errors) if names is None else names
    fig, ax = new_figure(3, 1, figsize=(10, 8), sharex=True)
    t_h = np.asarray(t) / 3600.0
    for i, lab in enumerate(("x (radial)", "y (along-track)", "z (normal)")):
        a = ax[i, 0]
        for name in names:
            a.semilogy(t_h, np.sqrt(uniform_filter1d(errors[name][:, i] ** 2, rms_epochs)), lw=0.8, label=name)
        a.axhline(RELATIVE_TRUTH_SIGMA_M, color="k", ls="--", lw=1.0, label="truth's own 1σ (≈ 2.8 cm)")
        a.set_ylabel(f"RMS error {lab} (m)")
    ax[0, 0].legend(loc="upper right", fontsize=7, ncol=3)
    ax[2, 0].set_xlabel("time since 2010-07-27 00:00 (h)")
    fig.suptitle(f"Filter errors against the POD truth (10-min RMS), GRACE-A/B, measurements: {variant}")
    return fig
