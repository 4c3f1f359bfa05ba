"""The imputation scorer: masking pattern, routing, and use in a search."""

import pickle

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import BaseEstimator, TransformerMixin
from sklearn.impute import SimpleImputer
from sklearn.metrics import mean_absolute_error, mean_squared_error
from sklearn.model_selection import GridSearchCV, GroupKFold, cross_validate
from sklearn.pipeline import make_pipeline
from sklearn.preprocessing import StandardScaler

from sklearn_crbm.metrics import fillin_error
from sklearn_crbm.model_selection import make_imputation_scorer

RNG = np.random.default_rng(0)
X_SMALL = RNG.normal(size=(20, 4))
IDS_SMALL = np.repeat([3, 7], [12, 8])


class _SpyImputer(TransformerMixin, BaseEstimator):
    """Fills with zeros and records what ``transform`` was given."""

    __metadata_request__transform = {"sequence_ids": True}

    def fit(self, X, y=None):
        self.n_features_in_ = X.shape[1]
        return self

    def transform(self, X, *, sequence_ids=None):
        self.seen_X_ = np.array(X, copy=True)
        self.seen_ids_ = None if sequence_ids is None else np.array(sequence_ids)
        return np.nan_to_num(np.asarray(X, dtype=float), nan=0.0)


def test_mask_covers_columns_from_start_fraction_in_every_sequence():
    scorer = make_imputation_scorer(columns=[1, 3], start=0.5)
    mask = scorer.missing_mask(X_SMALL, sequence_ids=IDS_SMALL)
    expected = np.zeros_like(mask)
    expected[6:12, [1, 3]] = True  # second half of the 12-frame sequence
    expected[16:20, [1, 3]] = True  # second half of the 8-frame sequence
    assert_array_equal(mask, expected)


def test_mask_with_frame_indices_and_stop():
    scorer = make_imputation_scorer(columns=[0], start=2, stop=5)
    mask = scorer.missing_mask(X_SMALL, sequence_ids=IDS_SMALL)
    assert_array_equal(np.flatnonzero(mask[:, 0]), [2, 3, 4, 14, 15, 16])
    assert not mask[:, 1:].any()


def test_mask_without_ids_treats_x_as_one_sequence():
    mask = make_imputation_scorer(columns=[0], start=0.75).missing_mask(X_SMALL)
    assert_array_equal(np.flatnonzero(mask[:, 0]), np.arange(15, 20))


def test_mask_by_bone_names_and_boolean_columns():
    names = ["root_tx", "lfemur_ex", "lfemur_ey", "rfemur_ex"]
    by_bone = make_imputation_scorer(bones="lfemur", feature_names=names, start=0.0)
    by_bool = make_imputation_scorer(columns=[False, True, True, False], start=0.0)
    by_name = make_imputation_scorer(
        columns=["lfemur_ex", "lfemur_ey"], feature_names=names, start=0.0
    )
    masks = [s.missing_mask(X_SMALL) for s in (by_bone, by_bool, by_name)]
    assert_array_equal(masks[0].all(axis=0), [False, True, True, False])
    assert_array_equal(masks[0], masks[1])
    assert_array_equal(masks[0], masks[2])


def test_bone_names_from_estimator_feature_names_in():
    names = np.array(["root_tx", "lfemur_ex", "lfemur_ey", "rfemur_ex"], dtype=object)
    imputer = SimpleImputer().fit(X_SMALL)
    imputer.feature_names_in_ = names
    scorer = make_imputation_scorer(bones=["rfemur"], start=0.0)
    mask = scorer.missing_mask(X_SMALL, estimator=imputer)
    assert_array_equal(mask.all(axis=0), [False, False, False, True])


def test_score_is_the_negative_error_on_erased_entries_only():
    X_train, X_test = X_SMALL[:10], X_SMALL[10:] + 5.0
    ids = np.repeat([0, 1], 5)
    imputer = SimpleImputer().fit(X_train)
    scorer = make_imputation_scorer(columns=[0, 2], start=0.4)
    mask = scorer.missing_mask(X_test, sequence_ids=ids)
    filled = X_test.copy()
    filled[mask] = np.broadcast_to(X_train.mean(axis=0), X_test.shape)[mask]
    expected = -mean_squared_error(X_test[mask], filled[mask])
    assert scorer(imputer, X_test, sequence_ids=ids) == pytest.approx(expected)
    # Observed entries never count: a constant offset elsewhere changes nothing.
    shifted = X_test.copy()
    shifted[:, [1, 3]] += 100.0
    assert scorer(imputer, shifted, sequence_ids=ids) == pytest.approx(expected)


