"""Statistics of generated motion: speed, step frequency, amplitude, spectra, style.

Every function takes motion in long format (``X`` of shape ``(n_frames,
n_features)`` with per-frame ``sequence_ids``, as everywhere in the package)
and returns one value per sequence, in the order the sequences appear, so
that real and generated motion, or two models, can be compared sequence by
sequence.  Channels are chosen by name (``feature_names``, or the columns of
a DataFrame) or by column index.
"""

from numbers import Integral

import numpy as np
from scipy.signal import welch
from sklearn.utils import check_array

from ..datasets import bone_columns
from ..utils._sequences import check_sequence_ids
from ..utils._validation import check_frame_rate

__all__ = [
    "forward_speed",
    "gait_statistics",
    "motion_amplitude",
    "nearest_style",
    "spectral_similarity",
    "step_frequency",
]

# Zero-padded FFT length of step_frequency: a frequency grid of
# frame_rate / 512 (0.06 Hz at 30 Hz) whatever the sequence length.
_FREQUENCY_FFT = 512


def _check_motion(X, sequence_ids, feature_names, name="X"):
    """Validated float array, the sequences, and the feature names (or None)."""
    names = feature_names
    if names is None and hasattr(X, "columns"):
        names = X.columns
    X = check_array(X, dtype=np.float64, input_name=name)
    if names is not None:
        names = np.asarray(names, dtype=object)
        if names.shape != (X.shape[1],):
            raise ValueError(
                f"feature_names has {names.shape[0]} names but {name} has "
                f"{X.shape[1]} columns."
            )
    return X, check_sequence_ids(sequence_ids, X.shape[0]), names


def _check_motion_pair(X, X_reference, sequence_ids, reference_ids, feature_names):
    """:func:`_check_motion` of both arrays, which must have the same columns."""
    X, sequences, names = _check_motion(X, sequence_ids, feature_names)
    X_reference, reference, _ = _check_motion(
        X_reference, reference_ids, None, name="X_reference"
    )
    if X_reference.shape[1] != X.shape[1]:
        raise ValueError(
            f"X has {X.shape[1]} features but X_reference has {X_reference.shape[1]}."
        )
    return X, sequences, names, X_reference, reference


def _columns(features, names, n_features):
    """Column indices of ``features`` (names or indices); None means all."""
    if features is None:
        return np.arange(n_features)
    if isinstance(features, str | Integral):
        features = [features]
    columns = []
    for feature in features:
        if isinstance(feature, Integral) and not isinstance(feature, bool):
            if not -n_features <= feature < n_features:
                raise ValueError(
                    f"Column {feature} is out of range for {n_features} features."
                )
            columns.append(int(feature) % n_features)
        elif isinstance(feature, str):
            if names is None:
                raise ValueError(
                    f"Feature {feature!r} is given by name, but X has no feature "
                    "names: pass feature_names=... or a DataFrame, or give column "
                    "indices."
                )
            matches = np.flatnonzero(names == feature)
            if len(matches) == 0:
                raise ValueError(f"No feature is named {feature!r}.")
            columns.append(int(matches[0]))
        else:
            raise TypeError(
                "Features must be names (str) or column indices (int), got "
                f"{feature!r}."
            )
    if not columns:
        raise ValueError("features must name at least one feature.")
    return np.asarray(columns, dtype=np.intp)


def _forward_feature(names):
    """The one feature named ``"{root}_dforward"``, or a ValueError."""
    if names is None:
        raise ValueError(
            "forward_speed needs the forward-displacement channel: pass feature= "
            "(its name or column index), or feature_names=... or a DataFrame with "
            "a column named '{root}_dforward' (RootRelativeEncoder's output)."
        )
    found = [str(n) for n in names if str(n).endswith("_dforward")]
    if len(found) != 1:
        raise ValueError(
            f"forward_speed found {len(found)} features named '{{root}}_dforward' "
            f"({found}); pass feature= to choose the forward-displacement channel."
        )
    return found[0]


def frame_forward_speed(X, column):
    """Forward speed of every frame, in length units per frame.

    The package's one definition of forward speed: the body's ground
    distance along its forward direction from each frame to the next,
    which :class:`~sklearn_crbm.preprocessing.RootRelativeEncoder` writes to
    its ``"{root}_dforward"`` channel, here column ``column`` of ``X``.
    :func:`forward_speed` averages it over each sequence;
    :class:`~sklearn_crbm.preprocessing.MotionContext` multiplies it by the
    frame rate (length units per second) before smoothing.
    """
    return X[:, column]


