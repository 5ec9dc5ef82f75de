"""The compiled backend (issue 21): both backends on EVERY registered estimator, same estimates.

For each name of :func:`hinfnav.estimators.registered_estimators`, built on
the (short) scenario of the paper that registers it: where a numba kernel
exists (:func:`hinfnav.estimators.compiled.kernel_status` is None) the
estimates and covariances of ``backend="numba"`` equal those of the NumPy
reference to 1e-10 relative (each state channel scaled by its largest
magnitude over the runs and steps; each covariance entry by
``sqrt(max P_ii · max P_jj)``). Where none exists ``backend="numba"`` raises
an InputError naming the backend and the reason, and ``"auto"`` runs the
NumPy path. The expected values are the NumPy path's own numbers (the same
equations computed twice); the kernels with and without outliers (the Huber
M-estimation's iterations, the strong-tracking fading) are both exercised.

CPU: the kernels compile once per installation (numba's on-disk cache, about
20 s of CPU for the Kalman kernel and 2-3 s each for the others on the
README's machine); this file takes about 39 s of CPU from an empty cache and
8 s from a filled one. Every kernel call is in ONE test item so that under
pytest-xdist one worker only compiles.
"""

import functools
import subprocess
import sys

import numpy as np
import pytest

import hinfnav as hn
import hinfnav.papers
from hinfnav.estimators import (AugmentedInputHuberSTKF, RecursiveHInfinityFilter, SigmaPointFilter, build_estimator,
                                registered_estimators)
from hinfnav.estimators import compiled
from hinfnav.estimators.compiled import kernel_status, select_backend
from hinfnav.metrics import NIS_KEYS
from hinfnav.papers.attitude2018 import Scenario as AttitudeScenario
from hinfnav.papers.attitude2018.chaser import P0_THRUST_STD, Q_THRUST_BASE
from hinfnav.papers.shi2018 import Scenario as ShiScenario
from hinfnav.papers.sun2011 import Scenario
from hinfnav.papers.sun2011.constants import DEFAULT_P0_STD
from hinfnav.papers.yang2020 import SUBSYSTEM_OF
from hinfnav.papers.yang2020 import Scenario as YangScenario
from hinfnav.sim import simulate_truth

SUN = Scenario(duration_s=30.0, rms_window_s=(5.0, 30.0))
SHI = ShiScenario(duration_s=40.0, rms_window_s=(4.0, 40.0), maneuver_time_s=20.0)
ATTITUDE = AttitudeScenario(orbits=0.05)
YANG = YangScenario(n_steps=300)
NAMES = registered_estimators()

#: The registered estimators that have a kernel on their scenario (a kernel lost by a refactoring fails here).
WITH_KERNEL = {"ekf", "ekf_known_input", "recursive_hinf", "ekf_augmented_thrust", "ekf_augmented_thrust_st", "hbf",
               "ukf", "stekf", "model_ekf", "model_ukf", "model_hbf", "model_stekf", "model_hinf", "huber_stekf",
               "published", "published_closed_loop", "designed", "designed_closed_loop", "designed_observer",
               "designed_observer_closed_loop", "model_lmi"}
#: ... and those that fall back: the attitude filters (quaternion states), the rate-adaptive filter (data-dependent
#: Q), the converted measurement (R from the reading), Yang 2020's extended-state filters (their own hooks) and the
#: benchmark's rate-adapted random-walk filter (data-dependent Q).
#: The benchmark's other generic filters are built on Sun's chaser, whose declared Kalman model they fit first.
WITHOUT_KERNEL = {"aekf", "astekf", "aaekf", "ekf_augmented_thrust_adaptive",
                  "ekf_converted", "yang2020_alg1", "yang2020_alg2", "yang2020_alg2_ideal", "yang2020_alg2_skip",
                  "yang2020_fused", "attitude_hbf", "attitude_ukf", "model_adaptive",
                  "model_stkf", "model_vbakf", "model_mckf",  # issue 33: no kernel yet (NumPy path)
                  "huber_ukf", "stukf"}  # compositions with strategies (issue 37): no kernel knows the combination


