"""Labels of the files of a folder: from a JSON file beside each, the name, a function.

A labelled corpus gives every motion file one label (a style, an actor, a
motion): the Bandai Namco Research Motion dataset puts ``{"content": 0,
"style": 2}`` in a JSON file beside each BVH file and names the labels, one a
line, in ``style_label.txt`` and ``content_label.txt``; other corpora put the
label in the file name (``walk_elderly_003.bvh``).  :func:`file_labels`
turns either into integer codes and label names.
"""

import json
import math
import os
import re
from numbers import Integral, Real
from pathlib import Path

import numpy as np

__all__ = ["file_labels"]

# Where a corpus keeps the names of the labels of a JSON key: beside the files,
# or (the Bandai Namco repository) in a "cfg" folder beside the data folder.
LABEL_NAME_FILES = ("{key}_label.txt", "../cfg/{key}_label.txt")


def file_labels(folder, paths, labels, label_names=None):
    """Integer code of every file's label, and the names the codes index.

    Parameters
    ----------
    folder : pathlib.Path
        The folder that was read.
    paths : list of pathlib.Path
        The files, in order.
    labels : str, re.Pattern or callable
        See :func:`~sklearn_crbm.datasets.read_bvh_folder`.
    label_names : sequence of str, path-like or None
        See :func:`~sklearn_crbm.datasets.read_bvh_folder`.

    Returns
    -------
    codes : ndarray of shape (n_files,)
        Index into ``names`` of each file's label.
    names : ndarray of str
        The label names, as text.  Names read from a file lose a prefix
        that all of them share up to an underscore (``"dataset-2_"`` of the
        Bandai Namco ``style_label.txt``).
    """
    if isinstance(labels, str):
        sources = [path.with_suffix(".json").name for path in paths]
        hint = _pattern_hint(labels, paths)
        values = [_json_label(path, labels, hint) for path in paths]
        if label_names is None:
            label_names = _label_name_file(folder, labels)
    elif isinstance(labels, re.Pattern):
        sources = [path.name for path in paths]
        values = [_name_label(folder, path, labels) for path in paths]
    elif callable(labels):
        sources = [f"{path.name} (labels= function)" for path in paths]
        values = [labels(path) for path in paths]
    else:
        raise TypeError(
            "labels must be a key of the JSON file beside each motion file (str), "
            "a compiled regular expression matched against each file's name, or a "
            f"function of the file's path; got {type(labels).__name__} {labels!r}."
        )
    values = [
        _checked_label(v, source) for v, source in zip(values, sources, strict=True)
    ]
    if label_names is None:
        _check_one_kind(values, sources)
        codes, names = _codes_of_distinct_values(values)
    else:
        codes, names = _codes_of_named_values(values, _read_names(label_names), paths)
        if isinstance(label_names, str | os.PathLike):
            names = _without_shared_prefix(names)
    return codes, _as_array([str(name) for name in names])


def _without_shared_prefix(names):
    """``names`` without the prefix all of them share up to an underscore
    (``"dataset-2_walk"``, ``"dataset-2_run"``: ``"walk"``, ``"run"``), if
    they stay distinct and non-empty."""
    cut = os.path.commonprefix(list(names)).rfind("_") + 1
    short = [name[cut:] for name in names]
    if len(names) < 2 or not cut or not all(short) or len(set(short)) < len(short):
        return names
    return short


def _checked_label(value, source):
    """``value`` (a numpy scalar as the Python value), or an error naming
    ``source`` if it is not a single name or finite number."""
    if isinstance(value, np.generic):
        value = value.item()
    if not isinstance(value, str | Real):
        raise TypeError(
            f"{source}: every label must be a single value (a name or a number); "
            f"got {type(value).__name__} {value!r:.80}."
        )
    if isinstance(value, Real) and not math.isfinite(value):
        raise ValueError(
            f"{source}: the label is {value!r}; NaN and infinity are not labels "
            "(a missing label?). Give every file a name or a finite number."
        )
    return value


def _kind(value):
    return type(value).__name__ if isinstance(value, bool | float | str) else "int"


def _check_one_kind(values, sources):
    """A TypeError when the labels mix kinds: ``true``, ``1`` and ``1.0`` are
    one value to Python and would merge into one class, and a number beside
    a name is probably a mistake too."""
    first = {}
    for value, source in zip(values, sources, strict=True):
        first.setdefault(_kind(value), (value, source))
    if len(first) > 1:
        (a, source_a), (b, source_b) = list(first.values())[:2]
        raise TypeError(
            f"The labels are not all of the same kind: {source_a} gives {a!r} "
            f"({_kind(a)}) but {source_b} gives {b!r} ({_kind(b)}). True, 1 and 1.0 "
            "would merge into one class; write every label the same way (e.g. "
            "all names), or give label_names and integer indices into them."
        )


