"""Issue 35 item 6: ``diverged`` at the χ² bound (10× kept as level 2), and a NaN-free NIS with missing channels.

Expected values are closed forms: for e ~ N(0, Σ) and a reported P = Σ/c the NEES is c·χ²(n), mean c·n; the
bounds (C3) from scipy's χ² quantiles; the NIS of the channels present recomputed here channel by channel.
"""

import warnings

import numpy as np
import pytest
from scipy.stats import chi2

from hinfnav.core.exceptions import FilterDivergenceWarning
from hinfnav.metrics import ConsistencyAccumulator, warn_if_diverged

RUNS, STEPS, N = 20, 400, 3
T = np.arange(STEPS) * 0.1
WINDOW = {"all": (0.0, T[-1])}


def _stats(c, seed=0):
    """Errors e ~ N(0, I₃) reported with P = I/c (c = 1: consistent; c = 5: 5× over-confident)."""
    rng = np.random.default_rng(seed)
    err = rng.standard_normal((RUNS, STEPS, N))
    P = np.broadcast_to(np.eye(N) / c, (RUNS, STEPS, N, N))
    acc = ConsistencyAccumulator(RUNS)
    acc.add(T, err, P, scale0=np.full(RUNS, 10.0))
    return acc.result("test"), acc.result("test").summary(WINDOW)


def test_five_times_over_confident_filter_is_flagged_at_level_one():
    hi = chi2.ppf(0.975, RUNS * N) / RUNS  # (C3), scipy directly: 4.15 for N = 20 runs of 3 dof
    stats, s = _stats(5.0)
    nees = s["windows"]["all"]["nees"]
    assert nees == pytest.approx(5 * N, rel=0.05)  # closed form: mean 5n, 400 x 20 samples
    assert hi < nees < 10 * hi  # beyond the bound, below the old 10x rule (which let it pass)
    assert s["diverged"] is True and s["diverged_level"] == 1 and "over-confident" in s["diverged_reasons"][0]
    with pytest.warns(FilterDivergenceWarning, match="over-confident"):
        warn_if_diverged(s, "five-times")


def test_consistent_filter_is_not_flagged_and_gross_over_confidence_is_level_two():
    _, ok = _stats(1.0)
    assert ok["diverged"] is False and ok["diverged_level"] == 0 and ok["diverged_reasons"] == []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        warn_if_diverged(ok, "consistent")
    _, gross = _stats(20.0)  # NEES about 60 > 10 x 4.15
    assert gross["diverged"] is True and gross["diverged_level"] == 2 and "grossly" in gross["diverged_reasons"][0]


def test_nis_is_finite_with_thirty_percent_missing_channels():
    rng = np.random.default_rng(3)
    m, runs, steps = 3, 50, 300
    sd = np.array([1.0, 2.0, 3.0])
    S = np.diag(sd**2)
    nu = rng.standard_normal((runs, steps, m)) * sd
    nu[rng.random(nu.shape) < 0.3] = np.nan  # 30 % of the channels missing
    t = np.arange(steps) * 1.0
    acc = ConsistencyAccumulator(runs)
    acc.add(t, np.zeros((runs, steps, 2)), None, nu, np.broadcast_to(S, (steps, m, m)), scale0=np.ones(runs))
    stats = acc.result()
    w = stats.window((0.0, t[-1]))
    assert np.all(np.isfinite(stats.nis)) and np.isfinite(w["nis"]) and np.isfinite(w["nis_inside"])
    # independent: per step, m times the sum over the channels present of (nu/sd)^2, over the count present
    present = ~np.isnan(nu)
    z2 = np.where(present, (np.nan_to_num(nu) / sd) ** 2, 0.0)
    expected = m * z2.sum(axis=(0, 2)) / present.sum(axis=(0, 2))
    np.testing.assert_allclose(stats.nis, expected, rtol=1e-12)
    assert w["nis_dof_mean"] == pytest.approx(present.sum() / runs / steps, rel=1e-12)
    assert w["nis_dof_mean"] == pytest.approx(0.7 * m, abs=0.05)
    assert w["nis"] == pytest.approx(m, rel=0.03)  # the scaled NIS of a consistent filter has mean m
    assert w["nis_inside"] == pytest.approx(0.95, abs=0.04)  # per-step bounds from the dof counted per step


def test_nis_unchanged_when_nothing_is_missing():
    rng = np.random.default_rng(4)
    nu = rng.standard_normal((5, 50, 2))
    acc = ConsistencyAccumulator(5)
    acc.add(np.arange(50.0), np.zeros((5, 50, 2)), None, nu, np.broadcast_to(np.eye(2), (50, 2, 2)),
            scale0=np.ones(5))
    stats = acc.result()
    # closed form: sum over runs of |nu|^2 / N, bit for bit the plain run average
    np.testing.assert_array_equal(stats.nis, (nu**2).sum(axis=2).sum(axis=0) / 5)
    assert stats.nis_dof is None and "nis_dof_mean" not in stats.window((0.0, 49.0))
