"""The fill-in protocol: which entries to erase, and the paper's fill-in cases.

One definition of "erase from half-way" for the whole package: frame ``i``
of a sequence of ``n`` frames is erased when ``start <= i / n < stop``.  The
imputation scorer, the command line, the benchmarks and the documentation
all build their masks with :func:`erasure_mask`, and
:func:`compare_imputers` scores imputers on the paper's cases.
"""

from functools import partial
from numbers import Integral, Real

import numpy as np
from sklearn.utils import Bunch
from sklearn.utils.validation import check_array

from ..datasets import bone_columns
from ..metrics import fillin_angle_rmse, fillin_error
from ..utils._sequences import check_sequence_ids

__all__ = [
    "compare_imputers",
    "erasure_mask",
    "make_fillin_cases",
    "paper_body_parts",
]

# The paper's test trials (§4.4): the held-out walk and jog of CMU subject 35.
PAPER_TRIALS = {"walk": "35_29", "jog": "35_18"}


def erasure_mask(
    X,
    *,
    columns=None,
    bones=None,
    feature_names=None,
    sequence_ids=None,
    start=0.5,
    stop=None,
    strict=True,
):
    """Boolean mask of the entries to erase: channels over a part of every sequence.

    The chosen channels (``columns`` and ``bones``) are erased in the frames
    of every sequence whose relative position lies in ``[start, stop)``:
    frame ``i`` of a sequence of ``n`` frames is erased when
    ``start <= i / n < stop``.  The default, ``start=0.5``, is the paper's
    protocol (Taylor, Hinton & Roweis 2006, §4.4): the channels are lost
    from half-way through to the end, which is the last ``n // 2`` frames
    (62 of the 125 frames of walk 35_29).  Integer ``start`` and ``stop``
    are frame indices counted from each sequence's first frame.

    This is the one definition of the erased part that
    :func:`make_imputation_scorer`, :func:`make_fillin_cases`, the command
    line and the benchmarks use.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Stacked sequences; only its shape is used (it may hold NaN).
    columns : array-like of int, bool or str, default=None
        Channels to erase: indices, a boolean mask over the features, or
        feature names.
    bones : str or array-like of str, default=None
        Bones whose channels to erase: every feature named
        ``"{bone}_{channel}"`` (see :func:`sklearn_crbm.datasets.bone_columns`).
        Added to ``columns``; give at least one of the two.
    feature_names : array-like of str, default=None
        Names of the features of ``X``, to resolve ``bones`` and names in
        ``columns``; default the columns of a DataFrame.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    start : float or int, default=0.5
        Where the erased part of every sequence begins: a float in
        ``[0, 1]`` is a position relative to the sequence's length, an int a
        frame index.
    stop : float or int, default=None
        Where it ends (excluded), in the units of ``start``; ``None`` is the
        end of every sequence.
    strict : bool, default=True
        Whether every bone in ``bones`` must have a channel, end sites
        listed with their joint excepted (they have none, so the bones of
        ``skeleton.descendants(...)`` need no False).  With False,
        bones without one are skipped (a preprocessor drops constant
        channels, such as the clavicles of CMU data), but at least one bone
        must have one.

    Returns
    -------
    mask : ndarray of bool of shape (n_frames, n_features)
        True where a value is erased.

    Raises
    ------
    ValueError
        If a bone or a named column is not in ``feature_names``, or if the
        pattern erases nothing.

    See Also
    --------
    make_imputation_scorer : Score an imputer on the entries erased this way.
    make_fillin_cases : The paper's fill-in cases, built with this mask.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.model_selection import erasure_mask
    >>> X = np.zeros((7, 3))
    >>> names = ["root_tx", "lfemur_ex", "lfemur_ey"]
    >>> erasure_mask(X, bones="lfemur", feature_names=names).astype(int)
    array([[0, 0, 0],
           [0, 0, 0],
           [0, 0, 0],
           [0, 0, 0],
           [0, 1, 1],
           [0, 1, 1],
           [0, 1, 1]])
    >>> ids = [0, 0, 0, 0, 1, 1, 1]
    >>> erasure_mask(X, columns=[0], sequence_ids=ids, start=0.25, stop=0.75)[:, 0]
    array([False,  True,  True, False, False,  True,  True])
    """
    check_erasure(columns, bones, start, stop)
    if feature_names is None and hasattr(X, "columns"):
        feature_names = np.asarray(X.columns, dtype=object)
    X = check_array(X, dtype=None, ensure_all_finite=False, input_name="X")
    n_frames, n_features = X.shape
    channels = _channel_mask(columns, bones, feature_names, n_features, strict)
    frames = np.zeros(n_frames, dtype=bool)
    sequences = check_sequence_ids(sequence_ids, n_frames)
    for first, length in zip(sequences.starts, sequences.lengths, strict=True):
        lo = _frame_position(start, length)
        hi = length if stop is None else _frame_position(stop, length)
        frames[first + lo : first + max(lo, hi)] = True
    mask = np.outer(frames, channels)
    if not mask.any():
        raise ValueError(
            f"The pattern erases nothing in X of shape {X.shape}: no sequence "
            f"has frames from start={start!r} to stop={stop!r}."
        )
    return mask


