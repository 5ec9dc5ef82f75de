"""Issue 35 item 5: the per-step orbital-rate fit δ_k of the GRACE day, solved to convergence, all minima.

Reference: an independent search written here — a different grid (step 0.0037, offset) over |δ| ≤ 4 and
scipy's bounded Brent minimiser on each bracketed local minimum, on f_k(δ) = ‖W (x_{k+1} − Φ(ω₀(1+δ)) x_k)‖²
evaluated one δ at a time. Agreement to 1e-6 in δ (Brent's tolerance 1e-11; f is smooth).
"""

import numpy as np
import pytest
from scipy.optimize import minimize_scalar

from hinfnav.papers.grace2010 import load
from hinfnav.papers.grace2010.mismatch import DELTA_SPAN, delta_minima, hill_transition, one_step_mismatch


@pytest.fixture(scope="module")
def data():
    return load()


def _dense_search(x, x1, w0):
    """All local minima of f per step by an independent grid + Brent (see the module docstring)."""
    W = np.array([1, 1, 1, 1 / w0, 1 / w0, 1 / w0])
    grid = np.arange(-DELTA_SPAN + 0.0013, DELTA_SPAN, 0.0037)
    P = hill_transition(w0 * (1 + grid))
    out = []
    for xk, x1k in zip(x, x1):
        f = np.sum(((x1k - P @ xk) * W) ** 2, axis=1)
        idx = np.nonzero((f[1:-1] <= f[:-2]) & (f[1:-1] <= f[2:]))[0] + 1

        def fk(d, xk=xk, x1k=x1k):
            return float(np.sum(((x1k - hill_transition(w0 * (1 + d)) @ xk) * W) ** 2))

        mins = [minimize_scalar(fk, bounds=(grid[i - 1], grid[i + 1]), method="bounded",
                                options={"xatol": 1e-11}) for i in idx]
        out.append(sorted((m.fun, m.x) for m in mins))
    return out


def _stats(best):
    return np.mean(best), np.max(np.abs(best))


def test_delta_minima_equal_an_independent_dense_search(data):
    w0 = data.orbital_rate
    steps = np.arange(0, data.truth.shape[0] - 1, 29)  # 298 steps spread over the day
    x, x1 = data.truth[steps], data.truth[steps + 1]
    fit = delta_minima(x, x1, w0)
    ref = _dense_search(x, x1, w0)
    counts = np.array([len(r) for r in ref])
    np.testing.assert_array_equal(fit["count"], counts)
    assert counts.max() == 2 and (counts == 2).any()  # the day has steps with two minima
    for k, r in enumerate(ref):
        np.testing.assert_allclose(fit["minima"][k, :len(r)], [d for _, d in r], rtol=0, atol=1e-6)
    best = np.array([r[0][1] for r in ref])
    pos = np.array([min((fv, d) for fv, d in r if d > -1)[1] for r in ref])
    np.testing.assert_allclose(_stats(fit["best"]), _stats(best), rtol=0, atol=1e-6)
    np.testing.assert_allclose(_stats(fit["best_positive_rate"]), _stats(pos), rtol=0, atol=1e-6)


@pytest.mark.slow
def test_day_statistics_equal_the_dense_search(data):
    # the whole day (8640 steps): the summary's statistics against the independent search, 1e-6
    one = one_step_mismatch(data)
    ref = _dense_search(data.truth[:-1], data.truth[1:], data.orbital_rate)
    best = np.array([r[0][1] for r in ref])
    pos = np.array([min((fv, d) for fv, d in r if d > -1)[1] for r in ref])
    fit = one["delta_fit"]
    assert fit["best"]["mean"] == pytest.approx(best.mean(), abs=1e-6)
    assert fit["best"]["max_abs"] == pytest.approx(np.abs(best).max(), abs=1e-6)
    assert fit["positive_rate"]["mean"] == pytest.approx(pos.mean(), abs=1e-6)
    assert fit["positive_rate"]["max_abs"] == pytest.approx(np.abs(pos).max(), abs=1e-6)
    assert fit["steps_with_two_or_more_minima"] == sum(len(r) >= 2 for r in ref)
    assert one["delta_mean"] == fit["best"]["mean"] and one["delta_bar_fit"] == fit["best"]["max_abs"]
