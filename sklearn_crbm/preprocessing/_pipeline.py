"""The paper's preprocessing chain as one Pipeline, and models on top of it."""

from pathlib import Path

import numpy as np
import sklearn
from scipy.sparse import issparse
from sklearn.pipeline import Pipeline
from sklearn.utils.metaestimators import available_if

from ..datasets import write_amc, write_bvh
from ..datasets._up_axis import check_up_axis
from ..metrics import forward_speed
from ..utils import random_windows
from ..utils._sequences import warn_if_sequences_unmarked
from ._data import StandardScaler
from ._expmap import ExpMapEncoder
from ._root import RootRelativeEncoder

__all__ = ["MotionPipeline", "make_motion_pipeline", "make_motion_preprocessor"]


def _check_routing(params):
    """Say how to turn routing on when ``sequence_ids`` or ``context`` is
    passed without it."""
    routed = [name for name in ("sequence_ids", "context") if name in params]
    if routed and not sklearn.get_config()["enable_metadata_routing"]:
        names = " and ".join(routed)
        raise ValueError(
            f"{names} reach{'es' * (len(routed) == 1)} the steps of a pipeline "
            "only through scikit-learn's metadata routing, which is off. Turn it "
            "on once, at the top of the script: sklearn.set_config("
            "enable_metadata_routing=True) (or for a block: with "
            "sklearn.config_context(enable_metadata_routing=True): ...). The "
            f"package's steps then receive {names} wherever they need them."
        )


def _has_sampler(pipeline):
    """Whether the final step is a generative model (for ``available_if``)."""
    return hasattr(pipeline._final_estimator, "sample")


