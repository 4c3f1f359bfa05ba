"""Tests of the generated-motion statistics on motion with known answers."""

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from sklearn_crbm.metrics import (
    forward_speed,
    gait_statistics,
    motion_amplitude,
    nearest_style,
    spectral_similarity,
    step_frequency,
)

FRAME_RATE = 30.0


def gait(period, n_frames=150, amplitude=1.0, speed=0.7, phase=0.0, noise=0.0, seed=0):
    """Two legs in anti-phase with the given period (frames), and a speed channel."""
    rng = np.random.default_rng(seed)
    t = np.arange(n_frames)
    angle = 2 * np.pi * t / period + phase
    legs = amplitude * np.column_stack([np.sin(angle), -np.sin(angle), np.cos(angle)])
    forward = speed + 0.05 * np.sin(2 * angle)
    X = np.column_stack([forward, legs])
    return X + noise * rng.standard_normal(X.shape)


NAMES = np.array(["root_dforward", "lfemur_ex", "rfemur_ex", "ltibia_ex"], dtype=object)


def test_forward_speed_is_the_per_sequence_mean_of_the_named_channel():
    X = np.vstack([gait(30, speed=0.7), gait(21, speed=2.0)])
    ids = np.repeat([5, 3], 150)
    assert_allclose(
        forward_speed(X, sequence_ids=ids, feature_names=NAMES), [0.7, 2.0], atol=0.01
    )
    assert_allclose(
        forward_speed(X, sequence_ids=ids, feature=0), [0.7, 2.0], atol=0.01
    )
    # only the last frames
    X[140:150, 0] = 5.0
    assert forward_speed(X, sequence_ids=ids, feature=0, last_frames=10)[0] == 5.0


def test_forward_speed_finds_the_channel_of_any_root():
    X = np.vstack([gait(30, speed=0.7), gait(21, speed=2.0)])
    ids = np.repeat([0, 1], 150)
    hips = NAMES.copy()
    hips[0] = "Hips_dforward"
    assert_allclose(
        forward_speed(X, sequence_ids=ids, feature_names=hips), [0.7, 2.0], atol=0.01
    )
    two = np.array(["Hips_dforward", "root_dforward", "a", "b"], dtype=object)
    with pytest.raises(ValueError, match=r"found 2 .*Hips_dforward.*feature="):
        forward_speed(X, feature_names=two)


@pytest.mark.parametrize("period", [20, 30, 45])
def test_step_frequency_finds_the_gait_cycle(period):
    X = gait(period, noise=0.1)
    frequency = step_frequency(X, feature_names=NAMES, features=NAMES[1:])
    assert frequency[0] == pytest.approx(FRAME_RATE / period, rel=0.05)
    # frame rate scales it
    half = step_frequency(X, features=[1, 2, 3], frame_rate=15.0)
    assert half[0] == pytest.approx(15.0 / period, rel=0.05)


def test_step_frequency_of_still_or_tiny_sequences_is_nan():
    X = np.vstack([np.zeros((50, 4)), gait(30)[:3]])
    frequency = step_frequency(X, sequence_ids=np.repeat([0, 1], [50, 3]))
    assert np.isnan(frequency).all()


def test_motion_amplitude_is_rms_of_channel_standard_deviations():
    X = gait(30, n_frames=300, amplitude=2.0)
    # three leg channels: sines and a cosine of amplitude 2 -> std sqrt(2) each
    assert_allclose(motion_amplitude(X, features=[1, 2, 3]), [np.sqrt(2)], rtol=1e-2)
    dying = gait(30, n_frames=300, amplitude=2.0)
    dying[200:, 1:] *= 0.01
    assert motion_amplitude(dying, features=[1, 2, 3], last_frames=100)[0] < 0.05
    assert motion_amplitude(dying, features=[1, 2, 3])[0] > 1.0


