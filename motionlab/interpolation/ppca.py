"""Probabilistic PCA (Tipping & Bishop 1999), in closed form and by EM, next to plain PCA.

PPCA is PCA as a generative model. A D-dimensional pose feature ``x`` is explained by a
q-dimensional latent ``z``:

.. math::

    z \\sim \\mathcal N(0, I_q), \\qquad x = W z + \\mu + \\varepsilon, \\qquad
    \\varepsilon \\sim \\mathcal N(0, \\sigma^2 I_D)
    \\quad\\Rightarrow\\quad x \\sim \\mathcal N(\\mu, C), \\; C = W W^\\top + \\sigma^2 I.

**Closed form.** With the sample covariance ``S`` and its eigen-decomposition ``S = U Λ Uᵀ``
(eigenvalues λ₁ ≥ … ≥ λ_D), the maximum-likelihood solution is

.. math::  \\sigma^2 = \\frac{1}{D-q} \\sum_{i>q} \\lambda_i, \\qquad
           W = U_q (\\Lambda_q - \\sigma^2 I)^{1/2}

(up to a rotation of the latent space): the discarded variance becomes isotropic noise.

**EM.** Treat ``z`` as missing data. With ``M = WᵀW + σ² I`` the E-step gives
``E[z] = M⁻¹ Wᵀ (x − μ)``; the M-step, written with ``S`` only, is

.. math::  W' = S W (\\sigma^2 I + M^{-1} W^\\top S W)^{-1}, \\qquad
           \\sigma'^2 = \\tfrac{1}{D} \\operatorname{tr}(S - S W M^{-1} W'^\\top).

Each step never lowers the log-likelihood
``L = −N/2 (D log 2π + log|C| + tr(C⁻¹ S))``; :attr:`PPCA.history` records it, and EM
converges to the closed-form answer. EM costs ``O(D² q)`` per step instead of an ``O(D³)``
eigen-decomposition, and extends to missing data.

**Versus PCA.** PCA keeps the top-q subspace and throws the rest away; it has no density, so it
cannot say how *likely* a pose is. PPCA gives the same subspace plus a noise level σ², a
likelihood for model selection and outlier (missing-frame) detection, and a posterior mean that
shrinks noisy projections towards μ.

Taught in ``notebooks/06_keypose_interpolation.ipynb``.
"""

from __future__ import annotations

import numpy as np

__all__ = ["PCA", "PPCA"]