def check_erasure(columns, bones, start, stop):
    """Check the arguments of :func:`erasure_mask` that do not depend on ``X``."""
    if columns is None and bones is None:
        raise ValueError(
            "Give the channels to erase: columns (indices, a boolean mask or "
            "feature names) and/or bones (bone names)."
        )
    if bones is not None and not isinstance(bones, str) and len(bones) == 0:
        raise ValueError("bones must name at least one bone.")
    for value, name in ((start, "start"), (stop, "stop")):
        if value is None and name == "stop":
            continue
        if isinstance(value, bool) or not isinstance(value, Real):
            raise TypeError(
                f"{name} must be a float in [0, 1] or an int, got {value!r}."
            )
        if isinstance(value, Integral):
            if value < 0:
                raise ValueError(f"{name} must be a frame index >= 0, got {value}.")
        elif not 0 <= value <= 1:
            raise ValueError(f"{name} as a fraction must be in [0, 1], got {value}.")


def _frame_position(value, length):
    """The first frame ``i`` of a ``length``-frame sequence at or after ``value``.

    A fraction counts the frames with ``i / length < value``: comparing the
    correctly rounded quotient with the float keeps ``0.3`` of 10 frames at
    frame 3, where ``ceil(0.3 * 10)`` would give 4.
    """
    if isinstance(value, Integral):
        return min(int(value), int(length))
    return int(np.count_nonzero(np.arange(length) / length < value))


def _channel_mask(columns, bones, feature_names, n_features, strict):
    """Boolean mask over the features: the columns and the bones' channels."""
    columns = None if columns is None else np.asarray(columns)
    names = None
    if feature_names is not None:
        names = np.asarray(feature_names, dtype=object)
        if len(names) != n_features:
            raise ValueError(
                f"{len(names)} feature names were given for X with {n_features} "
                "features."
            )
    needs_names = bones is not None or (
        columns is not None and columns.dtype.kind in "OUS"
    )
    if needs_names and names is None:
        raise ValueError(
            "Selecting channels by name needs feature names: pass feature_names= "
            "(e.g. preprocessor.get_feature_names_out()) or a DataFrame."
        )
    channels = np.zeros(n_features, dtype=bool)
    if columns is not None:
        channels |= _column_mask(columns, n_features, names)
    if bones is not None:
        channels[bone_columns(names, bones, strict=strict)] = True
    return channels


