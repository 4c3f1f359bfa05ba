"""Tests of style models of several label factors (content and style, issue 47)."""

import copy
import pickle

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import clone
from sklearn.frozen import FrozenEstimator

from sklearn_crbm import CRBMImputer, FactoredCRBM, LabelledCRBM
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.models import _style
from sklearn_crbm.models._factored import balanced_frames

CONTENTS = ("run", "walk")
STYLES = ("a", "b", "c")


def two_factor_data(random_state=0, skip=None):
    """Oscillations whose column 0 tells the content (+1 run, -1 walk) and
    column 1 the style (-1, 0, +1), two sequences of every cell but ``skip``."""
    X, ids = make_oscillations(n_sequences=12, n_frames=60, random_state=random_state)
    rng = np.random.default_rng(random_state)
    cells = [(c, s) for c in CONTENTS for s in STYLES] * 2
    y = np.array([cells[i] for i in ids])
    X[:, 0] = np.where(y[:, 0] == "run", 1.0, -1.0)
    X[:, 1] = np.searchsorted(STYLES, y[:, 1]) - 1.0
    X[:, :2] += 0.1 * rng.standard_normal((len(X), 2))
    if skip is not None:
        keep = ~np.all(y == skip, axis=1)
        X, ids, y = X[keep], ids[keep], y[keep]
    return X, ids, y


def labelled(**params):
    # few hidden units: the likelihood is exact, no annealing
    defaults = dict(n_components=8, order=2, n_iter=100, learning_rate=1e-2)
    return LabelledCRBM(**{**defaults, "random_state": 0, **params})


def factored(**params):
    defaults = dict(n_components=8, n_factors=4, n_style_features=3, order=2)
    defaults.update(cd_steps=1, n_iter=3, n_gibbs=3, random_state=0)
    return FactoredCRBM(**{**defaults, **params})


@pytest.fixture(scope="module")
def fitted():
    """A LabelledCRBM of content and style, never shown a running 'c'."""
    X, ids, y = two_factor_data(skip=("run", "c"))
    return labelled().fit(X, y, sequence_ids=ids)


@pytest.mark.parametrize("make", [labelled, factored])
def test_fit_takes_a_column_per_factor(make):
    X, ids, y = two_factor_data()
    model = make(n_iter=2).fit(X, y, sequence_ids=ids)
    assert isinstance(model.classes_, list) and model.n_outputs_ == 2
    assert_array_equal(model.classes_[0], CONTENTS)
    assert_array_equal(model.classes_[1], STYLES)
    assert model.n_context_ == 5  # one-hot blocks side by side
    one = make(n_iter=2).fit(X, y[:, 1], sequence_ids=ids)
    assert one.n_outputs_ == 1 and not isinstance(one.classes_, list)
    column = make(n_iter=2).fit(X, y[:, 1:], sequence_ids=ids)
    assert_array_equal(column.classes_, one.classes_)


def test_a_factor_of_one_class_is_refused():
    X, ids, y = two_factor_data()
    y[:, 0] = "walk"
    with pytest.raises(ValueError, match=r"y\[:, 0\] holds one class \('walk'\)"):
        factored().fit(X, y, sequence_ids=ids)


def test_integer_codes_are_labels_not_weights():
    """The ambiguity of issue 47: (n_frames, 2) integer codes are two factors."""
    X, ids, y = two_factor_data()
    codes = np.stack(
        [np.searchsorted(c, y[:, j]) for j, c in enumerate([CONTENTS, STYLES])], axis=1
    )
    model = factored().fit(X, codes, sequence_ids=ids)
    assert_array_equal(model.classes_[0], [0, 1])
    assert_array_equal(model.classes_[1], [0, 1, 2])
    assert model.predict(X, sequence_ids=ids).shape == (len(X), 2)


def test_predict_names_every_factor(fitted):
    X, ids, y = two_factor_data(random_state=1)
    predicted = fitted.predict(X, sequence_ids=ids)
    assert predicted.shape == (len(X), 2)
    assert_array_equal(predicted, y)  # the held-out pair ('run', 'c') too
    proba = fitted.predict_proba(X, sequence_ids=ids)
    assert [p.shape for p in proba] == [(len(X), 2), (len(X), 3)]
    for p in proba:
        assert_allclose(p.sum(axis=1), 1)
    log_proba = fitted.predict_log_proba(X, sequence_ids=ids)
    assert_allclose(np.exp(log_proba[1]), proba[1])


