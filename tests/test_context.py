"""A real-valued per-frame ``context`` on every method of every model.

``ConditionalRBM`` adds ``L y_t`` to its dynamic biases; the checks below
are the estimator checks of ``test_common.py`` that a context changes
(fit and refit, dtypes, partial_fit, clone and pickle, routing through a
Pipeline and a search), the exact math of the additive context, and the
errors of a context of the wrong kind.
"""

import pickle
import warnings

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from scipy.special import logit
from sklearn.base import clone
from sklearn.model_selection import GridSearchCV, GroupKFold
from sklearn.pipeline import make_pipeline

from sklearn_crbm import (
    ConditionalRBM,
    CRBMImputer,
    FactoredCRBM,
    LabelledCRBM,
    StackedCRBM,
    StandardScaler,
)
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.exceptions import GenerationWarning


def driven_data(random_state=0, n_sequences=6):
    """Oscillations whose level follows a per-sequence control signal."""
    X, ids = make_oscillations(
        n_sequences=n_sequences, n_frames=60, n_features=4, random_state=random_state
    )
    level = np.where(ids % 2 == 0, 1.0, -1.0)[:, None]
    context = np.hstack([level, np.linspace(-1, 1, len(X))[:, None]])
    X = X.copy()
    X[:, 0] += 1.5 * level[:, 0]
    return X, ids, context


def small_model(**params):
    return ConditionalRBM(
        **{"n_components": 8, "order": 2, "n_iter": 30, "random_state": 0, **params}
    )


@pytest.fixture(scope="module")
def fitted():
    X, ids, context = driven_data()
    return small_model(n_iter=200).fit(X, sequence_ids=ids, context=context)


def test_the_context_adds_to_the_dynamic_biases(fitted):
    X, ids, context = driven_data(random_state=1)
    model = clone(fitted).fit(X, sequence_ids=ids, context=context)
    assert model.n_context_ == 2
    assert model.context_to_visible_.shape == (4, 2)
    assert model.context_to_hidden_.shape == (8, 2)
    rng = np.random.default_rng(0)
    L_h = rng.standard_normal((8, 2))
    model.context_to_hidden_ = np.zeros((8, 2))
    before = model.transform(X, sequence_ids=ids, context=context)
    model.context_to_hidden_ = L_h
    after = model.transform(X, sequence_ids=ids, context=context)
    # the model standardises the context it is given
    z = (context - model.context_mean_) / model.context_scale_
    assert_allclose(z.mean(axis=0), 0, atol=1e-12)
    assert_allclose(logit(after) - logit(before), z @ L_h.T, atol=1e-8)
    # one step of prediction from the past alone, without hidden units:
    # the visible bias moves by L_v y
    model.components_ = np.zeros_like(model.components_)
    L_v = rng.standard_normal((4, 2))
    model.context_to_visible_ = np.zeros((4, 2))
    still = model.predict_next(X, sequence_ids=ids, context=context)
    model.context_to_visible_ = L_v
    moved = model.predict_next(X, sequence_ids=ids, context=context)
    assert_allclose(moved - still, z @ L_v.T, atol=1e-10)


def test_the_context_may_be_given_in_any_unit(fitted):
    """A control in other units (a speed in cm/s, not m/s) trains the same model."""
    X, ids, context = driven_data()
    rescaled = 100.0 * context + [5.0, -40.0]
    model = small_model(n_iter=200).fit(X, sequence_ids=ids, context=rescaled)
    assert_allclose(model.context_mean_, 100.0 * fitted.context_mean_ + [5, -40])
    assert_allclose(model.context_scale_, 100.0 * fitted.context_scale_)
    assert_allclose(model._layer.flat, fitted._layer.flat, rtol=1e-6, atol=1e-9)
    assert_allclose(
        model.score_samples(X, sequence_ids=ids, context=rescaled),
        fitted.score_samples(X, sequence_ids=ids, context=context),
        rtol=1e-6,
    )
    # a constant column is centred, not divided by zero
    constant = np.hstack([context, np.full((len(X), 1), 3.0)])
    model = small_model().fit(X, sequence_ids=ids, context=constant)
    assert model.context_scale_[2] == 1.0
    assert np.all(np.isfinite(model.transform(X, sequence_ids=ids, context=constant)))