def _check_last_frames(last_frames):
    if last_frames is None:
        return None
    if isinstance(last_frames, bool) or not isinstance(last_frames, Integral):
        raise ValueError(
            f"last_frames must be a positive integer, got {last_frames!r}."
        )
    if last_frames < 1:
        raise ValueError(
            f"last_frames must be a positive integer, got {last_frames!r}."
        )
    return int(last_frames)


def _segments(X, sequences, columns, last_frames=None):
    """The chosen columns of every sequence (only its last frames if asked)."""
    last_frames = _check_last_frames(last_frames)
    for start, stop in zip(sequences.starts, sequences.stops, strict=True):
        if last_frames is not None:
            start = max(start, stop - last_frames)
        yield X[start:stop, columns]


def forward_speed(
    X,
    *,
    sequence_ids=None,
    feature=None,
    feature_names=None,
    last_frames=None,
):
    """Mean forward displacement per frame of each sequence.

    The mean over the frames of each sequence of the channel that holds the
    body's forward displacement from one frame to the next (``root_dforward``
    of :class:`~sklearn_crbm.preprocessing.RootRelativeEncoder`, named
    ``"{root}_dforward"`` after the skeleton's root bone).  Pass the
    motion in the encoder's units (undo the standard scaling first) to get
    length units per frame; standardised motion gives the same ranking.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Motion, all sequences stacked in long format.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    feature : str or int or None, default=None
        The forward-displacement channel, by name or column index.  None
        takes the one feature whose name ends in ``"_dforward"``
        (``root_dforward`` for CMU data, ``Hips_dforward`` for a root called
        ``Hips``).
    feature_names : array-like of str, default=None
        Names of the columns of ``X``; default the columns of a DataFrame.
    last_frames : int, default=None
        Use only the last ``last_frames`` frames of each sequence.

    Returns
    -------
    speed : ndarray of shape (n_sequences,)
        Mean forward displacement per frame.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import forward_speed
    >>> X = np.array([[0.7, 0.0], [0.7, 1.0], [2.0, 0.0], [2.2, 1.0]])
    >>> forward_speed(X, sequence_ids=[0, 0, 1, 1], feature=0)
    array([0.7, 2.1])
    >>> forward_speed(X, sequence_ids=[0, 0, 1, 1],
    ...               feature_names=["root_dforward", "knee"], last_frames=1)
    array([0.7, 2.2])
    """
    X, sequences, names = _check_motion(X, sequence_ids, feature_names)
    if feature is None:
        feature = _forward_feature(names)
    columns = _columns(feature, names, X.shape[1])
    if len(columns) != 1:
        raise ValueError("forward_speed needs exactly one feature.")
    speeds = frame_forward_speed(X, columns[0])[:, None]
    return np.array(
        [
            segment[:, 0].mean()
            for segment in _segments(speeds, sequences, [0], last_frames)
        ]
    )


def motion_amplitude(
    X, *, sequence_ids=None, features=None, feature_names=None, last_frames=None
):
    """How much the chosen channels move in each sequence.

    The root mean square, over the chosen channels, of each channel's
    standard deviation over the frames of the sequence.  Motion that dies out
    (a generated walk that freezes into a pose) has an amplitude near zero;
    compare against the amplitude of real motion in the same units.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Motion, all sequences stacked in long format.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    features : list of str or int, default=None
        The channels, by name or column index (for example the leg joints);
        ``None`` means all.
    feature_names : array-like of str, default=None
        Names of the columns of ``X``; default the columns of a DataFrame.
    last_frames : int, default=None
        Use only the last ``last_frames`` frames of each sequence.

    Returns
    -------
    amplitude : ndarray of shape (n_sequences,)
        Amplitude, in the units of ``X``.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import motion_amplitude
    >>> t = np.arange(60)
    >>> swing = np.sin(2 * np.pi * t / 30)
    >>> X = np.column_stack([swing, 2 * swing])
    >>> motion_amplitude(X, features=[0]).round(3)
    array([0.707])
    >>> decaying = np.concatenate([swing[:30], 0.1 * swing[30:]])
    >>> motion_amplitude(decaying[:, None], last_frames=30).round(3)
    array([0.071])
    """
    X, sequences, names = _check_motion(X, sequence_ids, feature_names)
    columns = _columns(features, names, X.shape[1])
    return np.array(
        [
            np.sqrt(np.mean(segment.var(axis=0)))
            for segment in _segments(X, sequences, columns, last_frames)
        ]
    )


