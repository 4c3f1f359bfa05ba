"""Reading a folder of motion files into long format, one sequence per file."""

import os
from pathlib import Path

import numpy as np
from sklearn.utils import Bunch

from ..utils._sequences import stack_sequences
from ._acclaim import read_amc
from ._agreement import check_agreement
from ._bvh import read_bvh
from ._frame_rate import check_rate, kept_frames
from ._labels import file_labels
from ._skeleton import Skeleton

__all__ = ["read_amc_folder", "read_bvh_folder"]


def read_bvh_folder(
    folder, *, pattern="*.bvh", frame_rate=None, labels=None, label_names=None
):
    """Read every BVH file of a folder into one long-format data set.

    Each file is one sequence, named by its path relative to ``folder``
    without the suffix; files are read in sorted order.  All files must
    have the same skeleton (the same joints, parents and channel order) and
    stand along the same up axis, as trials of one capture set do.  With
    ``labels``, each file also has a label (a style, an actor...), given to
    each of its frames in ``target``.

    The joint that carries the body's travel (the first whose position
    channels change) should be the same in every file.  A file whose travel
    is carried by a joint above the one most files travel with (in one
    Bandai Namco file the ground joint ``joint_Root`` travels while its
    ``Hips`` stay) is rewritten: the joints above are set as still as in the
    other files and the travel moved into that joint, every joint below it
    in the same place, with a warning that names the file.  When as many
    files travel with one joint as with another, the lower joint is taken:
    the result never depends on the order of the files.

    Parameters
    ----------
    folder : path-like
        The folder.
    pattern : str, optional
        Which files, as for :meth:`pathlib.Path.glob`; default ``"*.bvh"``.
        ``"**/*.bvh"`` also reads sub-folders.
    frame_rate : float, default=None
        Frame rate of the returned data.  Files recorded faster are brought
        down to it by dropping frames (see :func:`resample_frames`), with a
        warning that names them when the files' rates differ.  ``None``
        keeps the files' rate, which must then be the same for all.
    labels : str, re.Pattern or callable, default=None
        Where each file's label comes from:

        - a str: that key of the JSON file of the same name beside each file,
          as the Bandai Namco Research Motion dataset has them (``"style"``
          reads ``walk_001.json``'s ``{"style": 2, ...}`` for
          ``walk_001.bvh``);
        - a compiled regular expression (:func:`re.compile`): searched in the
          file's sequence name, whose first group (or, without groups, the
          whole match) is the label, e.g. ``re.compile(r"walk_([a-z]+)_")``;
        - a callable: called with each file's :class:`~pathlib.Path`, it
          returns the label;
        - a list of these: several labels of every file (label factors,
          such as ``["content", "style"]``), for the style models'
          ``fit(X, y)`` with one column of ``y`` per factor.

        ``None`` reads no labels.
    label_names : sequence of str or path-like, default=None
        The names of the labels, in the order of their codes, or a text file
        with one name a line.  Integer labels index into them; other labels
        must be among them.  ``None``: for a JSON key, the file
        ``{key}_label.txt`` in ``folder`` or in ``folder/../cfg`` when there
        is one (the Bandai Namco repository's ``style_label.txt``), else the
        distinct labels in sorted order (numbers in numeric order).  Names
        read from a file lose a prefix that all of them share up to an
        underscore: the Bandai Namco ``dataset-2_walk``, ``dataset-2_run``...
        are ``walk``, ``run``...  Without label names the labels must
        be of one kind (all names, all integers, all booleans or all
        floats): ``true``, ``1`` and ``1.0`` are one value to Python and
        would merge into one class, so a mix is refused.  NaN is never a
        label.  With a list of ``labels``: None, or a list with one entry
        (None or as above) per label.

    Returns
    -------
    data : :class:`~sklearn.utils.Bunch`
        data : ndarray of shape (n_frames, n_features)
            Raw channels of all files, one after the other.
        sequence_ids : ndarray of shape (n_frames,)
            Index into ``sequence_names`` of every frame.
        target : ndarray of shape (n_frames,) or (n_frames, n_labels)
            Only with ``labels``: the code of every frame's label, an index
            into ``target_names``.  With a list of labels, every frame's
            label names instead, one column per label (``["run",
            "elderly"]``), ready to be the ``y`` of a style model.
        target_names : ndarray of str or list of ndarray of str
            Only with ``labels``: the label names, as text (labels that are
            numbers too), ready to use as class labels:
            ``target_names[target]`` is the label of every frame.  With a
            list of labels, a list with each label's names that some file
            has, in the order of their codes.
        sequence_names : ndarray of str
            One name per file, e.g. ``"walk_01"`` or ``"subject1/walk_01"``.
        feature_names : ndarray of str
            The channels, as :func:`read_bvh` names them.
        skeleton : Skeleton
            The first file's skeleton.
        skeletons : list of Skeleton
            Each file's own skeleton (bone lengths may differ between files).
        frame_rate : float
            Frames per second of ``data``.
        filenames : ndarray of str
            The path of every file.
        DESCR : str
            Where the data came from.

    Raises
    ------
    FileNotFoundError
        If ``folder`` is not a folder or has no file matching ``pattern``, or
        a JSON label file is missing.
    ValueError
        If a file is malformed, the files' skeletons or up axes differ,
        their frame rates differ and ``frame_rate`` is None (the message
        says what ``frame_rate=`` the slowest rate does to each file), a
        file is slower than ``frame_rate``, a file is empty, a file's travel
        cannot be moved into the joint most files travel with, a file's
        label is missing, not a finite value or not among ``label_names``
        (a str ``labels`` is a JSON key; a label from the file names needs
        a compiled pattern).  The message names the file.  With a list
        of labels, if ``label_names`` is not None or a list as long.
    TypeError
        If a label is not a single name or number, or the labels mix kinds
        (``true``, ``1`` and ``1.0`` would merge into one class).

    Warns
    -----
    UserWarning
        When a file's travel is moved into another joint (see above), or
        ``frame_rate`` drops frames of files whose rates differ.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> from sklearn_crbm.datasets import make_walker, read_bvh_folder, write_bvh
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> for seed in (0, 1):
    ...     walker = make_walker(n_sequences=1, n_frames=8, random_state=seed)
    ...     write_bvh(folder / f"walk_{seed}.bvh", walker.data, walker.skeleton,
    ...               frame_rate=120.0)
    >>> walks = read_bvh_folder(folder, frame_rate=30.0)
    >>> walks.data.shape, walks.sequence_ids.tolist(), list(walks.sequence_names)
    ((4, 57), [0, 0, 1, 1], ['walk_0', 'walk_1'])

    Labels from the file names, one per frame:

    >>> import re
    >>> walks = read_bvh_folder(folder, frame_rate=30.0,
    ...                         labels=re.compile(r"walk_([0-9])"))
    >>> walks.target.tolist(), list(walks.target_names)
    ([0, 0, 1, 1], ['0', '1'])

    Several labels, each file's from a JSON file beside it:

    >>> import json
    >>> for seed, style in ((0, "slow"), (1, "brisk")):
    ...     labels = {"content": "walk", "style": style}
    ...     _ = (folder / f"walk_{seed}.json").write_text(json.dumps(labels))
    >>> walks = read_bvh_folder(folder, frame_rate=30.0,
    ...                         labels=["content", "style"])
    >>> walks.target.tolist()
    [['walk', 'slow'], ['walk', 'slow'], ['walk', 'brisk'], ['walk', 'brisk']]
    >>> [list(names) for names in walks.target_names]
    [['walk'], ['brisk', 'slow']]
    """
    folder, paths = _matching_files(folder, pattern)
    sequences = []
    for path in paths:
        skeleton, data, names, rate = read_bvh(path)
        sequences.append((path, skeleton, data, rate))
    bunch = _long_format(folder, sequences, frame_rate, "BVH")
    return _with_labels(bunch, folder, paths, labels, label_names)