def _column_mask(columns, n_features, names):
    if columns.ndim != 1:
        raise ValueError(f"columns must be 1-D, got shape {columns.shape}.")
    if columns.dtype == bool:
        if len(columns) != n_features:
            raise ValueError(
                f"A boolean columns mask needs {n_features} entries, got "
                f"{len(columns)}."
            )
        return columns.copy()
    mask = np.zeros(n_features, dtype=bool)
    if columns.dtype.kind in "OUS":
        index = {str(name): i for i, name in enumerate(names)}
        unknown = [str(c) for c in columns if str(c) not in index]
        if unknown:
            raise ValueError(f"Unknown feature names in columns: {unknown}.")
        mask[[index[str(c)] for c in columns]] = True
        return mask
    if columns.dtype.kind not in "iu":
        raise TypeError(
            "columns must hold integer indices, booleans or feature names, got "
            f"dtype {columns.dtype}."
        )
    if len(columns) and (columns.min() < -n_features or columns.max() >= n_features):
        raise ValueError(
            f"columns holds indices out of range for {n_features} features: "
            f"{columns.tolist()}."
        )
    mask[columns] = True
    return mask


def paper_body_parts(skeleton, *, left_leg="lfemur", upper_body="lowerback"):
    """The paper's two erased body parts: the left leg and the upper body.

    Each part is a bone and every bone below it in ``skeleton``: the left
    leg from the left thigh down (on CMU data ``lfemur``, ``ltibia``,
    ``lfoot``, ``ltoes``), the upper body from the lower back up (the spine,
    neck, head, arms and hands).  The defaults are the CMU (ASF) bone names;
    name the top bones of another skeleton with ``left_leg`` and
    ``upper_body`` (in a BVH from Mixamo, for instance, ``"LeftUpLeg"`` and
    ``"Spine"``).

    Parameters
    ----------
    skeleton : Skeleton
        The skeleton whose bones to take.
    left_leg : str, default="lfemur"
        Top bone of the left leg.
    upper_body : str, default="lowerback"
        Top bone of the upper body.

    Returns
    -------
    parts : dict
        ``{"left leg": [bones], "upper body": [bones]}``, parents before
        children.

    Raises
    ------
    ValueError
        If the skeleton has no bone of that name; the message lists the
        skeleton's bones.

    Examples
    --------
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.model_selection import paper_body_parts
    >>> parts = paper_body_parts(make_walker(n_frames=10).skeleton)
    >>> parts["left leg"]
    ['lfemur', 'ltibia', 'lfoot']
    >>> parts["upper body"][:3]
    ['lowerback', 'thorax', 'head']
    """
    names = skeleton.bone_names
    parts = {"left leg": left_leg, "upper body": upper_body}
    missing = {part: bone for part, bone in parts.items() if bone not in names}
    if missing:
        which = ", ".join(f"{bone!r} ({part})" for part, bone in missing.items())
        raise ValueError(
            f"Skeleton {skeleton.name!r} has no bone {which}; name the top bones of "
            "its parts with left_leg=... and upper_body=.... Its bones are "
            f"{names}."
        )
    return {part: skeleton.descendants(bone) for part, bone in parts.items()}


