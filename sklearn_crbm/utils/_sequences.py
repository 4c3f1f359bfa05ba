"""Sequence bookkeeping: ``sequence_ids`` checks, history indexing, minibatch plans.

Data is in long format: ``X`` has shape ``(n_frames, n_features)`` with all
sequences stacked, each one contiguous and in time order.  ``sequence_ids``
holds one integer per frame; equal ids mark one sequence.  Everything that
needs the past of a frame gets it from here by index arithmetic, so no
estimator ever materialises the history of the whole data set.
"""

import warnings
import weakref
from dataclasses import dataclass
from numbers import Integral

import numpy as np

from ._array_api import array_ops

__all__ = [
    "CHUNK_FRAMES",
    "Sequences",
    "balanced_batches",
    "check_sequence_ids",
    "frame_history",
    "history_indices",
    "shuffled_batches",
    "remember_sequences",
    "validation_split",
    "warn_if_sequences_unmarked",
]


# Frames whose histories are gathered at once by the loops over whole data
# sets (transform, score and friends): bounds their memory on long data.
CHUNK_FRAMES = 4096


# Arrays whose sequences a loader knows: id(array) -> _LoadedSequences; see
# remember_sequences.
_KNOWN_SEQUENCES = {}
# Rows of X looked up in a loader's array before X counts as made of them.
_PROBE_ROWS = 16


class _LoadedSequences:
    """What a loader said of its array: a weak reference and the sequence ids."""

    def __init__(self, X, sequence_ids):
        key = id(X)
        forget = lambda _, key=key: _KNOWN_SEQUENCES.pop(key, None)  # noqa: E731
        self.reference = weakref.ref(X, forget)
        self.sequence_ids = np.asarray(sequence_ids)
        self._sorted = None

    def rows_of(self, data, X):
        """The row of ``data`` equal to each row of ``X`` (-1 where none),
        matched by a 64-bit hash of the rows' bytes: 16 bytes a row of
        ``data``, built on the first look-up."""
        hashes, order, _ = self._hash_index(data)
        wanted = _row_hashes(X)
        at = np.minimum(np.searchsorted(hashes, wanted), len(hashes) - 1)
        return np.where(hashes[at] == wanted, order[at], -1)

    def repeated_rows(self, data):
        """Where a row of ``data`` equals another row (a frame that two
        takes, or two moments of one, share): such a row says nothing of
        which sequence a copy of it came from."""
        return self._hash_index(data)[2]

    def _hash_index(self, data):
        if self._sorted is None:
            hashes = _row_hashes(data)
            order = np.argsort(hashes, kind="stable")
            sorted_hashes = hashes[order]
            repeated = np.zeros(len(hashes), dtype=bool)
            same = sorted_hashes[1:] == sorted_hashes[:-1]
            repeated[order[1:][same]] = repeated[order[:-1][same]] = True
            self._sorted = sorted_hashes, order, repeated
        return self._sorted


def _row_hashes(X):
    """A 64-bit hash of the bytes of every row (multiply and add, mod 2**64)."""
    rows = np.ascontiguousarray(X).view(np.uint8).reshape(len(X), -1)
    padding = -rows.shape[1] % 8
    if padding:
        rows = np.pad(rows, ((0, 0), (0, padding)))
    words = rows.view(np.uint64)
    multipliers = np.random.default_rng(0).integers(
        1, 2**63, size=words.shape[1], dtype=np.uint64
    ) * np.uint64(2) + np.uint64(1)
    return (words * multipliers).sum(axis=1, dtype=np.uint64)


def remember_sequences(X, sequence_ids):
    """Note that the array ``X`` (a loader's result) holds the sequences of
    ``sequence_ids``, so that a ``fit`` given ``X`` or rows of it without
    them, or a split that cuts them, can warn."""
    _KNOWN_SEQUENCES[id(X)] = _LoadedSequences(X, sequence_ids)


def _viewed_loader_ids(X):
    """The loader's sequence ids of ``X``, a loader's array or a view of it."""
    while isinstance(X, np.ndarray):
        entry = _KNOWN_SEQUENCES.get(id(X))
        if entry is not None and entry.reference() is X:
            return entry.sequence_ids
        if X.base is None or len(X.base) != len(X):
            return None
        X = X.base
    return None


def _copied_loader_ids(X):
    """The loader's sequence id of every row of ``X``, where each row of ``X``
    is a row of a loader's array (a cross-validation fold, a selection)."""
    probe = np.unique(np.linspace(0, len(X) - 1, _PROBE_ROWS).astype(np.intp))
    for entry in list(_KNOWN_SEQUENCES.values()):
        data = entry.reference()
        if data is None or data.shape[1:] != X.shape[1:] or data.dtype != X.dtype:
            continue
        if (entry.rows_of(data, X[probe]) < 0).any():
            continue
        rows = entry.rows_of(data, X)
        if (rows >= 0).all():
            # rows that several frames share are left out of the count
            repeated = entry.repeated_rows(data)
            rows = rows[~repeated[rows]]
            return entry.sequence_ids[rows], entry.sequence_ids[~repeated]
    return None