def test_greater_is_better_and_kwargs():
    imputer = SimpleImputer().fit(X_SMALL)
    error = make_imputation_scorer(mean_absolute_error, columns=[0])
    score = make_imputation_scorer(
        mean_squared_error, columns=[0], greater_is_better=True
    )
    mask = error.missing_mask(X_SMALL)
    fill = X_SMALL.mean(axis=0)[0]
    assert error(imputer, X_SMALL) == pytest.approx(
        -mean_absolute_error(X_SMALL[mask], np.full(mask.sum(), fill))
    )
    assert score(imputer, X_SMALL) > 0
    weights = np.arange(1.0, mask.sum() + 1)
    weighted = make_imputation_scorer(
        mean_squared_error, columns=[0], sample_weight=weights
    )
    assert weighted(imputer, X_SMALL) == pytest.approx(
        -mean_squared_error(
            X_SMALL[mask], np.full(mask.sum(), fill), sample_weight=weights
        )
    )


def test_score_func_with_missing_mask_gets_whole_frames():
    imputer = SimpleImputer().fit(X_SMALL)
    scorer = make_imputation_scorer(fillin_error, columns=[1, 2], start=0.5)
    mask = scorer.missing_mask(X_SMALL, sequence_ids=IDS_SMALL)
    filled = np.where(mask, X_SMALL.mean(axis=0), X_SMALL)
    expected = -fillin_error(X_SMALL, filled, missing_mask=mask)
    assert scorer(imputer, X_SMALL, sequence_ids=IDS_SMALL) == pytest.approx(expected)


def test_estimator_sees_the_erased_frames_and_the_ids():
    spy = _SpyImputer().fit(X_SMALL)
    scorer = make_imputation_scorer(columns=[2], start=0.5)
    scorer(spy, X_SMALL, sequence_ids=IDS_SMALL)
    mask = scorer.missing_mask(X_SMALL, sequence_ids=IDS_SMALL)
    assert_array_equal(np.isnan(spy.seen_X_), mask)
    assert_array_equal(spy.seen_X_[~mask], X_SMALL[~mask])
    assert_array_equal(spy.seen_ids_, IDS_SMALL)


def test_custom_missing_values_marker():
    imputer = SimpleImputer(missing_values=-999.0).fit(X_SMALL)
    scorer = make_imputation_scorer(columns=[0], missing_values=-999.0)
    reference = make_imputation_scorer(columns=[0])
    assert scorer(imputer, X_SMALL) == pytest.approx(
        reference(SimpleImputer().fit(X_SMALL), X_SMALL)
    )


def test_ids_passed_to_transform_only_when_requested():
    imputer = SimpleImputer().fit(X_SMALL)  # transform takes no sequence_ids
    scorer = make_imputation_scorer(columns=[0])
    with sklearn.config_context(enable_metadata_routing=True):
        with_routing = scorer(imputer, X_SMALL, sequence_ids=IDS_SMALL)
        spy = _SpyImputer()
        pipeline = make_pipeline(StandardScaler(), spy).fit(X_SMALL)
        scorer(pipeline, X_SMALL, sequence_ids=IDS_SMALL)
    assert_array_equal(spy.seen_ids_, IDS_SMALL)
    assert with_routing == pytest.approx(
        scorer(imputer, X_SMALL, sequence_ids=IDS_SMALL)
    )


def test_metadata_request_and_set_score_request():
    scorer = make_imputation_scorer(columns=[0])
    with sklearn.config_context(enable_metadata_routing=True):
        assert scorer.get_metadata_routing().consumes("score", ["sequence_ids"]) == {
            "sequence_ids"
        }
        scorer.set_score_request(sequence_ids=False)
        assert (
            scorer.get_metadata_routing().consumes("score", ["sequence_ids"]) == set()
        )
    with pytest.raises(RuntimeError, match="metadata routing"):
        scorer.set_score_request(sequence_ids=True)