def test_it_learns_what_the_context_says(fitted):
    X, ids, context = driven_data(random_state=2)
    flipped = context * [-1, 1]
    right = fitted.predict_next(X, sequence_ids=ids, context=context)
    wrong = fitted.predict_next(X, sequence_ids=ids, context=flipped)
    assert np.mean((X - right)[:, 0] ** 2) < 0.3 * np.mean((X - wrong)[:, 0] ** 2)
    assert fitted.score(X, sequence_ids=ids, context=context) > fitted.score(
        X, sequence_ids=ids, context=flipped
    )
    seed = X[ids == 0][:5]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GenerationWarning)
        high = fitted.sample(80, history=seed, context=[[1.0, 0.0]], random_state=0)
        low = fitted.sample(80, history=seed, context=[[-1.0, 0.0]], random_state=0)
    assert high[20:, 0].mean() - low[20:, 0].mean() > 2
    # a row per frame steers the motion over time
    ramp = np.linspace([-1.0, 0.0], [1.0, 0.0], 80)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GenerationWarning)
        steered = fitted.sample(80, history=seed, context=ramp, random_state=0)
    assert steered[-20:, 0].mean() - steered[5:25, 0].mean() > 1


def test_same_random_state_same_model_and_frames():
    X, ids, context = driven_data()
    one = small_model().fit(X, sequence_ids=ids, context=context)
    two = small_model().fit(X, sequence_ids=ids, context=context)
    assert_array_equal(one._layer.flat, two._layer.flat)
    assert_array_equal(
        one.sample(10, context=context[:1], n_sequences=2),
        two.sample(10, context=context[:1], n_sequences=2),
    )
    # refitting forgets the earlier fit
    assert_array_equal(
        one.fit(X, sequence_ids=ids, context=context)._layer.flat, two._layer.flat
    )
    assert one.fit(X, sequence_ids=ids).n_context_ == 0


@pytest.mark.parametrize("dtype", [np.float32, np.float64])
def test_every_method_keeps_the_dtype(dtype):
    X, ids, context = driven_data()
    model = small_model(n_iter=3).fit(
        X.astype(dtype), sequence_ids=ids, context=context
    )
    X = X.astype(dtype)
    given = dict(sequence_ids=ids, context=context)
    assert model.transform(X, **given).dtype == dtype
    assert model.predict_next(X, **given).dtype == dtype
    assert model.score_samples(X, **given).dtype == dtype
    assert model.sample(5, context=context[:5]).dtype == dtype
    assert_allclose(
        model.fit_transform(X, **given), model.transform(X, **given), rtol=1e-6
    )


def test_partial_fit_and_pickle_carry_the_context():
    X, ids, context = driven_data()
    model = small_model()
    for _ in range(3):
        model.partial_fit(X, sequence_ids=ids, context=context)
    assert model.n_iter_ == 3 and model.n_context_ == 2
    with pytest.raises(ValueError, match=r"shape \(n, 2\)"):
        model.partial_fit(X, sequence_ids=ids, context=context[:, :1])
    loaded = pickle.loads(pickle.dumps(model))
    assert_array_equal(
        loaded.score_samples(X, sequence_ids=ids, context=context),
        model.score_samples(X, sequence_ids=ids, context=context),
    )


def test_a_pipeline_and_a_search_route_the_context():
    X, ids, context = driven_data()
    with sklearn.config_context(enable_metadata_routing=True):
        pipe = make_pipeline(StandardScaler(), small_model(n_iter=5))
        pipe.fit(X, sequence_ids=ids, context=context)
        Z = pipe.transform(X, sequence_ids=ids, context=context)
        score = pipe.score(X, sequence_ids=ids, context=context)
        search = GridSearchCV(
            make_pipeline(StandardScaler(), small_model(n_iter=5)),
            {"conditionalrbm__n_components": [4, 8]},
            cv=GroupKFold(n_splits=3),
        ).fit(X, groups=ids, sequence_ids=ids, context=context)
    model = small_model(n_iter=5).fit(
        StandardScaler().fit_transform(X), sequence_ids=ids, context=context
    )
    scaled = pipe[0].transform(X)
    assert_allclose(Z, model.transform(scaled, sequence_ids=ids, context=context))
    assert score == model.score(scaled, sequence_ids=ids, context=context)
    assert search.best_estimator_[-1].n_context_ == 2
    with pytest.raises(ValueError, match="context reaches the steps of a pipeline"):
        from sklearn_crbm.preprocessing import MotionPipeline

        MotionPipeline([("model", small_model())]).fit(X, context=context)


