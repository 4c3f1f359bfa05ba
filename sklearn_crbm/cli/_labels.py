"""Several labels per take on the command line: ``fit --labels content,style``.

A folder whose takes carry several labels (the Bandai Namco dataset-2's
``{"content": 3, "style": 1}`` beside every file) is modelled as a whole:
``fit`` trains one style model on every frame's labels, one factor per key,
and ``sample --label run,elderly`` asks it for any combination, also one it
never saw.  This module reads and checks the labels; the model does the rest.
"""

import numpy as np

__all__ = ["label_keys", "label_request", "label_text", "seed_windows_for"]


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


def label_text(labels):
    """The names of one frame's labels (a tuple, one per key) as ``sample
    --label`` takes them: ``"run,elderly"``."""
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

    ``windows`` maps the training labels (a tuple, one per key) to real
    windows, as :meth:`~sklearn_crbm.preprocessing.MotionPipeline.style_windows`
    keeps them.  Those of exactly the labels asked for when the training takes
    had them; otherwise all those that share the most labels with them, the
    first key's label (the content) first: an elderly run never seen starts
    from the runs of every other style.  ``(None, None)`` when no saved
    label shares any.
    """
    request = tuple(request)
    if request in windows:
        return windows[request], label_text(request)

    def shared(labels):
        return (
            labels[0] == request[0],
            sum(a == b for a, b in zip(labels, request, strict=True)),
        )

    best = max((shared(labels) for labels in windows), default=(False, 0))
    if best == (False, 0):
        return None, None
    nearest = [labels for labels in windows if shared(labels) == best]
    named = " or ".join(label_text(labels) for labels in nearest[:2])
    if len(nearest) > 2:
        named += f" or {len(nearest) - 2} more"
    return np.concatenate([windows[labels] for labels in nearest]), named
