"""NearestNeighborImputer: the paper's baseline, checked against a plain loop."""

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.pipeline import make_pipeline

from sklearn_crbm.impute import NearestNeighborImputer, _nearest_neighbor


def brute_force(train, X):
    """The paper's description, one frame at a time."""
    X = X.copy()
    for t in range(len(X)):
        missing = np.isnan(X[t])
        if missing.any() and not missing.all():
            distances = [
                np.sqrt(np.sum((X[t, ~missing] - row[~missing]) ** 2)) for row in train
            ]
            X[t, missing] = train[int(np.argmin(distances)), missing]
    return X


def random_problem(seed=0, n_train=300, n_test=120, n_features=6):
    rng = np.random.default_rng(seed)
    train = rng.normal(size=(n_train, n_features))
    X = rng.normal(size=(n_test, n_features))
    mask = rng.random(X.shape) < 0.4
    mask[::7] = False  # complete frames
    mask[3, :] = True  # a wholly missing frame after observed ones
    X_missing = np.where(mask, np.nan, X)
    return train, X, X_missing, mask


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_equals_brute_force_loop(seed):
    train, _, X_missing, mask = random_problem(seed)
    filled = NearestNeighborImputer().fit(train).transform(X_missing)
    expected = brute_force(train, X_missing)
    partial = mask.any(axis=1) & ~mask.all(axis=1)
    assert_array_equal(filled[partial], expected[partial])
    assert not np.isnan(filled).any()


def test_chunking_does_not_change_the_result(monkeypatch):
    train, _, X_missing, _ = random_problem(3)
    expected = NearestNeighborImputer().fit(train).transform(X_missing)
    monkeypatch.setattr(_nearest_neighbor, "_MAX_DISTANCES", 700)
    filled = NearestNeighborImputer().fit(train).transform(X_missing)
    assert_array_equal(filled, expected)


def test_observed_values_are_returned_unchanged():
    train, _, X_missing, mask = random_problem(4)
    X_in = X_missing.copy()
    filled = NearestNeighborImputer().fit(train).transform(X_missing)
    assert_array_equal(filled[~mask], X_missing[~mask])
    assert_array_equal(np.isnan(X_missing), np.isnan(X_in))  # input untouched


def test_missing_channels_come_from_one_training_frame():
    train, _, X_missing, mask = random_problem(5)
    filled = NearestNeighborImputer().fit(train).transform(X_missing)
    for t in np.flatnonzero(mask.any(axis=1) & ~mask.all(axis=1)):
        rows = np.all(train[:, mask[t]] == filled[t, mask[t]], axis=1)
        assert rows.any()


def test_wholly_missing_frames_hold_the_previous_frame_of_their_sequence():
    train = np.arange(12.0).reshape(4, 3)
    X = np.array(
        [
            [np.nan, np.nan, np.nan],  # first frame of sequence 0: the mean
            [np.nan, np.nan, np.nan],  # still nothing before it: the mean
            [3.1, np.nan, 5.0],
            [np.nan, np.nan, np.nan],  # holds frame 2 (filled)
            [np.nan, np.nan, np.nan],  # first frame of sequence 1: the mean
            [9.0, 10.0, 11.0],
            [np.nan, np.nan, np.nan],
        ]
    )
    imputer = NearestNeighborImputer().fit(train)
    filled = imputer.transform(X, sequence_ids=[0, 0, 0, 0, 1, 1, 1])
    assert_allclose(filled[0], train.mean(axis=0))
    assert_allclose(filled[1], train.mean(axis=0))
    assert_allclose(filled[2], [3.1, 4.0, 5.0])
    assert_allclose(filled[3], filled[2])
    assert_allclose(filled[4], train.mean(axis=0))
    assert_allclose(filled[6], [9.0, 10.0, 11.0])
    # without sequence ids, frame 4 continues sequence 0
    assert_allclose(imputer.transform(X)[4], filled[2])


def test_other_missing_value_marker():
    train, _, X_missing, mask = random_problem(6)
    X_marked = np.where(mask, -999.0, X_missing)
    filled = (
        NearestNeighborImputer(missing_values=-999.0).fit(train).transform(X_marked)
    )
    expected = NearestNeighborImputer().fit(train).transform(X_missing)
    assert_array_equal(filled, expected)


def test_fit_leaves_out_incomplete_training_frames():
    train = np.array([[0.0, 0.0], [np.nan, 5.0], [10.0, 10.0]])
    imputer = NearestNeighborImputer().fit(train)
    assert_allclose(imputer.mean_, [5.0, 5.0])
    assert_array_equal(imputer.transform([[np.nan, 4.0]]), [[0.0, 4.0]])
    with pytest.raises(ValueError, match="every frame"):
        NearestNeighborImputer().fit([[np.nan, 1.0]])


def test_feature_names_out():
    imputer = NearestNeighborImputer().fit(np.eye(3))
    assert_array_equal(imputer.get_feature_names_out(), ["x0", "x1", "x2"])
    assert_array_equal(imputer.get_feature_names_out(["a", "b", "c"]), ["a", "b", "c"])


def test_fit_takes_and_checks_sequence_ids_as_the_other_imputers():
    train, _, X_missing, _ = random_problem(7)
    ids = np.repeat([0, 1, 2], 100)
    expected = NearestNeighborImputer().fit(train).transform(X_missing)
    imputer = NearestNeighborImputer().fit(train, sequence_ids=ids)
    assert_array_equal(imputer.transform(X_missing), expected)  # unused in fit
    with pytest.raises(ValueError, match="2 entries but X has 300 frames"):
        NearestNeighborImputer().fit(train, sequence_ids=ids[:2])
    with pytest.raises(ValueError, match="occurs in more than one"):
        NearestNeighborImputer().fit(train, sequence_ids=np.tile([0, 1], 150))
    # a Pipeline routes the ids to fit and transform, as for CRBMImputer
    with sklearn.config_context(enable_metadata_routing=True):
        pipe = make_pipeline(NearestNeighborImputer())
        pipe.fit(train, sequence_ids=ids)
        filled = pipe.transform(X_missing, sequence_ids=np.zeros(len(X_missing)))
    assert_array_equal(filled, expected)