class MotionPipeline(Pipeline):
    """A :class:`~sklearn.pipeline.Pipeline` of motion preprocessing and a model.

    The steps are the motion preprocessing (every step has an exact
    ``inverse_transform``: see :func:`make_motion_preprocessor`), optionally
    followed by a generative sequence model such as
    :class:`~sklearn_crbm.ConditionalRBM` (see :func:`make_motion_pipeline`).
    It is a scikit-learn Pipeline in every other respect (cloning, slicing,
    metadata routing of ``sequence_ids``, grid searches, pickling); what it
    adds works in the units of the raw channels:

    - :meth:`sample` generates with the model and returns raw channels;
    - :meth:`write_motion` writes raw channels as a BVH or AMC file;
    - :meth:`style_windows` picks seeds of a chosen style for :meth:`sample`;
    - :meth:`forward_speed` measures preprocessed motion in the skeleton's
      length units.

    Its ``fit`` and ``fit_transform`` say how to turn metadata routing on if
    ``sequence_ids`` is passed without it, and warn when ``X`` is the data of
    a loader's result of several sequences (files) given without them.  With
    a final model that needs complete frames, ``fit``, ``fit_transform`` and
    ``transform`` point frames with NaN to
    :class:`~sklearn_crbm.impute.CRBMImputer`.

    Parameters
    ----------
    steps : list of (str, estimator) tuples
        As for :class:`~sklearn.pipeline.Pipeline`.
    transform_input, memory, verbose
        As for :class:`~sklearn.pipeline.Pipeline`.

    Attributes
    ----------
    skeleton : Skeleton
        The skeleton of the raw channels (that of the first step that has
        one).

    See Also
    --------
    make_motion_pipeline : Preprocessing and a model in one pipeline.
    make_motion_preprocessor : The preprocessing alone.

    Examples
    --------
    >>> import sklearn
    >>> from sklearn_crbm import ConditionalRBM
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.preprocessing import make_motion_pipeline
    >>> walker = make_walker(n_sequences=2, n_frames=40, random_state=0)
    >>> model = ConditionalRBM(8, order=2, n_iter=2, random_state=0)
    >>> pipe = make_motion_pipeline(walker.skeleton, model)
    >>> with sklearn.config_context(enable_metadata_routing=True):
    ...     pipe = pipe.fit(walker.data, sequence_ids=walker.sequence_ids)
    >>> raw = pipe.sample(25, n_sequences=2, random_state=0)
    >>> raw.shape  # two sequences of 25 frames, in the skeleton's channels
    (50, 33)
    >>> pipe.write_motion("walk.bvh", raw[:25], frame_rate=30.0)  # doctest: +SKIP
    """

    def fit(self, X, y=None, **params):
        self._check_fit_input(X, params, "fit")
        return super().fit(X, y, **params)

    @available_if(Pipeline._can_fit_transform)
    def fit_transform(self, X, y=None, **params):
        self._check_fit_input(X, params, "fit_transform")
        return super().fit_transform(X, y, **params)

    @available_if(Pipeline._can_transform)
    def transform(self, X, **params):
        self._check_complete(X, "transform")
        return super().transform(X, **params)

    def _check_fit_input(self, X, params, method):
        _check_routing(params)
        self._validate_params()  # the steps, before the up axis reads them
        warn_if_sequences_unmarked(
            X, params.get("sequence_ids"), f"{type(self).__name__}.{method}", 4
        )
        self._check_complete(X, method)
        self._check_up_axis(X)

    def _check_complete(self, X, method):
        """Point to CRBMImputer when a final model that needs complete frames
        is given frames with NaN (the preprocessing steps pass NaN through)."""
        model = self._final_estimator
        if model == "passthrough" or model is None or not _has_sampler(self):
            return
        if model.__sklearn_tags__().input_tags.allow_nan or issparse(X):
            return  # the steps say what they think of sparse input
        try:
            values = np.asarray(X, dtype=np.float64)
        except (TypeError, ValueError):
            return  # not numbers: the steps' validation says so
        missing = np.isnan(values)
        if not missing.any():
            return
        frames = np.flatnonzero(missing.any(axis=1))
        raise ValueError(
            f"X holds NaN in {len(frames)} of its {len(values)} frames (the first "
            f"at frame {frames[0]}), but {type(self).__name__}.{method} needs "
            f"every channel of every frame for its {type(model).__name__}. Fill "
            "the gaps first with sklearn_crbm.impute.CRBMImputer (a model of "
            "the motion fills them in, frame by frame), or leave those frames out."
        )

    def _check_up_axis(self, X):
        """Warn when a root encoder's explicit ``up_axis`` is not the one the
        raw motion stands along (see ``Skeleton.detect_up_axis``)."""
        for name, step in self.steps:
            skeleton = getattr(step, "skeleton", None)
            setting = getattr(step, "up_axis", None)
            if not isinstance(step, RootRelativeEncoder) or None in (skeleton, setting):
                continue
            if np.shape(X)[1:] != (len(skeleton.feature_names),):
                continue  # not the skeleton's raw channels: nothing to detect on
            names = getattr(X, "columns", None)
            detected = skeleton.detect_up_axis(np.asarray(X, dtype=np.float64), names)
            check_up_axis(setting, detected, f"Step {name!r} sets", stacklevel=4)

    @property
    def skeleton(self):
        for _, step in self.steps:
            if hasattr(step, "skeleton"):
                return step.skeleton
        raise AttributeError(f"No step of {type(self).__name__} has a skeleton.")

    def _preprocessor(self):
        """The preprocessing steps: all but a final generative model."""
        return self[:-1] if _has_sampler(self) else self

    @available_if(_has_sampler)
    def sample(
        self, n_frames, *, history=None, n_sequences=1, random_state=None, **params
    ):
        """Generate motion with the final model, as raw channels.

        The model generates in the space it was trained in (its ``sample``);
        the preprocessing steps' ``inverse_transform`` brings every
        generated sequence back to the skeleton's raw channels (each starts
        at heading 0 and ground position (0, 0): see
        :class:`RootRelativeEncoder`).

        Parameters
        ----------
        n_frames : int
            Frames generated per sequence.
        history : array-like, default=None
            Seed frames in the model's space (the output of the preprocessing
            steps), as the model's ``sample`` takes them, for example from
            :meth:`style_windows`.  ``None``: the model's own seed windows
            of real training frames.
        n_sequences : int, default=1
            Sequences to generate.
        random_state : int, RandomState instance or None, default=None
            Seeds the generation.
        **params : dict
            Passed on to the model's ``sample``: ``y`` (a style model's
            labels of the new frames: one row of labels of every factor,
            such as ``("run", "elderly")``, or one row per frame, which
            switches labels on-line; a blend of a factor's labels is a
            mapping ``{label: weight}``), ``style`` (the labels of a model
            of one factor), ``context`` (every new frame's context, for a
            model fitted with one), ``n_gibbs``, ``hidden_noise``,
            ``sample_visibles``, ``n_mean_field``, ``n_jobs``.

        Returns
        -------
        X_raw : ndarray of shape (n_sequences * n_frames, n_raw_features)
            The generated frames in long format, in the skeleton's channels
            (``skeleton.feature_names``): rows ``k * n_frames`` to
            ``(k + 1) * n_frames - 1`` are sequence ``k``.
        """
        self._check_history(history)
        frames = self._final_estimator.sample(
            n_frames,
            history=history,
            n_sequences=n_sequences,
            random_state=random_state,
            **params,
        )
        n_sequences = frames.shape[0] // n_frames
        sequence_ids = np.repeat(np.arange(n_sequences), n_frames)
        with sklearn.config_context(enable_metadata_routing=True):
            return self[:-1].inverse_transform(
                np.asarray(frames), sequence_ids=sequence_ids
            )

    def _check_history(self, history):
        """Say in the raw channels' terms what a seed of the wrong shape lacks."""
        shape = np.shape(history) if history is not None else None
        model = self._final_estimator
        n_model = getattr(model, "n_features_in_", None)
        if shape is None or len(shape) not in (2, 3) or n_model is None:
            return  # the model's own checks say what is wrong
        width = max(model.history_length, 1)
        n_raw = len(self.skeleton.feature_names)
        if shape[-1] == n_model and shape[-2] >= width:
            return
        frames = f"{shape[-2]} frame{'s' * (shape[-2] != 1)}"
        got = (
            f"{frames} of the skeleton's {n_raw} raw channels"
            if shape[-1] == n_raw
            else f"{frames} of {shape[-1]} channels"
        )
        raise ValueError(
            f"history holds {got}, but sample seeds the model in its own space: "
            f"take at least {width} raw frames of {n_raw} channels through the "
            f"preprocessing (history=pipe[:-1].transform(raw_frames), which gives "
            f"{n_model} features per frame), or seeds from style_windows."
        )

    @available_if(_has_sampler)
    def style_windows(
        self, X, y, *, sequence_ids=None, n_windows=50, random_state=None
    ):
        """Windows of real frames of every style, to seed :meth:`sample`.

        ``X`` (raw channels) goes through the preprocessing steps; each
        window is ``max(history_length, 1)`` consecutive frames of one
        sequence that all have the same label, drawn as
        :func:`~sklearn_crbm.utils.random_windows` draws them.  Pass
        ``windows[style]`` as ``history`` to :meth:`sample` to generate from
        real motion of that style, as the paper's first demonstration does
        (§4.1: walking and jogging from one model).

        Parameters
        ----------
        X : array-like of shape (n_frames, n_raw_features)
            Real motion in raw channels, for example the training data.
        y : array-like of shape (n_frames,) or (n_frames, n_outputs)
            The style (any label) of every frame, or its labels of several
            factors (a row such as ``["run", "elderly"]``), as the model's
            ``fit`` took them.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence id of every frame; ``None`` means one sequence.
        n_windows : int, default=50
            Windows per style.
        random_state : int, numpy.random.Generator or None, default=None
            Seeds the draws (the styles are drawn in turn from one stream).

        Returns
        -------
        windows : dict
            ``{style: ndarray of shape (n_windows, width, n_features)}`` in
            the model's space, oldest frame first, the styles in order of
            first appearance; with several factors, keyed by the tuple of a
            row's labels (``("run", "elderly")``).

        Raises
        ------
        ValueError
            If a style has no run of ``width`` frames within one sequence.
        """
        y = np.asarray(y, dtype=object)
        if y.ndim not in (1, 2) or len(y) != len(X):
            raise ValueError(
                f"y must hold one style per frame: {len(X)} labels (or rows of "
                f"labels), got shape {y.shape}."
            )
        # several label factors: a row of labels is a style
        labels = [tuple(row) for row in y.tolist()] if y.ndim == 2 else y.tolist()
        index = {}
        codes = np.array(
            [index.setdefault(label, len(index)) for label in labels], dtype=np.intp
        )
        styles = list(index)
        params = {} if sequence_ids is None else {"sequence_ids": sequence_ids}
        _check_routing(params)
        Z = self[:-1].transform(X, **params)
        runs = _label_runs(sequence_ids, codes)
        width = max(self._final_estimator.history_length, 1)
        rng = np.random.default_rng(random_state)
        windows = {}
        for code, style in enumerate(styles):
            windows[style] = random_windows(
                Z,
                sequence_ids=runs,
                width=width,
                n_windows=n_windows,
                sequences=np.unique(runs[codes == code]),
                random_state=rng,
            )
        return windows

    def forward_speed(self, X, *, sequence_ids=None, last_frames=None):
        """Forward speed of preprocessed motion, in the skeleton's length units.

        ``X`` is the output of the preprocessing steps (the model's space,
        where the speed channel is standardised); the steps after the
        :class:`RootRelativeEncoder` are undone, and
        :func:`~sklearn_crbm.metrics.forward_speed` measures its
        ``{root}_dforward`` channel: the mean distance the body moves
        forward per frame, in the length units of the skeleton's file.

        Parameters
        ----------
        X : array-like of shape (n_frames, n_features)
            Motion in the space the preprocessing steps output.
        sequence_ids : array-like of shape (n_frames,), default=None
            Sequence id of every frame; ``None`` means one sequence.
        last_frames : int, default=None
            Use only the last ``last_frames`` frames of each sequence.

        Returns
        -------
        speed : ndarray of shape (n_sequences,)
            Length units per frame.
        """
        preprocessor = self._preprocessor()
        encoders = [
            k
            for k, (_, step) in enumerate(preprocessor.steps)
            if isinstance(step, RootRelativeEncoder)
        ]
        if not encoders:
            raise ValueError(
                "forward_speed needs a RootRelativeEncoder step, which measures "
                "the body's forward displacement; this pipeline has the steps "
                f"{[name for name, _ in preprocessor.steps]}."
            )
        root = encoders[-1]
        after = preprocessor[root + 1 :]
        unscaled = after.inverse_transform(X) if len(after) else X
        return forward_speed(
            unscaled,
            sequence_ids=sequence_ids,
            feature_names=preprocessor[: root + 1].get_feature_names_out(),
            last_frames=last_frames,
        )

    def write_motion(self, path, X, *, frame_rate=None):
        """Write one sequence of raw channels as a BVH or AMC file.

        The format follows the file's suffix: ``.bvh`` writes
        :func:`~sklearn_crbm.datasets.write_bvh`, ``.amc``
        :func:`~sklearn_crbm.datasets.write_amc` (for a skeleton read from
        an ASF file, which the AMC file goes with).

        Parameters
        ----------
        path : path-like
            The file, ending in ``.bvh`` or ``.amc``.
        X : array-like of shape (n_frames, n_raw_features)
            One sequence in the skeleton's channels, for example one
            sequence of :meth:`sample`.
        frame_rate : float, default=None
            Frames per second, required for BVH (AMC files do not say).
        """
        suffix = Path(path).suffix.lower()
        if suffix == ".bvh":
            if frame_rate is None:
                raise ValueError(
                    "A BVH file says its frame rate: pass frame_rate= (the "
                    "training data's, e.g. load_cmu35(...).frame_rate)."
                )
            write_bvh(path, X, self.skeleton, frame_rate)
        elif suffix == ".amc":
            write_amc(path, X, self.skeleton)
        else:
            raise ValueError(
                f"Cannot tell the format of {path}: name it *.bvh or *.amc."
            )


