"""gpilqg.GaussianProcess: every GP backend against scikit-learn's GaussianProcessRegressor with the same
kernel and hyperparameters, likelihood gradients and prediction gradients against finite differences,
shapes, errors and views.

Conventions: gpilqg's theta = [log l (D); log sf; log sn; extras]; scikit-learn's theta for
ConstantKernel * RBF + WhiteKernel is log [sf^2, l (D), sn^2]. Predictions are latent (no noise), which
is what GaussianProcessRegressor returns with alpha = sn^2.
"""

import numpy as np
import pytest
from scipy.spatial.distance import cdist
from sklearn.gaussian_process import GaussianProcessRegressor
from sklearn.gaussian_process.kernels import RBF, ConstantKernel, Kernel, WhiteKernel

import gpilqg

BACKENDS = ["exact", "fitc", "ssgp", "compact"]
TOL = 1e-8  # agreement with scikit-learn (absolute, on values of order 1)

# Hyperparameters used for the comparisons: l, sf, sn.
LENGTH = np.array([0.8, 1.3])
SF = 1.2
SN = 0.1


def data(n=40, seed=0):
    """N points in [-2, 2]^2 with smooth targets and a little noise."""
    rng = np.random.default_rng(seed)
    X = rng.uniform(-2.0, 2.0, size=(n, 2))
    y = np.sin(X[:, 0]) + 0.5 * np.cos(1.5 * X[:, 1]) + 0.05 * rng.standard_normal(n)
    return X, y


def query_points(n=25, seed=1):
    """Test inputs partly outside the training box."""
    return np.random.default_rng(seed).uniform(-2.5, 2.5, size=(n, 2))


def inducing_points():
    """Eight well separated FITC pseudo-inputs (M, D) inside the training box."""
    return np.array([[-1.5, -1.5], [-1.5, 0.0], [-1.5, 1.5], [0.0, -1.0],
                     [0.0, 1.0], [1.5, -1.5], [1.5, 0.0], [1.5, 1.5]])


def spectral_points(m=10, seed=2):
    """SSGP's unscaled spectral points W (m, D)."""
    return np.random.default_rng(seed).standard_normal((m, 2))


def shared_theta(length=LENGTH, sf=SF, sn=SN):
    return np.concatenate([np.log(length), [np.log(sf), np.log(sn)]])


def backend_theta(backend):
    """A parameter vector for `backend` at the comparison hyperparameters (extras column-major)."""
    theta = shared_theta()
    if backend == "fitc":
        return np.concatenate([theta, inducing_points().ravel(order="F")])
    if backend == "ssgp":
        return np.concatenate([theta, spectral_points().ravel(order="F")])
    if backend == "compact":  # l is the support radius here: wide enough for a few neighbours
        return shared_theta(length=np.array([1.5, 2.0]))
    return theta


def conditioned(backend, X=None, y=None):
    if X is None:
        X, y = data()
    return gpilqg.GaussianProcess(backend).fit(X, y, theta=backend_theta(backend))


# ------------------------------------------------------------------------------------------------
# scikit-learn kernels for the approximations


class _FixedKernel(Kernel):
    """A kernel without tunable hyperparameters (empty theta), for GaussianProcessRegressor(optimizer=None)."""

    def is_stationary(self):
        return False

    def diag(self, X):
        return np.full(X.shape[0], self.signal_variance)


class FitcKernel(_FixedKernel):
    """FITC's prior as a kernel (Quinonero-Candela & Rasmussen 2005, sec. 6):

    k_fitc(a, b) = Q(a, b) + [a is b] max(k(a, a) - Q(a, a), 0),  Q(a, b) = k(a, U) (Kuu + snu2 I)^-1 k(U, b),

    with the SE ARD kernel k, pseudo-inputs U and the library's jitter snu2 = 1e-6 sf^2 (GPML's rule). The
    diagonal correction applies to the training covariance only (Y is None); between test and training
    points the covariance is Q, and the prior variance at a test point is k(z, z) = sf^2 (diag). With these,
    GaussianProcessRegressor's predictive mean and variance are FITC's (the library's FitcPredictor is the
    same posterior written with the matrix inversion lemma).
    """

    def __init__(self, length_scale, signal_variance, inducing):
        self.length_scale = length_scale
        self.signal_variance = signal_variance
        self.inducing = inducing

    def _se(self, A, B):
        return self.signal_variance * np.exp(-0.5 * cdist(A / self.length_scale, B / self.length_scale, "sqeuclidean"))

    def __call__(self, X, Y=None, eval_gradient=False):
        U = self.inducing
        kuu = self._se(U, U) + 1e-6 * self.signal_variance * np.eye(len(U))
        kxu = self._se(X, U)
        if Y is None:
            q = kxu @ np.linalg.solve(kuu, kxu.T)
            return q + np.diag(np.maximum(self.signal_variance - np.diag(q), 0.0))
        return kxu @ np.linalg.solve(kuu, self._se(U, Y))


