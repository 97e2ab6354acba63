"""The FITC negative log marginal likelihood in a few lines of NumPy (no SciPy), an independent value
to check gpilqg's FITC case against when GPML is not there (a formula, not a peer: it is not timed).

With Kuu = k(Xu, Xu) + snu2 I, snu2 = 1e-6 sf^2 (GPML's jitter rule), Kuu = Luu Luu', V = Luu^-1 k(Xu, X),
Lambda = diag(max(sf^2 - colwise |V|^2, 0)) + sn^2 I (the diagonal of Kff - Qff, plus noise),
A = I + V Lambda^-1 V' = La La' and b = V Lambda^-1 y, the matrix inversion and determinant lemmas give
    y' (Qff + Lambda)^-1 y = y' Lambda^-1 y - |La^-1 b|^2,   log|Qff + Lambda| = log|Lambda| + log|A|,
    nlml = 0.5 (y' Lambda^-1 y - |La^-1 b|^2) + sum log diag La + 0.5 sum log Lambda + N/2 log(2 pi)
(Snelson & Ghahramani 2006; GPML 4.2's infFITC / apxSparse)."""

import math

import numpy as np


def _se(A, B, lengthscales, sf2):
    a, b = A / lengthscales, B / lengthscales
    squared = (a * a).sum(1)[:, None] + (b * b).sum(1)[None, :] - 2.0 * a @ b.T
    return sf2 * np.exp(-0.5 * np.maximum(squared, 0.0))


def fitc_nlml(X, y, theta, inducing):
    """theta = [log l (D), log sf, log sn, vec(Xu) (M x D, column-major)]."""
    d = X.shape[1]
    lengthscales, sf2, sn2 = np.exp(theta[:d]), math.exp(2.0 * theta[d]), math.exp(2.0 * theta[d + 1])
    Xu = np.asarray(theta[d + 2:]).reshape((inducing, d), order="F")
    Kuu = _se(Xu, Xu, lengthscales, sf2) + 1e-6 * sf2 * np.eye(inducing)
    V = np.linalg.solve(np.linalg.cholesky(Kuu), _se(Xu, X, lengthscales, sf2))  # NumPy alone, no SciPy
    lam = np.maximum(sf2 - (V * V).sum(0), 0.0) + sn2
    La = np.linalg.cholesky(np.eye(inducing) + (V / lam) @ V.T)
    c = np.linalg.solve(La, V @ (y / lam))
    return (0.5 * (y @ (y / lam) - c @ c) + np.log(np.diag(La)).sum() + 0.5 * np.log(lam).sum()
            + 0.5 * y.size * math.log(2.0 * math.pi))
