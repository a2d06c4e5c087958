"""PPCA: recovers a noisy low-rank subspace; EM raises the likelihood and meets the closed form."""

import numpy as np
import pytest

from motionlab.interpolation.ppca import PCA, PPCA


def low_rank(rng, n=2000, d=12, q=3, noise=0.1):
    basis, _ = np.linalg.qr(rng.normal(size=(d, q)))
    w = basis * np.array([3.0, 2.0, 1.5])[:q]
    z = rng.normal(size=(n, q))
    x = z @ w.T + np.arange(d) + noise * rng.normal(size=(n, d))
    return x, basis, noise**2


def max_principal_angle(a, b):
    s = np.linalg.svd(a.T @ b, compute_uv=False)
    return float(np.arccos(np.clip(s.min(), -1, 1)))


@pytest.mark.parametrize("method", ["closed", "em"])
def test_recovers_subspace_and_noise(method):
    rng = np.random.default_rng(0)
    x, basis, s2 = low_rank(rng)
    m = PPCA(3, method=method).fit(x)
    assert max_principal_angle(m.subspace(), basis) < 0.02
    assert m.sigma2 == pytest.approx(s2, rel=0.1)
    np.testing.assert_allclose(m.mean, np.arange(12), atol=0.2)


def test_em_likelihood_never_decreases_and_meets_closed_form():
    rng = np.random.default_rng(1)
    x, _, _ = low_rank(rng, n=800)
    em = PPCA(3, method="em", max_iter=5000, tol=1e-12).fit(x)  # EM is slow when σ² is small
    h = np.array(em.history)
    assert len(h) > 3
    assert np.all(np.diff(h) >= -1e-9)
    closed = PPCA(3).fit(x)
    assert em.log_likelihood() == pytest.approx(closed.log_likelihood(), abs=1e-5)
    assert closed.log_likelihood() == pytest.approx(closed.history[0])


def test_log_likelihood_matches_direct_gaussian_density():
    rng = np.random.default_rng(2)
    x, _, _ = low_rank(rng, n=300, d=5, q=2)
    m = PPCA(2).fit(x)
    c = m.covariance()
    xc = x - m.mean
    direct = -0.5 * (
        5 * np.log(2 * np.pi) + np.linalg.slogdet(c)[1] + np.einsum("ni,ij,nj->n", xc, np.linalg.inv(c), xc)
    )
    np.testing.assert_allclose(m.score_samples(x), direct, atol=1e-9)
    assert m.log_likelihood(x) == pytest.approx(m.log_likelihood(), abs=1e-9)


def test_same_subspace_as_pca_and_reconstruction():
    rng = np.random.default_rng(3)
    x, _, _ = low_rank(rng, n=500)
    p = PPCA(3).fit(x)
    pca = PCA(3).fit(x)
    assert max_principal_angle(p.subspace(), pca.components) < 1e-6
    rec = p.inverse_transform(p.transform(x))
    np.testing.assert_allclose(rec, pca.inverse_transform(pca.transform(x)), atol=1e-8)


def test_bad_input():
    with pytest.raises(ValueError, match="smaller than the data dimension"):
        PPCA(4).fit(np.zeros((10, 4)))
    with pytest.raises(ValueError, match="NaN"):
        PPCA(1).fit(np.array([[0.0, np.nan], [1.0, 2.0]]))
    with pytest.raises(ValueError, match="method"):
        PPCA(1, method="svd")


def test_ppca_refuses_too_few_samples_and_samples_that_do_not_vary():
    x = np.random.default_rng(0).normal(size=(3, 8))
    for method in ("closed", "em"):
        with pytest.raises(ValueError, match="needs more than 5 samples"):
            PPCA(5, method=method).fit(x)
        with pytest.raises(ValueError, match="all the same"):
            PPCA(3, method=method).fit(np.ones((20, 8)))
