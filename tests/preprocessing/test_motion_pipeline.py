"""MotionPipeline: sampling raw channels, seeds by style, speeds, files."""

import pickle

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import BaseEstimator, TransformerMixin, clone
from sklearn.model_selection import GridSearchCV, GroupKFold

from sklearn_crbm import ConditionalRBM, LabelledCRBM
from sklearn_crbm.datasets import make_walker, read_amc, read_bvh
from sklearn_crbm.metrics import forward_speed
from sklearn_crbm.preprocessing import (
    MotionPipeline,
    make_motion_pipeline,
    make_motion_preprocessor,
)


@pytest.fixture(autouse=True)
def routing():
    with sklearn.config_context(enable_metadata_routing=True):
        yield


@pytest.fixture(scope="module")
def walker():
    return make_walker(n_sequences=4, n_frames=40, random_state=0)


@pytest.fixture(scope="module")
def fitted(walker):
    model = ConditionalRBM(8, order=2, n_iter=3, random_state=0)
    with sklearn.config_context(enable_metadata_routing=True):
        return make_motion_pipeline(walker.skeleton, model).fit(
            walker.data, sequence_ids=walker.sequence_ids
        )


def test_sample_is_the_models_sample_in_raw_channels(fitted, walker):
    raw = fitted.sample(20, n_sequences=3, random_state=1, n_gibbs=5)
    frames = fitted[-1].sample(20, n_sequences=3, random_state=1, n_gibbs=5)
    ids = np.repeat(np.arange(3), 20)
    assert_array_equal(raw, fitted[:-1].inverse_transform(frames, sequence_ids=ids))
    assert raw.shape == (60, len(walker.skeleton.feature_names))
    # the same random_state gives the same motion; keyword arguments reach
    # the model's sample
    assert_array_equal(raw, fitted.sample(20, n_sequences=3, random_state=1, n_gibbs=5))
    one_step = fitted.sample(
        20, n_sequences=3, random_state=1, n_gibbs=5, n_mean_field=1
    )
    assert not np.allclose(raw, one_step)
    with pytest.raises(TypeError, match="no_such_parameter"):
        fitted.sample(5, no_such_parameter=1)


def test_sample_works_without_routing_and_with_a_seed_history(fitted):
    seed = fitted[:-1].transform(make_walker(n_frames=5, random_state=3).data)
    with sklearn.config_context(enable_metadata_routing=False):
        raw = fitted.sample(10, history=seed, random_state=0)
    frames = fitted[-1].sample(10, history=seed, random_state=0)
    assert_allclose(raw, fitted[:-1].inverse_transform(frames))


def test_only_a_pipeline_ending_in_a_generative_model_samples(walker):
    pre = make_motion_preprocessor(walker.skeleton)
    assert isinstance(pre, MotionPipeline)
    assert not hasattr(pre, "sample") and not hasattr(pre, "style_windows")
    assert pre.skeleton is walker.skeleton


def test_clone_pickle_and_grid_search_keep_it_a_motion_pipeline(fitted, walker):
    assert type(clone(fitted)) is MotionPipeline
    again = pickle.loads(pickle.dumps(fitted))
    assert_array_equal(
        again.sample(5, random_state=0), fitted.sample(5, random_state=0)
    )
    search = GridSearchCV(
        clone(fitted), {"model__n_components": [4, 8]}, cv=GroupKFold(2)
    )
    search.fit(
        walker.data, groups=walker.sequence_ids, sequence_ids=walker.sequence_ids
    )
    best = search.best_estimator_
    assert type(best) is MotionPipeline
    assert best.sample(7, random_state=0).shape == (7, walker.data.shape[1])


def test_style_windows_are_real_frames_of_one_style_in_one_sequence(fitted, walker):
    # label the first half of every sequence "slow", the second "fast"
    position = np.concatenate([np.arange(40)] * 4)
    styles = np.where(position < 20, "slow", "fast")

    def draw():
        return fitted.style_windows(
            walker.data,
            styles,
            sequence_ids=walker.sequence_ids,
            n_windows=30,
            random_state=0,
        )

    windows = draw()
    assert list(windows) == ["slow", "fast"]
    Z = fitted[:-1].transform(walker.data, sequence_ids=walker.sequence_ids)
    width = fitted[-1].history_length
    for style, drawn in windows.items():
        assert drawn.shape == (30, width, Z.shape[1])
        for window in drawn:
            (row,) = np.flatnonzero(np.all(Z == window[0], axis=1))
            rows = row + np.arange(width)
            assert_array_equal(Z[rows], window)
            assert len(set(walker.sequence_ids[rows])) == 1
            assert set(styles[rows]) == {style}
    again = draw()
    for style in windows:
        assert_array_equal(again[style], windows[style])
    raw = fitted.sample(6, history=windows["fast"][:2], random_state=0)
    assert raw.shape == (12, walker.data.shape[1])
    with pytest.raises(ValueError, match="one style per frame"):
        fitted.style_windows(walker.data, styles[:5])