def step_frequency(
    X,
    *,
    sequence_ids=None,
    features=None,
    feature_names=None,
    frame_rate=30.0,
    last_frames=None,
):
    """Dominant cycle frequency of the chosen channels in each sequence, in Hz.

    Each channel is centred and Hann-windowed, the power spectra of the
    chosen channels (zero-padded to a fine grid) are summed, and the
    frequency of the highest peak above the lowest resolvable frequency
    (``frame_rate / n_frames``) is returned.  For the joint angles of both
    legs the dominant cycle is the gait cycle (one left and one right step),
    so walking gives about 1 Hz and jogging about 1.4 Hz at 30 frames per
    second; a sequence that does not move gives ``nan``.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Motion, all sequences stacked in long format.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    features : list of str or int, default=None
        The channels, by name or column index (for example the hips and
        knees); ``None`` means all.
    feature_names : array-like of str, default=None
        Names of the columns of ``X``; default the columns of a DataFrame.
    frame_rate : float, default=30.0
        Frames per second.
    last_frames : int, default=None
        Use only the last ``last_frames`` frames of each sequence.

    Returns
    -------
    frequency : ndarray of shape (n_sequences,)
        Cycles per second (``nan`` for a sequence shorter than 4 frames or
        without motion).

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import step_frequency
    >>> t = np.arange(120)
    >>> walk = np.column_stack([np.sin(2 * np.pi * t / 30), np.cos(2 * np.pi * t / 30)])
    >>> jog = np.column_stack([np.sin(2 * np.pi * t / 21), np.cos(2 * np.pi * t / 21)])
    >>> ids = np.repeat([0, 1], 120)
    >>> step_frequency(np.vstack([walk, jog]), sequence_ids=ids).round(1)
    array([1. , 1.4])
    """
    frame_rate = check_frame_rate(frame_rate)
    X, sequences, names = _check_motion(X, sequence_ids, feature_names)
    columns = _columns(features, names, X.shape[1])
    frequencies = []
    for segment in _segments(X, sequences, columns, last_frames):
        n_frames = segment.shape[0]
        centred = segment - segment.mean(axis=0)
        if n_frames < 4 or not np.any(np.abs(centred) > 1e-12):
            frequencies.append(np.nan)
            continue
        n_fft = max(_FREQUENCY_FFT, 1 << int(np.ceil(np.log2(n_frames))))
        window = np.hanning(n_frames)[:, None]
        power = np.square(np.abs(np.fft.rfft(centred * window, n=n_fft, axis=0))).sum(1)
        grid = np.fft.rfftfreq(n_fft, d=1.0 / frame_rate)
        power[grid < frame_rate / n_frames] = -1.0
        frequencies.append(float(grid[np.argmax(power)]))
    return np.asarray(frequencies)


def gait_statistics(
    X,
    *,
    sequence_ids=None,
    feature_names=None,
    legs=("lfemur", "rfemur", "ltibia", "rtibia"),
    speed_feature=None,
    frame_rate=30.0,
    last_frames=None,
):
    """Forward speed and gait frequency of each sequence: what tells a walk from a jog.

    Column 0 is :func:`forward_speed` of ``speed_feature``, column 1 the
    :func:`step_frequency` of every channel of the ``legs`` bones (hips and
    knees by default).  Pass the rows of generated sequences and of
    training sequences of known style to :func:`nearest_style` to classify
    the generated ones, as the command line's demo and the generation
    benchmarks do.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        Motion after preprocessing (exponential maps, body-centred root),
        all sequences stacked in long format.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame; ``None`` means one sequence.
    feature_names : array-like of str, default=None
        Names of the columns of ``X`` (``"{bone}_{channel}"``); default the
        columns of a DataFrame.
    legs : sequence of str, default=("lfemur", "rfemur", "ltibia", "rtibia")
        Bones whose channels give the gait cycle: the CMU names of the hips
        and knees.  Name those of another skeleton here (Taylor's MIT data:
        ``("lhip", "rhip", "lknee", "rknee")``).
    speed_feature : str or int or None, default=None
        The forward-displacement channel; None takes the one feature named
        ``"{root}_dforward"``, as :func:`forward_speed` does.
    frame_rate : float, default=30.0
        Frames per second.
    last_frames : int, default=None
        Use only the last ``last_frames`` frames of each sequence.

    Returns
    -------
    statistics : ndarray of shape (n_sequences, 2)
        Forward speed (units of ``X`` per frame) and gait frequency (Hz) of
        every sequence.

    Raises
    ------
    ValueError
        If a bone of ``legs`` or ``speed_feature`` has no column; the
        message names it.

    See Also
    --------
    nearest_style : Classify sequences by these statistics.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import gait_statistics, nearest_style
    >>> t = np.arange(120)
    >>> def trial(speed, period):
    ...     swing = np.sin(2 * np.pi * t / period)
    ...     return np.column_stack([np.full(120, speed), swing, -swing])
    >>> names = ["root_dforward", "lfemur_ex", "rfemur_ex"]
    >>> X = np.vstack([trial(0.7, 30), trial(2.0, 21), trial(0.8, 27)])
    >>> ids = np.repeat([0, 1, 2], 120)
    >>> stats = gait_statistics(X, sequence_ids=ids, feature_names=names,
    ...                         legs=["lfemur", "rfemur"])
    >>> stats.round(1)
    array([[0.7, 1. ],
           [2. , 1.4],
           [0.8, 1.1]])
    >>> nearest_style(stats[2:], stats[:2], ["walk", "jog"])
    array(['walk'], dtype=object)
    """
    X, _, names = _check_motion(X, sequence_ids, feature_names)
    if names is None:
        raise ValueError(
            "gait_statistics finds the legs and the speed channel by name: pass "
            "feature_names=... (e.g. preprocessor.get_feature_names_out()) or a "
            "DataFrame."
        )
    common = dict(sequence_ids=sequence_ids, last_frames=last_frames)
    return np.column_stack(
        [
            forward_speed(X, feature=speed_feature, feature_names=names, **common),
            step_frequency(
                X, features=bone_columns(names, legs), frame_rate=frame_rate, **common
            ),
        ]
    )


