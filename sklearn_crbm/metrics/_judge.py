"""Judging generated motion: its style, and whether it stays alive."""

from numbers import Real

import numpy as np
from sklearn.utils import Bunch, check_array

from ..datasets import bone_columns
from ..utils._sequences import check_sequence_ids
from ._generation import (
    gait_statistics,
    motion_amplitude,
    nearest_style,
    spectral_similarity,
)

__all__ = ["judge_generated_motion"]

# Generated values are clipped here before the statistics are taken, so that
# a sequence that blew up still gets finite (and clearly wrong) statistics.
_CLIP = 1e3


def judge_generated_motion(
    X,
    X_reference,
    *,
    reference_styles,
    preprocessor,
    expected_styles=None,
    sequence_ids=None,
    reference_sequence_ids=None,
    legs=("lfemur", "rfemur", "ltibia", "rtibia"),
    frame_rate=30.0,
    last_frames=None,
    max_abs_value=10.0,
):
    """Style and liveliness of every generated sequence, against real motion.

    Both ``X`` (generated) and ``X_reference`` (real motion of known styles)
    are in the space the model was trained in: the output of
    ``preprocessor``.  Each generated sequence (only its last
    ``last_frames`` frames, where given) is judged by:

    - ``style``: the style of the nearest reference style in forward speed
      and gait frequency (:func:`gait_statistics` and
      :func:`nearest_style`);
    - ``dead``: its leg amplitude (:func:`motion_amplitude` of the ``legs``
      channels) is below half the mean amplitude of the reference
      sequences: the motion died out into a pose;
    - ``stalled``: its forward speed, in the skeleton's length units per
      frame, is below half the mean speed of the slowest reference style
      (the real walk): standing or shuffling in place, whatever the legs do;
    - ``blown``: a value of the whole sequence is beyond ``max_abs_value``
      (or NaN): the generation diverged;
    - ``keeps``: it has its expected style and is neither dead, stalled nor
      blown.

    Judging the reference motion against itself gives the statistics of the
    real sequences (for example their mean speed per style).

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Generated motion, all sequences stacked in long format.
    X_reference : array-like of shape (n_reference_frames, n_features)
        Real motion in the same space (typically the training data).
    reference_styles : array-like of shape (n_reference_sequences,)
        Style of every reference sequence, in order of appearance (for CMU
        subject 35: ``load_cmu35(...).motion``).
    preprocessor : MotionPipeline
        The fitted preprocessing whose output ``X`` is (see
        :func:`~sklearn_crbm.preprocessing.make_motion_preprocessor`): it
        names the channels and gives speeds in the skeleton's length units
        (:meth:`~sklearn_crbm.preprocessing.MotionPipeline.forward_speed`).
    expected_styles : array-like of shape (n_sequences,), default=None
        The style each generated sequence should have, for example that of
        its seed frames.  None expects each sequence to keep the style it is
        classified as.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame of ``X``; ``None`` means one sequence.
    reference_sequence_ids : array-like of shape (n_reference_frames,), default=None
        Sequence id of every frame of ``X_reference``.
    legs : sequence of str, default=("lfemur", "rfemur", "ltibia", "rtibia")
        Bones whose channels give the gait cycle and the leg amplitude (the
        CMU hips and knees); see :func:`gait_statistics`.
    frame_rate : float, default=30.0
        Frames per second.
    last_frames : int, default=None
        Judge only the last ``last_frames`` frames of each generated
        sequence (``blown`` always looks at every frame).
    max_abs_value : float, default=10.0
        A sequence with a value beyond this (in the units of ``X``, standard
        deviations after the package's preprocessing) has blown up.

    Returns
    -------
    verdict : :class:`~sklearn.utils.Bunch`
        One entry per generated sequence, in order of appearance, in arrays
        of shape (n_sequences,): ``style`` (object; None if a statistic is
        NaN), ``speed`` (length units per frame), ``frequency`` (Hz),
        ``amplitude`` (units of ``X``), ``max_abs_value``, ``similarity``
        (:func:`spectral_similarity` to the reference sequences of the
        expected style; NaN for a blown sequence), and the booleans
        ``dead``, ``stalled``, ``blown`` and ``keeps``.

    See Also
    --------
    gait_statistics : The statistics the style is classified on.
    sklearn_crbm.preprocessing.MotionPipeline.sample : Generate motion.

    Examples
    --------
    >>> import numpy as np
    >>> import sklearn
    >>> from sklearn_crbm.datasets import make_walker
    >>> from sklearn_crbm.metrics import judge_generated_motion
    >>> from sklearn_crbm.preprocessing import make_motion_preprocessor
    >>> walker = make_walker(n_sequences=4, n_frames=60, random_state=0)
    >>> pre = make_motion_preprocessor(walker.skeleton)
    >>> with sklearn.config_context(enable_metadata_routing=True):
    ...     Z = pre.fit_transform(walker.data, sequence_ids=walker.sequence_ids)
    >>> styles = ["walk", "walk", "walk", "walk"]
    >>> still = np.tile(Z[:1], (60, 1))  # one pose, held
    >>> verdict = judge_generated_motion(
    ...     np.vstack([Z[:60], still]), Z, sequence_ids=np.repeat([0, 1], 60),
    ...     reference_styles=styles, reference_sequence_ids=walker.sequence_ids,
    ...     preprocessor=pre, legs=["lfemur", "rfemur"])
    >>> verdict.keeps, verdict.dead
    (array([ True, False]), array([False,  True]))
    """
    if isinstance(max_abs_value, bool) or not isinstance(max_abs_value, Real):
        raise TypeError(f"max_abs_value must be a number, got {max_abs_value!r}.")
    names = np.asarray(preprocessor.get_feature_names_out(), dtype=object)
    X, sequences = _check_judged(X, sequence_ids, names, "X")
    X_reference, reference_sequences = _check_judged(
        X_reference, reference_sequence_ids, names, "X_reference"
    )
    reference_styles = np.asarray(reference_styles, dtype=object)
    if reference_styles.shape != (reference_sequences.n_sequences,):
        raise ValueError(
            f"reference_styles has {reference_styles.size} labels but "
            f"X_reference holds {reference_sequences.n_sequences} sequences: give "
            "one style per reference sequence, in order of appearance."
        )
    statistics = _Statistics(preprocessor, names, legs, frame_rate)
    reference = statistics(X_reference, reference_sequence_ids)
    verdict = statistics(X, sequence_ids, last_frames)
    verdict.style = nearest_style(verdict.gait, reference.gait, reference_styles)
    if expected_styles is None:
        expected = verdict.style
    else:
        expected = np.asarray(expected_styles, dtype=object)
        if expected.shape != (sequences.n_sequences,):
            raise ValueError(
                f"expected_styles has {expected.size} labels but X holds "
                f"{sequences.n_sequences} sequences."
            )
    slowest = min(
        reference.speed[reference_styles == style].mean()
        for style in np.unique(reference_styles)
    )
    verdict.max_abs_value = np.array(
        [
            np.max(np.abs(np.nan_to_num(X[a:b], nan=np.inf)))
            for a, b in zip(sequences.starts, sequences.stops, strict=True)
        ]
    )
    verdict.dead = verdict.amplitude < 0.5 * reference.amplitude.mean()
    verdict.stalled = verdict.speed < 0.5 * slowest
    verdict.blown = verdict.max_abs_value > max_abs_value
    verdict.keeps = (
        (verdict.style == expected) & ~verdict.dead & ~verdict.stalled & ~verdict.blown
    )
    verdict.similarity = _similarities(
        X,
        sequences,
        X_reference,
        reference_sequences,
        reference_styles,
        expected,
        ~verdict.blown,
        last_frames,
    )
    verdict.pop("gait")
    return verdict


