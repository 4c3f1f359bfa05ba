"""The paper's preprocessing chain as one Pipeline."""

import sklearn
from sklearn.pipeline import Pipeline

from ._data import StandardScaler
from ._expmap import ExpMapEncoder
from ._root import RootRelativeEncoder

__all__ = ["make_motion_preprocessor"]


def _check_routing(params):
    """Say how to turn routing on when ``sequence_ids`` is passed without it."""
    if "sequence_ids" in params and not sklearn.get_config()["enable_metadata_routing"]:
        raise ValueError(
            "sequence_ids reaches the steps of a pipeline only through "
            "scikit-learn's metadata routing, which is off. Turn it on once, "
            "at the top of the script: sklearn.set_config("
            "enable_metadata_routing=True) (or for a block: with "
            "sklearn.config_context(enable_metadata_routing=True): ...). The "
            "package's steps then receive sequence_ids wherever they need them."
        )


class MotionPipeline(Pipeline):
    """A Pipeline whose ``fit`` explains metadata routing when it is off."""

    def fit(self, X, y=None, **params):
        _check_routing(params)
        return super().fit(X, y, **params)

    def fit_transform(self, X, y=None, **params):
        _check_routing(params)
        return super().fit_transform(X, y, **params)


def make_motion_preprocessor(
    skeleton,
    *,
    angle_unit=None,
    continuous=False,
    reference="mean",
    up_axis=None,
    roll="euler",
    with_mean=True,
    with_std=True,
    constant_tol=1e-10,
):
    """The paper's preprocessing: exp maps, body-centred root, z-scores.

    Builds the :class:`~sklearn.pipeline.Pipeline` ``expmap``
    (:class:`ExpMapEncoder`) -> ``root`` (:class:`RootRelativeEncoder`) ->
    ``scale`` (:class:`StandardScaler`, which drops constant channels), as in
    Taylor et al. (2006), §3.  CMU subject 35 (62 raw channels) comes out with
    the paper's 62 dimensions, Taylor's MIT walking data (108 columns) with 49.

    It works on any skeleton: the root bone is the skeleton's first bone,
    whatever its name (``root``, ``Hips``, ``joint_Root``...), and needs
    position and rotation channels; its six channels come out as
    ``"{root}_pitch"``, ``"{root}_roll"``, ``"{root}_dheading"``,
    ``"{root}_dforward"``, ``"{root}_dsideways"``, ``"{root}_height"``
    (``root_pitch``, ... for CMU data, ``Hips_pitch``, ... for a root called
    ``Hips``).  The defaults give every pose an exact
    inverse (upside down included) and keep the exponential maps away from
    their jumps at a rotation of pi; ``reference="rest", roll="taylor"``
    reproduce the paper's encoding exactly (Taylor's ``preprocess1`` and
    ``preprocess2``), which is exact only for upright bodies.

    The two encoders request ``sequence_ids`` for ``fit``, ``transform`` and
    ``inverse_transform``: with ``sklearn.set_config(enable_metadata_routing=
    True)`` pass ``sequence_ids=`` once to the pipeline's ``fit``,
    ``fit_transform``, ``transform`` or ``inverse_transform``.  Every method
    has an exact inverse; ``inverse_transform`` starts every sequence at
    heading 0 and ground position (0, 0) (see :class:`RootRelativeEncoder`).

    Parameters
    ----------
    skeleton : Skeleton
        Describes the raw columns: ``X`` holds ``skeleton.feature_names`` in
        that order.  Also gives the up axis and the angle unit.
    angle_unit : {"deg", "rad"} or None, default=None
        Unit of the Euler channels; None takes ``skeleton.angle_unit``
        (degrees if the skeleton has none).
    continuous : bool, default=False
        Keep each sequence's exponential maps continuous through a rotation
        of pi (see :class:`ExpMapEncoder`).
    reference : {"mean", "rest"}, default="mean"
        Measure each joint's rotation from its mean over the training data
        (``"mean"``) or from the rest pose (``"rest"``, the paper); see
        :class:`ExpMapEncoder`.
    up_axis : {"x", "y", "z"} or None, default=None
        Vertical axis; None takes ``skeleton.up_axis`` (``"y"`` for ASF and
        BVH files, ``"z"`` for the MIT data).  The body's forward axis is the
        next one cyclically (y up: z forward; z up: x forward).  Fitting warns
        when the root's forward axis is nearly vertical in most frames, the
        sign of a wrong up axis.
    roll : {"euler", "taylor"}, default="euler"
        How the root's roll is encoded; see :class:`RootRelativeEncoder`.
    with_mean, with_std : bool, default=True
        Passed to :class:`StandardScaler`.
    constant_tol : float or None, default=1e-10
        Passed to :class:`StandardScaler`: the tolerance below which a
        channel counts as constant and is dropped.

    Returns
    -------
    pipeline : sklearn.pipeline.Pipeline
        Unfitted; ``get_feature_names_out()`` names every output channel
        once fitted.  Its ``fit`` and ``fit_transform`` say how to turn
        metadata routing on if ``sequence_ids`` is passed without it.

    Examples
    --------
    >>> import numpy as np
    >>> import sklearn
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.preprocessing import make_motion_preprocessor
    >>> walker = make_walker(n_sequences=2, n_frames=40, random_state=0)
    >>> walker.data.shape
    (80, 33)
    >>> with sklearn.config_context(enable_metadata_routing=True):
    ...     pre = make_motion_preprocessor(walker.skeleton)
    ...     Z = pre.fit_transform(walker.data, sequence_ids=walker.sequence_ids)
    ...     X_back = pre.inverse_transform(Z, sequence_ids=walker.sequence_ids)
    >>> Z.shape
    (80, 33)
    >>> pre.get_feature_names_out()[:8]
    array(['root_pitch', 'root_roll', 'root_dheading', 'root_dforward',
           'root_dsideways', 'root_height', 'lfemur_ex', 'lfemur_ey'],
          dtype=object)
    >>> # joint angles and height come back; the ground track starts at 0
    >>> bool(np.allclose(X_back[:, 6:], walker.data[:, 6:]))
    True
    """
    if angle_unit is None:
        angle_unit = getattr(skeleton, "angle_unit", None) or "deg"
    return MotionPipeline(
        [
            (
                "expmap",
                ExpMapEncoder(
                    skeleton,
                    angle_unit=angle_unit,
                    continuous=continuous,
                    reference=reference,
                ),
            ),
            (
                "root",
                RootRelativeEncoder(skeleton, up_axis=up_axis, roll=roll),
            ),
            (
                "scale",
                StandardScaler(
                    with_mean=with_mean, with_std=with_std, constant_tol=constant_tol
                ),
            ),
        ]
    )