def _spectra(X, sequences, columns, n_fft, last_frames=None):
    """Welch power spectrum (n_columns, n_fft // 2 + 1) of each sequence."""
    spectra, lengths = [], []
    for segment in _segments(X, sequences, columns, last_frames):
        n_frames = segment.shape[0]
        if n_frames < 2:
            raise ValueError(
                "spectral_similarity needs sequences of at least 2 frames; got one "
                f"of {n_frames}."
            )
        _, power = welch(
            segment,
            nperseg=min(n_fft, n_frames),
            nfft=n_fft,
            axis=0,
            detrend="constant",
        )
        spectra.append(power.T)
        lengths.append(n_frames)
    return spectra, np.asarray(lengths, dtype=np.float64)


def spectral_similarity(
    X,
    X_reference,
    *,
    sequence_ids=None,
    reference_sequence_ids=None,
    features=None,
    feature_names=None,
    n_fft=64,
    last_frames=None,
):
    """Similarity of each sequence's power spectrum to that of reference motion.

    For every sequence of ``X`` and for the reference motion (for example
    held-out real motion), the power spectrum of every chosen channel is
    estimated with Welch's method on segments of ``n_fft`` frames (shorter
    sequences use one segment, zero-padded to the same frequency grid).  The
    reference spectrum is the frame-weighted mean over the reference
    sequences.  Each spectrum, a table of channels by frequencies, is
    normalised to sum to one, and the similarity is the Bhattacharyya
    coefficient ``sum(sqrt(p * q))``: 1 when the sequence distributes its
    motion over channels and frequencies exactly as the reference does, 0
    when they share nothing.  It ignores the overall scale, so read it
    together with :func:`motion_amplitude`; a sequence without motion gets
    ``nan``.

    Parameters
    ----------
    X : array-like of shape (n_frames, n_features)
        The motion to judge, all sequences stacked in long format.
    X_reference : array-like of shape (n_reference_frames, n_features)
        Reference motion in the same representation.
    sequence_ids : array-like of shape (n_frames,), default=None
        Sequence id of every frame of ``X``; ``None`` means one sequence.
    reference_sequence_ids : array-like of shape (n_reference_frames,), default=None
        Sequence id of every frame of ``X_reference``.
    features : list of str or int, default=None
        The channels, by name or column index; ``None`` means all.
    feature_names : array-like of str, default=None
        Names of the columns of both arrays; default the columns of ``X`` if
        it is a DataFrame.
    n_fft : int, default=64
        Welch segment length in frames; the frequency resolution is
        ``frame_rate / n_fft``.
    last_frames : int, default=None
        Use only the last ``last_frames`` frames of each sequence of ``X``.

    Returns
    -------
    similarity : ndarray of shape (n_sequences,)
        Values in [0, 1]; higher is more similar.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import spectral_similarity
    >>> t = np.arange(200)
    >>> real = np.sin(2 * np.pi * t / 32)[:, None]
    >>> same_rhythm = 3 * np.sin(2 * np.pi * t / 32 + 1)[:, None]
    >>> other_rhythm = np.sin(2 * np.pi * t / 8)[:, None]
    >>> X = np.vstack([same_rhythm, other_rhythm])
    >>> spectral_similarity(X, real, sequence_ids=np.repeat([0, 1], 200)).round(2)
    array([1., 0.])
    """
    if isinstance(n_fft, bool) or not isinstance(n_fft, Integral) or n_fft < 4:
        raise ValueError(f"n_fft must be an integer >= 4, got {n_fft!r}.")
    X, sequences, names, X_reference, reference_sequences = _check_motion_pair(
        X, X_reference, sequence_ids, reference_sequence_ids, feature_names
    )
    columns = _columns(features, names, X.shape[1])
    reference, lengths = _spectra(X_reference, reference_sequences, columns, n_fft)
    reference = np.tensordot(lengths / lengths.sum(), np.asarray(reference), axes=1)
    total = reference.sum()
    if not total > 0:
        raise ValueError("The reference motion does not move: its spectrum is zero.")
    reference = reference / total
    similarities = []
    for spectrum in _spectra(X, sequences, columns, n_fft, last_frames)[0]:
        total = spectrum.sum()
        if not total > 0 or not np.isfinite(total):
            similarities.append(np.nan)
            continue
        similarities.append(float(np.sqrt(spectrum / total * reference).sum()))
    return np.asarray(similarities)