def _scenario(name):
    for sc in (SUN, SHI, ATTITUDE):
        if name in registered_estimators(sc):
            return sc
    return YANG.linear_truth(SUBSYSTEM_OF[name])


@functools.cache
def _built(name, on_sun=False):
    """The registered estimator on its own scenario (or the chaser's), built once for the module (designs cost)."""
    return build_estimator(SUN if on_sun else _scenario(name), name)


@pytest.fixture(scope="module")
def chaser_truth():
    # 11 runs: a block of compiled_lanes.LANES = 8 runs advanced together and 3 runs one at a time
    truth = simulate_truth(SUN.truth_model(maneuver=True), runs=11, seed=7)
    y = truth.y.copy()
    for r in (1, 9):  # an outlier in the block and one in the rest: Huber's iterations, strong tracking's fading
        y[r, 100] += 40.0 * np.sqrt(np.diag(SUN.measurement.R))
    return y, truth.u


def _relative(ref, got, scale):
    return float(np.max(np.abs(got - ref) / scale))


def _assert_same(ref, got, what):
    assert got.xhat.shape == ref.xhat.shape, what
    err = _relative(ref.xhat, got.xhat, np.abs(ref.xhat).max(axis=(0, 1)))
    assert err <= 1e-10, f"{what}: estimates differ by {err:.1e} (relative)"
    if ref.P is None:
        assert got.P is None, what
        return
    assert got.P.shape == ref.P.shape, what
    d = np.sqrt(np.abs(np.diagonal(ref.P, axis1=-2, axis2=-1)).max(axis=(0, 1)))
    err = _relative(ref.P, got.P, np.outer(d, d))
    assert err <= 1e-10, f"{what}: covariances differ by {err:.1e} (relative)"


def test_the_kernel_lists_cover_every_registered_estimator():
    assert set(NAMES) == WITH_KERNEL | WITHOUT_KERNEL
    have = {name for name in NAMES if kernel_status(_built(name)) is None}
    assert have == WITH_KERNEL


def test_numba_equals_numpy(chaser_truth):
    # ONE test item for every kernel call: under pytest-xdist the kernels then compile in one worker only
    # (a cold cache costs ~20 s of CPU per worker that compiles them).
    y, u = chaser_truth
    lanes = compiled._kernels().LANES  # numba imported here, not at collection
    assert y.shape[0] > lanes and y.shape[0] % lanes  # both the blocked and the one-run loops run
    for name in sorted(WITH_KERNEL):
        est = _built(name, on_sun=True)
        ref = est.estimate(y, u, SUN.xhat0, backend="numpy", diagnostics=NIS_KEYS)
        got = est.estimate(y, u, SUN.xhat0, backend="numba", diagnostics=NIS_KEYS)
        _assert_same(ref, got, name)
        assert select_backend(est, "auto", set(NIS_KEYS)) == "numba"
        # the NIS inputs (innovation and S), from the kernel's histories: those of the NumPy path
        assert set(got.diagnostics) == set(ref.diagnostics) & set(NIS_KEYS), name
        for key in got.diagnostics:
            r, g = ref.diagnostics[key], got.diagnostics[key]
            assert g.shape == r.shape, (name, key)
            err = float(np.max(np.abs(g - r)) / np.abs(r).max())
            assert err <= 1e-10, f"{name} {key}: differs by {err:.1e}"
    # the sigma-point kernel computes the points' deviations about zero, once for all runs: other weights too
    # (the cubature rule; alpha = 0.5, a negative centre weight), the same NumPy reference to 1e-10
    for options in ({"rule": "cubature"}, {"alpha": 0.5, "kappa": 1.0}):
        est = SigmaPointFilter.from_ekf(_built("ekf_known_input", on_sun=True), **options)
        _assert_same(est.estimate(y, u, SUN.xhat0, backend="numpy"), est.estimate(y, u, SUN.xhat0, backend="numba"), str(options))
    # Huber x strong tracking on the augmented model (no registered name on the chaser): fading, then Huber's correction
    st = _built("ekf_augmented_thrust_st", on_sun=True)
    est = AugmentedInputHuberSTKF(st.system, st.measurement, Q_input=Q_THRUST_BASE * np.eye(3),
                                  P0=np.diag(DEFAULT_P0_STD**2), P0_input=np.eye(3) * P0_THRUST_STD**2, rho=0.95, beta=1.0)
    assert kernel_status(est) is None
    _assert_same(est.estimate(y, u, SUN.xhat0, backend="numpy"), est.estimate(y, u, SUN.xhat0, backend="numba"), "huber x st")
    for keep in (False, "diagonal"):  # the covariance kept as asked
        for name in ("hbf", "ekf", "recursive_hinf", "ukf"):
            est = _built(name, on_sun=True)
            ref = est.estimate(y[:, :50], u[:, :50], SUN.xhat0, keep_covariance=keep, backend="numpy")
            got = est.estimate(y[:, :50], u[:, :50], SUN.xhat0, keep_covariance=keep, backend="numba")
            if keep is False:
                assert got.P is None and ref.P is None
            else:
                np.testing.assert_allclose(got.P, ref.P, rtol=1e-10, atol=1e-10 * np.abs(ref.P).max(), err_msg=name)
            np.testing.assert_allclose(got.xhat, ref.xhat, rtol=1e-10, atol=1e-10 * np.abs(ref.xhat).max(),
                                       err_msg=name)
    # theta far beyond the existence bound: the kernel's Cholesky of N fails, the NumPy path raises its error
    ref = _built("recursive_hinf", on_sun=True)
    est = RecursiveHInfinityFilter(ref.system, ref.measurement, theta=1e6, P0=ref.P0, Q=ref.Q, R=ref.R)
    with pytest.raises(hn.InputError, match="theta"):
        est.estimate(y, u, SUN.xhat0, backend="numba")


