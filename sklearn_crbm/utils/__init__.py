"""Utilities: sequence bookkeeping, minibatch plans, and windows of real frames.

:func:`check_sequence_ids` and :class:`Sequences` check ``sequence_ids`` and
say where each sequence starts and stops; :func:`history_indices` and
:func:`frame_history` gather the past of frames by index arithmetic;
:func:`shuffled_batches` and :func:`balanced_batches` plan minibatches;
:func:`random_windows` picks windows of real frames to seed generation.
"""

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