def nearest_style(features, reference_features, reference_styles):
    """Label each sequence with the style whose reference sequences it is nearest.

    A nearest-centroid classifier: every feature is divided by its standard
    deviation over the reference sequences, each style's centroid is the
    mean of its reference sequences, and each row of ``features`` gets the
    style of the nearest centroid (Euclidean).  Typical features are
    :func:`forward_speed` and :func:`step_frequency` of generated sequences,
    with those of the training sequences and their labels (``"walk"``,
    ``"jog"``) as reference.  Rows with a ``nan`` feature get ``None``.

    Parameters
    ----------
    features : array-like of shape (n_sequences, n_statistics)
        Statistics of the sequences to label, one row per sequence (a 1-D
        array is one statistic).
    reference_features : array-like of shape (n_reference, n_statistics)
        The same statistics of sequences of known style (a 1-D array is one
        statistic).
    reference_styles : array-like of shape (n_reference,)
        Style of each reference sequence.

    Returns
    -------
    styles : ndarray of shape (n_sequences,), dtype object
        The nearest style of every sequence.

    Examples
    --------
    >>> import numpy as np
    >>> from sklearn_crbm.metrics import nearest_style
    >>> speed = [0.7, 0.72, 2.0, 1.9]
    >>> nearest_style([0.8, 1.8, 1.2], speed, ["walk", "walk", "jog", "jog"])
    array(['walk', 'jog', 'walk'], dtype=object)
    """
    features = np.asarray(features, dtype=np.float64)
    reference_features = np.asarray(reference_features, dtype=np.float64)
    if features.ndim == 1:
        features = features[:, None]
    if reference_features.ndim == 1:
        reference_features = reference_features[:, None]
    reference_styles = np.asarray(reference_styles, dtype=object)
    if features.ndim != 2 or reference_features.ndim != 2:
        raise ValueError("features must be 1-D or 2-D: one row per sequence.")
    if reference_features.shape[0] != reference_styles.shape[0]:
        raise ValueError(
            f"reference_features has {reference_features.shape[0]} rows but "
            f"reference_styles has {reference_styles.shape[0]} labels."
        )
    if features.shape[1] != reference_features.shape[1]:
        raise ValueError(
            f"features has {features.shape[1]} statistics but reference_features "
            f"has {reference_features.shape[1]}."
        )
    if not np.isfinite(reference_features).all():
        raise ValueError("reference_features contains NaN or infinity.")
    scale = reference_features.std(axis=0)
    scale[scale == 0] = 1.0
    styles = list(dict.fromkeys(reference_styles.tolist()))
    if not styles:
        raise ValueError("reference_styles is empty.")
    centroids = np.array(
        [reference_features[reference_styles == s].mean(axis=0) for s in styles]
    )
    distances = np.linalg.norm((features[:, None, :] - centroids[None]) / scale, axis=2)
    labels = np.empty(features.shape[0], dtype=object)
    finite = np.isfinite(features).all(axis=1)
    labels[finite] = np.asarray(styles, dtype=object)[
        np.argmin(distances[finite], axis=1)
    ]
    labels[~finite] = None
    return labels