def test_predict_of_strings_and_numbers_keeps_each():
    X, ids, y = two_factor_data()
    mixed = np.empty(y.shape, dtype=object)
    mixed[:, 0] = y[:, 0]
    mixed[:, 1] = np.searchsorted(STYLES, y[:, 1])
    model = factored().fit(X, mixed, sequence_ids=ids)
    assert model.classes_[1].dtype.kind == "i"
    predicted = model.predict(X[:60])
    assert isinstance(predicted[0, 0], str) and isinstance(predicted[0, 1], int)


def test_pruned_posterior_matches_every_combination(fitted, monkeypatch):
    """Combinations ruled out early are not scored later, at no cost in accuracy."""
    X, ids, _ = two_factor_data(random_state=2)
    sequences = fitted._check_inference_input(X, ids)[1]
    pruned = fitted._class_log_likelihoods(X, sequences)
    assert np.isneginf(pruned).any()  # some were dropped
    monkeypatch.setattr(_style, "PRUNE_NATS", np.inf)
    every = fitted._class_log_likelihoods(X, sequences)
    assert np.all(np.isfinite(every))
    scored = np.isfinite(pruned)
    assert_allclose(pruned[scored], every[scored])
    assert_allclose(
        fitted._posterior(X, sequences, pruned),
        fitted._posterior(X, sequences, every),
        atol=1e-10,
    )


def test_priors_of_every_factor(fitted):
    X, ids, _ = two_factor_data(random_state=1)
    model = copy.deepcopy(fitted).set_params(priors=[[1, 1], [1, 1, 1]])
    assert_allclose(
        model.predict_proba(X[:60])[1], fitted.predict_proba(X[:60])[1], atol=1e-12
    )
    model.set_params(priors=[1, 1, 1])
    with pytest.raises(ValueError, match="list of 2 arrays, one per factor"):
        model.predict(X[:60])
    model.set_params(priors=[[1, 1], [1, 1]])
    with pytest.raises(ValueError, match=r"priors\[1\] must hold one non-negative"):
        model.predict(X[:60])


def test_sample_takes_a_row_for_every_frame_or_one_per_frame(fitted):
    # the pair never seen: the content's effect and the style's add
    unseen = fitted.sample(40, y=("run", "c"), n_sequences=3, random_state=0)
    assert_allclose(
        unseen[:, :2].reshape(3, 40, 2)[:, 20:].mean(axis=(0, 1)), [1, 1], atol=0.2
    )
    rows = [("walk", "a")] * 30 + [("walk", "b")] * 30  # the style switches
    switched = fitted.sample(60, y=rows, n_sequences=3, random_state=0)
    tracks = switched[:, 1].reshape(3, 60)
    assert tracks[:, 20:30].mean() < -0.7 and abs(tracks[:, 50:].mean()) < 0.3
    same = fitted.sample(60, style=np.array(rows), n_sequences=3, random_state=0)
    assert_array_equal(same, switched)


def test_a_blend_is_a_mapping_per_factor(fitted):
    blend = ("walk", {"a": 0.5, "c": 0.5})
    frames = fitted.sample(40, y=blend, n_sequences=3, random_state=0)
    weights = fitted._style_weights(blend, 2)
    assert_allclose(weights, [[0, 1, 0.5, 0, 0.5]] * 2)
    # a blend halfway between styles a and c moves like style b
    assert abs(frames[:, 1].reshape(3, 40)[:, 20:].mean()) < 0.35
    with pytest.raises(ValueError, match=r"sum to 0.8: they must sum to 1"):
        fitted.sample(5, y=("walk", {"a": 0.4, "c": 0.4}))
    with pytest.raises(ValueError, match=r"y\[:, 1\] holds the style 'd', not seen"):
        fitted.sample(5, y=("walk", {"a": 0.5, "d": 0.5}))


