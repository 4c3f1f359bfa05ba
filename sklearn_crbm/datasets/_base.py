"""Where the motion-capture data lives, and the loaders of the real data sets."""

import os
from pathlib import Path

import numpy as np
from sklearn.utils import Bunch

from ..utils._sequences import remember_sequences, stack_sequences
from ._bandai import (
    BANDAI_FOLDER,
    DATASET2_FOLDER,
    dataset2_filenames,
    dataset2_selection,
)
from ._bvh import read_bvh
from ._folders import _long_format, _with_labels, read_bvh_folder
from ._frame_rate import kept_frames
from ._mit import load_mit_mat
from ._parsing import load_mat_variables
from ._skeleton import Skeleton

__all__ = [
    "get_data_home",
    "load_bandai_dataset2",
    "load_bandai_walks",
    "load_cmu35",
    "load_mit_walk",
]

DATA_HOME_ENV = "SKLEARN_CRBM_DATA"
FRAME_RATE = 30.0

CMU35_FOLDER = "cmu_subject35"
MIT_FOLDER = "taylor_mhmublv_mit"

# Trials of cmu35WalkJog.mat, in the order of its label columns, with frames.
CMU35_TRAIN = [
    ("35_01", 90), ("35_02", 102), ("35_03", 107), ("35_04", 109), ("35_05", 107),
    ("35_06", 110), ("35_07", 90), ("35_08", 114), ("35_09", 96), ("35_10", 108),
    ("35_11", 97), ("35_12", 100), ("35_13", 114), ("35_14", 103), ("35_15", 102),
    ("35_16", 111), ("35_17", 42), ("35_19", 40), ("35_20", 41), ("35_21", 41),
    ("35_22", 42), ("35_23", 41), ("35_24", 38), ("35_25", 42), ("35_26", 35),
    ("35_28", 105), ("35_30", 103), ("35_31", 106), ("35_32", 98), ("35_33", 106),
    ("35_34", 104),
]  # fmt: skip
CMU35_TEST = [("35_18", 44), ("35_29", 125)]
CMU35_JOGS = {f"35_{i}" for i in range(17, 27)}

MIT_SEQUENCE_NAMES = [
    "Normal1_M_551-2300",
    "Normal1_M_2621-3660",
    "Normal1_M_3791-16300",
]
MIT_RECORDING_RATE = 120.0


def get_data_home(data_home=None):
    """The folder that holds the motion-capture data sets.

    Parameters
    ----------
    data_home : path-like, default=None
        Used as is when given.  Otherwise ``$SKLEARN_CRBM_DATA`` when set,
        else ``~/sklearn_crbm_data``.  The folder is not created.

    Returns
    -------
    data_home : pathlib.Path

    Examples
    --------
    >>> from sklearn_crbm.datasets import get_data_home
    >>> str(get_data_home("/tmp/mocap"))
    '/tmp/mocap'
    """
    if data_home is None:
        data_home = os.environ.get(DATA_HOME_ENV) or Path("~") / "sklearn_crbm_data"
    return Path(data_home).expanduser()


def _data_file(data_home, folder, filename, fetcher):
    """Path of a data file, or a FileNotFoundError telling how to get it."""
    path = get_data_home(data_home) / folder / filename
    if not path.is_file():
        raise FileNotFoundError(
            f"Data file {path} not found. Download the data with "
            f"sklearn_crbm.datasets.{fetcher}(data_home=...), or set "
            f"${DATA_HOME_ENV} to a folder that has {folder}/{filename}."
        )
    return path


def _sequence_ids_from_labels(labels, expected, path):
    """Per-frame ids from one-hot labels, checked against the known trial lengths."""
    labels = np.asarray(labels)
    lengths = labels.sum(axis=0).astype(int).tolist()
    ids = np.argmax(labels, axis=1)
    expected_lengths = [n for _, n in expected]
    if (
        lengths != expected_lengths
        or np.any(np.diff(ids) < 0)
        or np.any(labels.sum(axis=1) != 1)
    ):
        raise ValueError(
            f"{path} does not have the expected trials {expected}; the file may be "
            "damaged. Fetch it again with sklearn_crbm.datasets.fetch_cmu35()."
        )
    return ids