def make_fillin_cases(
    data, preprocessor, *, trials=None, body_parts=None, start=0.5, stop=None
):
    """The paper's fill-in cases: a body part of a held-out trial, erased.

    For every trial and every body part, the trial's frames in the
    preprocessor's space with the part's channels erased by
    :func:`erasure_mask` (by default from half-way through to the end), and
    the same erasure in the raw channels, so that a fill can be scored both
    with the paper's error and in degrees.  With the defaults and the test
    subset of :func:`~sklearn_crbm.datasets.load_cmu35` these are the four
    cases of the paper's §4.4 (walk 35_29 and jog 35_18, left leg and upper
    body).

    Parameters
    ----------
    data : Bunch
        Motion shaped like the output of
        :func:`~sklearn_crbm.datasets.load_cmu35`: ``data`` (raw
        channels), ``sequence_ids``, ``sequence_names``, ``feature_names``
        and ``skeleton``.
    preprocessor : transformer
        Fitted, with ``transform``, ``inverse_transform`` and
        ``get_feature_names_out`` (e.g. a fitted
        :func:`~sklearn_crbm.preprocessing.make_motion_preprocessor`).
    trials : dict, default=None
        ``{label: sequence name}`` of the trials to erase; ``None`` is the
        paper's ``{"walk": "35_29", "jog": "35_18"}``.
    body_parts : dict, default=None
        ``{part: [bone names]}``; ``None`` is
        ``paper_body_parts(data.skeleton)``.  Bones without a channel after
        preprocessing (constant channels dropped) are skipped.
    start, stop : float or int, default=0.5 and None
        The erased part of each trial, as in :func:`erasure_mask`.

    Returns
    -------
    cases : dict
        ``{(label, part): case}`` in the order of ``trials`` then
        ``body_parts``.  Each case is a :class:`~sklearn.utils.Bunch` with
        ``trial`` (its name), ``bones``, ``X`` (the trial, preprocessed),
        ``missing_mask``, ``X_missing`` (``X`` with NaN where erased),
        ``first_missing`` (the first erased frame), ``raw`` (the trial's raw
        channels) and ``raw_missing_mask`` (the erased bones' raw channels),
        and ``errors(X_filled)``, which returns the pair
        ``(fillin_error, fillin_angle_rmse)`` of a fill of ``X_missing``:
        the paper's error in the preprocessor's space, and the RMS error in
        degrees of the raw channels after ``inverse_transform``.

    See Also
    --------
    erasure_mask : The entries erased.
    sklearn_crbm.metrics.fillin_error : The paper's fill-in error.
    sklearn_crbm.metrics.fillin_angle_rmse : The error in degrees.

    Examples
    --------
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.impute import NearestNeighborImputer
    >>> from sklearn_crbm.model_selection import make_fillin_cases
    >>> from sklearn_crbm.preprocessing import make_motion_preprocessor
    >>> walker = make_walker(n_sequences=3, n_frames=41, random_state=0)
    >>> train = walker.sequence_ids < 2
    >>> preprocessor = make_motion_preprocessor(walker.skeleton)
    >>> Z = preprocessor.fit_transform(walker.data[train])
    >>> cases = make_fillin_cases(walker, preprocessor, trials={"walk": "walk_2"})
    >>> list(cases)
    [('walk', 'left leg'), ('walk', 'upper body')]
    >>> case = cases["walk", "left leg"]
    >>> case.first_missing, int(case.missing_mask.any(axis=1).sum())
    (21, 20)
    >>> filled = NearestNeighborImputer().fit(Z).transform(case.X_missing)
    >>> error, degrees = case.errors(filled)
    >>> bool(error > 0 and degrees > 0)
    True
    """
    trials = PAPER_TRIALS if trials is None else dict(trials)
    if body_parts is None:
        body_parts = paper_body_parts(data.skeleton)
    names = preprocessor.get_feature_names_out()
    sequence_names = list(data.sequence_names)
    cases = {}
    for label, trial in trials.items():
        if trial not in sequence_names:
            raise ValueError(
                f"No sequence is named {trial!r}; the sequences are {sequence_names}."
            )
        raw = data.data[np.asarray(data.sequence_ids) == sequence_names.index(trial)]
        X = preprocessor.transform(raw)
        for part, bones in body_parts.items():
            erase = dict(bones=bones, strict=False, start=start, stop=stop)
            mask = erasure_mask(X, feature_names=names, **erase)
            case = Bunch(
                trial=trial,
                bones=list(bones),
                X=X,
                missing_mask=mask,
                X_missing=np.where(mask, np.nan, X),
                first_missing=int(np.flatnonzero(mask.any(axis=1))[0]),
                raw=raw,
                raw_missing_mask=erasure_mask(
                    raw, feature_names=data.feature_names, **erase
                ),
            )
            case.errors = partial(_case_errors, case, preprocessor)
            cases[label, part] = case
    return cases


def _case_errors(case, preprocessor, X_filled):
    """``(fillin_error, fillin_angle_rmse)`` of a fill of ``case.X_missing``."""
    raw = preprocessor.inverse_transform(X_filled)
    return (
        fillin_error(case.X, X_filled, missing_mask=case.missing_mask),
        fillin_angle_rmse(case.raw, raw, missing_mask=case.raw_missing_mask),
    )