def test_one_factor_models_take_blends_as_mappings():
    X, ids, y = two_factor_data()
    model = labelled(n_iter=2).fit(X, y[:, 1], sequence_ids=ids)
    blend = {"a": 0.25, "c": 0.75}
    assert_allclose(model._style_weights(blend, 1), [[0.25, 0, 0.75]])
    a = model.sample(5, y=blend, random_state=0)
    b = model.sample(5, style=np.tile([0.25, 0, 0.75], (5, 1)), random_state=0)
    assert_array_equal(a, b)
    with pytest.raises(
        ValueError, match=r"one style label per frame, shape \(n_frames,\)"
    ):
        model.sample(5, y=np.tile([0.25, 0, 0.75], (5, 1)))


@pytest.mark.parametrize(
    "bad, match",
    [
        (("walk",), r"a label of each of the model's 2 label factors"),
        (np.full((7, 2), "walk"), r"y gives 7 frames' labels but 5 are needed"),
        (("walk", "a", "b"), r"shape \(3,\)"),
        (("jog", "a"), r"y\[:, 0\] holds the style 'jog', not seen in fit"),
    ],
)
def test_bad_rows_of_labels_say_what_to_write(fitted, bad, match):
    with pytest.raises(ValueError, match=match):
        fitted.sample(5, y=bad)


def test_y_and_style_are_not_both_given(fitted):
    with pytest.raises(ValueError, match="both y= and style="):
        fitted.sample(5, y=("walk", "a"), style=("walk", "a"))


def test_a_model_without_labels_refuses_y():
    X, ids, _ = two_factor_data()
    model = labelled(n_iter=2).fit(X, context=X[:, :1], sequence_ids=ids)
    with pytest.raises(ValueError, match="not on labels.*y="):
        model.sample(5, y=("walk", "a"))


def test_scores_and_transform_take_rows_of_labels(fitted):
    X, ids, y = two_factor_data(random_state=1)
    right = fitted.score(X, y, sequence_ids=ids)
    flipped = y.copy()
    flipped[:, 0] = np.where(y[:, 0] == "run", "walk", "run")
    wrong = fitted.score(X, flipped, sequence_ids=ids)
    assert right > wrong
    unknown = fitted.score(X, sequence_ids=ids)  # the mixture over combinations
    assert np.isfinite(unknown) and unknown < right + 0.5
    assert fitted.score_samples(X, style=y, sequence_ids=ids).shape == (len(X),)
    given = fitted.transform(X, style=y, sequence_ids=ids)
    inferred = fitted.transform(X, sequence_ids=ids)  # from the posterior
    assert_allclose(inferred, given, atol=1e-6)


def test_imputer_fills_in_with_several_factors(fitted):
    X, ids, y = two_factor_data(random_state=1)
    missing = X.copy()
    missing[::3, 2] = np.nan
    imputer = CRBMImputer(FrozenEstimator(fitted), n_gibbs=3, random_state=0)
    imputer.fit(X, y, sequence_ids=ids)
    for style in (y, None):
        filled = imputer.transform(missing, style=style, sequence_ids=ids)
        assert np.all(np.isfinite(filled))


def test_persistence_and_clone(fitted):
    again = pickle.loads(pickle.dumps(fitted))
    X = two_factor_data(random_state=1)[0][:60]
    assert_array_equal(again.predict(X), fitted.predict(X))
    assert clone(fitted).get_params() == fitted.get_params()


def test_generation_warnings_name_every_factor(fitted):
    fitted = pickle.loads(pickle.dumps(fitted))
    fitted.generation_statistics_.label_amplitude = np.full(5, 1e6)
    with pytest.warns(UserWarning, match=r"asked for \('walk', 'a'\)"):
        fitted.sample(120, y=("walk", "a"), random_state=0)


def test_styles_are_balanced_by_combination():
    weights = np.array([[1, 0, 1, 0]] * 4 + [[1, 0, 0, 1]] * 2 + [[0, 1, 0, 1]], float)
    frames = np.arange(7)
    repeated = balanced_frames(frames, weights, [slice(0, 2), slice(2, 4)])
    assert_array_equal(repeated, [0, 1, 2, 3, 4, 4, 5, 5, 6, 6, 6, 6])