class SsgpKernel(_FixedKernel):
    """SSGP's prior as a kernel (Lazaro-Gredilla et al. 2010): f(x) = phi(x)' a with a ~ N(0, sf^2/m I) and
    phi(x) = [cos(S x); sin(S x)], S = W / l, so k(a, b) = sf^2/m phi(a)' phi(b) = sf^2/m sum_r cos(s_r'(a - b)).
    Bayesian linear regression on phi and the GP with this kernel have the same predictive distribution
    (Woodbury), so scikit-learn's N x N computation checks the library's 2m x 2m one.
    """

    def __init__(self, frequencies, signal_variance):
        self.frequencies = frequencies
        self.signal_variance = signal_variance

    def _features(self, X):
        z = X @ self.frequencies.T
        return np.hstack([np.cos(z), np.sin(z)])

    def __call__(self, X, Y=None, eval_gradient=False):
        Y = X if Y is None else Y
        m = self.frequencies.shape[0]
        return self.signal_variance / m * self._features(X) @ self._features(Y).T


class WendlandKernel(_FixedKernel):
    """The compact backend's kernel (compact.hpp; GPML's covPPard with v = 1): with r the
    length-scale-scaled distance and j = floor(D/2) + 2, k(a, b) = sf^2 (1 - r)_+^(j+1) ((j+1) r + 1).
    The backend is an exact GP with this kernel (sparse Cholesky), so the predictions must agree.
    """

    def __init__(self, length_scale, signal_variance):
        self.length_scale = length_scale
        self.signal_variance = signal_variance

    def __call__(self, X, Y=None, eval_gradient=False):
        Y = X if Y is None else Y
        r = cdist(X / self.length_scale, Y / self.length_scale)
        j = X.shape[1] // 2 + 2
        return self.signal_variance * np.maximum(1.0 - r, 0.0) ** (j + 1) * ((j + 1) * r + 1.0)


def sklearn_kernel(backend, theta):
    d = 2
    length, sf2 = np.exp(theta[:d]), np.exp(2 * theta[d])
    extras = theta[d + 2:].reshape((-1, d), order="F")
    if backend == "exact":
        return ConstantKernel(sf2, "fixed") * RBF(length, "fixed")
    if backend == "fitc":
        return FitcKernel(length, sf2, extras)
    if backend == "ssgp":
        return SsgpKernel(extras / length, sf2)
    return WendlandKernel(length, sf2)


def sklearn_regressor(backend, X, y, theta):
    noise_variance = np.exp(2 * theta[3])
    return GaussianProcessRegressor(sklearn_kernel(backend, theta), alpha=noise_variance, optimizer=None,
                                    normalize_y=False).fit(X, y)


# ------------------------------------------------------------------------------------------------
# Predictions against scikit-learn


@pytest.mark.parametrize("backend", BACKENDS)
def test_predictions_match_sklearn(backend):
    """Mean and latent std agree with GaussianProcessRegressor to 1e-8 with the same kernel (see the
    kernel classes above for why each approximation's kernel is exactly that one)."""
    X, y = data()
    Xs = np.vstack([query_points(), X[:5]])  # also at training inputs
    gp = conditioned(backend, X, y)
    mean, std = gp.predict(Xs, return_std=True)
    ref_mean, ref_std = sklearn_regressor(backend, X, y, backend_theta(backend)).predict(Xs, return_std=True)
    assert np.max(np.abs(mean - ref_mean)) < TOL
    assert np.max(np.abs(std - ref_std)) < TOL
    assert np.std(mean) > 0.1  # a non-trivial posterior: the comparison could fail