def load_cmu35(data_home=None, *, subset="all"):
    """CMU subject 35 walking and jogging: the paper's 2813 frames.

    The 33 trials of CMU subject 35 that Taylor, Hinton & Roweis (2006) used,
    as raw AMC channels at 30 Hz (every 4th frame of the 120 Hz originals):
    root translation in ASF length units and all rotations as Euler angles in
    degrees, in the channel order of ``35.asf``.  23 trials are walks and 10
    are jogs.

    ================  ===========  ========================================
    subset            frames       trials
    ================  ===========  ========================================
    ``"train"``       2644         31 trials (35_01 ... 35_34 but 18, 27, 29)
    ``"test"``        169          jog 35_18, then walk 35_29
    ``"all"``         2813         the training trials, then the test pair
    ================  ===========  ========================================

    Needs ``cmu_subject35/cmu35WalkJog.mat`` and ``cmu_subject35/35.asf`` in
    ``data_home`` (see :func:`fetch_cmu35`).

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`.
    subset : {"all", "train", "test"}, default="all"
        Which trials.

    Returns
    -------
    data : :class:`~sklearn.utils.Bunch`
        data : ndarray of shape (n_frames, 62)
            Raw channels.
        sequence_ids : ndarray of shape (n_frames,)
            Index into ``sequence_names`` of every frame.
        sequence_names : ndarray of str
            Trial names such as ``"35_01"``.
        motion : ndarray of str
            ``"walk"`` or ``"jog"`` per sequence.
        feature_names : ndarray of str
            ``root_tx`` ... ``rthumb_rz``, from the skeleton.
        skeleton : Skeleton
            From ``35.asf``.
        frame_rate : float
            30.0.
        DESCR : str
            Description and the CMU attribution.

    Raises
    ------
    FileNotFoundError
        If the data are not in ``data_home``; the message tells how to fetch them.

    Examples
    --------
    >>> from sklearn_crbm.datasets import load_cmu35
    >>> cmu = load_cmu35(subset="test")  # doctest: +SKIP
    >>> cmu.data.shape, list(cmu.sequence_names)  # doctest: +SKIP
    ((169, 62), ['35_18', '35_29'])
    """
    if subset not in ("all", "train", "test"):
        raise ValueError(f"subset must be 'all', 'train' or 'test', got {subset!r}.")
    mat_path = _data_file(data_home, CMU35_FOLDER, "cmu35WalkJog.mat", "fetch_cmu35")
    asf_path = _data_file(data_home, CMU35_FOLDER, "35.asf", "fetch_cmu35")
    skeleton = Skeleton.from_asf(asf_path)
    mat = load_mat_variables(
        mat_path, ("Y", "lbls", "Ytest", "lblstest"), "fetch_cmu35"
    )
    parts = []
    if subset in ("all", "train"):
        parts.append((mat["Y"], mat["lbls"], CMU35_TRAIN))
    if subset in ("all", "test"):
        parts.append((mat["Ytest"], mat["lblstest"], CMU35_TEST))
    data, ids, names, offset = [], [], [], 0
    for values, labels, trials in parts:
        data.append(np.asarray(values, dtype=np.float64))
        ids.append(_sequence_ids_from_labels(labels, trials, mat_path) + offset)
        names += [name for name, _ in trials]
        offset += len(trials)
    data = np.concatenate(data)
    if data.shape[1] != len(skeleton.feature_names):
        raise ValueError(
            f"{mat_path} has {data.shape[1]} channels but {asf_path} describes "
            f"{len(skeleton.feature_names)}."
        )
    sequence_ids = np.concatenate(ids)
    remember_sequences(data, sequence_ids)
    return Bunch(
        data=data,
        sequence_ids=sequence_ids,
        sequence_names=np.array(names, dtype=object),
        motion=np.array(
            ["jog" if n in CMU35_JOGS else "walk" for n in names], dtype=object
        ),
        feature_names=skeleton.feature_names,
        skeleton=skeleton,
        frame_rate=FRAME_RATE,
        DESCR=CMU35_DESCR,
    )


