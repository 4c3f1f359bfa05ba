"""Several labels per take on the command line: ``fit --labels content,style``.

A folder whose takes carry several labels (the Bandai Namco dataset-2's
``{"content": 3, "style": 1}`` beside every file) is modelled as a whole:
``fit`` trains one style model on every frame's labels, one factor per key,
and ``sample --label run,elderly`` asks it for any combination, also one it
never saw.  This module reads and checks the labels; the model does the rest.
"""

from pathlib import Path

import numpy as np

from ..datasets._labels import file_labels

__all__ = [
    "label_keys",
    "label_request",
    "label_text",
    "read_several_labels",
    "seed_windows_for",
]


def label_keys(text):
    """``--labels`` as the list of its JSON keys: ``"content,style"`` gives
    ``["content", "style"]``; one key, or a pattern (which holds a group,
    and may hold a comma), is a list of one."""
    if text is None:
        return None
    if "(" in text:
        return [text]
    keys = [key.strip() for key in text.split(",")]
    if not all(keys) or len(set(keys)) != len(keys):
        raise ValueError(
            f"--labels {text!r}: give one JSON key, or several different keys "
            "separated by commas (content,style)."
        )
    return keys


def read_several_labels(folder, data, keys):
    """Every frame's label of each key: ``(n_frames, len(keys))`` names.

    ``data`` is the folder as read (its ``filenames`` and ``sequence_ids``);
    each key is read from the JSON file beside every take, named by
    ``{key}_label.txt`` where there is one (without the prefix every name
    shares), as :func:`~sklearn_crbm.datasets.read_bvh_folder` reads one.
    """
    paths = [Path(name) for name in data.filenames]
    per_take = np.empty((len(paths), len(keys)), dtype=object)
    for k, key in enumerate(keys):
        codes, names = file_labels(Path(folder), paths, key)
        per_take[:, k] = [str(name) for name in names[codes]]
    return per_take[data.sequence_ids]


def label_text(labels):
    """The names of one frame's labels as ``sample --label`` takes them."""
    return ",".join(str(label) for label in labels)


def label_request(text, keys, classes):
    """``sample --label`` as one label per key, checked against the model's.

    Parameters
    ----------
    text : str
        ``"run,elderly"``: one name per key, in the order of ``keys``.
    keys : list of str
        The keys the model was fitted on (``fit --labels``).
    classes : list of array-like
        The labels of each key the model knows.

    Returns
    -------
    request : tuple of str
    """
    names = tuple(name.strip() for name in text.split(","))
    if len(names) != len(keys):
        example = label_text(str(known[0]) for known in classes)
        raise ValueError(
            f"--label {text!r}: the model was fitted on {len(keys)} labels "
            f"({', '.join(keys)}); give one of each, separated by commas, such as "
            f"--label {example}."
        )
    for name, key, known in zip(names, keys, classes, strict=True):
        known = [str(label) for label in known]
        if name not in known:
            raise ValueError(
                f"--label {text!r}: the model knows no {key} {name!r}; its "
                f"{key} labels are {', '.join(known)}."
            )
    return names


def seed_windows_for(windows, request):
    """The saved seed windows nearest to the labels asked for, and what they are.

    ``windows`` maps :func:`label_text` of the training labels to real
    windows.  Those of exactly the labels asked for when the training takes
    had them; otherwise all those that share the most labels with them, the
    first key's label (the content) first: an elderly run never seen starts
    from the runs of every other style.  ``(None, None)`` when no saved
    label shares any.
    """
    request = list(request)
    name = label_text(request)
    if name in windows:
        return windows[name], name

    def shared(text):
        labels = text.split(",")
        return (
            labels[0] == request[0],
            sum(a == b for a, b in zip(labels, request, strict=True)),
        )

    best = max((shared(text) for text in windows), default=(False, 0))
    if best == (False, 0):
        return None, None
    nearest = [text for text in windows if shared(text) == best]
    named = " or ".join(nearest[:2])
    if len(nearest) > 2:
        named += f" or {len(nearest) - 2} more"
    return np.concatenate([windows[text] for text in nearest]), named
