"""StyleJudge: the style of windows of motion, and whether the motion is alive."""

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from sklearn.base import clone
from sklearn.utils.estimator_checks import (
    check_param_validation,
)

from sklearn_crbm.datasets import bone_columns, load_bandai_walks
from sklearn_crbm.metrics import StyleJudge
from sklearn_crbm.preprocessing import make_motion_preprocessor

LEGS = ["UpperLeg_L", "UpperLeg_R", "LowerLeg_L", "LowerLeg_R"]


# --------------------------------------------------------- the Bandai walks
@pytest.fixture(scope="module")
def bandai_split(data_home):
    """Takes 001-005 of every style for training, 006 held out; preprocessed."""
    walks = load_bandai_walks(data_home)
    ids = walks.sequence_ids
    styles = walks.target_names[walks.target]
    train = walks.takes[ids] <= 5
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(walks.skeleton)
        Z_train = pre.fit_transform(walks.data[train], sequence_ids=ids[train])
        Z_test = pre.transform(walks.data[~train], sequence_ids=ids[~train])
    legs = bone_columns(pre.get_feature_names_out(), LEGS)
    return (
        (Z_train, styles[train], ids[train]),
        (Z_test, styles[~train], ids[~train]),
        legs,
    )


@pytest.fixture(scope="module")
def bandai_judge(bandai_split):
    (Z, y, ids), _, legs = bandai_split
    return StyleJudge(legs=legs).fit(Z, y, sequence_ids=ids)


def test_held_out_takes_are_judged_right_and_alive(bandai_judge, bandai_split):
    _, (Z, y, ids), _ = bandai_split
    # measured: 101 of 101 windows of the seven takes 006 (and 645 of 645
    # leaving out each take in turn)
    assert bandai_judge.score(Z, y, sequence_ids=ids) >= 0.99
    sequence_styles = bandai_judge.predict(Z, sequence_ids=ids, per="sequence")
    assert_array_equal(sequence_styles, bandai_judge.classes_)  # one take each
    verdict = bandai_judge.verdict(Z, y, sequence_ids=ids)
    assert len(verdict.starts) == 101
    # measured: 100 of 101 windows alive (one leg amplitude 0.73 of its style's)
    assert verdict.alive.mean() >= 0.95
    assert verdict.accepted.mean() >= 0.95
    assert np.all(np.abs(verdict.frequency_ratio - 1) <= 0.15)


def test_frozen_motion_gets_a_style_but_is_not_alive(bandai_judge, bandai_split):
    _, (Z, _, _), _ = bandai_split
    for frozen in (np.zeros((200, Z.shape[1])), np.repeat(Z[:1], 200, axis=0)):
        verdict = bandai_judge.verdict(frozen, "normal")
        # the classifier alone is sure of some style...
        assert verdict.proba.max(axis=1).min() > 0.9
        # ...but nothing moves
        assert_allclose(verdict.amplitude_ratio, 0.0, atol=1e-12)
        assert np.isnan(verdict.frequency_ratio).all()
        assert not verdict.alive.any() and not verdict.accepted.any()


# -------------------------------------------------------- synthetic motion
def _walks(periods, n_frames=240, amplitude=1.0):
    """One sine per style (its own period), two channels in antiphase."""
    t = np.arange(n_frames)[:, None]
    X = np.vstack(
        [amplitude * np.hstack([np.sin(2 * np.pi * t / p), -np.sin(2 * np.pi * t / p)])
         for p in periods]
    )  # fmt: skip
    ids = np.repeat(np.arange(len(periods)), n_frames)
    return X, ids


@pytest.fixture(scope="module")
def sine_judge():
    X, ids = _walks([30, 20])
    y = np.array(["slow", "fast"])[ids]
    return StyleJudge(window=60, stride=30).fit(X, y, sequence_ids=ids), X, y, ids


def test_liveliness_ratios_are_exact(sine_judge):
    judge, X, y, ids = sine_judge
    # the reference is the median real window: a full-period window of a sine
    # of amplitude 1 has standard deviation 1/sqrt(2)
    assert_allclose(judge.reference_amplitude_, np.sqrt(0.5), rtol=1e-12)
    assert_allclose(judge.reference_frequency_, [1 / 20, 1 / 30], atol=1 / 512)
    louder = judge.verdict(1.6 * X, y, sequence_ids=ids)
    assert_allclose(louder.amplitude_ratio, 1.6, rtol=1e-12)
    assert not louder.alive.any()  # 60% louder than the style
    slow_as_fast = judge.verdict(X[ids == 0], "fast")
    assert_allclose(slow_as_fast.frequency_ratio, 20 / 30, atol=0.02)
    assert not slow_as_fast.correct.any() and not slow_as_fast.alive.any()
    # without a style asked for, liveliness is against the judged style
    own = judge.verdict(X, sequence_ids=ids)
    assert_array_equal(own.requested, own.predicted)
    assert own.accepted.all()


