"""The root's path: its steps integrated back, and which bone travels."""

import warnings
from collections import Counter

import numpy as np

__all__ = []

_ROOT_OUT = ("pitch", "roll", "dheading", "dforward", "dsideways", "height")


def _wrap(angle):
    """Angles wrapped into ``[-pi, pi)``."""
    return (angle + np.pi) % (2.0 * np.pi) - np.pi


def _integrate(dheading, dforward, dsideways, sequences):
    """Heading (wrapped) and ground position of every frame from the deltas,
    each sequence starting at heading 0 and ground position (0, 0)."""
    n = len(dheading)
    heading = np.zeros(n)
    ground = np.zeros((n, 2))
    for start, stop in zip(sequences.starts, sequences.stops, strict=True):
        moves = slice(start, stop - 1)
        h = np.concatenate([[0.0], np.cumsum(dheading[moves])])
        heading[start:stop] = h
        cos, sin = np.cos(h[:-1]), np.sin(h[:-1])
        steps = np.column_stack(
            [
                cos * dforward[moves] + sin * dsideways[moves],
                sin * dforward[moves] - cos * dsideways[moves],
            ]
        )
        ground[start + 1 : stop] = np.cumsum(steps, axis=0)
    return _wrap(heading), ground


def _outputs(channels, up):
    """The encoded channels, in the order of ``_ROOT_OUT``, that ``channels`` give."""
    present = set(channels)
    rotation = len(present & {"ex", "ey", "ez"})
    ground = sum(f"t{a}" in present for a in "xyz" if a != up) == 2
    given = {
        "pitch": rotation == 3,
        "roll": rotation == 3,
        "dheading": rotation > 0,
        "dforward": ground,
        "dsideways": ground,
        "height": f"t{up}" in present,
    }
    return [c for c in _ROOT_OUT if given[c]]


def _travels(names, X, bone):
    """Whether the bone's translation channels change in ``X``."""
    columns = [i for i, n in enumerate(names) if n in {f"{bone}_t{a}" for a in "xyz"}]
    return len(columns) == 3 and np.ptp(X[:, columns], axis=0).max() > 0


def _most_common_root(travelling):
    """The root most sequences travel with (``(sequence, root)`` pairs); a
    warning names the others."""
    counts = Counter(root for _, root in travelling)
    root, count = counts.most_common(1)[0]
    odd = [(k, r) for k, r in travelling if r != root]
    shown = ", ".join(f"{r!r} in sequence {k}" for k, r in odd[:5])
    more = f" and {len(odd) - 5} more" if len(odd) > 5 else ""
    warnings.warn(
        f"The body travels with {shown}{more}, but with {root!r} in {count} of "
        f"the {len(travelling)} sequences that travel: {root!r} is encoded as the "
        "root, and in "
        "those sequences the travel passes through as ordinary channels. Read "
        "the files with read_bvh_folder, which moves the travel into the joint "
        "most files travel with, or pass root=.",
        UserWarning,
        stacklevel=5,
    )
    return root