def _label_runs(sequence_ids, y):
    """Ids of the runs of frames with one label within one sequence."""
    ids = np.zeros(len(y), dtype=np.intp) if sequence_ids is None else sequence_ids
    ids = np.asarray(ids)
    new_run = np.ones(len(y), dtype=bool)
    new_run[1:] = (ids[1:] != ids[:-1]) | (y[1:] != y[:-1])
    return np.cumsum(new_run) - 1


def make_motion_pipeline(skeleton, model, **preprocessor_params):
    """The paper's preprocessing followed by a generative model, as one pipeline.

    The steps of :func:`make_motion_preprocessor` (``expmap``, ``root``,
    ``scale``) then ``model``, named ``"model"``, in a
    :class:`MotionPipeline`: ``fit`` preprocesses and trains on raw
    channels, :meth:`MotionPipeline.sample` generates raw channels, and
    :meth:`MotionPipeline.write_motion` writes them as BVH or AMC.

    Parameters
    ----------
    skeleton : Skeleton
        Describes the raw columns, as for :func:`make_motion_preprocessor`.
    model : estimator
        The model, trained on the preprocessed motion, for example a
        :class:`~sklearn_crbm.ConditionalRBM`; with a ``sample`` method the
        pipeline can generate.
    **preprocessor_params : dict
        Passed to :func:`make_motion_preprocessor` (``reference``, ``roll``,
        ``up_axis``...).

    Returns
    -------
    pipeline : MotionPipeline
        Unfitted.

    Examples
    --------
    >>> from sklearn_crbm import ConditionalRBM
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.preprocessing import make_motion_pipeline
    >>> walker = make_walker(n_sequences=1, n_frames=10, random_state=0)
    >>> pipe = make_motion_pipeline(walker.skeleton, ConditionalRBM(8))
    >>> [name for name, _ in pipe.steps]
    ['expmap', 'root', 'scale', 'model']
    """
    preprocessor = make_motion_preprocessor(skeleton, **preprocessor_params)
    return MotionPipeline([*preprocessor.steps, ("model", model)])


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
    scale_floor=0.01,
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
        Vertical axis; None takes ``skeleton.up_axis``, which the file
        readers detect from the motion (see
        :meth:`~sklearn_crbm.datasets.Skeleton.detect_up_axis`; ``"z"`` for
        the MIT data).  The body's forward axis is the next one cyclically
        (y up: z forward; z up: x forward).  Fitting warns when an axis given
        here is not the one the motion stands along.
    roll : {"euler", "taylor"}, default="euler"
        How the root's roll is encoded; see :class:`RootRelativeEncoder`.
    with_mean, with_std : bool, default=True
        Passed to :class:`StandardScaler`.
    constant_tol : float or None, default=1e-10
        Passed to :class:`StandardScaler`: the tolerance below which a
        channel counts as constant and is dropped.
    scale_floor : float, default=0.01
        Passed to :class:`StandardScaler`: a channel that moves less than
        this fraction of the typical channel is scaled as if it moved that
        much, so that held-out takes of the same motion stay within the
        range of the training data.

    Returns
    -------
    pipeline : MotionPipeline
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
                    with_mean=with_mean,
                    with_std=with_std,
                    constant_tol=constant_tol,
                    scale_floor=scale_floor,
                ),
            ),
        ]
    )