def test_repr_and_pickle():
    names = ["lfemur_ex", "b_x", "c_x", "d_x"]
    scorer = make_imputation_scorer(
        bones=["lfemur"], start=0.25, stop=0.75, feature_names=names
    )
    assert repr(scorer) == (
        "make_imputation_scorer(mean_squared_error, greater_is_better=False, "
        "bones=['lfemur'], start=0.25, stop=0.75)"
    )
    clone = pickle.loads(pickle.dumps(scorer))
    imputer = SimpleImputer().fit(X_SMALL)
    assert clone(imputer, X_SMALL) == scorer(imputer, X_SMALL)


@pytest.mark.parametrize(
    "kwargs, error, match",
    [
        ({}, ValueError, "Give the channels"),
        ({"columns": [0], "start": 1.5}, ValueError, r"\[0, 1\]"),
        ({"columns": [0], "start": -1}, ValueError, ">= 0"),
        ({"columns": [0], "start": "half"}, TypeError, "start must be"),
        ({"columns": [0], "stop": True}, TypeError, "stop must be"),
        ({"bones": []}, ValueError, "at least one bone"),
    ],
)
def test_invalid_construction(kwargs, error, match):
    with pytest.raises(error, match=match):
        make_imputation_scorer(**kwargs)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"columns": [7]}, "out of range"),
        ({"columns": [True, False]}, "boolean columns mask needs 4"),
        ({"columns": ["x"]}, "needs feature names"),
        ({"columns": ["x"], "feature_names": list("abcd")}, "Unknown feature"),
        ({"bones": "head", "feature_names": list("abcd")}, "No column belongs"),
        ({"bones": "head", "feature_names": ["a_x"]}, "1 feature names"),
        ({"columns": [0], "start": 30}, "erases nothing"),
    ],
)
def test_invalid_pattern_for_x(kwargs, match):
    with pytest.raises(ValueError, match=match):
        make_imputation_scorer(**kwargs).missing_mask(X_SMALL)


def test_transform_changing_the_columns_is_an_error():
    scorer = make_imputation_scorer(columns=[0])
    estimator = make_pipeline(SimpleImputer(), _DropFirst())
    estimator.fit(X_SMALL)
    with pytest.raises(ValueError, match="columns of the input"):
        scorer(estimator, X_SMALL)


class _DropFirst(TransformerMixin, BaseEstimator):
    def fit(self, X, y=None):
        self.n_features_in_ = X.shape[1]
        return self

    def transform(self, X):
        return np.asarray(X)[:, 1:]


def test_grid_search_with_simple_imputer_routes_ids_to_the_scorer():
    """A search picks the better trivial imputer, scored on held-out sequences."""
    rng = np.random.default_rng(1)
    ids = np.repeat(np.arange(6), 30)
    # Channel 0 jumps from -30 to 5 half-way through every sequence and the
    # first frame is at 5 too: the median of the training frames (about 5)
    # fills the erased second halves better than their mean or zero.
    X = rng.normal(size=(180, 3))
    X[:, 0] = np.where(np.tile(np.arange(30), 6) >= 15, 5.0, -30.0)
    X[:, 0] += 0.1 * rng.normal(size=180)
    X[::30, 0] = 5.0
    scorer = make_imputation_scorer(columns=[0], start=0.5)
    with sklearn.config_context(enable_metadata_routing=True):
        search = GridSearchCV(
            SimpleImputer(),
            {"strategy": ["mean", "median", "constant"]},
            scoring=scorer,
            cv=GroupKFold(n_splits=3),
        ).fit(X, groups=ids, sequence_ids=ids)
        # The same numbers by hand for the first split.
        train, test = next(GroupKFold(n_splits=3).split(X, groups=ids))
        by_hand = scorer(
            SimpleImputer(strategy="median").fit(X[train]),
            X[test],
            sequence_ids=ids[test],
        )
        results = cross_validate(
            SimpleImputer(strategy="median"),
            X,
            cv=GroupKFold(n_splits=3),
            scoring={"fill": scorer},
            params={"groups": ids, "sequence_ids": ids},
        )
    assert search.best_params_ == {"strategy": "median"}
    scores = dict(
        zip(
            [p["strategy"] for p in search.cv_results_["params"]],
            search.cv_results_["mean_test_score"],
            strict=True,
        )
    )
    assert scores["median"] > scores["mean"] and scores["median"] > scores["constant"]
    assert search.cv_results_["split0_test_score"][1] == pytest.approx(by_hand)
    assert_allclose(
        results["test_fill"],
        [search.cv_results_[f"split{k}_test_score"][1] for k in range(3)],
    )
