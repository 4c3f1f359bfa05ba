"""CRBMImputer's offset correction (``offset_shrinkage``) and observation gain
(``observation_gain``), against a loop written out."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.frozen import FrozenEstimator
from sklearn.utils._param_validation import InvalidParameterError

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.impute import CRBMImputer


@pytest.fixture(scope="module")
def data():
    X, ids = make_oscillations(n_sequences=5, n_frames=40, n_features=3, random_state=0)
    return X, ids


@pytest.fixture(scope="module")
def model(data):
    X, ids = data
    return ConditionalRBM(4, order=2, n_iter=20, random_state=0).fit(
        X, sequence_ids=ids
    )


def _sigmoid(a):
    return 1 / (1 + np.exp(-a))


def reference_fill(model, X_missing, shrinkage, gain=1.0):
    """The corrected on-line fill with ``n_gibbs=0`` and one chain, written out.

    Frame ``t`` (past ``x[t-1], x[t-2]``, the fills where missing): dynamic
    biases ``b = b0 + sum_q A_q x[t-q]`` and ``c = c0 + sum_q B_q x[t-q]``;
    prediction ``v <- b + W^T sigmoid(c + W v)`` ten times from ``v = b``;
    the residual ``x_t - v`` of each observed channel is summed (frames from
    the order on).  A missing channel starts at its previous value, an
    observed one at ``v + gain * (x_t - v)``; the missing channels get one
    mean-field step ``b + W^T sigmoid(c + W start)``, plus ``sum / (n +
    shrinkage)`` unless ``shrinkage`` is None.  The first frames must be
    complete.
    """
    W = model.components_
    A = model.autoregressive_
    B = model.past_to_hidden_
    b0, c0 = model.intercept_visible_, model.intercept_hidden_
    x = X_missing.copy()
    missing = np.isnan(X_missing)
    sums = np.zeros(x.shape[1])
    counts = np.zeros(x.shape[1])
    for t in range(2, len(x)):
        b = b0 + sum(A[q] @ x[t - 1 - q] for q in range(2))
        c = c0 + sum(B[q] @ x[t - 1 - q] for q in range(2))
        v = b.copy()
        for _ in range(10):
            v = b + W.T @ _sigmoid(c + W @ v)
        seen = ~missing[t]
        sums[seen] += x[t, seen] - v[seen]
        counts[seen] += 1
        if missing[t].any():
            start = np.where(missing[t], x[t - 1], v + gain * (x[t] - v))
            fill = b + W.T @ _sigmoid(c + W @ start)
            if shrinkage is not None:
                fill += sums / np.maximum(counts + shrinkage, 1)
            x[t] = np.where(missing[t], fill, x[t])
    return x


def test_matches_the_loop_written_out(model, data):
    X, ids = data
    X_missing = X[ids == 0].copy()
    X_missing[8:, 1] = np.nan
    X_missing[12:16, 2] = np.nan  # a gap: its residuals resume after it
    imputer = CRBMImputer(
        FrozenEstimator(model),
        n_gibbs=0,
        n_particles=1,
        offset_shrinkage=2.5,
        observation_gain=1.0,
    ).fit(X)
    expected = reference_fill(model, X_missing, 2.5)
    assert_allclose(imputer.transform(X_missing), expected, rtol=1e-10, atol=1e-12)
    # and the correction does something: without it the fills differ
    plain = imputer.set_params(offset_shrinkage=None).transform(X_missing)
    assert np.abs(plain - expected)[8:, 1].max() > 1e-3


def residual_variance(model, X, ids):
    """Variance of ``X - predict_next(X)`` over frames with ``order`` past frames."""
    residuals = X - model.predict_next(X, sequence_ids=ids)
    index = np.arange(len(ids))
    first = np.r_[True, ids[1:] != ids[:-1]]
    position = index - np.maximum.accumulate(np.where(first, index, 0))
    return np.var(residuals[position >= model.order], axis=0)


def test_residual_variance_is_that_of_the_one_step_residuals(model, data):
    X, ids = data
    imputer = CRBMImputer(FrozenEstimator(model)).fit(X, sequence_ids=ids)
    expected = residual_variance(model, X, ids)
    assert_allclose(imputer.residual_variance_, expected, rtol=1e-10)
    # a gap splits a sequence: frames right after it have no full past
    X_gap = X.copy()
    X_gap[10, 0] = np.nan
    imputer.fit(X_gap, sequence_ids=ids)
    runs = ids + (np.arange(len(ids)) > 10) * (ids == 0) * 100
    keep = ~np.isnan(X_gap).any(axis=1)
    assert_allclose(
        imputer.residual_variance_,
        residual_variance(model, X_gap[keep], runs[keep]),
        rtol=1e-10,
    )


def channel_gains(model, X, ids, gain):
    """``observation_weighting="residual"``: ``1 + (g - 1) min(m / v_j, 3)``."""
    variance = residual_variance(model, X, ids)
    weights = np.minimum(np.median(variance) / variance, 3)
    return np.maximum(1 + (gain - 1) * weights, 0)


@pytest.mark.parametrize("shrinkage", [None, 2.5])
@pytest.mark.parametrize("gain", [0.0, 3.0])
@pytest.mark.parametrize("weighting", ["uniform", "residual"])
def test_observation_gain_matches_the_loop_written_out(
    model, data, shrinkage, gain, weighting
):
    X, ids = data
    X_missing = X[ids == 2].copy()
    X_missing[10:, 0] = np.nan
    X_missing[14:20, 2] = np.nan
    imputer = CRBMImputer(
        FrozenEstimator(model),
        n_gibbs=0,
        n_particles=1,
        offset_shrinkage=shrinkage,
        observation_gain=gain,
        observation_weighting=weighting,
    ).fit(X, sequence_ids=ids)
    gains = gain if weighting == "uniform" else channel_gains(model, X, ids, gain)
    if weighting == "residual" and gain > 1:
        assert np.ptp(gains) > 0.1  # the channels do get different gains
    expected = reference_fill(model, X_missing, shrinkage, gains)
    filled = imputer.transform(X_missing)
    assert_allclose(filled, expected, rtol=1e-10, atol=1e-12)
    observed = ~np.isnan(X_missing)
    assert_array_equal(filled[observed], X_missing[observed])
    # the gain does something: with 1 the fills differ
    plain = imputer.set_params(observation_gain=1.0).transform(X_missing)
    assert_allclose(plain, reference_fill(model, X_missing, shrinkage), rtol=1e-10)
    assert np.abs(plain - expected)[10:, 0].max() > 1e-6  # a weak model: small


def test_gain_zero_ignores_the_frame_s_observed_values(model, data):
    """With gain 0 the hidden units see the prediction, not the observation."""
    X, ids = data
    X_missing = X[ids == 3].copy()
    X_missing[20:, 0] = np.nan
    X_moved = X_missing.copy()
    X_moved[25, 1:] += 2.0  # the observed channels of frame 25 only
    imputer = CRBMImputer(
        FrozenEstimator(model),
        n_particles=4,
        offset_shrinkage=None,
        observation_gain=0.0,
        observation_weighting="uniform",
        random_state=0,
    ).fit(X)
    filled, moved = imputer.transform(X_missing), imputer.transform(X_moved)
    assert_array_equal(moved[:26, 0], filled[:26, 0])
    assert np.abs(moved[26:, 0] - filled[26:, 0]).max() > 1e-3  # the past moved
    # with gain 1 they are seen
    imputer.set_params(observation_gain=1.0)
    assert imputer.transform(X_moved)[25, 0] != imputer.transform(X_missing)[25, 0]


def test_infinite_shrinkage_is_no_correction(model, data):
    X, ids = data
    X_missing = X[ids < 2].copy()
    X_missing[20:, :2] = np.nan
    imputer = CRBMImputer(
        FrozenEstimator(model), n_gibbs=5, n_particles=3, random_state=0
    )
    imputer.fit(X)
    plain = imputer.set_params(offset_shrinkage=None).transform(
        X_missing, sequence_ids=ids[ids < 2]
    )
    huge = imputer.set_params(offset_shrinkage=1e12).transform(
        X_missing, sequence_ids=ids[ids < 2]
    )
    assert_allclose(huge, plain, atol=1e-9)


def test_keeps_a_shifted_channel_where_the_model_would_pull_it_back(model, data):
    """A channel offset from every training sequence stays offset when lost."""
    X, ids = data
    X_test = X[ids == 4] + np.array([1.5, 0.0, 0.0])
    X_missing = X_test.copy()
    X_missing[20:, 0] = np.nan
    errors = {}
    for shrinkage in (None, 5.0):
        imputer = CRBMImputer(
            FrozenEstimator(model), offset_shrinkage=shrinkage, random_state=0
        ).fit(X)
        filled = imputer.transform(X_missing)
        errors[shrinkage] = np.mean((filled - X_test)[20:, 0] ** 2)
        # reproducible for a random_state
        assert_array_equal(imputer.transform(X_missing), filled)
    assert errors[5.0] < 0.5 * errors[None]


def test_complete_frames_and_observed_values_are_untouched(model, data):
    X, ids = data
    X_missing = X[ids == 1].copy()
    X_missing[15:, 2] = np.nan
    filled = (
        CRBMImputer(FrozenEstimator(model), random_state=0).fit(X).transform(X_missing)
    )
    observed = ~np.isnan(X_missing)
    assert_array_equal(filled[observed], X_missing[observed])
    assert np.isfinite(filled).all()


@pytest.mark.parametrize(
    "name, value",
    [
        ("offset_shrinkage", -1),
        ("observation_gain", -1),
        ("observation_weighting", "variance"),
    ],
)
def test_bad_inference_parameters_are_rejected(data, name, value):
    X, _ = data
    imputer = CRBMImputer(ConditionalRBM(3, n_iter=1), **{name: value})
    with pytest.raises(InvalidParameterError, match=name):
        imputer.fit(X)


def test_binary_fills_stay_probabilities():
    """A channel on throughout, where the model expects it half the time."""
    X, ids = make_oscillations(n_sequences=5, n_frames=60, n_features=4, random_state=0)
    B = (X > 0).astype(float)
    model = ConditionalRBM(8, order=2, n_iter=30, visible_type="binary", random_state=0)
    imputer = CRBMImputer(model, offset_shrinkage=0.0, random_state=0)
    imputer.fit(B[ids < 4], sequence_ids=ids[ids < 4])
    X_missing = B[ids == 4].copy()
    X_missing[:, 0] = 1.0
    X_missing[30:, 0] = np.nan
    filled = imputer.transform(X_missing)
    assert filled[30:, 0].max() == 1.0  # the correction reaches the bound ...
    assert (filled >= 0).all() and (filled <= 1).all()  # ... and stops there