def load_mit_walk(data_home=None):
    """Taylor's MIT walking data (Hsu, Pulli & Popovic 2005) at 30 Hz.

    The three clean segments of ``Normal1_M`` shipped with Taylor's NIPS 2006
    code, downsampled from 120 Hz to 30 Hz by keeping every 4th frame from
    the first (``[::4]``, as Taylor's ``dropframes``): 438 + 260 + 3128 =
    3826 frames.  Each frame has 18 nodes of 6 columns: an exponential map
    (radians) and an offset, except for the root whose last three columns are
    its position; z is up and the subject walks along +x.  Bone names are
    listed in :mod:`sklearn_crbm.datasets._mit`: ``root``, ``lhip``,
    ``lknee``, ``lankle``, ``ltoe``, ``rhip`` ... ``spine``, ``lcollar``,
    ``lshoulder``, ``lelbow``, ``lwrist``, ``rcollar`` ... ``rwrist``.

    Needs ``taylor_mhmublv_mit/data.mat`` in ``data_home`` (see
    :func:`fetch_mit_walk`).

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`.

    Returns
    -------
    data : :class:`~sklearn.utils.Bunch`
        With ``data`` (3826, 108), ``sequence_ids``, ``sequence_names``,
        ``motion`` (all ``"walk"``), ``feature_names`` (``root_ex``,
        ``root_ey``, ``root_ez``, ``root_tx``, ``root_ty``, ``root_tz``,
        ``lhip_ex``, ... ``lhip_ox``, ...), ``skeleton`` (``up_axis="z"``,
        ``angle_unit="rad"``), ``frame_rate`` (30.0) and ``DESCR``.

    Raises
    ------
    FileNotFoundError
        If the data are not in ``data_home``; the message tells how to fetch them.

    Examples
    --------
    >>> from sklearn_crbm.datasets import load_mit_walk
    >>> mit = load_mit_walk()  # doctest: +SKIP
    >>> mit.data.shape  # doctest: +SKIP
    (3826, 108)
    """
    path = _data_file(data_home, MIT_FOLDER, "data.mat", "fetch_mit_walk")
    skel, motions = load_mit_mat(path)
    skeleton = Skeleton.from_mit(skel, motions[0][0])
    sequences = [
        motion[kept_frames(len(motion), MIT_RECORDING_RATE, FRAME_RATE)]
        for motion in motions
    ]
    data, sequence_ids = stack_sequences(sequences)
    return Bunch(
        data=data,
        sequence_ids=sequence_ids,
        sequence_names=np.array(MIT_SEQUENCE_NAMES[: len(sequences)], dtype=object),
        motion=np.array(["walk"] * len(sequences), dtype=object),
        feature_names=skeleton.feature_names,
        skeleton=skeleton,
        frame_rate=FRAME_RATE,
        DESCR=MIT_DESCR,
    )