@pytest.mark.parametrize(
    "make",
    [
        lambda: small_model(n_iter=3),
        lambda: StackedCRBM((6, 4), order=1, n_iter=3, random_state=0),
        lambda: LabelledCRBM(6, order=2, n_iter=3, random_state=0),
        lambda: FactoredCRBM(
            6, n_factors=4, n_style_features=3, order=2, n_iter=2, cd_steps=1
        ),
    ],
    ids=["crbm", "stack", "labelled", "factored"],
)
def test_every_model_takes_the_context_everywhere(make):
    X, ids, context = driven_data()
    model = make().fit(X, sequence_ids=ids, context=context)
    assert model.n_context_ == 2
    given = dict(sequence_ids=ids, context=context)
    flipped = dict(sequence_ids=ids, context=-context)
    for method in ("transform", "predict_next", "score_samples"):
        right = getattr(model, method)(X, **given)
        assert not np.array_equal(right, getattr(model, method)(X, **flipped))
    estimate = model.estimate_log_likelihood(X, **given)
    assert estimate.log_likelihood.shape == (len(X),)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", GenerationWarning)
        one = model.sample(10, context=context[:1], random_state=0)
        same = model.sample(10, context=np.repeat(context[:1], 10, 0), random_state=0)
        other = model.sample(10, context=-context[:1], random_state=0)
    assert_array_equal(one, same)
    assert not np.array_equal(one, other)
    X_missing = X.copy()
    X_missing[20:40, 0] = np.nan
    imputer = CRBMImputer(model, n_particles=2, random_state=0)
    imputer.fit(X, **given)
    filled = imputer.transform(X_missing, **given)
    assert not np.array_equal(filled, imputer.transform(X_missing, **flipped))
    assert imputer.sample(X_missing, 2, **given).shape == (2, *X.shape)


@pytest.mark.parametrize(
    "call, message",
    [
        (lambda m, X, c: m.transform(X), "fitted with a context of 2 columns"),
        (lambda m, X, c: m.sample(3), "fitted with a context of 2 columns"),
        (lambda m, X, c: m.score(X), "fitted with a context of 2 columns"),
        (
            lambda m, X, c: m.transform(X, context=c[:, :1]),
            r"shape \(n, 2\) with n = 360",
        ),
        (lambda m, X, c: m.transform(X, context=c[:-1]), r"got shape \(359, 2\)"),
        (lambda m, X, c: m.transform(X, context=c[:, 0]), r"reshape\(-1, 1\)"),
        (
            lambda m, X, c: m.sample(3, context=c[:2]),
            r"with n = 1 or 3: .* got shape \(2, 2\)",
        ),
        (lambda m, X, c: m.predict_next(X, context=c * np.nan), "NaN or infinity"),
        (lambda m, X, c: m.transform(X, style="fast"), "has no styles"),
    ],
)
def test_a_context_of_the_wrong_kind_says_what_to_give(fitted, call, message):
    X, _, context = driven_data()
    with pytest.raises(ValueError, match=message):
        call(fitted, X, context)


def test_errors_of_the_context_in_fit():
    X, ids, context = driven_data()
    with pytest.raises(TypeError, match="array of numbers"):
        small_model().fit(X, context=np.full(context.shape, "a"))
    with pytest.raises(ValueError, match="NaN or infinity"):
        small_model().fit(X, context=context * np.inf)
    plain = small_model(n_iter=2).fit(X, sequence_ids=ids)
    with pytest.raises(ValueError, match="fitted without context"):
        plain.transform(X, context=context)
    labels = np.where(ids % 2 == 0, "a", "b")
    with pytest.raises(ValueError, match="got both y and context="):
        LabelledCRBM(4, order=1, n_iter=2).fit(X, labels, context=context)
    model = LabelledCRBM(4, order=1, n_iter=2).fit(X, context=context)
    assert not hasattr(model, "classes_")
    with pytest.raises(ValueError, match="not on labels"):
        model.predict(X)
    with pytest.raises(ValueError, match="requires y to be passed"):
        LabelledCRBM(4, order=1, n_iter=2).fit(X)
