import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.utils import (
    balanced_batches,
    check_sequence_ids,
    frame_history,
    history_indices,
    shuffled_batches,
)


def test_none_means_one_sequence():
    seqs = check_sequence_ids(None, 7)
    assert_array_equal(seqs.starts, [0])
    assert_array_equal(seqs.lengths, [7])
    assert_array_equal(seqs.valid_frames(3), [3, 4, 5, 6])


def test_runs_are_found_in_order_of_appearance():
    ids = np.array([5, 5, 5, 2, 2, 9, 9, 9, 9])
    seqs = check_sequence_ids(ids, len(ids))
    assert_array_equal(seqs.starts, [0, 3, 5])
    assert_array_equal(seqs.lengths, [3, 2, 4])
    assert_array_equal(seqs.ids, [5, 2, 9])
    assert_array_equal(seqs.per_frame_ids(), ids)
    assert_array_equal(seqs.frame_starts(), [0, 0, 0, 3, 3, 5, 5, 5, 5])
    # order 2: the 2-frame sequence has no valid frame
    assert_array_equal(seqs.valid_frames(2), [2, 7, 8])
    assert_array_equal(seqs.valid_frames(0), np.arange(9))


def test_integral_floats_are_accepted():
    seqs = check_sequence_ids(np.array([0.0, 0.0, 1.0]), 3)
    assert_array_equal(seqs.lengths, [2, 1])


@pytest.mark.parametrize(
    "ids, error, match",
    [
        (np.array([0, 1, 0]), ValueError, "sequence id 0 occurs in more than one"),
        (np.array([0, 0]), ValueError, "2 entries but X has 3 frames"),
        (np.array([[0, 0, 0]]), ValueError, "1-D"),
        (np.array([0.0, np.nan, 1.0]), ValueError, "NaN"),
        (np.array([0.5, 0.5, 1.0]), TypeError, "integers"),
        (np.array(["a", "a", "b"]), TypeError, "integers"),
        (np.array([True, True, False]), TypeError, "integers"),
    ],
)
def test_bad_sequence_ids(ids, error, match):
    with pytest.raises(error, match=match):
        check_sequence_ids(ids, 3)


def test_history_indices_clip_at_sequence_start():
    frames = np.array([0, 1, 5, 6])
    starts = np.array([0, 0, 5, 5])
    assert_array_equal(
        history_indices(frames, 2, starts), [[0, 0], [0, 0], [5, 5], [5, 5]]
    )
    assert_array_equal(history_indices(np.array([4]), 3), [[3, 2, 1]])


def test_frame_history_is_lag_major():
    X = np.arange(12.0).reshape(6, 2)
    hist = frame_history(X, np.array([3, 5]), 2)
    assert_array_equal(hist, [[4, 5, 2, 3], [8, 9, 6, 7]])
    out = np.empty((2, 4))
    assert frame_history(X, np.array([3, 5]), 2, out=out) is out
    assert_array_equal(out, hist)


@pytest.mark.parametrize("plan", [balanced_batches, shuffled_batches])
@pytest.mark.parametrize(
    "n_frames, batch_size", [(1000, 100), (1037, 100), (7, 100), (250, 1)]
)
def test_batch_plans_cover_every_frame_once(plan, n_frames, batch_size):
    frames = np.arange(10, 10 + n_frames)
    batches = plan(frames, batch_size, np.random.default_rng(0))
    assert all(0 < len(b) <= batch_size for b in batches)
    assert_array_equal(np.sort(np.concatenate(batches)), frames)
    assert len(batches) == -(-n_frames // batch_size)


def test_balanced_batches_draw_from_the_whole_data_set():
    frames = np.arange(2000)
    for batch in balanced_batches(frames, 100, np.random.default_rng(1)):
        # one frame from each chunk of 20 consecutive frames: spread over all of it
        assert_array_equal(np.sort(batch) // 20, np.arange(100))


def test_empty_frames_give_no_batches():
    assert balanced_batches(np.empty(0, dtype=int), 10, np.random.default_rng(0)) == []
    assert shuffled_batches(np.empty(0, dtype=int), 10, np.random.default_rng(0)) == []