def load_bandai_walks(data_home=None):
    """Bandai Namco walks in seven styles, with the style of every frame.

    The content *walk* of the second set of the Bandai Namco Research Motion
    dataset (Kobayashi et al., 2023): one actor walking in the styles
    active, elderly, exhausted, feminine, masculine, normal and youthful,
    takes 001-006 of each (42 takes, 11,337 frames at 30 frames per second),
    read with :func:`read_bvh_folder` and the label of each take from its
    JSON file and ``style_label.txt``.  The skeleton has a static
    ``joint_Root`` above the moving ``Hips``, and position and rotation
    channels on every joint (Y up, centimetres); the default
    :func:`~sklearn_crbm.preprocessing.make_motion_preprocessor` encodes it
    with an exact inverse.

    Needs the folder ``bandai_walk_styles/`` in ``data_home`` (see
    :func:`fetch_bandai_walks`).

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`.

    Returns
    -------
    data : :class:`~sklearn.utils.Bunch`
        data : ndarray of shape (11337, 132)
            Raw BVH channels.
        sequence_ids : ndarray of shape (n_frames,)
            Index into ``sequence_names`` of every frame.
        sequence_names : ndarray of str
            Take names such as ``"dataset-2_walk_active_001"``.
        takes : ndarray of shape (n_sequences,)
            The take number of every sequence (1 to 6).
        target : ndarray of shape (n_frames,)
            The style of every frame, an index into ``target_names``.
        target_names : ndarray of str
            ``"active"``, ``"elderly"``, ``"exhausted"``, ``"feminine"``,
            ``"masculine"``, ``"normal"``, ``"youthful"``.
        feature_names, skeleton, skeletons, frame_rate, filenames
            As :func:`read_bvh_folder` with ``labels="style"`` gives them.
        DESCR : str
            Description, licence and citation.

    Raises
    ------
    FileNotFoundError
        If the data are not in ``data_home``; the message tells how to fetch them.

    Examples
    --------
    >>> from sklearn_crbm.datasets import load_bandai_walks
    >>> walks = load_bandai_walks()  # doctest: +SKIP
    >>> walks.data.shape, list(walks.target_names[:2])  # doctest: +SKIP
    ((11337, 132), ['active', 'elderly'])
    """
    names = _data_file(
        data_home, BANDAI_FOLDER, "style_label.txt", "fetch_bandai_walks"
    )
    walks = read_bvh_folder(
        names.parent, pattern="*_walk_*.bvh", frame_rate=FRAME_RATE, labels="style"
    )
    walks.takes = np.array([int(name[-3:]) for name in walks.sequence_names])
    walks.DESCR = BANDAI_DESCR
    return walks


# The label keys of the JSON file beside every take of dataset-2: the
# columns of load_bandai_dataset2's target.
DATASET2_LABELS = ("content", "style")


def load_bandai_dataset2(data_home=None, *, contents=None, styles=None, takes=None):
    """Bandai Namco dataset-2: ten contents in seven styles, both labels per frame.

    The second set of the Bandai Namco Research Motion dataset (Kobayashi et
    al., 2023): one actor performing ten contents (``walk``,
    ``walk-turn-left``, ``walk-turn-right``, ``run``, ``wave-both-hands``,
    ``wave-left-hand``, ``wave-right-hand``, ``raise-up-both-hands``,
    ``raise-up-left-hand``, ``raise-up-right-hand``) in each of seven styles
    (``active``, ``elderly``, ``exhausted``, ``feminine``, ``masculine``,
    ``normal``, ``youthful``), takes 001-012 of every content and style:
    840 takes, 132,297 frames at 30 frames per second, or the cells and
    takes asked for.  Each take's content and style come from its JSON file,
    named by ``content_label.txt`` and ``style_label.txt``.  The skeleton is
    that of :func:`load_bandai_walks` (whose takes are among these).

    The walks, turns and runs are cyclic locomotion; the waves are cyclic
    upper-body motion (each take raises the arms first and lowers them
    last); the raises are one action, then rest.

    Needs the folder ``bandai_dataset2/`` in ``data_home`` with the files
    asked for (see :func:`fetch_bandai_dataset2`, which takes the same
    ``contents``, ``styles`` and ``takes``).

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`.
    contents : str or list of str, default=None
        The contents to load, such as ``"run"`` or ``["walk", "run"]``;
        ``None`` means all ten.
    styles : str or list of str, default=None
        The styles to load; ``None`` means all seven.
    takes : int or list of int, default=None
        The take numbers to load, from 1 to 12; ``None`` means all twelve.

    Returns
    -------
    data : :class:`~sklearn.utils.Bunch`
        data : ndarray of shape (n_frames, 132)
            Raw BVH channels of the takes, in sorted order of their names.
        sequence_ids : ndarray of shape (n_frames,)
            Index into ``sequence_names`` of every frame.
        sequence_names : ndarray of str
            Take names such as ``"dataset-2_run_elderly_001"``.
        takes : ndarray of shape (n_sequences,)
            The take number of every sequence (1 to 12).
        target : ndarray of str of shape (n_frames, 2)
            The content and style of every frame, such as ``["run",
            "elderly"]``: the ``y`` of a model of several label factors.
        target_columns : tuple of str
            ``("content", "style")``, the columns of ``target``.
        target_names : list of two ndarrays of str
            The contents and the styles loaded, in the dataset's order.
        feature_names, skeleton, skeletons, frame_rate, filenames
            As :func:`read_bvh_folder` gives them.
        DESCR : str
            Description, licence and citation.

    Raises
    ------
    ValueError
        If a content, style or take is not one of the corpus's.
    FileNotFoundError
        If a take asked for is not in ``data_home``; the message tells how
        to fetch it.

    See Also
    --------
    load_bandai_walks : The walks alone, takes 001-006, with one label.

    Examples
    --------
    >>> from sklearn_crbm.datasets import load_bandai_dataset2
    >>> corpus = load_bandai_dataset2(
    ...     contents=["walk", "run"], styles="elderly", takes=[1, 2]
    ... )  # doctest: +SKIP
    >>> corpus.sequence_names.tolist()  # doctest: +SKIP
    ['dataset-2_run_elderly_001', 'dataset-2_run_elderly_002', \
'dataset-2_walk_elderly_001', 'dataset-2_walk_elderly_002']
    >>> corpus.target[0].tolist()  # doctest: +SKIP
    ['run', 'elderly']
    """
    selection = dataset2_selection(contents, styles, takes)
    folder = get_data_home(data_home) / DATASET2_FOLDER
    paths = [folder / name for name in dataset2_filenames(*selection)]
    _check_dataset2_files(folder, paths, selection)
    sequences = []
    for path in paths:
        skeleton, data, _, rate = read_bvh(path)
        sequences.append((path, skeleton, data, rate))
    corpus = _long_format(folder, sequences, FRAME_RATE, "BVH")
    corpus = _with_labels(corpus, folder, paths, list(DATASET2_LABELS), None)
    corpus.update(
        target_columns=DATASET2_LABELS,
        takes=np.array([int(name[-3:]) for name in corpus.sequence_names]),
        DESCR=DATASET2_DESCR,
    )
    return corpus