def _loader_sequences(X):
    """``(ids of X's rows, ids of the loader's whole array)``, or None when
    ``X`` is not made of a loader's rows."""
    if not isinstance(X, np.ndarray) or X.ndim != 2 or len(X) == 0:
        return None
    ids = _viewed_loader_ids(X)
    if ids is not None:
        return ids, ids
    return _copied_loader_ids(X)


def _cut_sequences(row_ids, all_ids):
    """The sequences of which ``row_ids`` holds some frames but not all."""
    present, counts = np.unique(row_ids, return_counts=True)
    ids, totals = np.unique(all_ids, return_counts=True)
    whole = dict(zip(ids.tolist(), totals.tolist(), strict=True))
    return [
        s
        for s, n in zip(present.tolist(), counts.tolist(), strict=True)
        if n < whole[s]
    ]


def stack_sequences(sequences):
    """Sequences of frames in long format: ``(data, sequence_ids)``.

    The frames of every sequence, one after the other, and the sequence
    number of every frame (0 for the first sequence); the loader's ids are
    remembered for :func:`warn_if_sequences_unmarked`.
    """
    data = np.concatenate(sequences)
    sequence_ids = np.repeat(np.arange(len(sequences)), [len(s) for s in sequences])
    remember_sequences(data, sequence_ids)
    return data, sequence_ids


def warn_if_sequences_unmarked(X, sequence_ids, method, stacklevel=3):
    """Warn when ``X`` holds frames of several of a loader's sequences and
    ``sequence_ids`` is None (every frame would count as one sequence), or
    when a split cut one or two of them in the middle (as ``KFold`` does)."""
    found = _loader_sequences(X)
    if found is None:
        return
    row_ids, all_ids = found
    n_sequences = len(np.unique(row_ids))
    cut = _cut_sequences(row_ids, all_ids)
    split_advice = (
        "to cross-validate, split whole sequences: cv=GroupKFold() with "
        "groups=data.sequence_ids."
    )
    if sequence_ids is None and n_sequences >= 2:
        warnings.warn(
            f"{method} got no sequence_ids, but X holds frames of {n_sequences} "
            "sequences (files) of a loader's result: they are treated as one "
            "sequence, and the jumps between them as motion. Pass sequence_ids="
            "data.sequence_ids (through a Pipeline, after sklearn.set_config("
            "enable_metadata_routing=True)); " + split_advice,
            UserWarning,
            stacklevel=stacklevel,
        )
    elif n_sequences >= 2 and 1 <= len(cut) <= 2:
        warnings.warn(
            f"{method}: X holds whole sequences of a loader's result and only "
            f"part of {len(cut)} (ids {cut}), as when a split such as KFold cuts "
            "sequences in the middle: the frames of a cut sequence are scored "
            "or trained without the frames before them. If that is not meant, "
            + split_advice,
            UserWarning,
            stacklevel=stacklevel,
        )


@dataclass(frozen=True)
class Sequences:
    """Where each sequence of a long-format array starts and how long it is.

    Attributes
    ----------
    starts : ndarray of shape (n_sequences,)
        Index of the first frame of each sequence, in order of appearance.
    lengths : ndarray of shape (n_sequences,)
        Number of frames of each sequence.
    ids : ndarray of shape (n_sequences,)
        The id of each sequence as given by the user (``arange`` when the
        user gave ``None``).
    """

    starts: np.ndarray
    lengths: np.ndarray
    ids: np.ndarray

    @property
    def n_frames(self):
        return int(self.lengths.sum())

    @property
    def n_sequences(self):
        return len(self.starts)

    @property
    def stops(self):
        return self.starts + self.lengths

    def frame_starts(self):
        """Index of the first frame of its sequence, for every frame."""
        return np.repeat(self.starts, self.lengths)

    def valid_frames(self, order):
        """Indices of the frames that have ``order`` past frames in their sequence."""
        first = self.starts + order
        counts = np.maximum(self.stops - first, 0)
        return _ranges(first, counts)

    def frames_with_past(self, order, needed_by):
        """:meth:`valid_frames`; a ValueError naming ``needed_by`` if there are none."""
        frames = self.valid_frames(order)
        if len(frames) == 0:
            raise ValueError(
                f"{needed_by} needs frames with {order} past frames in their own "
                "sequence; every sequence given is shorter. Pass longer sequences."
            )
        return frames

    def per_frame_ids(self):
        """Sequence id of every frame."""
        return np.repeat(self.ids, self.lengths)


