"""AutoregressiveImputer: ridge fit and on-line conditional means, written out."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.impute import AutoregressiveImputer


def gaussian_ar(n_frames=400, n_features=4, seed=0):
    """Frames of a stable AR(2) with correlated noise, and its parameters."""
    rng = np.random.default_rng(seed)
    A1 = 0.5 * np.eye(n_features) + 0.1 * rng.normal(size=(n_features, n_features))
    A2 = -0.2 * np.eye(n_features)
    root = rng.normal(size=(n_features, n_features))
    noise_cov = 0.1 * (root @ root.T + np.eye(n_features))
    intercept = rng.normal(size=n_features)
    X = np.zeros((n_frames, n_features))
    noise = rng.multivariate_normal(np.zeros(n_features), noise_cov, size=n_frames)
    for t in range(2, n_frames):
        X[t] = intercept + A1 @ X[t - 1] + A2 @ X[t - 2] + noise[t]
    return X, (A1, A2), intercept, noise_cov


def test_fit_is_ridge_least_squares_with_intercept():
    X, ids = make_oscillations(n_sequences=3, n_frames=40, random_state=0)
    alpha = 0.7
    imputer = AutoregressiveImputer(order=2, alpha=alpha).fit(X, sequence_ids=ids)
    # the normal equations, frame by frame, history never crossing a sequence
    rows = [t for t in range(len(X)) if t >= 2 and ids[t - 2] == ids[t]]
    H = np.array([np.concatenate([X[t - 1], X[t - 2], [1.0]]) for t in rows])
    Y = X[rows]
    penalty = alpha * np.eye(H.shape[1])
    penalty[-1, -1] = 0.0  # the intercept is not penalised
    # centring the columns is what leaves the intercept unpenalised
    Hc = H[:, :-1] - H[:, :-1].mean(axis=0)
    W = np.linalg.solve(Hc.T @ Hc + penalty[:-1, :-1], Hc.T @ (Y - Y.mean(axis=0)))
    b = Y.mean(axis=0) - H[:, :-1].mean(axis=0) @ W
    assert_allclose(imputer.coef_[0], W[:6].T, atol=1e-10)
    assert_allclose(imputer.coef_[1], W[6:].T, atol=1e-10)
    assert_allclose(imputer.intercept_, b, atol=1e-10)
    residual = Y - H[:, :-1] @ W - b
    expected_cov = residual.T @ residual / len(rows) + 1e-6 * np.eye(6)
    assert_allclose(imputer.covariance_, expected_cov, atol=1e-10)


def test_recovers_a_gaussian_ar():
    X, (A1, A2), intercept, noise_cov = gaussian_ar(n_frames=20000)
    imputer = AutoregressiveImputer(order=2, alpha=0.0).fit(X)
    assert_allclose(imputer.coef_[0], A1, atol=0.03)
    assert_allclose(imputer.coef_[1], A2, atol=0.03)
    assert_allclose(imputer.covariance_, noise_cov, atol=0.02)


def test_fill_is_the_online_conditional_mean():
    X, _, _, _ = gaussian_ar(n_frames=300, seed=1)
    imputer = AutoregressiveImputer(order=2, alpha=0.5).fit(X[:250])
    test = X[250:].copy()
    mask = np.zeros(test.shape, dtype=bool)
    mask[20:, [0, 2]] = True
    mask[35, :] = True  # a wholly missing frame
    filled = imputer.transform(np.where(mask, np.nan, test))

    # written out: frame by frame, the past is the already filled frames
    A1, A2 = imputer.coef_
    S = imputer.covariance_
    expected = np.where(mask, np.nan, test)
    for t in range(2, len(test)):
        m = mask[t]
        if not m.any():
            continue
        mu = imputer.intercept_ + A1 @ expected[t - 1] + A2 @ expected[t - 2]
        o = ~m
        gain = S[np.ix_(m, o)] @ np.linalg.inv(S[np.ix_(o, o)]) if o.any() else 0
        expected[t, m] = mu[m] + (gain @ (test[t, o] - mu[o]) if o.any() else 0)
    assert_allclose(filled, expected, atol=1e-10)
    assert_array_equal(filled[~mask], test[~mask])


def test_diagonal_covariance_fills_from_the_past_alone():
    X, _, _, _ = gaussian_ar(n_frames=300, seed=2)
    imputer = AutoregressiveImputer(order=2, covariance_type="diag").fit(X[:250])
    assert_array_equal(imputer.covariance_, np.diag(np.diag(imputer.covariance_)))
    test = X[250:].copy()
    test[10:, 1] = np.nan
    filled = imputer.transform(test)
    for t in range(10, len(test)):
        mu = imputer.intercept_ + sum(
            imputer.coef_[q - 1] @ filled[t - q] for q in (1, 2)
        )
        assert filled[t, 1] == pytest.approx(mu[1], abs=1e-10)


def test_first_frame_and_edge_padding():
    X, ids = make_oscillations(n_sequences=4, n_frames=40, random_state=1)
    imputer = AutoregressiveImputer(order=3).fit(X, sequence_ids=ids)
    test = X[ids == 0].copy()
    test[0, :3] = np.nan
    test[1, 3:] = np.nan
    filled = imputer.transform(test)
    # frame 0: the Gaussian of all training frames
    S, mean = imputer.frame_covariance_, imputer.mean_
    o, m = np.arange(3, 6), np.arange(3)
    expected0 = mean[m] + S[np.ix_(m, o)] @ np.linalg.solve(
        S[np.ix_(o, o)], test[0, o] - mean[o]
    )
    assert_allclose(filled[0, :3], expected0, atol=1e-10)
    # frame 1: its past is frame 0, repeated for the lags before the start
    mu = imputer.intercept_ + sum(imputer.coef_[q] @ filled[0] for q in range(3))
    S = imputer.covariance_
    expected1 = mu[o] + S[np.ix_(o, m)] @ np.linalg.solve(
        S[np.ix_(m, m)], test[1, m] - mu[m]
    )
    assert_allclose(filled[1, 3:], expected1, atol=1e-10)


def test_sequences_do_not_share_a_past():
    X, ids = make_oscillations(n_sequences=4, n_frames=40, random_state=2)
    imputer = AutoregressiveImputer().fit(X, sequence_ids=ids)
    X_missing = X.copy()
    X_missing[ids >= 2] = np.where(np.arange(6) < 2, np.nan, X[ids >= 2])
    together = imputer.transform(X_missing, sequence_ids=ids)
    apart = [imputer.transform(X_missing[ids == k]) for k in range(4)]
    assert_allclose(together, np.concatenate(apart))


def test_order_zero_is_a_gaussian_conditional():
    X, _ = make_oscillations(n_sequences=2, n_frames=50, random_state=3)
    imputer = AutoregressiveImputer(order=0).fit(X)
    assert imputer.coef_.shape == (0, 6, 6)
    assert_allclose(imputer.covariance_, imputer.frame_covariance_)
    test = X[:5].copy()
    test[:, 0] = np.nan
    S, mean = imputer.frame_covariance_, imputer.mean_
    gain = S[0, 1:] @ np.linalg.inv(S[1:, 1:])
    assert_allclose(
        imputer.transform(test)[:, 0], mean[0] + (X[:5, 1:] - mean[1:]) @ gain
    )


def test_too_short_sequences_raise():
    X = np.zeros((6, 2))
    with pytest.raises(ValueError, match="lower order"):
        AutoregressiveImputer(order=3).fit(X, sequence_ids=[0, 0, 0, 1, 1, 1])
