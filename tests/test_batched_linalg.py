"""The batched small-matrix kernels the nonlinear filters run on (``hinfnav.core.linalg``).

Expected values: NumPy's own ``linalg.inv`` and ``@`` on the same matrices
(independent computations); tolerances say how many units of round-off.
"""

import numpy as np
import pytest

from hinfnav.core.linalg import SERIAL_PRODUCT_SIZE, congruence, inv_spd, matmul_shared


def _spd(rng, shape, m):
    A = rng.normal(size=shape + (m, m))
    return A @ np.swapaxes(A, -1, -2) + 0.1 * np.eye(m)


@pytest.mark.parametrize("m", [1, 2, 3, 4, 6])
def test_inv_spd_equals_numpy_inverse(m):
    rng = np.random.default_rng(m)
    S = _spd(rng, (200,), m)
    # adjugate / determinant: relative error of order cond(S) * eps, as for LU (cond < 1e4 here)
    np.testing.assert_allclose(inv_spd(S), np.linalg.inv(S), rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(inv_spd(S[0]), np.linalg.inv(S[0]), rtol=1e-10, atol=1e-12)  # one matrix
    if m <= 3:
        assert np.array_equal(inv_spd(S), np.swapaxes(inv_spd(S), -1, -2))  # exactly symmetric


def test_inv_spd_leading_axes_and_singular():
    rng = np.random.default_rng(1)
    S = _spd(rng, (7, 4), 3)
    np.testing.assert_allclose(inv_spd(S), np.linalg.inv(S), rtol=1e-10, atol=1e-12)
    bad = np.stack([np.eye(3), np.zeros((3, 3))])
    with pytest.raises(np.linalg.LinAlgError):  # a singular matrix is handed to numpy, which refuses it
        inv_spd(bad)


@pytest.mark.parametrize("runs,n,k", [(1, 6, 3), (1000, 9, 9), (5000, 9, 9), (300, 3, 5)])
def test_matmul_shared_is_bitwise_the_stacked_product(runs, n, k):
    rng = np.random.default_rng(runs)
    A = rng.normal(size=(runs, n, n))
    B = rng.normal(size=(n, k))
    out = matmul_shared(A, B)
    # 1000 and 5000 runs of 9 x 9 exceed one serial product: blocks of rows, each row the same dot products
    assert (runs * n * n * k > SERIAL_PRODUCT_SIZE) == (runs >= 1000)
    assert np.array_equal(out, A @ B)
    assert np.array_equal(matmul_shared(A[:1], B), out[:1])  # independent of the batch size
    assert np.array_equal(matmul_shared(A[0], B), A[0] @ B)  # no batch: plain product


def test_congruence_equals_F_P_Ft():
    rng = np.random.default_rng(3)
    P = _spd(rng, (400,), 9)
    F = rng.normal(size=(9, 9))
    np.testing.assert_allclose(congruence(F, P), F @ P @ F.T, rtol=1e-12, atol=1e-12 * np.abs(P).max())
    np.testing.assert_allclose(congruence(F, P[0]), F @ P[0] @ F.T, rtol=1e-12)
    Fr = rng.normal(size=(400, 9, 9))  # one F per run: the plain product
    assert np.array_equal(congruence(Fr, P), Fr @ P @ np.swapaxes(Fr, -1, -2))