def _json_label(path, key, hint):
    json_path = path.with_suffix(".json")
    try:
        with open(json_path, encoding="utf-8") as f:
            content = json.load(f)
    except FileNotFoundError:
        raise FileNotFoundError(
            f"{path.name} has no label file {json_path.name} beside it; labels="
            f"{key!r} reads the label from a JSON file of the same name. {hint}"
        ) from None
    except UnicodeDecodeError as exc:
        raise ValueError(f"{json_path} is not UTF-8 text: {exc}.") from None
    except RecursionError:
        raise ValueError(
            f"{json_path} is not a label file: its JSON is nested too deeply."
        ) from None
    except ValueError as exc:  # JSONDecodeError, or an integer of too many digits
        raise ValueError(f"{json_path} is not valid JSON: {exc}.") from None
    if not isinstance(content, dict) or key not in content:
        found = sorted(content) if isinstance(content, dict) else type(content).__name__
        raise ValueError(
            f"{json_path} has no key {key!r}; it has {found}. A str labels= is a "
            f"key of the JSON file beside each motion file. {hint}"
        )
    return content[key]


def _pattern_hint(key, paths):
    """How to take the label from the file names instead of the JSON key
    ``key``: a pattern with a group, which the command line's ``--labels``
    tells from a key."""
    example = "walk_([a-z]+)_"
    if "_" in key.strip("_") and any(key in path.stem for path in paths):
        # 'dataset-2_run' of 'dataset-2_run_normal_001': a name, whose last
        # part is probably the label
        example = f"{key.strip('_').rsplit('_', 1)[0]}_([^_]+)"
    return (
        "To take the label from the file names, give a pattern with a group "
        f"around the label: labels=re.compile(r'{example}') (on the command line, "
        f"--labels '{example}'; without a group, --labels is a key)."
    )


def _name_label(folder, path, pattern):
    name = path.relative_to(folder).with_suffix("").as_posix()
    match = pattern.search(name)
    if match is None:
        raise ValueError(
            f"The file name {name!r} does not match labels={pattern.pattern!r}; "
            "every file's name must give its label."
        )
    return match.group(1) if pattern.groups else match.group(0)


def _label_name_file(folder, key):
    for template in LABEL_NAME_FILES:
        candidate = folder / template.format(key=key)
        if candidate.is_file():
            return candidate
    return None


def _read_names(label_names):
    if isinstance(label_names, str | os.PathLike):
        try:
            text = Path(label_names).read_text(encoding="utf-8")
        except UnicodeDecodeError as exc:
            raise ValueError(
                f"{label_names} is not UTF-8 text: {exc}; label_names reads one "
                "name a line."
            ) from None
        names = [line.strip() for line in text.splitlines() if line.strip()]
    else:
        names = list(label_names)
    if not names or len(set(names)) != len(names):
        raise ValueError(
            f"label_names must be distinct names, at least one; got {names!r}."
        )
    return names


def _codes_of_distinct_values(values):
    try:
        distinct = set(values)
    except TypeError:
        raise TypeError(
            "Every label must be a single value (a name or a number); got "
            f"{[v for v in values if not isinstance(v, str | Integral)][:3]}."
        ) from None
    try:
        names = sorted(distinct)
    except TypeError:
        raise TypeError(
            "The labels are of types that do not sort together "
            f"({sorted({type(v).__name__ for v in values})}); give label_names."
        ) from None
    index = {name: code for code, name in enumerate(names)}
    return np.array([index[v] for v in values], dtype=np.intp), names


def _codes_of_named_values(values, names, paths):
    """Codes of labels that are names, or integer indices into the names."""
    index = {name: code for code, name in enumerate(names)}
    codes = []
    for value, path in zip(values, paths, strict=True):
        if isinstance(value, Integral) and not isinstance(value, bool):
            if not 0 <= value < len(names):
                raise ValueError(
                    f"{path.name} has label {value}, but there are {len(names)} "
                    f"label names {names}."
                )
            codes.append(int(value))
        elif value in index:
            codes.append(index[value])
        else:
            raise ValueError(
                f"{path.name} has label {value!r}, which is not one of the label "
                f"names {names}."
            )
    return np.array(codes, dtype=np.intp), names


def _as_array(names):
    array = np.empty(len(names), dtype=object)
    array[:] = names
    return array
