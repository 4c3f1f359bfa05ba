"""Utilities: sequence bookkeeping, and windows of real frames to seed generation."""

from ._sequences import (
    Sequences,
    balanced_batches,
    check_sequence_ids,
    frame_history,
    history_indices,
    shuffled_batches,
)
from ._windows import random_windows

__all__ = [
    "Sequences",
    "balanced_batches",
    "check_sequence_ids",
    "frame_history",
    "history_indices",
    "random_windows",
    "shuffled_batches",
]