def _check_dataset2_files(folder, paths, selection):
    """A FileNotFoundError saying how to fetch the takes asked for, if missing."""
    missing = [
        path
        for path in paths
        if not (path.is_file() and path.with_suffix(".json").is_file())
    ]
    missing += [
        folder / f"{key}_label.txt"
        for key in DATASET2_LABELS
        if not (folder / f"{key}_label.txt").is_file()
    ]
    if not missing:
        return
    contents, styles, takes = selection
    asked = ", ".join(
        f"{key}={list(value)!r}"
        for key, value in zip(("contents", "styles", "takes"), selection, strict=True)
        if len(value) < {"contents": 10, "styles": 7, "takes": 12}[key]
    )
    raise FileNotFoundError(
        f"{len(missing)} file{'s' * (len(missing) != 1)} of the takes asked for "
        f"{'are' if len(missing) != 1 else 'is'} not in {folder}, such as "
        f"{missing[0].name} (or its JSON label). Download them with "
        f"sklearn_crbm.datasets.fetch_bandai_dataset2(data_home=...{', ' * bool(asked)}"
        f"{asked}), or set ${DATA_HOME_ENV} to a folder that has "
        f"{DATASET2_FOLDER}/."
    )


CMU35_DESCR = """\
CMU subject 35: walking and jogging
-----------------------------------

The 33 trials of subject 35 of the CMU Graphics Lab Motion Capture Database
used by Taylor, Hinton & Roweis, "Modeling Human Motion Using Binary Latent
Variables" (NIPS 2006): 23 walks and 10 jogs (trials 17-26 and 18), 2813
frames at 30 Hz (every 4th frame of the 120 Hz originals, as in GPmat's
``cmu35WalkJog.mat``).

**Data Set Characteristics:**

    :Frames: 2813 (train: 31 trials, 2644 frames; test: jog 35_18 and walk
        35_29, 169 frames)
    :Channels: 62 raw AMC channels in the order of the ASF file: root
        translation (ASF length units, ``length 0.45``), then Euler angles in
        degrees for every bone with degrees of freedom
    :Skeleton: ``35.asf``, 31 bones, y up

The data used in this project was obtained from mocap.cs.cmu.edu.
The database was created with funding from NSF EIA-0196217.

CMU's terms let anyone use the data for any purpose, commercial use included,
but the raw data may not be resold (converted forms included).
"""