def read_amc_folder(
    folder,
    skeleton=None,
    *,
    pattern="*.amc",
    amc_frame_rate=120.0,
    frame_rate=None,
    labels=None,
    label_names=None,
):
    """Read every AMC file of a folder into one long-format data set.

    Like :func:`read_bvh_folder` for Acclaim files.  Each AMC file is read
    with ``skeleton`` when given; otherwise with the ASF file beside it
    whose name is the longest start of the AMC file's name (``35.asf`` for
    ``35_01.amc``, ``charleston.asf`` for ``charleston1.amc``), or the only
    ASF file of its folder.

    Parameters
    ----------
    folder : path-like
        The folder.
    skeleton : Skeleton or path-like, default=None
        The skeleton of every file, or the path of its ASF file.
    pattern : str, optional
        Which files, as for :meth:`pathlib.Path.glob`; default ``"*.amc"``.
    amc_frame_rate : float, default=120.0
        Frames per second of the AMC files, which do not say (CMU: 120).
    frame_rate : float, default=None
        Frame rate of the returned data: files are brought down to it by
        dropping frames (see :func:`resample_frames`).  ``None`` keeps
        ``amc_frame_rate``.
    labels : str, re.Pattern or callable, default=None
        Each file's label, as for :func:`read_bvh_folder`.
    label_names : sequence of str or path-like, default=None
        The names of the labels, as for :func:`read_bvh_folder`.

    Returns
    -------
    data : :class:`~sklearn.utils.Bunch`
        As for :func:`read_bvh_folder`.

    Raises
    ------
    FileNotFoundError
        If ``folder`` is not a folder, has no file matching ``pattern``, or
        an AMC file has no ASF file to go with it.
    ValueError
        If a file is malformed, or the files' skeletons or up axes differ.

    Examples
    --------
    >>> from sklearn_crbm.datasets import read_amc_folder
    >>> cmu = read_amc_folder("cmu_subject35", frame_rate=30.0)  # doctest: +SKIP
    >>> cmu.sequence_names[:2]  # doctest: +SKIP
    array(['35_01', '35_02'], dtype=object)
    """
    amc_frame_rate = check_rate(amc_frame_rate, "amc_frame_rate")
    folder, paths = _matching_files(folder, pattern)
    if skeleton is not None and not isinstance(skeleton, Skeleton):
        skeleton = Skeleton.from_asf(skeleton)
    skeletons = {}
    sequences = []
    for path in paths:
        own = skeleton
        if own is None:
            asf = _asf_for(path)
            if asf not in skeletons:
                skeletons[asf] = Skeleton.from_asf(asf)
            own = skeletons[asf]
        data, _ = read_amc(path, own)
        sequences.append((path, own, data, amc_frame_rate))
    bunch = _long_format(folder, sequences, frame_rate, "AMC")
    return _with_labels(bunch, folder, paths, labels, label_names)


