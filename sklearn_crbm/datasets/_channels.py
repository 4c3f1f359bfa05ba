"""Finding the columns that belong to bones, by feature name."""

import numpy as np

__all__ = ["bone_columns"]


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
        Bone names.
    strict : bool, default=True
        If True, every bone must have a column.  If False, bones without a
        column are skipped (a preprocessor drops constant channels, such as
        the clavicles of CMU data), but at least one bone must have one.

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
    >>> bone_columns(names, ["lfemur", "ltibia"])
    array([1, 2, 3])
    >>> bone_columns(names, ["lfemur", "lclavicle"], strict=False)
    array([1, 2])
    """
    names = [str(name) for name in feature_names]
    bones = [bones] if isinstance(bones, str) else list(bones)
    columns = []
    for bone in bones:
        found = [i for i, name in enumerate(names) if name.startswith(f"{bone}_")]
        if not found and not strict:
            continue
        if not found:
            known = sorted({name.rsplit("_", 1)[0] for name in names})
            raise ValueError(
                f"No column belongs to bone {bone!r}: no feature name starts with "
                f"'{bone}_'. The bones with columns are: {known}."
            )
        columns.extend(found)
    if not columns:
        raise ValueError(f"None of the bones {bones} has a column in feature_names.")
    return np.array(sorted(set(columns)), dtype=np.intp)
