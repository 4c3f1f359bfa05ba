"""liveliness, most_moving_channels, jitter and foot_skating: exact values."""

import numpy as np
import pytest

from sklearn_crbm.metrics import (
    foot_skating,
    jitter,
    liveliness,
    most_moving_channels,
)


def test_most_moving_channels_rank_within_sequence_motion():
    t = np.arange(100)
    wave = np.sin(2 * np.pi * t / 25)
    # column 2 differs between the sequences but stands still within each
    X = np.column_stack([wave, 3 * wave, np.repeat([0.0, 50.0], 50), 2 * wave])
    ids = np.repeat([0, 1], 50)
    assert most_moving_channels(X, sequence_ids=ids, n_channels=3).tolist() == [1, 3, 0]
    assert most_moving_channels(X, sequence_ids=ids, features=[0, 2]).tolist() == [0, 2]
    with pytest.raises(ValueError, match="n_channels must be a positive integer"):
        most_moving_channels(X, n_channels=0)


def test_liveliness_is_the_ratio_of_mean_standard_deviations():
    t = np.arange(100)
    real = np.column_stack([np.sin(2 * np.pi * t / 25), 0.01 * t % 1])
    half = 0.5 * real
    frozen = np.zeros_like(real)
    X = np.vstack([real, half, frozen])
    ids = np.repeat([0, 1, 2], 100)
    value = liveliness(X, real, sequence_ids=ids, n_channels=1)
    assert value == pytest.approx([1.0, 0.5, 0.0])
    # the judged channels are the reference's, whatever X does elsewhere
    noisy = real.copy()
    noisy[:, 1] += np.random.default_rng(0).normal(size=100)
    assert liveliness(noisy, real, n_channels=1) == pytest.approx([1.0])
    with pytest.raises(ValueError, match="does not move"):
        liveliness(X, np.ones((10, 2)))


def test_jitter_is_the_mean_norm_of_the_third_difference():
    rng = np.random.default_rng(0)
    positions = rng.normal(size=(20, 4, 3))
    third = np.diff(positions, n=3, axis=0)
    expected = np.linalg.norm(third, axis=2).mean()
    assert jitter(positions) == pytest.approx([expected])
    assert jitter(positions.reshape(20, 12)) == pytest.approx([expected])
    cubic = np.arange(10.0)[:, None, None] ** 2 * np.ones((1, 2, 3))
    assert jitter(cubic) == pytest.approx([0.0])
    assert np.isnan(jitter(positions[:3])).all()
    with pytest.raises(ValueError, match=r"shape \(n_frames, n_joints, 3\)"):
        jitter(np.zeros((5, 4)))


def test_foot_skating_counts_horizontal_motion_while_down():
    # a foot planted for 3 frames while sliding 1 unit a frame, then lifted
    height = np.array([0.0, 1.0, 2.0, 20.0, 20.0])
    forward = np.array([0.0, 1.0, 2.0, 10.0, 20.0])
    side = np.zeros(5)
    foot = np.column_stack([forward, height, side])[:, None, :]
    assert foot_skating(foot, feet=[0]) == pytest.approx([(1 + 1 + 8) / 3])
    # z up: the same foot on its side
    z_up = foot[:, :, [0, 2, 1]]
    assert foot_skating(z_up, feet=[0], up_axis=2) == pytest.approx([10 / 3])
    assert foot_skating(foot, feet=[0], contact_height=0.5) == pytest.approx([1.0])
    with pytest.raises(ValueError, match="up_axis must be 0, 1 or 2"):
        foot_skating(foot, feet=[0], up_axis=3)