def test_windows_cover_every_frame_and_the_end(sine_judge):
    judge, X, y, ids = sine_judge
    short_ids = np.repeat([4, 9], [130, 240])
    X2 = X[: 130 + 240]
    verdict = judge.verdict(X2, sequence_ids=short_ids)
    # 0, 30, 60 and the last window 70; 0, 30, ..., 180
    assert verdict.starts.tolist() == [0, 30, 60, 70] + list(range(0, 181, 30))
    assert verdict.sequence_ids.tolist() == [4] * 4 + [9] * 7
    window_proba = judge.predict_proba(X2, sequence_ids=short_ids, per="window")
    assert_allclose(window_proba, verdict.proba)
    # a frame's probabilities are the mean over the windows that hold it
    frame_proba = judge.predict_proba(X2, sequence_ids=short_ids)
    first = (
        np.concatenate(([0], np.cumsum([130])))[
            np.searchsorted([4, 9], verdict.sequence_ids)
        ]
        + verdict.starts
    )
    for frame in range(len(X2)):
        holding = (first <= frame) & (frame < first + 60)
        assert_allclose(frame_proba[frame], window_proba[holding].mean(axis=0))
    sequence_proba = judge.predict_proba(X2, sequence_ids=short_ids, per="sequence")
    assert_allclose(sequence_proba[0], window_proba[:4].mean(axis=0))
    assert judge.predict(X2, sequence_ids=short_ids).shape == (370,)


def test_windows_of_two_labels_are_left_out(sine_judge):
    judge, X, y, ids = sine_judge
    # one sequence that changes style at frame 240: windows starting at
    # 210 and 225 hold both styles
    one = np.zeros(len(X), dtype=int)
    fitted = clone(judge).set_params(stride=15).fit(X, y, sequence_ids=one)
    assert fitted.n_windows_ == len(range(0, 421, 15)) - 3  # 195, 210, 225 mixed
    assert fitted.score(X, y, sequence_ids=one) == 1.0


def test_a_transition_is_judged_against_the_last_frames_style(sine_judge):
    judge, X, y, ids = sine_judge
    one = np.zeros(len(X), dtype=int)
    verdict = judge.verdict(X, y, sequence_ids=one)
    assert_array_equal(verdict.requested, y[verdict.starts + 59])
    whole = (verdict.starts + 60 <= 240) | (verdict.starts >= 240)
    assert verdict.accepted[whole].all()


def test_input_errors(sine_judge):
    judge, X, y, ids = sine_judge
    with pytest.raises(ValueError, match="'proud' is not one of the judge's styles"):
        judge.verdict(X, "proud", sequence_ids=ids)
    with pytest.raises(ValueError, match=r"one label per frame \(480\), got shape"):
        judge.verdict(X, y[:10], sequence_ids=ids)
    with pytest.raises(ValueError, match="per must be 'frame', 'window' or 'seq"):
        judge.predict(X, sequence_ids=ids, per="take")
    with pytest.raises(ValueError, match="Sequence 1 has 20 frames, fewer than"):
        judge.predict(X[:260], sequence_ids=ids[:260])
    with pytest.raises(ValueError, match="stride=90 is larger than window=60"):
        clone(judge).set_params(stride=90).fit(X, y, sequence_ids=ids)
    with pytest.raises(ValueError, match="only one class"):
        clone(judge).fit(X, np.full(len(X), "slow"), sequence_ids=ids)
    with pytest.raises(ValueError, match=r"legs must be column indices of X"):
        clone(judge).set_params(legs=[0, 5]).fit(X, y, sequence_ids=ids)
    with pytest.raises(ValueError, match="No window of 60 frames .* \\['fast'\\]"):
        clone(judge).fit(X[:280], y[:280], sequence_ids=np.zeros(280, dtype=int))
    with pytest.raises(ValueError, match="sample_weight is not supported"):
        judge.score(X, y, sequence_ids=ids, sample_weight=np.ones(len(X)))
    with pytest.raises(ValueError, match="480 frames; give one label per frame"):
        judge.score(X, y[:-1], sequence_ids=ids)


def test_param_validation():
    check_param_validation("StyleJudge", StyleJudge())