def _matching_files(folder, pattern):
    if not isinstance(folder, (str, os.PathLike)):
        raise TypeError(
            f"folder must be the path of a folder, got {type(folder).__name__} "
            f"{folder!r}."
        )
    folder = Path(folder)
    if not folder.is_dir():
        raise FileNotFoundError(f"{folder} is not a folder.")
    if not isinstance(pattern, str) or not pattern or Path(pattern).is_absolute():
        raise ValueError(
            f"pattern must be a non-empty pattern relative to the folder, such as "
            f"'*.bvh' or '**/*.bvh', got {pattern!r}; to read another folder, "
            "pass it as folder."
        )
    paths = sorted(p for p in folder.glob(pattern) if p.is_file())
    if not paths:
        raise FileNotFoundError(f"No file in {folder} matches {pattern!r}.")
    return folder, paths


def _asf_for(amc_path):
    """The ASF file that goes with an AMC file (see :func:`read_amc_folder`)."""
    candidates = sorted(amc_path.parent.glob("*.asf"))
    if len(candidates) == 1:
        return candidates[0]
    stem = amc_path.stem.lower()
    prefixes = [asf for asf in candidates if stem.startswith(asf.stem.lower())]
    if not prefixes:
        raise FileNotFoundError(
            f"No ASF file for {amc_path}: its folder has "
            f"{[p.name for p in candidates]}, none of whose names starts "
            f"{amc_path.stem!r}. Pass skeleton= to read_amc_folder."
        )
    return max(prefixes, key=lambda asf: len(asf.stem))


def _with_labels(bunch, folder, paths, labels, label_names):
    """``bunch`` with every frame's label code (``target``) and ``target_names``."""
    if labels is None:
        if label_names is not None:
            raise ValueError(
                "label_names names the labels that labels= reads; pass labels= too."
            )
        return bunch
    if isinstance(labels, list | tuple):
        return _with_several_labels(bunch, folder, paths, labels, label_names)
    codes, names = file_labels(folder, paths, labels, label_names)
    bunch.target = codes[bunch.sequence_ids]
    bunch.target_names = names
    return bunch


def _with_several_labels(bunch, folder, paths, labels, label_names):
    """``bunch`` with every frame's label names of each of ``labels`` (a
    column each) and each label's names that the files have."""
    if not labels:
        raise ValueError("labels is an empty list: give at least one label.")
    if label_names is None:
        label_names = [None] * len(labels)
    if not isinstance(label_names, list | tuple) or len(label_names) != len(labels):
        raise ValueError(
            f"With {len(labels)} labels, label_names must be None or a list of "
            f"{len(labels)} entries, one per label (each None, a names file or a "
            f"list of names); got {label_names!r}."
        )
    columns, present = [], []
    for key, names_of_key in zip(labels, label_names, strict=True):
        codes, names = file_labels(folder, paths, key, names_of_key)
        columns.append(names[codes[bunch.sequence_ids]])
        present.append(names[np.unique(codes)])
    target = np.empty((len(bunch.sequence_ids), len(labels)), dtype=object)
    for j, column in enumerate(columns):
        target[:, j] = column
    bunch.target = target
    bunch.target_names = present
    return bunch


def _long_format(folder, sequences, frame_rate, kind):
    """The Bunch of :func:`read_bvh_folder` from ``(path, skeleton, data, rate)``."""
    sequences = check_agreement(sequences, frame_rate)
    first_skeleton = sequences[0][1]
    if frame_rate is None:  # the files' rates agree to RATIO_TOLERANCE
        frame_rate = min(rate for _, _, _, rate in sequences)
        kept = [data for _, _, data, _ in sequences]
    else:
        frame_rate = check_rate(frame_rate, "frame_rate")
        kept = [
            data[kept_frames(len(data), rate, frame_rate)]
            for _, _, data, rate in sequences
        ]
    names = [
        path.relative_to(folder).with_suffix("").as_posix()
        for path, _, _, _ in sequences
    ]
    data, sequence_ids = stack_sequences(kept)
    return Bunch(
        data=data,
        sequence_ids=sequence_ids,
        sequence_names=np.array(names, dtype=object),
        feature_names=first_skeleton.feature_names,
        skeleton=first_skeleton,
        skeletons=[skeleton for _, skeleton, _, _ in sequences],
        frame_rate=frame_rate,
        filenames=np.array([str(path) for path, _, _, _ in sequences], dtype=object),
        DESCR=(
            f"{len(kept)} {kind} files read from {folder}, "
            f"{frame_rate:g} frames per second."
        ),
    )
