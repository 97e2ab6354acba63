"""scikit-learn's GaussianProcessRegressor as the peer of gpilqg's exact GP (cases a, b, d, e of
bench/peers/compare_peers.py), at gpilqg's hyperparameters exactly (case e: from scikit-learn's own
default start).

The kernel ConstantKernel * RBF(ARD) + WhiteKernel is
    k(a, b) = sf^2 exp(-0.5 sum_d (a_d - b_d)^2 / l_d^2) + sn^2 [a == b],
gpilqg's squared exponential plus noise (gp/include/gpilqg/gp/kernel.hpp). scikit-learn's log
parameters are t = [log sf^2, log l_1..log l_D, log sn^2] (the order of Sum(Product(Constant, RBF),
White), checked at run time); gpilqg's are theta = [log l_1..log l_D, log sf, log sn]. So
    t = [2 theta_D, theta_0..theta_{D-1}, 2 theta_{D+1}],
and by the chain rule, with lml = -nlml,
    d nlml / d theta_d = -d lml / d t_{d+1}   (length-scales),
    d nlml / d theta_D = -2 d lml / d t_0,    d nlml / d theta_{D+1} = -2 d lml / d t_{D+1}.
alpha = 0 (scikit-learn's default adds 1e-10 to the diagonal, which gpilqg does not) and
normalize_y = False (gpilqg's GP is zero-mean on its targets, without normalisation).
"""

import warnings

import numpy as np
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, WhiteKernel

from peer_timing import time_repeated

# Used where no box is given: wide enough for any value the cases use (bounds only matter to fit).
_WIDE = (1e-12, 1e12)
_EXPECTED_ORDER = ["k1__k1__constant_value", "k1__k2__length_scale", "k2__noise_level"]


def kernel(theta, lower=None, upper=None):
    """The scikit-learn kernel at gpilqg's theta, in gpilqg's box [lower, upper] when given."""
    theta = np.asarray(theta, dtype=float)
    d = theta.size - 2
    if lower is None:
        sf_box, l_box, sn_box = _WIDE, _WIDE, _WIDE
    else:
        lo, hi = np.exp(np.asarray(lower, dtype=float)), np.exp(np.asarray(upper, dtype=float))
        sf_box, sn_box = (lo[d] ** 2, hi[d] ** 2), (lo[d + 1] ** 2, hi[d + 1] ** 2)
        l_box = np.column_stack([lo[:d], hi[:d]])
    k = (ConstantKernel(np.exp(2.0 * theta[d]), sf_box) * RBF(np.exp(theta[:d]), l_box)
         + WhiteKernel(np.exp(2.0 * theta[d + 1]), sn_box))
    order = [h.name for h in k.hyperparameters if not h.fixed]
    if order != _EXPECTED_ORDER:
        raise RuntimeError("scikit-learn orders the kernel's parameters %s; this script maps %s" % (order, _EXPECTED_ORDER))
    return k


def to_sklearn(theta):
    """gpilqg's theta -> scikit-learn's t (module docstring)."""
    theta = np.asarray(theta, dtype=float)
    d = theta.size - 2
    return np.concatenate([[2.0 * theta[d]], theta[:d], [2.0 * theta[d + 1]]])


def from_sklearn(t):
    """scikit-learn's t -> gpilqg's theta."""
    t = np.asarray(t, dtype=float)
    d = t.size - 2
    return np.concatenate([t[1:d + 1], [0.5 * t[0], 0.5 * t[d + 1]]])


def nlml_gradient(lml_gradient):
    """d lml / d t (scikit-learn) -> d nlml / d theta (gpilqg), the chain rule of the docstring."""
    g = np.asarray(lml_gradient, dtype=float)
    d = g.size - 2
    return -np.concatenate([g[1:d + 1], [2.0 * g[0], 2.0 * g[d + 1]]])


def _conditioned(X, y, theta):
    """A regressor holding (X, y) at theta, without optimising (one Cholesky, untimed)."""
    return GaussianProcessRegressor(kernel(theta), alpha=0.0, optimizer=None, normalize_y=False).fit(X, y)


