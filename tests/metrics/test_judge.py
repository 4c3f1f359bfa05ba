"""judge_generated_motion against the generation benchmarks' formulas."""

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import bone_columns, load_cmu35
from sklearn_crbm.metrics import (
    forward_speed,
    gait_statistics,
    judge_generated_motion,
    motion_amplitude,
    nearest_style,
    spectral_similarity,
)
from sklearn_crbm.preprocessing import make_motion_preprocessor

LEGS = ("lfemur", "rfemur", "ltibia", "rtibia")


@pytest.fixture(scope="module")
def cmu(data_home):
    cmu = load_cmu35(data_home, subset="train")
    pre = make_motion_preprocessor(cmu.skeleton)
    with sklearn.config_context(enable_metadata_routing=True):
        Z = pre.fit_transform(cmu.data, sequence_ids=cmu.sequence_ids)
    return cmu, pre, Z


def _generated(cmu, pre, Z):
    """Sequences of known fate: a walk, a jog, a frozen pose, a walk in place,
    a blow-up, a NaN."""
    trial = {k: Z[cmu.sequence_ids == k] for k in (0, 1, 2, 16)}
    frozen = np.tile(trial[1][:1], (60, 1))
    unscaled = pre[-1].inverse_transform(trial[2])
    unscaled[:, list(pre[:-1].get_feature_names_out()).index("root_dforward")] *= 0.2
    in_place = pre[-1].transform(unscaled)
    blown = trial[1] * 30.0
    broken = trial[0].copy()
    broken[10, 4] = np.nan
    sequences = [trial[0], trial[16], frozen, in_place, blown, broken]
    ids = np.repeat(np.arange(6), [len(s) for s in sequences])
    expected = np.array(["walk"] * 6, dtype=object)
    return np.vstack(sequences), ids, expected


def _benchmark_judge(X, ids, expected, Z, cmu, pre, last_frames):
    """The verdicts written from their definitions, as the old benchmark's judge."""
    names = np.asarray(pre.get_feature_names_out(), dtype=object)
    root_names = pre[:-1].get_feature_names_out()
    legs = list(names[bone_columns(names, LEGS)])
    styles = np.asarray(cmu.motion, dtype=object)

    def statistics(Y, y_ids, last=None):
        finite = np.clip(np.nan_to_num(Y, nan=0.0), -1e3, 1e3)
        gait = gait_statistics(
            finite, sequence_ids=y_ids, feature_names=names, last_frames=last
        )
        speed = forward_speed(
            pre[-1].inverse_transform(finite),
            sequence_ids=y_ids,
            feature_names=root_names,
            last_frames=last,
        )
        amplitude = motion_amplitude(
            finite,
            sequence_ids=y_ids,
            feature_names=names,
            features=legs,
            last_frames=last,
        )
        return gait, speed, amplitude

    train_gait, train_speed, train_amplitude = statistics(Z, cmu.sequence_ids)
    gait, speed, amplitude = statistics(X, ids, last_frames)
    style = nearest_style(gait, train_gait, styles)
    max_abs = np.array(
        [np.abs(np.nan_to_num(X[ids == k], nan=np.inf)).max() for k in np.unique(ids)]
    )
    dead = amplitude < 0.5 * train_amplitude.mean()
    stalled = speed < 0.5 * train_speed[styles == "walk"].mean()
    blown = max_abs > 10.0
    keeps = (style == expected) & ~dead & ~stalled & ~blown
    similarity = np.full(len(expected), np.nan)
    usable = np.array([np.isfinite(X[ids == k]).all() for k in np.unique(ids)])
    chosen = np.flatnonzero(usable & ~blown)
    real = np.isin(cmu.sequence_ids, np.flatnonzero(styles == "walk"))
    similarity[chosen] = spectral_similarity(
        X[np.isin(ids, chosen)],
        Z[real],
        sequence_ids=ids[np.isin(ids, chosen)],
        reference_sequence_ids=cmu.sequence_ids[real],
        last_frames=last_frames,
    )
    return dict(
        style=style,
        speed=speed,
        frequency=gait[:, 1],
        amplitude=amplitude,
        max_abs_value=max_abs,
        dead=dead,
        stalled=stalled,
        blown=blown,
        keeps=keeps,
        similarity=similarity,
    )


@pytest.mark.parametrize("last_frames", [None, 30])
def test_verdicts_are_the_generation_benchmarks(cmu, last_frames):
    cmu, pre, Z = cmu
    X, ids, expected = _generated(cmu, pre, Z)
    verdict = judge_generated_motion(
        X,
        Z,
        sequence_ids=ids,
        reference_sequence_ids=cmu.sequence_ids,
        reference_styles=cmu.motion,
        expected_styles=expected,
        preprocessor=pre,
        last_frames=last_frames,
    )
    oracle = _benchmark_judge(X, ids, expected, Z, cmu, pre, last_frames)
    assert sorted(verdict) == sorted(oracle)
    for key, value in oracle.items():
        assert_array_equal(verdict[key], value, err_msg=key)
    # the fates the sequences were built to have
    assert_array_equal(verdict.style[:2], ["walk", "jog"])
    assert_array_equal(verdict.keeps, [True, False, False, False, False, False])
    assert_array_equal(verdict.dead[:4], [False, False, True, False])
    assert_array_equal(verdict.stalled[:4], [False, False, False, True])
    assert_array_equal(verdict.blown, [False] * 4 + [True] * 2)
    assert np.isnan(verdict.similarity[4:]).all()
    assert (verdict.similarity[:4] > 0).all()


def test_real_motion_judged_against_itself_gives_its_speeds(cmu):
    cmu, pre, Z = cmu
    verdict = judge_generated_motion(
        Z,
        Z,
        sequence_ids=cmu.sequence_ids,
        reference_sequence_ids=cmu.sequence_ids,
        reference_styles=cmu.motion,
        preprocessor=pre,
    )
    # by hand: the root's mean step along the ground, in ASF length units
    for k, speed in enumerate(verdict.speed):
        root = cmu.data[cmu.sequence_ids == k][:, [0, 2]]
        step = np.linalg.norm(np.diff(root, axis=0), axis=1).mean()
        assert speed == pytest.approx(step, rel=0.05)
    styles = np.asarray(cmu.motion)
    assert (verdict.style == styles).mean() > 0.9
    assert not (verdict.dead | verdict.stalled).any()


def test_bad_labels_say_what_is_wrong(cmu):
    cmu, pre, Z = cmu
    common = dict(reference_sequence_ids=cmu.sequence_ids, preprocessor=pre)
    with pytest.raises(ValueError, match="one style per reference sequence"):
        judge_generated_motion(Z[:50], Z, reference_styles=["walk"], **common)
    with pytest.raises(ValueError, match="expected_styles has 2 labels"):
        judge_generated_motion(
            Z[:50],
            Z,
            reference_styles=cmu.motion,
            expected_styles=["walk", "jog"],
            **common,
        )
    with pytest.raises(ValueError, match="has 3 columns but the preprocessor"):
        judge_generated_motion(Z[:50, :3], Z, reference_styles=cmu.motion, **common)
