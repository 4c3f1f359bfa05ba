"""What a new user meets first (issue 38): messages in their terms, sequences
that a loader knows, float32 through the pipeline, recognition done once."""

import re
import warnings

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_array_equal
from sklearn.model_selection import cross_val_score

from sklearn_crbm import ConditionalRBM, FactoredCRBM, LabelledCRBM
from sklearn_crbm.datasets import (
    make_oscillations,
    make_walker,
    read_bvh_folder,
    write_bvh,
)
from sklearn_crbm.preprocessing import make_motion_pipeline

X, IDS = make_oscillations(n_sequences=4, n_frames=30, random_state=0)
STYLES = np.where(IDS < 2, "a", "b")
TINY_FACTORED = dict(n_factors=4, n_style_features=2, order=2, n_iter=2)


@pytest.fixture(scope="module")
def factored():
    model = FactoredCRBM(8, **TINY_FACTORED, random_state=0)
    return model.fit(X, STYLES, sequence_ids=IDS)


@pytest.fixture(scope="module")
def walks(tmp_path_factory):
    """A folder of three BVH files, read back with read_bvh_folder."""
    folder = tmp_path_factory.mktemp("walks")
    for seed in range(3):
        walker = make_walker(n_sequences=1, n_frames=20, random_state=seed)
        write_bvh(folder / f"walk_{seed}.bvh", walker.data, walker.skeleton, 30.0)
    return read_bvh_folder(folder)


@pytest.fixture
def pipeline(walks):
    model = ConditionalRBM(6, order=3, n_iter=2, random_state=0)
    pipe = make_motion_pipeline(walks.skeleton, model)
    with sklearn.config_context(enable_metadata_routing=True):
        return pipe.fit(walks.data, sequence_ids=walks.sequence_ids)


# -- labels as the user wrote them -------------------------------------------


def test_an_unseen_style_is_shown_as_written(factored):
    message = "style holds the style 'sad', not seen in fit; the styles are ['a', 'b']"
    with pytest.raises(ValueError, match=re.escape(message)):
        factored.sample(5, style="sad")


@pytest.mark.parametrize("model", [FactoredCRBM(8, **TINY_FACTORED), LabelledCRBM(8)])
def test_a_style_model_of_one_class_says_so(model):
    with pytest.raises(ValueError, match=r"y holds one class \('walk'\)"):
        model.fit(X, np.full(len(X), "walk"), sequence_ids=IDS)


# -- the pipeline speaks of raw frames and channels ---------------------------


def test_a_raw_seed_is_described_in_raw_channels(pipeline, walks):
    message = (
        "history holds 1 frame of the skeleton's 57 raw channels, but sample "
        "seeds the model in its own space: take at least 3 raw frames of 57 "
        "channels through the preprocessing"
    )
    with pytest.raises(ValueError, match=re.escape(message)):
        pipeline.sample(10, history=walks.data[:1])
    seed = pipeline[:-1].transform(walks.data[:3])  # what the message says works
    assert pipeline.sample(4, history=seed, random_state=0).shape == (4, 57)


@pytest.mark.parametrize("method", ["fit", "transform"])
def test_nan_in_raw_frames_points_to_the_imputer(pipeline, walks, method):
    X_missing = walks.data.copy()
    X_missing[[4, 30], 7] = np.nan
    with pytest.raises(ValueError) as error:
        getattr(pipeline, method)(X_missing)
    message = str(error.value)
    assert "X holds NaN in 2 of its 60 frames (the first at frame 4)" in message
    assert "CRBMImputer" in message and "HistGradientBoosting" not in message


def test_fit_without_routing_says_how_to_turn_it_on(walks):
    pipe = make_motion_pipeline(walks.skeleton, ConditionalRBM(4, n_iter=1))
    with sklearn.config_context(enable_metadata_routing=False):
        with pytest.raises(ValueError, match=r"sklearn.set_config\(enable_metadata"):
            pipe.fit(walks.data, sequence_ids=walks.sequence_ids)


# -- a loader's sequences are not silently merged -----------------------------


def test_fitting_a_loaders_data_without_its_sequence_ids_warns(walks):
    pipe = make_motion_pipeline(walks.skeleton, ConditionalRBM(4, n_iter=1))
    for fit in (ConditionalRBM(4, n_iter=1).fit, pipe.fit):
        with pytest.warns(UserWarning, match="holds frames of 3 sequences"):
            fit(walks.data)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ConditionalRBM(4, n_iter=1).fit(walks.data, sequence_ids=walks.sequence_ids)
        ConditionalRBM(4, n_iter=1).fit(walks.data[walks.sequence_ids == 0])