@pytest.mark.parametrize("name", sorted(WITHOUT_KERNEL))
def test_no_kernel_refuses_numba_and_auto_runs_numpy(name):
    est = _built(name)
    assert kernel_status(est)
    with pytest.raises(hn.InputError, match="backend='numba' is not available"):
        est.estimate(np.zeros((1, 2, est.measurement.n_meas)), np.zeros((1, 2, max(est.n_input, 1))),
                     np.zeros(est.n_state), backend="numba")
    assert select_backend(est, "auto") == "numpy"


def test_backend_options_checked(chaser_truth):
    y, u = chaser_truth
    est = build_estimator(SUN, "hbf")
    with pytest.raises(hn.InputError, match="backend"):
        est.estimate(y, u, SUN.xhat0, backend="fortran")
    with pytest.raises(hn.InputError, match="diagnostics other than innovation"):
        est.estimate(y, u, SUN.xhat0, diagnostics=True, backend="numba")
    assert select_backend(est, "auto", None) == "numpy"  # diagnostics asked: the NumPy path
    est.missing = "skip"
    assert "missing='skip'" in kernel_status(est)
    assert select_backend(est, "auto") == "numpy"


def test_auto_is_the_default_and_says_why_it_falls_back(chaser_truth, monkeypatch, caplog):
    # the default of estimate is "auto": the kernel's numbers (bitwise those of backend="numba")
    y, u = chaser_truth
    est = _built("stekf", on_sun=True)
    np.testing.assert_array_equal(est.estimate(y, u, SUN.xhat0).xhat,
                                  est.estimate(y, u, SUN.xhat0, backend="numba").xhat)
    assert compiled.why_numpy(est) is None
    assert "diagnostics" in compiled.why_numpy(est, True)
    with caplog.at_level("INFO", logger="hinfnav.backend"):  # the fallback is reported when asked (logging)
        est.estimate(y[:, :5], u[:, :5], SUN.xhat0, diagnostics=True)
    assert "NumPy path: diagnostics" in caplog.text
    # HINFNAV_BACKEND (the CLI's --backend) and use_backend set the default of every estimate
    monkeypatch.setenv(compiled.BACKEND_VARIABLE, "numpy")
    assert select_backend(est, None) == "numpy"
    with compiled.use_backend("numba"):
        assert select_backend(est, None) == "numba"
    assert select_backend(est, None) == "numpy"
    monkeypatch.setenv(compiled.BACKEND_VARIABLE, "fortran")
    with pytest.raises(hn.InputError, match="HINFNAV_BACKEND"):
        select_backend(est, None)