def test_forward_speed_is_the_encoders_speed_channel(fitted, walker):
    Z = fitted[:-1].transform(walker.data, sequence_ids=walker.sequence_ids)
    encoded = fitted[:2].transform(walker.data, sequence_ids=walker.sequence_ids)
    expected = forward_speed(
        encoded,
        sequence_ids=walker.sequence_ids,
        feature_names=fitted[:2].get_feature_names_out(),
    )
    for pipeline in (fitted, fitted[:-1]):
        speed = pipeline.forward_speed(Z, sequence_ids=walker.sequence_ids)
        assert_allclose(speed, expected, rtol=1e-12)
    with pytest.raises(ValueError, match="needs a RootRelativeEncoder"):
        fitted[2:].forward_speed(Z)


def test_write_motion_writes_bvh_and_amc_that_read_back(fitted, walker, tmp_path):
    raw = fitted.sample(12, random_state=0)
    fitted.write_motion(tmp_path / "walk.bvh", raw, frame_rate=30.0)
    skeleton, data, _, rate = read_bvh(tmp_path / "walk.bvh")
    assert rate == 30.0
    # every bone end of the ASF skeleton is a joint (or end site) of the file
    written = skeleton.forward_kinematics(data)
    ends = walker.skeleton.forward_kinematics(raw)
    gaps = np.linalg.norm(written[:, None] - ends[:, :, None], axis=-1).min(axis=2)
    assert gaps.max() < 1e-4
    fitted.write_motion(tmp_path / "walk.amc", raw)
    data, _ = read_amc(tmp_path / "walk.amc", walker.skeleton)
    assert_allclose(data, raw, atol=1e-5)
    with pytest.raises(ValueError, match="pass frame_rate="):
        fitted.write_motion(tmp_path / "walk.bvh", raw)
    with pytest.raises(ValueError, match=r"\*\.bvh or \*\.amc"):
        fitted.write_motion(tmp_path / "walk.txt", raw)


class _StyleModel(TransformerMixin, BaseEstimator):
    """A stand-in for a style model: ``sample`` takes a ``style``."""

    history_length = 1

    def fit(self, X, y=None):
        self.n_features_in_ = X.shape[1]
        self.mean_ = X.mean(axis=0)
        return self

    def transform(self, X):
        return X

    def sample(
        self, n_frames, *, history=None, style, n_sequences=1, random_state=None
    ):
        shift = {"walk": 0.0, "jog": 1.0}[style]
        return np.tile(self.mean_ + shift, (n_sequences * n_frames, 1))


def test_sample_passes_keywords_through_to_the_models_sample(walker):
    pipe = make_motion_pipeline(walker.skeleton, _StyleModel())
    pipe.fit(walker.data, sequence_ids=walker.sequence_ids)
    walk, jog = (pipe.sample(4, n_sequences=2, style=s) for s in ("walk", "jog"))
    assert walk.shape == jog.shape == (8, walker.data.shape[1])
    assert not np.allclose(walk, jog)
    with pytest.raises(TypeError, match="style"):
        pipe.sample(4)


def test_a_model_of_several_label_factors_samples_any_row(walker):
    rows = np.array(
        [("walk", "slow"), ("jog", "slow"), ("walk", "brisk"), ("jog", "brisk")]
    )
    y = rows[walker.sequence_ids]
    model = LabelledCRBM(8, order=2, n_iter=3, n_gibbs=3, random_state=0)
    pipe = make_motion_pipeline(walker.skeleton, model)
    pipe.fit(walker.data, y, sequence_ids=walker.sequence_ids)
    frames = pipe.sample(4, n_sequences=2, y=("jog", "slow"), random_state=0)
    assert frames.shape == (8, walker.data.shape[1])
    switched = pipe.sample(4, y=[("walk", "slow")] * 2 + [("jog", "brisk")] * 2)
    assert switched.shape == (4, walker.data.shape[1])
    windows = pipe.style_windows(
        walker.data, y, sequence_ids=walker.sequence_ids, n_windows=3, random_state=0
    )
    assert list(windows) == [tuple(row) for row in rows]
    seeded = pipe.sample(4, history=windows[("jog", "brisk")], y=("jog", "brisk"))
    assert seeded.shape == (12, walker.data.shape[1])