def _check_judged(X, sequence_ids, names, name):
    """``X`` as floats (NaN allowed: generation may diverge) and its sequences."""
    X = check_array(X, dtype=np.float64, ensure_all_finite=False, input_name=name)
    if X.shape[1] != len(names):
        raise ValueError(
            f"{name} has {X.shape[1]} columns but the preprocessor outputs "
            f"{len(names)} features."
        )
    return X, check_sequence_ids(sequence_ids, X.shape[0])


class _Statistics:
    """Per-sequence gait, speed, frequency and leg amplitude of motion."""

    def __init__(self, preprocessor, names, legs, frame_rate):
        self.preprocessor = preprocessor
        self.names = names
        self.legs = legs
        self.leg_channels = list(names[bone_columns(names, legs)])
        self.frame_rate = frame_rate

    def __call__(self, X, sequence_ids, last_frames=None):
        finite = np.clip(np.nan_to_num(X, nan=0.0), -_CLIP, _CLIP)
        common = dict(sequence_ids=sequence_ids, last_frames=last_frames)
        gait = gait_statistics(
            finite,
            feature_names=self.names,
            legs=self.legs,
            frame_rate=self.frame_rate,
            **common,
        )
        return Bunch(
            gait=gait,
            speed=self.preprocessor.forward_speed(finite, **common),
            frequency=gait[:, 1],
            amplitude=motion_amplitude(
                finite, feature_names=self.names, features=self.leg_channels, **common
            ),
        )


def _similarities(
    X, sequences, X_reference, reference, reference_styles, expected, usable, last
):
    """Spectral similarity of every usable sequence to its expected style's trials."""
    similarity = np.full(sequences.n_sequences, np.nan)
    finite = np.array(
        [
            np.isfinite(X[a:b]).all()
            for a, b in zip(sequences.starts, sequences.stops, strict=True)
        ],
        dtype=bool,
    )
    reference_ids = reference.per_frame_ids()
    for style in np.unique(expected[expected != None]):  # noqa: E711
        chosen = np.flatnonzero((expected == style) & finite & usable)
        real = np.isin(reference_ids, reference.ids[reference_styles == style])
        if len(chosen) == 0 or not real.any():
            continue
        rows = np.concatenate(
            [np.arange(sequences.starts[k], sequences.stops[k]) for k in chosen]
        )
        similarity[chosen] = spectral_similarity(
            X[rows],
            X_reference[real],
            sequence_ids=np.repeat(np.arange(len(chosen)), sequences.lengths[chosen]),
            reference_sequence_ids=reference_ids[real],
            last_frames=last,
        )
    return similarity
