"""CRBMImputer: on-line, clamped, reproducible fills that never leave a NaN."""

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.exceptions import NotFittedError
from sklearn.frozen import FrozenEstimator
from sklearn.pipeline import make_pipeline

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer


def circles(n_sequences, n_frames, seed):
    """A point going round a circle at a random speed: sin and cos channels.

    Given the sine alone a frame is ambiguous (rising or falling), so nearest
    neighbour guesses the cosine's sign; the past resolves it.
    """
    rng = np.random.default_rng(seed)
    blocks = []
    for _ in range(n_sequences):
        omega = 2 * np.pi / rng.uniform(14, 22)
        phase = omega * np.arange(n_frames) + rng.uniform(0, 2 * np.pi)
        blocks.append(np.sqrt(2) * np.c_[np.sin(phase), np.cos(phase)])
    X = np.concatenate(blocks) + 0.05 * rng.standard_normal((n_sequences * n_frames, 2))
    return X, np.repeat(np.arange(n_sequences), n_frames)


@pytest.fixture(scope="module")
def fitted():
    X, ids = make_oscillations(n_sequences=6, n_frames=40, n_features=5, random_state=0)
    model = ConditionalRBM(n_components=12, order=2, n_iter=20, random_state=0)
    imputer = CRBMImputer(model, n_gibbs=5, random_state=0)
    return imputer.fit(X, sequence_ids=ids)


@pytest.fixture(scope="module")
def test_data():
    X, ids = make_oscillations(n_sequences=3, n_frames=30, n_features=5, random_state=1)
    return X, ids