def _ranges(starts, counts):
    """Concatenate ``arange(s, s + c)`` for every pair, without a Python loop."""
    counts = np.asarray(counts, dtype=np.intp)
    total = int(counts.sum())
    if total == 0:
        return np.empty(0, dtype=np.intp)
    offsets = np.repeat(
        np.asarray(starts, dtype=np.intp) - np.cumsum(counts) + counts, counts
    )
    return offsets + np.arange(total, dtype=np.intp)


def check_sequence_ids(sequence_ids, n_frames):
    """Validate ``sequence_ids`` and describe the sequences it marks.

    Parameters
    ----------
    sequence_ids : array-like of shape (n_frames,) or None
        One integer id per frame.  Each id must form exactly one contiguous
        run.  ``None`` means that all frames form one sequence.
    n_frames : int
        Number of rows of the ``X`` the ids belong to.

    Returns
    -------
    sequences : Sequences
        Start and length of every sequence.

    Raises
    ------
    ValueError
        If the ids have the wrong shape or length, contain NaN, or an id
        occurs in more than one run.
    TypeError
        If the ids are not integers.
    """
    if sequence_ids is None:
        return Sequences(
            starts=np.zeros(1 if n_frames else 0, dtype=np.intp),
            lengths=np.full(1 if n_frames else 0, n_frames, dtype=np.intp),
            ids=np.zeros(1 if n_frames else 0, dtype=np.intp),
        )
    if hasattr(sequence_ids, "toarray") or hasattr(sequence_ids, "tocsr"):
        raise TypeError(
            "sequence_ids must be a dense 1-D array of integers, got a sparse matrix."
        )
    ids = np.asarray(sequence_ids)
    if ids.ndim != 1:
        raise ValueError(
            f"sequence_ids must be 1-D with one id per frame, got an array of "
            f"shape {ids.shape}."
        )
    if ids.shape[0] != n_frames:
        raise ValueError(
            f"sequence_ids has {ids.shape[0]} entries but X has {n_frames} frames; "
            "pass one sequence id per row of X."
        )
    ids = _as_integer_ids(ids)
    if n_frames == 0:
        empty = np.empty(0, dtype=np.intp)
        return Sequences(starts=empty, lengths=empty.copy(), ids=ids[:0])
    change = np.flatnonzero(ids[1:] != ids[:-1]) + 1
    starts = np.concatenate(([0], change)).astype(np.intp)
    run_ids = ids[starts]
    unique, counts = np.unique(run_ids, return_counts=True)
    if np.any(counts > 1):
        offending = unique[counts > 1][0].item()
        raise ValueError(
            f"sequence id {offending!r} occurs in more than one contiguous run of "
            "frames; each sequence must be stored as one contiguous block in time "
            "order. Sort X and sequence_ids by (sequence, time) or give the runs "
            "distinct ids."
        )
    lengths = np.diff(np.concatenate((starts, [n_frames]))).astype(np.intp)
    return Sequences(starts=starts, lengths=lengths, ids=run_ids)


def _as_integer_ids(ids):
    kind = ids.dtype.kind
    if kind in "iu":
        return ids
    if kind == "b":
        raise TypeError("sequence_ids must be integers, got booleans.")
    if kind == "f":
        if not np.all(np.isfinite(ids)):
            raise ValueError(
                "sequence_ids contains NaN or infinity; give every frame an "
                "integer sequence id."
            )
        if np.any(ids != np.round(ids)):
            raise TypeError(
                "sequence_ids must be integers, got non-integral floats; give "
                "every frame an integer sequence id."
            )
        if np.any(np.abs(ids) >= 2.0**63):
            raise ValueError(
                "sequence_ids holds ids beyond the 64-bit integer range; number "
                "the sequences 0, 1, 2, ..."
            )
        return ids.astype(np.int64)
    if kind == "O":
        try:
            as_int = ids.astype(np.int64)
        except OverflowError:
            raise ValueError(
                "sequence_ids holds ids beyond the 64-bit integer range; number "
                "the sequences 0, 1, 2, ..."
            ) from None
        except (TypeError, ValueError) as exc:
            raise TypeError(
                "sequence_ids must be integers; got objects that are not. Map "
                "sequence names to integers, e.g. with np.unique(names, "
                "return_inverse=True)."
            ) from exc
        if not np.array_equal(as_int, ids):
            raise TypeError("sequence_ids must be integers.")
        return as_int
    raise TypeError(
        f"sequence_ids must be integers, got dtype {ids.dtype}. Map sequence "
        "names to integers, e.g. with np.unique(names, return_inverse=True)."
    )