def nlml_case(X, y, theta, repeats):
    """Case a: log_marginal_likelihood(t, eval_gradient=True), as gpilqg's NLML and gradient."""
    gpr = _conditioned(X, y, theta)
    t = to_sklearn(theta)
    timing, (lml, grad) = time_repeated(repeats, lambda: gpr.log_marginal_likelihood(t, eval_gradient=True))
    return {**timing, "nlml": -float(lml), "gradient": nlml_gradient(grad).tolist()}


class _CountingRegressor(GaussianProcessRegressor):
    """GaussianProcessRegressor that counts the optimiser's evaluations (the calls with a gradient);
    the optimiser, its settings and the values are scikit-learn's own."""

    def log_marginal_likelihood(self, theta=None, eval_gradient=False, clone_kernel=True):
        if eval_gradient:
            self.evaluations_ = getattr(self, "evaluations_", 0) + 1
        return super().log_marginal_likelihood(theta, eval_gradient, clone_kernel)


def fit_case(X, y, initial, lower, upper, repeats):
    """Case b: fit with one start (n_restarts_optimizer=0) from gpilqg's initial values in gpilqg's box,
    scipy's L-BFGS-B through optimizer='fmin_l_bfgs_b' with scikit-learn's settings. Returns the time,
    the optimum in gpilqg's theta, and the evaluations. Warnings (e.g. ConvergenceWarning) are kept
    in the result instead of printed."""
    def work():
        gpr = _CountingRegressor(kernel(initial, lower, upper), alpha=0.0, optimizer="fmin_l_bfgs_b",
                                 n_restarts_optimizer=0, normalize_y=False)
        return gpr.fit(X, y)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        timing, gpr = time_repeated(repeats, work, warm_up=False)
    theta = from_sklearn(gpr.kernel_.theta)
    return {**timing, "theta": theta.tolist(), "evaluations": gpr.evaluations_,
            "nlml": -float(gpr.log_marginal_likelihood(gpr.kernel_.theta)),
            "warnings": sorted({str(w.message) for w in caught}), "regressor": gpr}


def default_kernel(d):
    """The kernel a user writes for this model with every parameter at the default scikit-learn documents
    (constant_value = length_scale = noise_level = 1.0, bounds (1e-5, 1e5)), one length-scale per input."""
    return ConstantKernel() * RBF(np.ones(d)) + WhiteKernel()


def default_fit_case(X, y, repeats):
    """Case e: a whole fit as a user calls it, GaussianProcessRegressor(default_kernel(D),
    n_restarts_optimizer=0) with every other setting at its default (alpha = 1e-10, L-BFGS-B at SciPy's
    tolerances): one start, from the default kernel. Returns the time, the evaluations, the optimum in
    gpilqg's theta and its NLML under the common function nlml_of (alpha = 0, gpilqg's model)."""
    def work():
        gpr = _CountingRegressor(default_kernel(X.shape[1]), n_restarts_optimizer=0)
        return gpr.fit(X, y)

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        timing, gpr = time_repeated(repeats, work, warm_up=False)
    theta = from_sklearn(gpr.kernel_.theta)
    return {**timing, "theta": theta.tolist(), "evaluations": gpr.evaluations_, "nlml": nlml_of(X, y, theta),
            "start": from_sklearn(default_kernel(X.shape[1]).theta).tolist(),
            "warnings": sorted({str(w.message) for w in caught})}


def nlml_of(X, y, theta):
    """scikit-learn's NLML of (X, y) at gpilqg's theta with alpha = 0: the function both fits of case e
    are scored with."""
    return nlml_at(_conditioned(X, y, theta), theta)


def nlml_at(gpr, theta):
    """scikit-learn's NLML of gpr's training data at gpilqg's theta (to put two optima on one scale)."""
    return -float(gpr.log_marginal_likelihood(to_sklearn(theta)))


def predict_case(X, y, theta, X_test, repeats):
    """Case d: predict(X_test, return_std=True). scikit-learn's std includes the WhiteKernel's noise
    (kernel_.diag), so the latent variance gpilqg returns is std^2 - sn^2."""
    gpr = _conditioned(X, y, theta)
    timing, (mean, std) = time_repeated(repeats, lambda: gpr.predict(X_test, return_std=True))
    noise_variance = np.exp(2.0 * np.asarray(theta, dtype=float)[-1])
    return {**timing, "mean": mean, "variance": std ** 2 - noise_variance}
