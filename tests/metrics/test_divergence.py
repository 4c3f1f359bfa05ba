"""Tests of metrics.divergence against constructed sequences."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from sklearn_crbm.metrics import divergence


def _cycle(n_frames=600, phase=0.0):
    t = np.arange(n_frames) / 7.0 + phase
    return np.column_stack([np.sin(t), 2 * np.cos(t), 0.5 * np.sin(2 * t)])


def test_copies_diverge_by_zero():
    X = np.stack([_cycle()] * 4)
    assert divergence(X) == 0.0


def test_independent_noise_diverges_by_about_one():
    rng = np.random.default_rng(0)
    X = rng.normal(3.0, 2.0, size=(6, 2000, 5))
    assert_allclose(divergence(X), 1.0, atol=0.02)


def test_a_shifted_copy_diverges_by_its_phase():
    # sin against sin shifted by phi: RMS difference sqrt(2 (1 - cos phi)) sigma
    for phi in (np.pi / 6, np.pi / 2, np.pi):
        X = np.stack([_cycle(phase=0.0)[:, :2], _cycle(phase=phi)[:, :2]])
        assert_allclose(divergence(X), np.sqrt(1 - np.cos(phi)), atol=0.01)


def test_long_format_matches_three_d_and_frames_are_per_sequence():
    rng = np.random.default_rng(1)
    X = rng.standard_normal((3, 50, 4))
    X[:, :20] = X[0, :20]  # the sequences start as copies, then part
    ids = np.repeat([7, 3, 5], 50)
    long = X.reshape(-1, 4)
    assert_allclose(divergence(long, sequence_ids=ids), divergence(X))
    assert divergence(X, frames=slice(0, 20)) == pytest.approx(0.0, abs=1e-12)
    assert divergence(X, frames=slice(20, None)) > 0.8
    assert_allclose(
        divergence(X, frames=np.arange(20, 50)), divergence(X, frames=slice(20, 50))
    )
    assert_allclose(divergence(X, features=[0, 2]), divergence(X[:, :, [0, 2]]))


def test_scale_of_the_channels_weighs_them():
    # a still channel with noise on it barely counts; a scaled copy counts fully
    X = np.stack([_cycle()[:, :1], _cycle()[:, :1]])
    rng = np.random.default_rng(2)
    quiet = 1e-3 * rng.standard_normal((2, 600, 1))
    assert divergence(np.concatenate([X, quiet], axis=2)) < 5e-3
    assert_allclose(divergence(3 * X + 1), divergence(X))


@pytest.mark.parametrize(
    "X, kwargs, match",
    [
        (np.zeros((1, 10, 2)), {}, "at least 2"),
        (np.ones((20, 2)), {}, "holds one"),
        (np.ones((20, 2)), {"sequence_ids": np.repeat([0, 1], [8, 12])}, "same number"),
        (np.ones((2, 10, 2)), {"sequence_ids": np.zeros(20, int)}, "only with a 2-D"),
        (np.ones((2, 10, 2)), {}, "do not move"),
        (np.ones((2, 10, 2)), {"frames": slice(0, 1)}, "at least 2 frames"),
        (np.ones((2, 10, 2)), {"frames": [0, 10]}, "beyond"),
        (np.ones((2, 10, 2)), {"frames": [0.5, 1.5]}, "frame indices"),
        (np.ones((2, 10, 2)), {"features": [2]}, "beyond"),
    ],
)
def test_bad_input_is_refused(X, kwargs, match):
    with pytest.raises(ValueError, match=match):
        divergence(X, **kwargs)


def test_non_finite_input_is_refused():
    X = np.zeros((2, 10, 2))
    X[0, 3, 1] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        divergence(X)