def test_lti_filter_kernel_with_missing_readings(chaser_truth):
    # the LTI filter (12) (the published and designed filters): the kernel equals the NumPy loop to 1e-10,
    # with the known-input correction and with missing='skip' (a NaN reading replaced by H x̂, as on the NumPy path)
    y, u = chaser_truth
    for name in ("published", "published_closed_loop", "designed_observer"):
        est = _built(name, on_sun=True)
        ref = est.estimate(y, u, SUN.xhat0, backend="numpy", diagnostics=NIS_KEYS)
        got = est.estimate(y, u, SUN.xhat0, backend="numba", diagnostics=NIS_KEYS)
        _assert_same(ref, got, name)
        assert got.diagnostics == ref.diagnostics == {}
    est = _built("published", on_sun=True)
    y_gap = y.copy()
    y_gap[:, 40:60, 1] = np.nan
    y_gap[3, 100:120] = np.nan
    est.missing = "skip"
    try:
        assert kernel_status(est) is None
        _assert_same(est.estimate(y_gap, u, SUN.xhat0, backend="numpy"),
                     est.estimate(y_gap, u, SUN.xhat0, backend="numba"), "lti skip")
    finally:
        est.missing = "refuse"


def test_kernels_are_declared_by_the_class_itself():
    # a subclass that changes a hook does not inherit its base's kernel; declaring compiled_kernel restores it
    from hinfnav.estimators import ExtendedKalmanFilter

    base = _built("ekf", on_sun=True)

    class Mine(ExtendedKalmanFilter):
        pass

    class MineDeclared(ExtendedKalmanFilter):
        compiled_kernel = "kalman"

    mine = Mine(base.system, base.measurement, P0=base.P0, Q=base.Q, R=base.R)
    assert "its base class declares the 'kalman' kernel" in kernel_status(mine)
    assert kernel_status(MineDeclared(base.system, base.measurement, P0=base.P0, Q=base.Q, R=base.R)) is None


def test_numba_not_imported_without_the_backend():
    code = "import sys, hinfnav.estimators; import hinfnav.papers; assert 'numba' not in sys.modules"
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)


def test_every_cell_of_the_example_campaign_runs_compiled():
    # benchmarks/campaign_example.toml: every cell's estimator, with the NIS inputs the runner asks for
    # (diagnostics=NIS_KEYS), runs on its kernel under the default backend "auto" (why_numpy is None)
    from pathlib import Path

    from hinfnav.campaign import build_scenario, load_campaign

    campaign = load_campaign(Path(__file__).parents[1] / "benchmarks" / "campaign_example.toml")
    seen = set()
    for cell in campaign.cells():
        key = (cell.scenario, repr(sorted(cell.settings.items())), cell.estimator, repr(sorted(cell.options.items())))
        if key in seen:
            continue
        seen.add(key)
        est = build_estimator(build_scenario(cell.scenario, **cell.settings), cell.estimator, **cell.options)
        assert compiled.why_numpy(est, set(NIS_KEYS)) is None, (cell.estimator, compiled.why_numpy(est, set(NIS_KEYS)))
        assert select_backend(est, None, set(NIS_KEYS)) == "numba"
    assert len(seen) >= 5


def test_cli_backend_option():
    # python -m hinfnav --backend {auto,numpy,numba} COMMAND: the choice is checked by the parser
    from hinfnav.cli import _parser

    assert _parser().parse_args(["--backend", "numpy", "reproduce"]).backend == "numpy"
    assert _parser().parse_args(["reproduce"]).backend is None  # HINFNAV_BACKEND or "auto"
    with pytest.raises(SystemExit):
        _parser().parse_args(["--backend", "fortran", "reproduce"])
