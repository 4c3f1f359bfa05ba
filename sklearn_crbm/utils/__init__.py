"""Utilities shared by the estimators: sequence bookkeeping."""

from ._sequences import (
    Sequences,
    balanced_batches,
    check_sequence_ids,
    frame_history,
    history_indices,
    shuffled_batches,
)

__all__ = [
    "Sequences",
    "balanced_batches",
    "check_sequence_ids",
    "frame_history",
    "history_indices",
    "shuffled_batches",
]