def history_indices(frames, n_lags, frame_starts=None):
    """Row indices of the ``n_lags`` past frames of each frame, most recent first.

    Parameters
    ----------
    frames : ndarray of shape (n,)
        Indices of the frames whose history is wanted.
    n_lags : int
        How many past frames.
    frame_starts : ndarray of shape (n,), default=None
        First frame of the sequence of each frame.  When given, a lag that
        would reach before the start of the sequence is clipped to that start
        (the first frame is repeated); when None the caller guarantees that
        every frame has a full history.

    Returns
    -------
    indices : ndarray of shape (n, n_lags)
        ``indices[i, q - 1]`` is the row of frame ``frames[i] - q``.
    """
    lags = np.arange(1, n_lags + 1, dtype=np.intp)
    indices = np.asarray(frames, dtype=np.intp)[:, None] - lags
    if frame_starts is not None:
        np.maximum(
            indices, np.asarray(frame_starts, dtype=np.intp)[:, None], out=indices
        )
    return indices


def frame_history(X, frames, n_lags, frame_starts=None, out=None):
    """Gather the flattened history ``[x[t-1], ..., x[t-n_lags]]`` of each frame.

    Returns an array of shape ``(len(frames), n_lags * n_features)`` whose
    block ``q - 1`` holds frame ``t - q``.
    """
    n_features = X.shape[1]
    on_device = hasattr(frames, "__array_namespace__") and not isinstance(
        frames, np.ndarray
    )
    if on_device and frame_starts is None:
        # frames on the device (a training minibatch): indices there too
        lags = array_ops(frames).arange(1, n_lags + 1, dtype=frames.dtype)
        indices = frames[:, None] - lags
    else:
        indices = history_indices(frames, n_lags, frame_starts)
    if not isinstance(X, np.ndarray):  # another array API namespace
        ops = array_ops(X)
        if isinstance(indices, np.ndarray):
            indices = ops.asarray(indices)
        gathered = ops.take(X, ops.reshape(indices, (-1,)), axis=0)
        flat = ops.reshape(gathered, (indices.shape[0], n_lags * n_features))
        return ops._into(out, flat)
    if out is None:
        return X[indices.ravel()].reshape(len(indices), n_lags * n_features)
    # mode="clip": with mode="raise" numpy buffers ``out`` (several times slower)
    np.take(X, indices.ravel(), axis=0, out=out.reshape(-1, n_features), mode="clip")
    return out


def validation_split(sequences, fraction, rng):
    """Hold out whole sequences: a boolean mask of the validation frames.

    Sequences are taken in a random order until they hold at least
    ``fraction`` of the frames; at least one is held out and at least one
    kept.

    Raises
    ------
    ValueError
        If there are fewer than two sequences.
    """
    if sequences.n_sequences < 2:
        raise ValueError(
            "early_stopping holds out whole sequences for validation, but the "
            "data is a single sequence; pass sequence_ids marking several "
            "sequences, or early_stopping=False."
        )
    order = rng.permutation(sequences.n_sequences)
    held = np.cumsum(sequences.lengths[order]) < fraction * sequences.n_frames
    count = min(max(int(held.sum()) + 1, 1), sequences.n_sequences - 1)
    mask = np.zeros(sequences.n_frames, dtype=bool)
    for k in order[:count]:
        mask[sequences.starts[k] : sequences.stops[k]] = True
    return mask


def _check_batch_size(batch_size):
    if isinstance(batch_size, bool) or not isinstance(batch_size, Integral):
        raise TypeError(f"batch_size must be an integer, got {batch_size!r}.")
    if batch_size < 1:
        raise ValueError(f"batch_size must be at least 1, got {batch_size!r}.")


def shuffled_batches(frames, batch_size, rng):
    """The original code's plan: all valid frames shuffled, cut into batches.

    Returns a list of index arrays; only the last batch may be smaller.
    """
    _check_batch_size(batch_size)
    order = rng.permutation(frames)
    return [order[i : i + batch_size] for i in range(0, len(order), batch_size)]


def balanced_batches(frames, batch_size, rng):
    """The paper's plan: every batch holds one frame from each chunk.

    The valid frames, in time order, are cut into consecutive chunks of
    ``n_batches`` frames; the frames of each chunk are dealt at random to the
    batches, one each.  Every batch thus draws about evenly from the whole
    data set (every sequence, every style) and holds no two neighbouring
    frames, which keeps the frames of a batch as uncorrelated as possible.
    """
    _check_batch_size(batch_size)
    n_frames = len(frames)
    if n_frames == 0:
        return []
    n_batches = -(-n_frames // batch_size)
    n_chunks = -(-n_frames // n_batches)
    padded = np.full(n_chunks * n_batches, -1, dtype=np.intp)
    padded[:n_frames] = frames
    chunks = padded.reshape(n_chunks, n_batches)
    chunks = rng.permuted(chunks, axis=1)
    batches = []
    for column in chunks.T[rng.permutation(n_batches)]:
        batch = column[column >= 0]
        if len(batch):
            batches.append(batch)
    return batches