MIT_DESCR = """\
MIT walking data (Hsu, Pulli & Popovic 2005)
--------------------------------------------

The sample data of Graham Taylor's code for "Modeling Human Motion Using
Binary Latent Variables" (NIPS 2006): three clean segments (rows 551-2300,
2621-3660 and 3791-16300) of ``Normal1_M`` from E. Hsu's style-translation
data, at 30 Hz after keeping every 4th frame of the 120 Hz recording.

**Data Set Characteristics:**

    :Frames: 3826 (438 + 260 + 3128)
    :Channels: 108: 18 nodes x (3 exponential-map values in radians + 3
        offset values); the root's last three are its position; z is up
    :Skeleton: Taylor's ``skel`` of type 'mit', 18 nodes

Credit: E. Hsu, K. Pulli, J. Popovic, "Style Translation for Human Motion",
SIGGRAPH 2005, http://people.csail.mit.edu/ehsu/work/sig05stf/. Taylor's
README: "The sample data we have included has been provided by Eugene Hsu".
Distributed with Taylor's code (uoguelph-mlrg/mhmublv) under the Educational
Community License 2.0; keep the notice and give credit.
"""

BANDAI_DESCR = """\
Bandai Namco Research Motion dataset: walks in seven styles
-----------------------------------------------------------

The content *walk* of the second set of the Bandai Namco Research Motion
dataset (BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset): one
actor walking in seven styles, takes 001-006 of each, with the style of each
take from its JSON label file.

**Data Set Characteristics:**

    :Frames: 11,337 in 42 takes (200 to 466 frames each), 30 per second
    :Styles: active, elderly, exhausted, feminine, masculine, normal,
        youthful (6 takes each)
    :Channels: 132 raw BVH channels: position and rotation (ZXY Euler
        angles in degrees) of each of 22 joints
    :Skeleton: a static ``joint_Root`` above the moving ``Hips``; Y up,
        centimetres

Licence: Creative Commons Attribution-NonCommercial 4.0 International (the
``LICENSE`` file). Please cite: M. Kobayashi, C.-C. Liao, K. Inoue, S.
Yojima, M. Takahashi, "Motion Capture Dataset for Practical Use of AI-based
Motion Editing and Stylization", arXiv:2306.08861, 2023.
"""

DATASET2_DESCR = """\
Bandai Namco Research Motion dataset-2: ten contents in seven styles
--------------------------------------------------------------------

The second set of the Bandai Namco Research Motion dataset
(BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset): one actor
performing ten contents in seven styles, takes 001-012 of every content and
style, with the content and style of each take from its JSON label file.

**Data Set Characteristics:**

    :Frames: 132,297 in 840 takes, 30 per second (the takes 001-012 of all
        70 cells; the whole dataset-2 has 2,902 takes)
    :Contents: walk, walk-turn-left, walk-turn-right, run (cyclic
        locomotion); wave-both-hands, wave-left-hand, wave-right-hand
        (cyclic, upper body); raise-up-both-hands, raise-up-left-hand,
        raise-up-right-hand (one action, then rest)
    :Styles: active, elderly, exhausted, feminine, masculine, normal,
        youthful
    :Channels: 132 raw BVH channels: position and rotation (ZXY Euler
        angles in degrees) of each of 22 joints
    :Skeleton: a static ``joint_Root`` above the moving ``Hips``; Y up,
        centimetres

Licence: Creative Commons Attribution-NonCommercial 4.0 International (the
``LICENSE`` file). Please cite: M. Kobayashi, C.-C. Liao, K. Inoue, S.
Yojima, M. Takahashi, "Motion Capture Dataset for Practical Use of AI-based
Motion Editing and Stylization", arXiv:2306.08861, 2023.
"""