def _data(x, name: str = "x") -> np.ndarray:
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 2:
        raise ValueError(f"expected {name} as an (N, D) array of N samples, got shape {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ValueError(f"{name} holds NaN or infinite values (fill or drop those rows first)")
    return x


class PCA:
    """Plain PCA: the top-``q`` eigenvectors of the sample covariance.

    Attributes (after :meth:`fit`)
    ------------------------------
    mean : ndarray (D,)
    components : ndarray (D, q)       orthonormal columns
    variances : ndarray (D,)          all eigenvalues of ``S``, decreasing
    """

    def __init__(self, q: int) -> None:
        """A PCA with ``q`` latent dimensions, not fitted yet.

        Raises
        ------
        ValueError unless ``q`` is a whole number >= 1.
        """
        if int(q) != q or q < 1:
            raise ValueError(f"latent size q must be a positive integer, got {q!r}")
        self.q = int(q)

    def fit(self, x) -> PCA:
        """Fit the mean and the ``q`` principal axes to samples ``x`` (N, D).

        Raises
        ------
        ValueError when ``q`` exceeds the data dimension D.
        """
        x = _data(x)
        if self.q > x.shape[1]:
            raise ValueError(f"latent size q={self.q} exceeds the data dimension D={x.shape[1]}")
        self.mean = x.mean(axis=0)
        xc = x - self.mean
        s = xc.T @ xc / len(x)
        lam, u = np.linalg.eigh(s)
        order = np.argsort(lam)[::-1]
        self.variances = np.maximum(lam[order], 0.0)
        self.components = u[:, order[: self.q]]
        return self

    def transform(self, x) -> np.ndarray:
        """Coordinates (N, q) in the principal subspace."""
        return (_data(x) - self.mean) @ self.components

    def inverse_transform(self, z) -> np.ndarray:
        return np.asarray(z, dtype=np.float64) @ self.components.T + self.mean

    def explained_variance_ratio(self) -> float:
        return float(self.variances[: self.q].sum() / max(self.variances.sum(), 1e-300))


class PPCA:
    """Probabilistic PCA with ``q`` latent dimensions.

    Parameters
    ----------
    q : int             latent size
    method : str        ``"closed"`` (eigen-decomposition) or ``"em"``
    max_iter : int      EM iterations at most
    tol : float         EM stops when the log-likelihood per sample rises by less than this
    seed : int          EM's random initial ``W``

    Attributes
    ----------
    mean : ndarray (D,)       μ (this and the following are set by :meth:`fit`)
    W : ndarray (D, q)        loading matrix
    sigma2 : float            noise variance σ²
    history : list of float   log-likelihood per sample after each EM step (closed form: one entry)
    """

    def __init__(self, q: int, method: str = "closed", max_iter: int = 500, tol: float = 1e-8, seed: int = 0) -> None:
        """A probabilistic PCA with ``q`` latent dimensions, fitted by ``method``, not fitted yet.

        Raises
        ------
        ValueError unless ``q`` is a whole number >= 1 and ``method`` is ``'closed'`` or ``'em'``.
        """
        if int(q) != q or q < 1:
            raise ValueError(f"latent size q must be a positive integer, got {q!r}")
        if method not in ("closed", "em"):
            raise ValueError(f"method must be 'closed' or 'em', got {method!r}")
        self.q, self.method, self.max_iter, self.tol, self.seed = int(q), method, int(max_iter), float(tol), seed

    # ------------------------------------------------------------------ fitting
    def fit(self, x) -> PPCA:
        """Fit μ, W and σ² to samples ``x`` (N, D).

        Raises
        ------
        ValueError unless ``q`` is smaller than the data dimension D and than the number of
        samples N, and the samples vary (a constant set has no principal directions).
        """
        x = _data(x)
        n, d = x.shape
        if self.q >= d:
            raise ValueError(f"latent size q={self.q} must be smaller than the data dimension D={d}")
        if self.q >= n:
            raise ValueError(f"latent size q={self.q} needs more than {self.q} samples, got N={n}")
        self.mean = x.mean(axis=0)
        xc = x - self.mean
        s = xc.T @ xc / n
        if not np.trace(s) > 0:
            raise ValueError(f"the {n} samples are all the same: no direction of variance to fit")
        self._s = s
        if self.method == "closed":
            lam, u = np.linalg.eigh(s)
            order = np.argsort(lam)[::-1]
            lam, u = np.maximum(lam[order], 0.0), u[:, order]
            self.sigma2 = max(float(lam[self.q :].mean()), 1e-12)
            self.W = u[:, : self.q] * np.sqrt(np.maximum(lam[: self.q] - self.sigma2, 0.0))
            self.history = [self._loglik_s(s)]
        else:
            rng = np.random.default_rng(self.seed)
            scale = np.sqrt(np.trace(s) / d)
            self.W = rng.standard_normal((d, self.q)) * scale
            self.sigma2 = float(np.trace(s) / d)
            self.history = [self._loglik_s(s)]
            for _ in range(self.max_iter):
                self._em_step(s)
                self.history.append(self._loglik_s(s))
                if abs(self.history[-1] - self.history[-2]) < self.tol:
                    break
        return self

    def _em_step(self, s: np.ndarray) -> None:
        w, s2 = self.W, self.sigma2
        q = self.q
        m_inv = np.linalg.inv(w.T @ w + s2 * np.eye(q))
        sw = s @ w
        w_new = sw @ np.linalg.inv(s2 * np.eye(q) + m_inv @ w.T @ sw)
        s2_new = float(np.trace(s - sw @ m_inv @ w_new.T) / s.shape[0])
        self.W, self.sigma2 = w_new, max(s2_new, 1e-12)

    # ------------------------------------------------------------------ likelihood
    def covariance(self) -> np.ndarray:
        """Model covariance ``C = W Wᵀ + σ² I`` (D, D)."""
        return self.W @ self.W.T + self.sigma2 * np.eye(self.W.shape[0])

    def _loglik_s(self, s: np.ndarray) -> float:
        d = s.shape[0]
        c = self.covariance()
        sign, logdet = np.linalg.slogdet(c)
        return float(-0.5 * (d * np.log(2 * np.pi) + logdet + np.trace(np.linalg.solve(c, s))))

    def log_likelihood(self, x=None) -> float:
        """Average log-likelihood per sample (of the training data when ``x`` is None)."""
        if x is None:
            return self._loglik_s(self._s)
        return float(np.mean(self.score_samples(x)))

    def score_samples(self, x) -> np.ndarray:
        """Log-density ``log N(x_n; μ, C)`` of each sample (N,)."""
        x = _data(x)
        c = self.covariance()
        _, logdet = np.linalg.slogdet(c)
        xc = x - self.mean
        maha = np.sum(xc * np.linalg.solve(c, xc.T).T, axis=1)
        return -0.5 * (x.shape[1] * np.log(2 * np.pi) + logdet + maha)

    # ------------------------------------------------------------------ latent space
    def transform(self, x) -> np.ndarray:
        """Posterior means ``E[z | x] = M⁻¹ Wᵀ (x − μ)``, shape (N, q)."""
        x = _data(x)
        m = self.W.T @ self.W + self.sigma2 * np.eye(self.q)
        return np.linalg.solve(m, self.W.T @ (x - self.mean).T).T

    def inverse_transform(self, z) -> np.ndarray:
        """Reconstruction ``W (WᵀW)⁻¹ M E[z] + μ`` (undoes the posterior shrinkage), (N, D)."""
        z = np.asarray(z, dtype=np.float64)
        wtw = self.W.T @ self.W
        m = wtw + self.sigma2 * np.eye(self.q)
        return (self.W @ np.linalg.solve(wtw, m @ z.T)).T + self.mean

    def subspace(self) -> np.ndarray:
        """An orthonormal basis (D, q) of the span of ``W``."""
        u, _, _ = np.linalg.svd(self.W, full_matrices=False)
        return u
