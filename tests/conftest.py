"""Fixtures shared by the test files: the paper's scenario, a short one, random test systems.

The scenarios are immutable (frozen dataclasses with read-only arrays), so one
instance serves the whole session.
"""

import control
import numpy as np
import pytest

from hinfnav.core import spectral_radius
from hinfnav.metrics import rms_per_run
from hinfnav.papers.sun2011 import Scenario

#: Tests marked ``slow`` (each took at least 1 s, fixture set-up included, in ``pytest --durations=0``
#: on the 2-core CI machine); every notebook is ``slow`` and ``notebook`` too. ``pytest -m "not slow"``
#: is the contributor's inner loop; CI runs everything.
SLOW = {
    "tests/test_attitude2018_filters.py::test_thrust_augmentation_fixes_the_first_500_s_of_the_maneuver",
    "tests/test_bad_inputs.py::test_cli_subprocess_has_no_traceback",
    "tests/test_campaign.py::test_bad_spec_files_and_clients",
    "tests/test_campaign.py::test_two_worker_cluster_gives_bitwise_the_serial_numbers",
    "tests/test_cli.py::test_bad_input_gives_a_clear_message_not_a_traceback",
    "tests/test_cli.py::test_simulate_json_fields",
    "tests/test_cli_mixed.py::test_design_h2_front_reports_the_knee",
    "tests/test_contract.py::test_converges_without_noise_on_a_stable_problem",
    "tests/test_design.py::test_observer_gamma_is_at_least_general_and_passes_through_sweep",
    "tests/test_design.py::test_solvers_agree_and_gamma_nondecreasing",
    "tests/test_design_corner_cases.py::test_loose_certificate_warns_with_both_numbers",
    "tests/test_docs.py::test_docs_build_without_warnings_and_hold_the_api",
    "tests/test_generic_layers.py::test_closed_loop_on_the_estimate_converges_like_the_ideal_loop",
    "tests/test_mixed_h2hinf.py::test_front_is_monotone_and_every_point_certified",
    "tests/test_mixed_h2hinf.py::test_near_gamma_star_the_filter_reaches_the_hinf_optimum",
    "tests/test_notebook_parameters.py::test_notebook_labels_follow_the_parameters",
    "tests/test_sun2011_closed_loop.py::test_every_loop_reaches_the_target",
    "tests/test_table1.py::test_each_row_is_reproduced_by_the_command_it_names",
    "tests/test_table1.py::test_table1_cell",
}
#: Test files (or single tests) that run a paper's whole ``reproduce`` pipeline: ``reproduce`` and ``slow``.
REPRODUCE = (
    "tests/test_attitude2018_reproduce.py",
    "tests/test_outputs.py::test_interrupted_and_concurrent_reproduce_never_mix_two_runs",
    "tests/test_paper_notebooks.py::test_run_notebooks_executes_the_named_notebooks_into_the_folder",
    "tests/test_reproduce_skeleton.py",
    "tests/test_shi2018_reproduce.py",
    "tests/test_sun2011_reproduce.py",
    "tests/test_yang2020_reproduce.py",
)


def pytest_collection_modifyitems(config, items):
    """Add the ``slow``, ``notebook`` and ``reproduce`` markers (declared in pyproject.toml)."""
    for item in items:
        nodeid = item.nodeid.split("[")[0]
        if nodeid.endswith(".ipynb") or ".ipynb::" in nodeid:
            item.add_marker(pytest.mark.notebook)
            item.add_marker(pytest.mark.slow)
        if nodeid in SLOW:
            item.add_marker(pytest.mark.slow)
        if nodeid.startswith(REPRODUCE):
            item.add_marker(pytest.mark.reproduce)
            item.add_marker(pytest.mark.slow)


#: Length and error window of the short scenario (600 steps of 0.1 s).
SHORT_DURATION_S = 60.0
SHORT_WINDOW_S = (10.0, 60.0)


@pytest.fixture(scope="session")
def scenario():
    """The paper's scenario (Section 4): T = 0.1 s, 1000 s, RMS window 100–1000 s."""
    return Scenario()


@pytest.fixture(scope="session")
def short_scenario():
    """The paper's scenario cut to 60 s (RMS window 10–60 s), for fast structural checks."""
    return Scenario(duration_s=SHORT_DURATION_S, rms_window_s=SHORT_WINDOW_S)


@pytest.fixture(scope="session")
def make_short_scenario():
    """``make(**changes)``: the short scenario with some settings changed (e.g. ``B=0``)."""

    def make(**changes):
        return Scenario(duration_s=SHORT_DURATION_S, rms_window_s=SHORT_WINDOW_S, **changes)

    return make


def _random_stable(rng, n, m, p, rho):
    """A random discrete system with spectral radius rho (built here, not by control.drss)."""
    A = rng.standard_normal((n, n))
    A *= rho / spectral_radius(A)
    return control.ss(A, rng.standard_normal((n, m)), rng.standard_normal((p, n)), np.zeros((p, m)), True)


@pytest.fixture(scope="session")
def random_stable():
    """``make(rng, n, m, p, rho)``: a random discrete ``control.StateSpace`` with spectral radius rho."""
    return _random_stable


def _random_uncertain(rng, n=3, p=2, m=2, q=2, l=2, r=2, rho=0.8, size=0.1):
    """Random (A, B, C, D, L, H, E): ρ(A) = rho, ‖H‖₂ = ‖E‖₂ = √size."""
    A = rng.standard_normal((n, n))
    A *= rho / spectral_radius(A)
    B, C, D, L = (rng.standard_normal(s) for s in [(n, p), (m, n), (m, q), (l, n)])
    H = rng.standard_normal((n, r))
    E = rng.standard_normal((r, n))
    H *= np.sqrt(size) / np.linalg.norm(H, 2)
    E *= np.sqrt(size) / np.linalg.norm(E, 2)
    return A, B, C, D, L, H, E


@pytest.fixture(scope="session")
def random_uncertain():
    """``make(rng, n=3, p=2, m=2, q=2, l=2, r=2, rho=0.8, size=0.1)``: random uncertain plant matrices."""
    return _random_uncertain


def _assert_rms_matches(error, t, window, sigma, n_se=4.0):
    """Per-component RMS over runs and window vs sigma, within n_se standard errors.

    The standard error is that of the mean over runs of the per-run mean
    square (runs are independent; samples within a run are not), carried to
    the RMS by the delta method. Returns ``(rms, se)``.
    """
    per_run = rms_per_run(error, t, window) ** 2
    rms = np.sqrt(per_run.mean(axis=0))
    se = per_run.std(axis=0, ddof=1) / np.sqrt(per_run.shape[0]) / (2 * rms)
    assert np.all(np.abs(rms - sigma) < n_se * se), (rms, sigma, se)
    return rms, se


@pytest.fixture(scope="session")
def assert_rms_matches():
    """``check(error, t, window, sigma, n_se=4.0)``: Monte Carlo RMS against a predicted std (see above)."""
    return _assert_rms_matches