@pytest.mark.parametrize("backend", BACKENDS)
def test_predictions_with_gradients_match_the_plain_ones(backend):
    """The per-point path (with gradients) and the batch path (without) give the same mean and std."""
    gp = conditioned(backend)
    Xs = query_points()
    mean, std = gp.predict(Xs, return_std=True)
    mean_g, std_g, _, _ = gp.predict(Xs, return_std=True, return_grad=True)
    np.testing.assert_allclose(mean_g, mean, rtol=0, atol=1e-12)
    np.testing.assert_allclose(std_g, std, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(gp.predict(Xs), gp.predict(Xs, return_grad=True)[0])


# ------------------------------------------------------------------------------------------------
# Log marginal likelihood


def test_exact_log_marginal_likelihood_matches_sklearn():
    """Value and gradient at a theta other than the conditioned one, against scikit-learn with the noise as
    a WhiteKernel: d/dlog l is the same, d/dlog sf = 2 d/dlog sf^2, d/dlog sn = 2 d/dlog sn^2."""
    X, y = data()
    gp = conditioned("exact", X, y)
    theta = shared_theta(length=np.array([0.5, 2.0]), sf=0.9, sn=0.2)
    lml, grad = gp.log_marginal_likelihood(theta, eval_gradient=True)

    kernel = ConstantKernel(1.0) * RBF([1.0, 1.0]) + WhiteKernel(1.0)
    sk = GaussianProcessRegressor(kernel, alpha=0.0, optimizer=None).fit(X, y)
    sk_theta = np.log(np.concatenate([[0.9**2], [0.5, 2.0], [0.2**2]]))
    ref_lml, ref_grad = sk.log_marginal_likelihood(sk_theta, eval_gradient=True)
    expected = np.concatenate([ref_grad[1:3], [2 * ref_grad[0], 2 * ref_grad[3]]])
    assert abs(lml - ref_lml) < TOL
    np.testing.assert_allclose(grad, expected, rtol=0, atol=TOL)


def known_noise(n=40, seed=3):
    """Known noise variances that grow along the data, as an actuator's noise grows with |u|: from 0 to
    16 times the learned part sn^2 = 0.01."""
    return np.linspace(0.0, 0.16, n) * np.random.default_rng(seed).uniform(0.5, 1.0, n)


def test_known_noise_likelihood_matches_sklearn_with_per_sample_alpha():
    """y ~ N(0, K + diag(sn^2 + v_i)) with v known: value and gradient against scikit-learn with
    alpha = v and the learned part as a WhiteKernel, at a theta other than the conditioned one."""
    X, y = data()
    v = known_noise()
    gp = gpilqg.GaussianProcess("exact").fit(X, y, theta=shared_theta(), noise_variance=v)
    theta = shared_theta(length=np.array([0.5, 2.0]), sf=0.9, sn=0.2)
    lml, grad = gp.log_marginal_likelihood(theta, eval_gradient=True)

    kernel = ConstantKernel(1.0) * RBF([1.0, 1.0]) + WhiteKernel(1.0)
    sk = GaussianProcessRegressor(kernel, alpha=v, optimizer=None).fit(X, y)
    sk_theta = np.log(np.concatenate([[0.9**2], [0.5, 2.0], [0.2**2]]))
    ref_lml, ref_grad = sk.log_marginal_likelihood(sk_theta, eval_gradient=True)
    expected = np.concatenate([ref_grad[1:3], [2 * ref_grad[0], 2 * ref_grad[3]]])
    assert abs(lml - ref_lml) < TOL
    np.testing.assert_allclose(grad, expected, rtol=0, atol=TOL)
    # The known noise changes the likelihood: the comparison could fail.
    assert abs(lml - gpilqg.GaussianProcess("exact").fit(X, y, theta=theta).log_marginal_likelihood()) > 1.0


def test_known_noise_predictions_match_sklearn_and_its_gradient_finite_differences():
    """Mean and latent std against scikit-learn with alpha = sn^2 + v; d lml / d theta against central
    differences; a fit with known noise learns a smaller homoscedastic part than one without."""
    X, y = data()
    v = known_noise()
    gp = gpilqg.GaussianProcess("exact").fit(X, y, theta=shared_theta(), noise_variance=v)
    Xs = np.vstack([query_points(), X[:5]])
    mean, std = gp.predict(Xs, return_std=True)
    ref = GaussianProcessRegressor(ConstantKernel(SF**2, "fixed") * RBF(LENGTH, "fixed"), alpha=SN**2 + v,
                                   optimizer=None).fit(X, y)
    ref_mean, ref_std = ref.predict(Xs, return_std=True)
    assert np.max(np.abs(mean - ref_mean)) < TOL
    assert np.max(np.abs(std - ref_std)) < TOL

    theta = shared_theta() + 0.05
    _, grad = gp.log_marginal_likelihood(theta, eval_gradient=True)
    h = 1e-6
    fd = np.array([(gp.log_marginal_likelihood(theta + h * e) - gp.log_marginal_likelihood(theta - h * e)) / (2 * h)
                   for e in np.eye(theta.size)])
    np.testing.assert_allclose(grad, fd, rtol=1e-5, atol=1e-5)

    # Targets whose noise is the known one plus white noise of std 0.05: the learned sn is near 0.05
    # with the known part, and takes the known part's average in too without it.
    rng = np.random.default_rng(5)
    Xn = rng.uniform(-2.0, 2.0, size=(200, 2))
    vn = np.linspace(0.0, 0.25, 200)
    yn = np.sin(Xn[:, 0]) + np.sqrt(vn + 0.05**2) * rng.standard_normal(200)
    with_known = gpilqg.GaussianProcess("exact", restarts=0).fit(Xn, yn, noise_variance=vn)
    without = gpilqg.GaussianProcess("exact", restarts=0).fit(Xn, yn)
    assert np.exp(with_known.theta_[3]) < 0.5 * np.exp(without.theta_[3])


@pytest.mark.parametrize("backend", ["fitc", "ssgp"])
def test_known_noise_of_the_sparse_backends_matches_sklearn_with_their_kernels(backend):
    """FITC's Lambda and SSGP's weighted features take v as the exact GP does: the value, mean and latent
    std against scikit-learn with the backend's own kernel and alpha = sn^2 + v, to 1e-8."""
    X, y = data()
    v = known_noise()
    theta = backend_theta(backend)
    gp = gpilqg.GaussianProcess(backend).fit(X, y, theta=theta, noise_variance=v)
    ref = GaussianProcessRegressor(sklearn_kernel(backend, theta), alpha=np.exp(2 * theta[3]) + v, optimizer=None,
                                   normalize_y=False).fit(X, y)
    assert abs(gp.log_marginal_likelihood() - ref.log_marginal_likelihood_value_) < TOL
    Xs = np.vstack([query_points(), X[:5]])
    mean, std = gp.predict(Xs, return_std=True)
    ref_mean, ref_std = ref.predict(Xs, return_std=True)
    assert np.max(np.abs(mean - ref_mean)) < TOL
    assert np.max(np.abs(std - ref_std)) < TOL
    # The known noise changes the likelihood: the comparison could fail.
    assert abs(gp.log_marginal_likelihood() - conditioned(backend, X, y).log_marginal_likelihood()) > 1.0


@pytest.mark.parametrize("backend", ["compact"])
def test_known_noise_is_refused_by_the_backends_that_do_not_take_it(backend):
    X, y = data()
    with pytest.raises(ValueError, match=f"backend '{backend}' does not take a known noise variance per point"):
        gpilqg.GaussianProcess(backend, inducing=8, frequencies=10).fit(X, y, theta=backend_theta(backend),
                                                                        noise_variance=known_noise())


def test_known_noise_of_the_wrong_size_or_negative_is_refused():
    X, y = data()
    with pytest.raises(gpilqg.InputError, match="noise_variance has 3 entries but y has 40"):
        gpilqg.GaussianProcess().fit(X, y, noise_variance=np.ones(3))
    with pytest.raises(ValueError, match="known noise variance 2 is -1; expected a finite value >= 0"):
        gpilqg.GaussianProcess().fit(X, y, noise_variance=np.where(np.arange(40) == 2, -1.0, 0.1))


@pytest.mark.parametrize("backend", BACKENDS)
def test_log_marginal_likelihood_matches_sklearn(backend):
    """The value at the conditioned theta, for every backend, against scikit-learn's with the same kernel."""
    X, y = data()
    gp = conditioned(backend, X, y)
    ref = sklearn_regressor(backend, X, y, backend_theta(backend)).log_marginal_likelihood_value_
    assert abs(gp.log_marginal_likelihood() - ref) < TOL
    assert abs(gp.log_marginal_likelihood_value_ - ref) < TOL


@pytest.mark.parametrize("backend", BACKENDS)
def test_log_marginal_likelihood_gradient_matches_finite_differences(backend):
    """d lml / d theta (all entries, extras included) against central differences with step 1e-6."""
    gp = conditioned(backend)
    theta = backend_theta(backend) + 0.05  # away from the conditioned point: a non-zero gradient
    lml, grad = gp.log_marginal_likelihood(theta, eval_gradient=True)
    assert lml == pytest.approx(gp.log_marginal_likelihood(theta))
    h = 1e-6
    fd = np.empty_like(theta)
    for i in range(theta.size):
        e = np.zeros_like(theta)
        e[i] = h
        fd[i] = (gp.log_marginal_likelihood(theta + e) - gp.log_marginal_likelihood(theta - e)) / (2 * h)
    np.testing.assert_allclose(grad, fd, rtol=1e-5, atol=1e-5)
    assert np.max(np.abs(grad)) > 0.1


# ------------------------------------------------------------------------------------------------
# Prediction gradients


@pytest.mark.parametrize("backend", BACKENDS)
def test_prediction_gradients_match_finite_differences(backend):
    """d mean / dz and d std / dz against central differences of predict (step 1e-6)."""
    gp = conditioned(backend)
    Xs = query_points(10)
    _, _, mean_grad, std_grad = gp.predict(Xs, return_std=True, return_grad=True)
    h = 1e-6
    for d in range(2):
        e = np.zeros(2)
        e[d] = h
        mp, sp = gp.predict(Xs + e, return_std=True)
        mm, sm = gp.predict(Xs - e, return_std=True)
        np.testing.assert_allclose(mean_grad[:, d], (mp - mm) / (2 * h), rtol=1e-6, atol=1e-6)
        np.testing.assert_allclose(std_grad[:, d], (sp - sm) / (2 * h), rtol=1e-6, atol=1e-6)
    assert np.max(np.abs(mean_grad)) > 0.1


# ------------------------------------------------------------------------------------------------
# Fitting


@pytest.mark.parametrize("backend", BACKENDS)
def test_fit_improves_the_likelihood_and_sets_the_attributes(backend):
    X, y = data(60)
    gp = gpilqg.GaussianProcess(backend, inducing=10, frequencies=10, max_evaluations=60, restarts=0)
    assert gp.fit(X, y) is gp
    summary = gp.fit_summary_
    assert summary["backend"] == backend
    assert summary["evaluations"] > 1
    assert summary["log_marginal_likelihood"] > summary["initial_log_marginal_likelihood"]
    assert gp.log_marginal_likelihood() == pytest.approx(gp.log_marginal_likelihood_value_, rel=1e-8)
    assert gp.backend_ == backend
    assert gp.n_features_in_ == 2
    assert gp.conditioning_status_ in ("ok", "jitter added")
    assert gp.jitter_ >= 0.0
    np.testing.assert_allclose(gp.length_scales_, np.exp(gp.theta_[:2]))
    assert gp.signal_std_ == pytest.approx(np.exp(gp.theta_[2]))
    assert gp.noise_std_ == pytest.approx(np.exp(gp.theta_[3]))
    residual = gp.predict(X) - y
    assert np.sqrt(np.mean(residual**2)) < 0.5 * np.std(y)


def test_fit_with_theta_conditions_without_optimising():
    X, y = data()
    theta = backend_theta("fitc")
    gp = gpilqg.GaussianProcess("fitc", inducing=3).fit(X, y, theta=theta)  # M is read from theta
    np.testing.assert_array_equal(gp.theta_, theta)
    assert gp.fit_summary_["termination"] == "not optimised"
    np.testing.assert_array_equal(gp.inducing_inputs_, inducing_points())


def test_exact_backend_conditions_on_a_subsample():
    X, y = data(50)
    gp = gpilqg.GaussianProcess("exact", exact_points=20).fit(X, y, theta=shared_theta())
    assert gp.X_train_.shape == (20, 2)
    rows = {tuple(r) for r in X}
    assert all(tuple(r) in rows for r in gp.X_train_)


# ------------------------------------------------------------------------------------------------
# Shapes, dtypes, views


@pytest.mark.parametrize("backend", BACKENDS)
def test_output_shapes_and_dtypes(backend):
    gp = conditioned(backend)
    Xs = query_points(7)
    mean = gp.predict(Xs)
    assert mean.shape == (7,) and mean.dtype == np.float64
    outputs = gp.predict(Xs, return_std=True, return_grad=True)
    assert [o.shape for o in outputs] == [(7,), (7,), (7, 2), (7, 2)]
    assert all(o.dtype == np.float64 for o in outputs)
    assert [o.shape for o in gp.predict(Xs, return_grad=True)] == [(7,), (7, 2)]
    assert [o.shape for o in gp.predict(Xs, return_std=True)] == [(7,), (7,)]
    theta = backend_theta(backend)
    assert gp.theta_.shape == theta.shape and gp.theta_.dtype == np.float64
    lml, grad = gp.log_marginal_likelihood(eval_gradient=True)
    assert isinstance(lml, float) and isinstance(gp.log_marginal_likelihood(), float)
    assert grad.shape == theta.shape and grad.dtype == np.float64
    assert gp.length_scales_.shape == (2,)
    assert isinstance(gp.signal_std_, float) and isinstance(gp.noise_std_, float)
    assert gp.X_train_.shape == (40, 2) and gp.y_train_.shape == (40,)


def test_prediction_accepts_any_layout_and_integer_input():
    gp = conditioned("exact")
    Xs = query_points(6)
    expected = gp.predict(Xs)
    np.testing.assert_array_equal(gp.predict(np.asfortranarray(Xs)), expected)
    np.testing.assert_array_equal(gp.predict(Xs.tolist()), expected)
    strided = np.repeat(Xs, 2, axis=0)[::2]
    assert not strided.flags.c_contiguous
    np.testing.assert_array_equal(gp.predict(strided), expected)
    assert gp.predict(np.array([[1, 0]])).shape == (1,)


@pytest.mark.parametrize("backend,attribute,rows", [("fitc", "inducing_inputs_", 8), ("ssgp", "spectral_points_", 10)])
def test_extras_are_views_into_theta(backend, attribute, rows):
    gp = conditioned(backend)
    extras = getattr(gp, attribute)
    assert extras.shape == (rows, 2)
    assert np.shares_memory(extras, gp.theta_)
    np.testing.assert_array_equal(extras, gp.theta_[4:].reshape((rows, 2), order="F"))
    assert not extras.flags.writeable


def test_extras_of_other_backends_raise_attribute_error():
    gp = conditioned("exact")
    with pytest.raises(AttributeError, match="fitc backend only"):
        gp.inducing_inputs_
    assert not hasattr(gp, "spectral_points_")


def test_fitted_arrays_are_read_only_views_of_the_model():
    """theta_, X_train_ and y_train_ are views of the model's memory (two reads share it) that keep the
    model alive through a refit; X and y themselves are copied once by fit (the model owns them)."""
    X, y = data()
    gp = conditioned("exact", X, y)
    for name in ("theta_", "X_train_", "y_train_"):
        first, second = getattr(gp, name), getattr(gp, name)
        assert first is not second and np.shares_memory(first, second)
        assert not first.flags.owndata and not first.flags.writeable
        with pytest.raises(ValueError):
            first[0] = 1.0
    np.testing.assert_array_equal(gp.X_train_, X)
    np.testing.assert_array_equal(gp.y_train_, y)
    assert not np.shares_memory(gp.X_train_, X)  # the documented copy

    theta_view, theta = gp.theta_, backend_theta("exact")
    gp.fit(X, y, theta=theta + 0.5)  # a new model: the old view keeps the old one alive
    np.testing.assert_array_equal(theta_view, theta)
    np.testing.assert_array_equal(gp.theta_, theta + 0.5)


# ------------------------------------------------------------------------------------------------
# Errors


def test_predict_before_fit_raises_runtime_error():
    gp = gpilqg.GaussianProcess("ssgp")
    with pytest.raises(RuntimeError, match="not fitted yet"):
        gp.predict(query_points())
    with pytest.raises(RuntimeError, match="not fitted yet"):
        gp.log_marginal_likelihood()
    with pytest.raises(RuntimeError, match="not fitted yet"):
        gp.theta_


def test_wrong_shapes_raise_input_error():
    X, y = data()
    gp = gpilqg.GaussianProcess()
    with pytest.raises(gpilqg.InputError, match=r"X must be a 2-D array of shape \(N, D\); got shape \(40,\)"):
        gp.fit(X[:, 0], y)
    with pytest.raises(gpilqg.InputError, match=r"y must be a 1-D array of shape \(N,\); got shape \(40, 1\)"):
        gp.fit(X, y[:, None])
    with pytest.raises(gpilqg.InputError, match="X has 40 rows but y has 39 entries"):
        gp.fit(X, y[:-1])
    with pytest.raises(gpilqg.InputError, match="must be an array of real numbers"):
        gp.fit(X, "abc")
    gp.fit(X, y, theta=shared_theta())
    with pytest.raises(gpilqg.InputError, match="X has 3 columns; the model was fitted to D = 2"):
        gp.predict(np.zeros((4, 3)))
    with pytest.raises(ValueError, match="theta has 5 entries; the exact model has 4"):
        gp.log_marginal_likelihood(np.zeros(5))


def test_non_finite_inputs_raise_value_error_with_the_librarys_message():
    X, y = data()
    X[3, 1] = np.nan
    gp = gpilqg.GaussianProcess()
    with pytest.raises(ValueError, match="input row 3, column 1 is nan; expected finite inputs"):
        gp.fit(X, y)
    gp.fit(*data(), theta=shared_theta())
    Xs = query_points(5)
    Xs[2, 0] = np.inf
    with pytest.raises(gpilqg.InputError, match=r"X\[2, 0\] = inf is not finite"):
        gp.predict(Xs)
    with pytest.raises(gpilqg.InputError, match=r"theta\[1\] = nan is not finite"):
        gp.log_marginal_likelihood(np.array([0.0, np.nan, 0.0, 0.0]))


def test_bad_settings_raise_value_error_with_the_librarys_message():
    with pytest.raises(ValueError, match="unknown GP backend 'gauss' \\(known: exact, fitc, ssgp, compact\\)"):
        gpilqg.GaussianProcess("gauss")
    with pytest.raises(ValueError, match="inducing must be >= 1, got 0"):
        gpilqg.GaussianProcess("fitc", inducing=0)
    with pytest.raises(ValueError, match="FitOptions::restarts = -1"):
        gpilqg.GaussianProcess(restarts=-1)
    assert gpilqg.gp_backends == BACKENDS


def test_constant_targets_raise_value_error():
    X, _ = data()
    with pytest.raises(ValueError, match="targets equal"):
        gpilqg.GaussianProcess().fit(X, np.ones(len(X)))


def test_get_params_and_repr():
    gp = gpilqg.GaussianProcess("fitc", inducing=7, seed=3)
    params = gp.get_params()
    assert params["backend"] == "fitc" and params["inducing"] == 7 and params["seed"] == 3
    assert gpilqg.GaussianProcess(**params).get_params() == params
    assert repr(gp) == "GaussianProcess(backend='fitc')"


def test_every_public_member_has_a_docstring():
    cls = gpilqg.GaussianProcess
    assert cls.__doc__ and "theta" in cls.__doc__
    for name in ["fit", "predict", "log_marginal_likelihood", "get_params", "theta_", "length_scales_",
                 "signal_std_", "noise_std_", "inducing_inputs_", "spectral_points_", "X_train_", "y_train_",
                 "backend_", "n_features_in_", "conditioning_status_", "jitter_", "log_marginal_likelihood_value_",
                 "fit_summary_"]:
        assert getattr(cls, name).__doc__, name