def test_spectral_similarity_prefers_the_same_rhythm_over_scale_and_phase():
    reference = np.vstack([gait(30, seed=1, noise=0.05), gait(32, seed=2, noise=0.05)])
    reference_ids = np.repeat([0, 1], 150)
    candidates = np.vstack(
        [
            gait(31, amplitude=3.0, phase=1.0, noise=0.05),  # same rhythm, other scale
            gait(12, noise=0.05),  # much faster
            np.random.default_rng(0).standard_normal((150, 4)),  # noise
        ]
    )
    similarity = spectral_similarity(
        candidates,
        reference,
        sequence_ids=np.repeat([0, 1, 2], 150),
        reference_sequence_ids=reference_ids,
        features=[1, 2, 3],
    )
    assert similarity[0] > 0.9
    assert similarity[1] < 0.5
    assert similarity[2] < 0.8
    assert np.all((similarity >= 0) & (similarity <= 1 + 1e-12))
    assert_allclose(
        spectral_similarity(reference, reference, features=[1, 2, 3]), [1.0], atol=0.02
    )


def test_spectral_similarity_of_still_motion_is_nan_and_errors_are_clear():
    reference = gait(30)
    still = np.zeros((100, 4))
    assert np.isnan(spectral_similarity(still, reference))[0]
    with pytest.raises(ValueError, match="does not move"):
        spectral_similarity(reference, still)
    with pytest.raises(ValueError, match="features"):
        spectral_similarity(reference, reference[:, :3])
    with pytest.raises(ValueError, match="n_fft"):
        spectral_similarity(reference, reference, n_fft=2)


def test_nearest_style_uses_standardised_centroids():
    reference = np.array([[0.7, 0.9], [0.72, 0.85], [2.0, 1.35], [1.9, 1.4]])
    styles = ["walk", "walk", "jog", "jog"]
    labels = nearest_style([[0.8, 0.9], [1.8, 1.3], [np.nan, 1.0]], reference, styles)
    assert_array_equal(labels, np.array(["walk", "jog", None], dtype=object))
    # 1-D features work too
    assert_array_equal(
        nearest_style([0.5, 3.0], reference[:, 0], styles),
        np.array(["walk", "jog"], dtype=object),
    )
    with pytest.raises(ValueError, match="labels"):
        nearest_style([0.5], reference, styles[:3])
    with pytest.raises(ValueError, match="statistics"):
        nearest_style([[0.5, 1.0, 2.0]], reference, styles)


def test_bad_feature_selection_is_an_error():
    X = gait(30)
    with pytest.raises(ValueError, match="feature_names"):
        forward_speed(X)
    with pytest.raises(ValueError, match="named 'knee'"):
        motion_amplitude(X, features=["knee"], feature_names=NAMES)
    with pytest.raises(ValueError, match="out of range"):
        motion_amplitude(X, features=[7])
    with pytest.raises(ValueError, match="feature_names has 2"):
        forward_speed(X, feature_names=["a", "b"])
    with pytest.raises(ValueError, match="last_frames"):
        motion_amplitude(X, last_frames=0)
    with pytest.raises(ValueError, match="frame_rate"):
        step_frequency(X, frame_rate=0)
    with pytest.raises(ValueError, match="exactly one"):
        forward_speed(X, feature=[0, 1])


def test_gait_statistics_are_speed_and_leg_frequency_and_classify_styles():
    X = np.vstack([gait(30, speed=0.7), gait(21, speed=2.0), gait(28, speed=0.8)])
    ids = np.repeat([0, 1, 2], 150)
    stats = gait_statistics(
        X, sequence_ids=ids, feature_names=NAMES, legs=["lfemur", "rfemur", "ltibia"]
    )
    assert stats.shape == (3, 2)
    assert_array_equal(stats[:, 0], forward_speed(X, sequence_ids=ids, feature=0))
    assert_array_equal(
        stats[:, 1], step_frequency(X, sequence_ids=ids, features=[1, 2, 3])
    )
    assert_array_equal(
        nearest_style(stats[2:], stats[:2], ["walk", "jog"]), np.array(["walk"])
    )


def test_gait_statistics_name_the_missing_bone_and_need_names():
    X = gait(30)
    with pytest.raises(ValueError, match="No column belongs to bone 'rtibia'"):
        gait_statistics(X, feature_names=NAMES)  # the CMU default legs
    with pytest.raises(ValueError, match="feature_names"):
        gait_statistics(X, legs=["lfemur"])
    with pytest.raises(ValueError, match="No feature is named 'pelvis_dforward'"):
        gait_statistics(
            X, feature_names=NAMES, legs=["lfemur"], speed_feature="pelvis_dforward"
        )