def compare_imputers(imputers, cases, *, n_repeats=None, random_state=None):
    """Score fitted imputers on fill-in cases: the paper's error and degrees.

    Every imputer fills ``X_missing`` of every case of
    :func:`make_fillin_cases`, and the fill is scored with the case's
    ``errors``: the paper's error (:func:`~sklearn_crbm.metrics.fillin_error`)
    and the RMS error of the erased joint angles in degrees
    (:func:`~sklearn_crbm.metrics.fillin_angle_rmse`).  An imputer that
    draws fills (one with ``sample``, such as
    :class:`~sklearn_crbm.CRBMImputer`) is scored, with ``n_repeats``, by
    the mean error of that many single draws, as in the paper's §4.4;
    the others fill once with ``transform``.

    Parameters
    ----------
    imputers : dict
        ``{name: imputer}``, each fitted on data in the space of the cases'
        ``X`` (for example ``KNNImputer``,
        :class:`~sklearn_crbm.impute.NearestNeighborImputer`,
        :class:`~sklearn_crbm.impute.AutoregressiveImputer`,
        :class:`~sklearn_crbm.CRBMImputer`).
    cases : dict
        ``{key: case}`` from :func:`make_fillin_cases`.
    n_repeats : int, default=None
        Single draws averaged per case for imputers with ``sample``.  None
        fills once with every imputer's ``transform`` (a ``CRBMImputer``
        then averages its ``n_draws`` fills into one).
    random_state : int, RandomState instance or None, default=None
        Seeds the draws of ``sample``, the same for every case.

    Returns
    -------
    scores : dict
        ``{name: {key: {"error": float, "angle_rmse": float}}}``, in the
        order of ``imputers`` and ``cases``.

    See Also
    --------
    make_fillin_cases : The cases.
    make_imputation_scorer : A fill-in error as a scorer for a grid search.

    Examples
    --------
    >>> from sklearn.impute import KNNImputer
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.impute import NearestNeighborImputer
    >>> from sklearn_crbm.model_selection import compare_imputers, make_fillin_cases
    >>> from sklearn_crbm.preprocessing import make_motion_preprocessor
    >>> walker = make_walker(n_sequences=3, n_frames=41, random_state=0)
    >>> train = walker.sequence_ids < 2
    >>> preprocessor = make_motion_preprocessor(walker.skeleton)
    >>> Z = preprocessor.fit_transform(walker.data[train])
    >>> cases = make_fillin_cases(walker, preprocessor, trials={"walk": "walk_2"})
    >>> scores = compare_imputers(
    ...     {"NN": NearestNeighborImputer().fit(Z),
    ...      "KNN(5)": KNNImputer(n_neighbors=5).fit(Z)}, cases)
    >>> sorted(scores["NN"])
    [('walk', 'left leg'), ('walk', 'upper body')]
    >>> sorted(scores["NN"]["walk", "left leg"])
    ['angle_rmse', 'error']
    """
    if not isinstance(imputers, dict) or not imputers:
        raise TypeError(
            "imputers must be a non-empty dict {name: fitted imputer}, got "
            f"{type(imputers).__name__}."
        )
    if n_repeats is not None and (
        isinstance(n_repeats, bool)
        or not isinstance(n_repeats, Integral)
        or n_repeats < 1
    ):
        raise ValueError(f"n_repeats must be None or an int >= 1, got {n_repeats!r}.")
    return {
        name: {
            key: _case_scores(imputer, case, n_repeats, random_state)
            for key, case in cases.items()
        }
        for name, imputer in imputers.items()
    }


def _case_scores(imputer, case, n_repeats, random_state):
    """``{"error", "angle_rmse"}`` of one imputer's fill of one case."""
    if n_repeats is not None and hasattr(imputer, "sample"):
        draws = imputer.sample(
            case.X_missing, n_samples=n_repeats, random_state=random_state
        )
        error, degrees = np.mean([case.errors(draw) for draw in draws], axis=0)
    else:
        error, degrees = case.errors(imputer.transform(case.X_missing))
    return {"error": float(error), "angle_rmse": float(degrees)}
