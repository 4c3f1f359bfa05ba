"""What fit keeps of the training data must not copy the data."""

import tracemalloc

import numpy as np

from sklearn_crbm.metrics._liveliness import generation_statistics
from sklearn_crbm.utils._sequences import check_sequence_ids


def test_generation_statistics_do_not_copy_the_data():
    # a float64 copy of X alone would be twice X's size
    rng = np.random.default_rng(0)
    X = rng.normal(size=(1_000_000, 8)).astype(np.float32)
    sequences = check_sequence_ids(np.repeat(np.arange(10_000), 100), X.shape[0])
    tracemalloc.start()
    try:
        base, _ = tracemalloc.get_traced_memory()
        statistics = generation_statistics(X, sequences)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak - base < X.nbytes / 2
    X64 = X.astype(np.float64)
    mean = X64.mean(axis=0)
    np.testing.assert_array_equal(statistics.mean, mean)
    assert statistics.scale == X64.std(axis=0).max()
    np.testing.assert_array_equal(statistics.reach, np.abs(X64 - mean).max(axis=0))


def test_generation_statistics_of_labels_do_not_copy_them():
    rng = np.random.default_rng(0)
    X = rng.normal(size=(1_000_000, 8)).astype(np.float32)
    labels = np.full((X.shape[0], 8), 1 / 8, dtype=np.float32)
    sequences = check_sequence_ids(np.repeat(np.arange(10_000), 100), X.shape[0])
    tracemalloc.start()
    try:
        base, _ = tracemalloc.get_traced_memory()
        statistics = generation_statistics(X, sequences, labels)
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert peak - base < labels.nbytes / 2
    np.testing.assert_allclose(statistics.label_weight, 1_000_000 / 8)
