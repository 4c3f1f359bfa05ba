"""Seed windows of real frames: which sequences, which frames, reproducibility."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.utils import random_windows

# frame value = 100 * sequence + position in the sequence
LENGTHS = [5, 2, 8]
IDS = np.repeat([4, 7, 9], LENGTHS)
X = np.column_stack(
    [100 * IDS + np.concatenate([np.arange(n) for n in LENGTHS]), np.zeros(15)]
).astype(float)


def test_windows_are_consecutive_frames_of_one_chosen_sequence():
    windows = random_windows(
        X, sequence_ids=IDS, width=3, n_windows=50, sequences=[4, 9], random_state=0
    )
    assert windows.shape == (50, 3, 2)
    sequence = windows[:, :, 0] // 100
    assert_array_equal(sequence, sequence[:, :1].repeat(3, axis=1))
    assert set(sequence[:, 0]) == {4, 9}
    assert_array_equal(np.diff(windows[:, :, 0], axis=1), 1)


def test_sequences_shorter_than_the_window_are_never_drawn():
    windows = random_windows(X, sequence_ids=IDS, width=3, n_windows=30, random_state=1)
    assert 7 not in set(windows[:, 0, 0] // 100)
    with pytest.raises(ValueError, match="No sequence to draw from has 3 frames"):
        random_windows(X, sequence_ids=IDS, width=3, sequences=[7])


def test_same_seed_same_windows_and_a_generator_continues_its_stream():
    a = random_windows(X, sequence_ids=IDS, width=2, n_windows=4, random_state=3)
    b = random_windows(X, sequence_ids=IDS, width=2, n_windows=4, random_state=3)
    assert_array_equal(a, b)
    rng = np.random.default_rng(3)
    first = random_windows(X, sequence_ids=IDS, width=2, n_windows=2, random_state=rng)
    second = random_windows(X, sequence_ids=IDS, width=2, n_windows=2, random_state=rng)
    assert_array_equal(np.concatenate([first, second]), a)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"width": 0}, "width must be a positive integer"),
        ({"width": 2, "n_windows": 1.5}, "n_windows must be a positive integer"),
        ({"width": 2, "sequences": [5]}, "ids not in sequence_ids"),
    ],
)
def test_bad_arguments(kwargs, match):
    with pytest.raises(ValueError, match=match):
        random_windows(X, sequence_ids=IDS, **kwargs)