def patterns(n_frames, n_features, seed=0):
    """Missingness patterns: first frames, whole frames, whole sequences, random."""
    rng = np.random.default_rng(seed)
    yield (
        "tail",
        np.add.outer(np.arange(n_frames) >= n_frames // 2, np.zeros(n_features)) > 0,
    )
    first = np.zeros((n_frames, n_features), dtype=bool)
    first[[0, 1, 30, 31, 60], :2] = True
    yield "first frames", first
    whole = np.zeros((n_frames, n_features), dtype=bool)
    whole[[0, 5, 6, 7, 30, 89]] = True
    yield "whole frames", whole
    everything = np.ones((n_frames, n_features), dtype=bool)
    yield "everything", everything
    yield "random", rng.random((n_frames, n_features)) < 0.5


@pytest.mark.parametrize("n_particles", [1, 3])
def test_no_nan_left_and_observed_values_untouched(fitted, test_data, n_particles):
    X, ids = test_data
    imputer = fitted.set_params(n_particles=n_particles, n_draws=2)
    for name, mask in patterns(*X.shape):
        X_missing = np.where(mask, np.nan, X)
        filled = imputer.transform(X_missing, sequence_ids=ids)
        assert np.isfinite(filled).all(), name
        assert_array_equal(filled[~mask], X[~mask], err_msg=name)
        draws = imputer.sample(X_missing, n_samples=2, sequence_ids=ids)
        assert draws.shape == (2, *X.shape)
        assert np.isfinite(draws).all(), name
        assert_array_equal(
            draws[:, ~mask], np.broadcast_to(X[~mask], (2, (~mask).sum()))
        )
    fitted.set_params(n_particles=1, n_draws=1)


def test_complete_input_comes_back_unchanged(fitted, test_data):
    X, ids = test_data
    assert_array_equal(fitted.transform(X, sequence_ids=ids), X)


@pytest.mark.parametrize("n_particles", [1, 4])
def test_online_fill_ignores_later_frames(fitted, test_data, n_particles):
    X, ids = test_data
    imputer = fitted.set_params(n_particles=n_particles, n_draws=3)
    mask = np.zeros(X.shape, dtype=bool)
    mask[10:, 1:3] = True
    mask[40:, :] = True
    X_missing = np.where(mask, np.nan, X)
    reference = imputer.transform(X_missing, sequence_ids=ids)
    t = 20  # frames up to t of sequence 0 must not depend on anything after
    changed = X_missing.copy()
    changed[t + 1 : 30] = np.random.default_rng(0).normal(size=(29 - t, X.shape[1])) * 5
    changed[t + 1 : 30, 0] = np.nan  # a different missingness later, too
    filled = imputer.transform(changed, sequence_ids=ids)
    assert_array_equal(filled[: t + 1], reference[: t + 1])
    assert not np.array_equal(filled[t + 1 : 30], reference[t + 1 : 30])
    fitted.set_params(n_particles=1, n_draws=1)


def test_n_draws_averages_single_draws(fitted, test_data):
    X, ids = test_data
    X_missing = X.copy()
    X_missing[15:, 2:] = np.nan
    draws = fitted.sample(X_missing, n_samples=4, sequence_ids=ids, random_state=3)
    averaged = fitted.set_params(n_draws=4, random_state=3).transform(
        X_missing, sequence_ids=ids
    )
    fitted.set_params(n_draws=1, random_state=0)
    assert_allclose(averaged, draws.mean(axis=0), rtol=1e-6, atol=1e-6)
    assert not np.allclose(draws[0], draws[1])  # the draws do differ


def test_random_state_makes_fills_reproducible(fitted, test_data):
    X, ids = test_data
    X_missing = X.copy()
    X_missing[10:, :2] = np.nan
    first = fitted.transform(X_missing, sequence_ids=ids)
    assert_array_equal(fitted.transform(X_missing, sequence_ids=ids), first)
    other = fitted.sample(X_missing, sequence_ids=ids, random_state=1)[0]
    assert not np.array_equal(other, first)
    assert_array_equal(
        fitted.sample(X_missing, sequence_ids=ids, random_state=1)[0], other
    )


def test_sequences_are_filled_independently(fitted, test_data):
    """Sequence ids matter: the past never crosses into another sequence."""
    X, ids = test_data
    X_missing = X.copy()
    X_missing[30:33, :] = np.nan  # the start of sequence 1
    filled = fitted.transform(X_missing, sequence_ids=ids)
    alone = fitted.transform(X_missing[30:60])
    assert np.isfinite(filled).all()
    # Each draw's chains advance in lockstep with the other sequences, so the
    # random numbers differ, but the start frames follow the training mean.
    assert_array_equal(filled[:30], X[:30])
    assert np.isfinite(alone).all()


def test_beats_nearest_neighbour_when_the_past_matters():
    X, ids = circles(8, 60, seed=0)
    X_test, test_ids = circles(3, 60, seed=1)
    X_missing = X_test.copy()
    X_missing[np.arange(len(X_test)) % 60 >= 30, 1] = np.nan
    mask = np.isnan(X_missing)
    model = ConditionalRBM(n_components=16, order=2, n_iter=60, random_state=0)
    crbm = CRBMImputer(model, n_draws=5, random_state=0).fit(X, sequence_ids=ids)
    nearest = NearestNeighborImputer().fit(X)
    crbm_error = np.mean(
        (crbm.transform(X_missing, sequence_ids=test_ids) - X_test)[mask] ** 2
    )
    nn_error = np.mean((nearest.transform(X_missing) - X_test)[mask] ** 2)
    assert crbm_error < 0.2 * nn_error


def test_particles_are_weighted_by_the_observed_channels():
    """With particles, draws that contradict the observed channels die out."""
    X, ids = circles(8, 60, seed=0)
    X_test, test_ids = circles(2, 60, seed=1)
    X_missing = X_test.copy()
    X_missing[20:60, 1] = np.nan
    X_missing[80:, 1] = np.nan
    mask = np.isnan(X_missing)
    model = ConditionalRBM(n_components=16, order=2, n_iter=60, random_state=0)
    imputer = CRBMImputer(model, n_gibbs=10, random_state=0).fit(X, sequence_ids=ids)
    errors = {}
    for n_particles in (1, 10):
        draws = imputer.set_params(n_particles=n_particles).sample(
            X_missing, n_samples=5, sequence_ids=test_ids
        )
        errors[n_particles] = np.mean((draws - X_test)[:, mask] ** 2)
        assert np.isfinite(draws).all()
    assert errors[10] <= errors[1] * 1.1


def test_other_missing_value_marker(fitted, test_data):
    X, ids = test_data
    mask = np.zeros(X.shape, dtype=bool)
    mask[12:, 3] = True
    with_nan = fitted.transform(np.where(mask, np.nan, X), sequence_ids=ids)
    marker = fitted.set_params(missing_values=-1e6)
    with_marker = marker.transform(np.where(mask, -1e6, X), sequence_ids=ids)
    fitted.set_params(missing_values=np.nan)
    assert_array_equal(with_marker, with_nan)


def test_fit_learns_from_complete_runs_only():
    X, ids = make_oscillations(n_sequences=3, n_frames=40, n_features=4, random_state=0)
    X_gappy = X.copy()
    X_gappy[[5, 50, 51], 1] = np.nan
    model = ConditionalRBM(n_components=8, order=2, n_iter=3, random_state=0)
    imputer = CRBMImputer(model).fit(X_gappy, sequence_ids=ids)
    complete = ~np.isnan(X_gappy).any(axis=1)
    assert_allclose(imputer.mean_, X[complete].mean(axis=0))
    # the runs, not the sequences: frames 5, 50 and 51 split them
    expected = CRBMImputer(model).fit(
        X[complete],
        sequence_ids=np.repeat(np.arange(5), [5, 34, 10, 28, 40]),
    )
    assert_array_equal(imputer.estimator_.components_, expected.estimator_.components_)
    with pytest.raises(ValueError, match="every frame"):
        CRBMImputer(model).fit(np.full((5, 2), np.nan))


def test_default_estimator_is_a_conditional_rbm():
    X, ids = make_oscillations(n_sequences=2, n_frames=20, n_features=3, random_state=0)
    imputer = CRBMImputer(n_gibbs=2).fit(X[:, :3], sequence_ids=ids)
    assert type(imputer.estimator_) is ConditionalRBM
    assert imputer.estimator is None


def test_default_estimator_is_seeded_from_random_state():
    X, ids = make_oscillations(n_sequences=2, n_frames=20, n_features=3, random_state=0)
    X_missing = X.copy()
    X_missing[25:, 1] = np.nan
    fits = [
        CRBMImputer(n_gibbs=2, random_state=seed).fit(X, sequence_ids=ids)
        for seed in (0, 0, 1)
    ]
    assert isinstance(fits[0].estimator_.random_state, int)
    assert_array_equal(fits[0].estimator_.components_, fits[1].estimator_.components_)
    assert not np.array_equal(
        fits[0].estimator_.components_, fits[2].estimator_.components_
    )
    assert_array_equal(
        fits[0].transform(X_missing, sequence_ids=ids),
        fits[1].transform(X_missing, sequence_ids=ids),
    )
    unseeded = CRBMImputer(n_gibbs=2).fit(X, sequence_ids=ids)
    assert unseeded.estimator_.random_state is None


def test_frozen_fitted_model_is_used_without_training(test_data):
    X, ids = make_oscillations(n_sequences=6, n_frames=40, n_features=5, random_state=0)
    params = dict(n_components=12, order=2, n_iter=20, random_state=0)
    model = ConditionalRBM(**params).fit(X, sequence_ids=ids)
    weights = model.components_.copy()
    # fit data the model has never seen: training on it would change the weights
    X_other, ids_other = make_oscillations(
        n_sequences=2, n_frames=30, n_features=5, random_state=7
    )
    frozen = CRBMImputer(FrozenEstimator(model), n_gibbs=5, random_state=0)
    frozen.fit(X_other, sequence_ids=ids_other)
    assert frozen.estimator_ is model
    assert model.n_iter_ == 20
    assert_array_equal(model.components_, weights)
    # fills as an imputer that trained the same model on the same data
    frozen.fit(X, sequence_ids=ids)  # mean_ (where first frames start) from X
    trained = CRBMImputer(ConditionalRBM(**params), n_gibbs=5, random_state=0)
    trained.fit(X, sequence_ids=ids)
    X_test, test_ids = test_data
    X_missing = X_test.copy()
    X_missing[10:, :2] = np.nan
    assert_array_equal(
        frozen.transform(X_missing, sequence_ids=test_ids),
        trained.transform(X_missing, sequence_ids=test_ids),
    )


def test_frozen_model_must_be_fitted_on_the_same_features():
    X, ids = make_oscillations(n_sequences=2, n_frames=20, n_features=3, random_state=0)
    unfitted = FrozenEstimator(ConditionalRBM(4, order=2))
    with pytest.raises(NotFittedError, match="unfitted model: fit the model first"):
        CRBMImputer(unfitted).fit(X, sequence_ids=ids)
    model = ConditionalRBM(4, order=2, n_iter=2, random_state=0).fit(X[:, :2])
    with pytest.raises(ValueError, match="fitted on 2 features but X has 3"):
        CRBMImputer(FrozenEstimator(model)).fit(X, sequence_ids=ids)


def test_verbose_reports_training(capsys):
    X, ids = make_oscillations(n_sequences=2, n_frames=20, n_features=3, random_state=0)
    model = ConditionalRBM(4, order=2, n_iter=4, random_state=0)
    CRBMImputer(model, verbose=2).fit(X, sequence_ids=ids)
    lines = capsys.readouterr().out.splitlines()
    assert lines[0].startswith("[CRBMImputer] training ConditionalRBM(")
    assert lines[0].endswith("on 40 complete frames in 2 sequences")
    assert lines[1].startswith("[ConditionalRBM] one-step error: RMS error")
    assert [line.split(":")[0] for line in lines[2:]] == [
        "[ConditionalRBM] epoch 2",
        "[ConditionalRBM] epoch 4",
    ]
    assert model.verbose == 0  # the clone was told, not the user's model
    CRBMImputer(model).fit(X, sequence_ids=ids)
    assert capsys.readouterr().out == ""


def test_metadata_routing_passes_sequence_ids(monkeypatch):
    X, ids = make_oscillations(n_sequences=3, n_frames=20, n_features=3, random_state=0)
    seen = []
    original = CRBMImputer.transform

    def spy(self, X, *, sequence_ids=None):
        seen.append(sequence_ids)
        return original(self, X, sequence_ids=sequence_ids)

    monkeypatch.setattr(CRBMImputer, "transform", spy)
    model = ConditionalRBM(n_components=4, order=2, n_iter=2, random_state=0)
    with sklearn.config_context(enable_metadata_routing=True):
        pipe = make_pipeline(CRBMImputer(model, n_gibbs=2, random_state=0))
        pipe.fit_transform(X, sequence_ids=ids)
        X_missing = X.copy()
        X_missing[5:, 0] = np.nan
        pipe.transform(X_missing, sequence_ids=ids)
    assert len(seen) == 2
    assert all(s is not None and np.array_equal(s, ids) for s in seen)


def test_sample_rejects_bad_counts(fitted, test_data):
    X, _ = test_data
    for bad in (0, 1.5, True):
        with pytest.raises(ValueError, match="n_samples"):
            fitted.sample(X, n_samples=bad)


@pytest.mark.parametrize("n_particles", [1, 3])
def test_stacked_estimator(test_data, n_particles):
    from sklearn_crbm.models._stacked import StackedCRBM

    X_train, ids = make_oscillations(
        n_sequences=4, n_frames=30, n_features=5, random_state=0
    )
    stack = StackedCRBM((8, 6), order=2, n_iter=5, random_state=0)
    imputer = CRBMImputer(stack, n_gibbs=4, n_particles=n_particles, random_state=0)
    imputer.fit(X_train, sequence_ids=ids)
    assert [layer.n_components for layer in imputer.estimator_.layers_] == [8, 6]
    X, test_ids = test_data
    for name, mask in patterns(*X.shape):
        filled = imputer.transform(np.where(mask, np.nan, X), sequence_ids=test_ids)
        assert np.isfinite(filled).all(), name
        assert_array_equal(filled[~mask], X[~mask], err_msg=name)
    mask = np.zeros(X.shape, dtype=bool)
    mask[10:, :2] = True
    X_missing = np.where(mask, np.nan, X)
    reference = imputer.transform(X_missing, sequence_ids=test_ids)
    changed = X_missing.copy()
    changed[21:30] += 3.0
    filled = imputer.transform(changed, sequence_ids=test_ids)
    assert_array_equal(filled[:21], reference[:21])


def test_observed_log_likelihood_hand_computed():
    from sklearn_crbm._engines._gibbs import observed_log_likelihood
    from sklearn_crbm.layers._crbm import CRBMLayer

    def frame_rbms(n_features, visible_type, n_frames):
        layer = CRBMLayer(n_features, 2, 1, 1, visible_type, np.float64)
        return layer.initialize(rng).frame_rbms(np.zeros((n_frames, n_features)))

    rng = np.random.default_rng(0)
    gaussian = frame_rbms(3, "gaussian", 2)
    prediction = np.array([[0.0, 1.0, 2.0], [1.0, 1.0, 1.0]])
    visible = np.array([[1.0, 1.0, 99.0], [1.0, 3.0, 0.0]])
    observed = np.array([[True, True, False], [True, True, True]])
    assert_allclose(
        observed_log_likelihood(gaussian, prediction, visible, observed),
        [-0.5 * 1.0, -0.5 * (0.0 + 4.0 + 1.0)],
    )
    binary = frame_rbms(2, "binary", 1)
    prediction = np.array([[0.8, 0.25]])
    assert_allclose(
        observed_log_likelihood(
            binary, prediction, np.array([[1.0, 0.0]]), observed[:1, :2]
        ),
        [np.log(0.8) + np.log(0.75)],
    )


def test_stacked_gibbs_with_one_layer_is_gibbs_frames():
    from sklearn_crbm._engines._gibbs import gibbs_frames, stacked_gibbs_frames
    from sklearn_crbm.layers._crbm import CRBMLayer

    rng = np.random.default_rng(0)
    params = CRBMLayer(4, 5, 2, 2, "gaussian", np.float64).initialize(rng)
    params.weights *= 50
    history = rng.normal(size=(6, 8))
    start = rng.normal(size=(6, 4))
    observed = rng.random((6, 4)) < 0.5
    rbms = params.frame_rbms(history)
    expected = gibbs_frames(
        rbms, start, 5, np.random.default_rng(1), observed_mask=observed
    )
    got = stacked_gibbs_frames(
        [rbms], start, 5, np.random.default_rng(1), observed_mask=observed
    )
    assert_array_equal(got, expected)
    assert_array_equal(got[observed], start[observed])