def test_a_fold_of_a_loaders_data_without_sequence_ids_warns(walks):
    # cross_val_score's folds are copies of the loader's rows
    with sklearn.config_context(enable_metadata_routing=False):
        with pytest.warns(UserWarning, match="holds frames of 2 sequences"):
            cross_val_score(ConditionalRBM(4, n_iter=1), walks.data, cv=3)


def test_a_split_that_cuts_a_sequence_warns(walks):
    model = ConditionalRBM(4, n_iter=1)
    fold = np.r_[0:30, 40:60]  # the second file of three cut in the middle
    with pytest.warns(UserWarning, match=r"only part of 1 \(ids \[1\]\).*GroupKFold"):
        model.fit(walks.data[fold], sequence_ids=walks.sequence_ids[fold])
    whole = np.r_[0:20, 40:60]
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        model.fit(walks.data[whole], sequence_ids=walks.sequence_ids[whole])
        model.fit(walks.data[:10])  # part of one take, deliberately


def test_whole_takes_that_share_a_frame_with_another_are_not_called_cut(tmp_path):
    # two takes of a corpus can hold the same frame (a rest pose): taking
    # one of them whole must not read as cutting it
    walker = make_walker(n_sequences=1, n_frames=20, random_state=10)
    other = make_walker(n_sequences=1, n_frames=20, random_state=11).data
    other[5] = walker.data[12]
    for name, data in (("a", walker.data), ("b", other), ("c", walker.data[::-1])):
        write_bvh(tmp_path / f"walk_{name}.bvh", data, walker.skeleton, 30.0)
    takes = read_bvh_folder(tmp_path)
    first_two = takes.sequence_ids < 2
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        ConditionalRBM(4, n_iter=1).fit(
            takes.data[first_two], sequence_ids=takes.sequence_ids[first_two]
        )


# -- float32 in, float32 out ---------------------------------------------------


def test_float32_raw_channels_stay_float32(walks):
    X32 = walks.data.astype(np.float32)
    model = ConditionalRBM(6, order=2, n_iter=2, random_state=0)
    pipe = make_motion_pipeline(walks.skeleton, model)
    with sklearn.config_context(enable_metadata_routing=True):
        pipe.fit(X32, sequence_ids=walks.sequence_ids)
        Z = pipe[:-1].transform(X32, sequence_ids=walks.sequence_ids)
        back = pipe[:-1].inverse_transform(Z, sequence_ids=walks.sequence_ids)
    assert Z.dtype == back.dtype == pipe[-1].components_.dtype == np.float32
    assert pipe.sample(5, random_state=0).dtype == np.float32
    np.testing.assert_allclose(back[:, 6:], X32[:, 6:], atol=1e-3)


# -- recognition: one pass per style for predict and predict_proba ------------


def test_predict_and_predict_proba_share_one_pass(factored, monkeypatch):
    calls = []
    original = FactoredCRBM._class_log_likelihoods

    def counted(self, *args):
        calls.append(1)
        return original(self, *args)

    monkeypatch.setattr(FactoredCRBM, "_class_log_likelihoods", counted)
    model = FactoredCRBM(8, **TINY_FACTORED).fit(X, STYLES, sequence_ids=IDS)
    predicted = model.predict(X, sequence_ids=IDS)
    proba = model.predict_proba(X, sequence_ids=IDS)
    log_proba = model.predict_log_proba(X, sequence_ids=IDS)
    assert len(calls) == 1
    assert_array_equal(model.classes_[proba.argmax(axis=1)], predicted)
    np.testing.assert_allclose(np.exp(log_proba), proba)
    proba[:] = 0  # the caller's copy: the kept posterior is unchanged
    assert model.predict_proba(X, sequence_ids=IDS).sum(axis=1) == pytest.approx(1)
    # other frames, other sequences or other parameters: a new pass
    model.predict(X[::-1], sequence_ids=IDS)
    model.predict(X, sequence_ids=IDS // 2)
    model.partial_fit(X, STYLES, sequence_ids=IDS)
    model.predict(X, sequence_ids=IDS)
    assert len(calls) == 4


def test_the_kept_posterior_is_the_one_computed_afresh(factored):
    kept = factored.predict_proba(X, sequence_ids=IDS)
    fresh = FactoredCRBM(8, **TINY_FACTORED, random_state=0)
    fresh = fresh.fit(X, STYLES, sequence_ids=IDS)
    assert_array_equal(fresh.predict_proba(X, sequence_ids=IDS), kept)
