"""Channels: their names, and the columns of raw data that hold them.

The vocabulary that the skeleton, the file readers and the writers share,
kept apart from the data model so that no module needs to know another
module's file format.
"""

import numpy as np

__all__ = [
    "END_SITE_SUFFIX",
    "EULER_CHANNELS",
    "EXPMAP_CHANNELS",
    "KNOWN_CHANNELS",
    "OFFSET_CHANNELS",
    "TRANSLATION_CHANNELS",
    "bone_columns",
    "column_indices",
    "frame_columns",
]

EULER_CHANNELS = ("rx", "ry", "rz")
EXPMAP_CHANNELS = ("ex", "ey", "ez")
TRANSLATION_CHANNELS = ("tx", "ty", "tz")
OFFSET_CHANNELS = ("ox", "oy", "oz")
# A BVH end site is a bone without channels named after its parent.
END_SITE_SUFFIX = "_end"
KNOWN_CHANNELS = (
    EULER_CHANNELS + EXPMAP_CHANNELS + TRANSLATION_CHANNELS + OFFSET_CHANNELS
)


def bone_columns(feature_names, bones, *, strict=True):
    """Indices of the columns named ``"{bone}_..."`` for the given bones.

    Works on raw channel names (``lfemur_rx``), exponential maps
    (``lfemur_ex``) and anything else that follows the ``"{bone}_{channel}"``
    convention, e.g. the output of ``get_feature_names_out()`` of a fitted
    preprocessor, so "the left leg" can be selected by bone name at any stage.

    Parameters
    ----------
    feature_names : array-like of str
        Column names.
    bones : str or iterable of str
        Bone names.  An end site (a BVH joint without channels, named
        ``"{parent}_end"``) listed with its parent needs no column, so the
        bones of :meth:`Skeleton.descendants` can be passed as they are.
    strict : bool, default=True
        If True, every other bone must have a column.  If False, bones
        without a column are skipped (a preprocessor drops constant
        channels, such as the clavicles of CMU data), but at least one bone
        must have one.

    Returns
    -------
    columns : ndarray of int
        Column indices in increasing order.

    Raises
    ------
    ValueError
        If a bone has no column (``strict=True``) or no bone has one.

    Examples
    --------
    >>> from sklearn_crbm.datasets import bone_columns
    >>> names = ["root_tx", "lfemur_rx", "lfemur_ry", "ltibia_rx", "rfemur_rx"]
    >>> bone_columns(names, ["lfemur", "ltibia", "ltibia_end"])
    array([1, 2, 3])
    >>> bone_columns(names, ["lfemur", "lclavicle"], strict=False)
    array([1, 2])
    """
    names = [str(name) for name in feature_names]
    bones = [bones] if isinstance(bones, str) else list(bones)
    columns = []
    for bone in bones:
        found = [i for i, name in enumerate(names) if name.startswith(f"{bone}_")]
        if not found and (not strict or _end_site_of_listed_bone(bone, bones)):
            continue
        if not found:
            known = sorted({name.rsplit("_", 1)[0] for name in names})
            raise ValueError(
                f"No column belongs to bone {bone!r}: no feature name starts with "
                f"'{bone}_'. The bones with columns are: {known}. To skip bones "
                "without columns (a preprocessor drops the channels that never "
                "change), pass strict=False."
            )
        columns.extend(found)
    if not columns:
        raise ValueError(f"None of the bones {bones} has a column in feature_names.")
    return np.array(sorted(set(columns)), dtype=np.intp)


def _end_site_of_listed_bone(bone, bones):
    """Whether ``bone`` is named as the end site of another of ``bones``."""
    return bone.endswith(END_SITE_SUFFIX) and bone[: -len(END_SITE_SUFFIX)] in bones


def frame_columns(data, feature_names, required):
    """``(X, columns)``: ``data`` as a 2-D float64 array and the
    :func:`column_indices` of its ``feature_names``; a clear error for sparse,
    non-numeric or not 2-D data."""
    if hasattr(data, "toarray") or hasattr(data, "tocsr"):
        raise TypeError(
            "data must be a dense array of raw channels, got a sparse matrix; "
            "convert it with .toarray()."
        )
    try:
        X = np.asarray(data, dtype=np.float64)
    except (TypeError, ValueError) as exc:
        raise ValueError(
            f"data must be a numeric array of shape (n_frames, n_features): {exc}"
        ) from None
    if X.ndim != 2:
        raise ValueError(
            f"data must be 2-D (n_frames, n_features), got shape {X.shape}."
        )
    return X, column_indices(feature_names, required, n_columns=X.shape[1])


def column_indices(feature_names, required, *, n_columns=None):
    """Map each required feature name to its column.

    Parameters
    ----------
    feature_names : array-like of str
        Name of every column.
    required : list of str
        Names that must be present.
    n_columns : int, default=None
        Expected number of columns, checked when given.

    Returns
    -------
    columns : dict
        ``name -> column index`` for every name in ``feature_names``.

    Raises
    ------
    ValueError
        If a required name is missing (all missing names are listed), a name
        repeats, or the number of names does not match ``n_columns``.
    """
    names = [str(n) for n in np.asarray(feature_names, dtype=object).ravel()]
    if n_columns is not None and len(names) != n_columns:
        raise ValueError(
            f"Got {len(names)} feature names for data with {n_columns} columns."
        )
    columns = {}
    for i, name in enumerate(names):
        if name in columns:
            raise ValueError(f"Feature name {name!r} occurs more than once.")
        columns[name] = i
    missing = [name for name in required if name not in columns]
    if missing:
        raise ValueError(f"The data lack these channels of the skeleton: {missing}.")
    return columns
