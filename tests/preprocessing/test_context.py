"""MotionContext: per-frame forward speed and turning rate from motion."""

import numpy as np
import pandas as pd
import pytest
import sklearn
from sklearn.pipeline import make_pipeline
from sklearn.utils._param_validation import InvalidParameterError

from sklearn_crbm.datasets import Bone, Skeleton, load_cmu35
from sklearn_crbm.metrics import forward_speed
from sklearn_crbm.preprocessing import (
    ExpMapEncoder,
    MotionContext,
    RootRelativeEncoder,
)

FRAME_RATE = 30.0
SKELETON = Skeleton(
    [
        Bone(
            "root", None, np.zeros(3), 0.0, ("tx", "ty", "tz", "rx", "ry", "rz"), "xyz"
        ),
        Bone("knee", "root", np.array([0.0, -1.0, 0.0]), 1.0, ("rx",), "x"),
    ],
    up_axis="y",
)


def walk(steps, turns, *, heading=0.3, start=(5.0, -2.0)):
    """Raw channels (y up, forward z) of a root moving ``steps[t]`` along its
    heading and turning ``turns[t]`` radians left from frame t to t + 1."""
    heading = heading + np.concatenate([[0.0], np.cumsum(turns[:-1])])
    x = start[0] + np.concatenate([[0.0], np.cumsum(steps[:-1] * np.sin(heading[:-1]))])
    z = start[1] + np.concatenate([[0.0], np.cumsum(steps[:-1] * np.cos(heading[:-1]))])
    n = len(steps)
    knee = 20.0 * np.sin(np.arange(n) / 3.0)
    return np.column_stack(
        [x, np.full(n, 17.0), z, np.zeros(n), np.rad2deg(heading), np.zeros(n), knee]
    )


def constant_walk(n, step, turn, **kwargs):
    return walk(np.full(n, step), np.full(n, turn), **kwargs)


def test_constant_walk_gives_its_speed_and_turning_rate():
    X = constant_walk(80, 0.6, 0.02)
    context = MotionContext(SKELETON, frame_rate=FRAME_RATE).fit(X)
    C = context.transform(X)
    assert C.shape == (80, 2)
    np.testing.assert_allclose(C[:, 0], 0.6 * FRAME_RATE, rtol=1e-10)
    np.testing.assert_allclose(C[:, 1], 0.02 * FRAME_RATE, rtol=1e-10)
    assert context.source_ == "raw" and context.root_ == "root"
    assert context.window_frames_ == 31


def test_turning_right_and_moving_sideways_have_their_signs():
    X = constant_walk(40, 0.5, -0.05)
    C = MotionContext(
        SKELETON, signals=["turning_rate", "sideways_speed", "forward_speed"]
    ).fit_transform(X)
    np.testing.assert_allclose(C[:, 0], -0.05 * FRAME_RATE, rtol=1e-10)
    np.testing.assert_allclose(C[:, 1], 0.0, atol=1e-10)
    np.testing.assert_allclose(C[:, 2], 0.5 * FRAME_RATE, rtol=1e-10)


def test_frame_rate_scales_the_rates():
    X = constant_walk(40, 0.5, 0.01)
    C = MotionContext(SKELETON, frame_rate=120.0).fit_transform(X)
    np.testing.assert_allclose(C, [[60.0, 1.2]] * 40, rtol=1e-10)


def test_ramp_is_exact_away_from_the_ends_and_cut_windows_at_them():
    n, half = 60, 6  # window of 13 frames
    steps = 0.2 + 0.01 * np.arange(n)
    X = walk(steps, np.zeros(n))
    context = MotionContext(SKELETON, window=13 / FRAME_RATE).fit(X)
    speed = context.transform(X)[:, 0] / FRAME_RATE
    assert context.window_frames_ == 2 * half + 1
    # the last frame repeats the step of the one before
    rates = np.append(steps[:-1], steps[-2])
    interior = np.arange(half, n - 1 - half)
    np.testing.assert_allclose(speed[interior], steps[interior], rtol=1e-10)
    for t in (0, 3, n - 1):
        window = rates[max(t - half, 0) : t + half + 1]
        np.testing.assert_allclose(speed[t], window.mean(), rtol=1e-10)


def test_zero_window_keeps_every_frame():
    steps = np.random.default_rng(0).uniform(0.1, 1.0, 30)
    X = walk(steps, np.zeros(30))
    speed = MotionContext(SKELETON, window=0).fit_transform(X)[:, 0]
    np.testing.assert_allclose(speed[:-1], FRAME_RATE * steps[:-1], rtol=1e-10)


def test_neither_deltas_nor_smoothing_cross_sequences():
    first = constant_walk(50, 0.4, 0.01)
    second = constant_walk(30, 1.1, -0.03, heading=2.0, start=(-40.0, 90.0))
    X = np.vstack([first, second])
    ids = np.repeat([7, 3], [50, 30])
    context = MotionContext(SKELETON).fit(X, sequence_ids=ids)
    C = context.transform(X, sequence_ids=ids)
    np.testing.assert_allclose(C[:50], [[12.0, 0.3]] * 50, rtol=1e-10)
    np.testing.assert_allclose(C[50:], [[33.0, -0.9]] * 30, rtol=1e-10)
    # one sequence: the jump between them leaks into both sides
    joined = context.transform(X)
    assert np.abs(joined[35:65] - C[35:65]).max() > 1.0
    # each sequence alone gives the same
    np.testing.assert_allclose(context.transform(second), C[50:], rtol=1e-12)


def test_root_relative_output_and_plain_deltas_agree_with_raw():
    X = np.vstack(
        [constant_walk(40, 0.4, 0.01), walk(np.linspace(0.2, 1, 40), np.full(40, 0.02))]
    )
    ids = np.repeat([0, 1], 40)
    raw = MotionContext(SKELETON).fit_transform(X, sequence_ids=ids)

    expmap = ExpMapEncoder(SKELETON).fit(X)
    root = RootRelativeEncoder(SKELETON).fit(expmap.transform(X))
    encoded = root.transform(expmap.transform(X), sequence_ids=ids)
    names = root.get_feature_names_out()
    frame = pd.DataFrame(encoded, columns=names)
    context = MotionContext().fit(frame, sequence_ids=ids)
    assert context.source_ == "root_relative" and context.root_ == "root"
    np.testing.assert_allclose(
        context.transform(frame, sequence_ids=ids), raw, rtol=1e-12
    )

    deltas = encoded[
        :, [list(names).index(f"root_{d}") for d in ("dforward", "dheading")]
    ]
    plain = MotionContext().fit(deltas)
    assert plain.source_ == "deltas" and plain.root_ is None
    np.testing.assert_allclose(
        plain.transform(deltas, sequence_ids=ids), raw, rtol=1e-12
    )


def test_raw_dataframe_in_any_column_order():
    X = constant_walk(40, 0.5, 0.01)
    order = [6, 4, 0, 2, 1, 3, 5]
    frame = pd.DataFrame(X[:, order], columns=SKELETON.feature_names[order])
    context = MotionContext(SKELETON, signals=("forward_speed",)).fit(frame)
    assert context.source_ == "raw"
    np.testing.assert_allclose(context.transform(frame), 15.0, rtol=1e-10)
    np.testing.assert_array_equal(context.get_feature_names_out(), ["forward_speed"])


def test_sequence_ids_reach_it_through_a_pipeline():
    X = np.vstack(
        [constant_walk(30, 0.4, 0.0), constant_walk(30, 0.9, 0.0, start=(50, 50))]
    )
    ids = np.repeat([0, 1], 30)
    with sklearn.config_context(enable_metadata_routing=True):
        C = make_pipeline(MotionContext(SKELETON)).fit_transform(X, sequence_ids=ids)
    np.testing.assert_allclose(C[:, 0], np.repeat([12.0, 27.0], 30), rtol=1e-10)


def test_bad_input_is_named():
    X = constant_walk(20, 0.5, 0.01)
    with pytest.raises(ValueError, match="signals must name distinct signals"):
        MotionContext(SKELETON, signals=["speed"]).fit(X)
    with pytest.raises(ValueError, match="signals must name distinct signals"):
        MotionContext(SKELETON, signals=[]).fit(X)
    with pytest.raises(InvalidParameterError, match="window"):
        MotionContext(SKELETON, window=-1.0).fit(X)
    with pytest.raises(InvalidParameterError, match="frame_rate"):
        MotionContext(SKELETON, frame_rate=0).fit(X)
    X_nan = X.copy()
    X_nan[3, 0] = np.nan
    with pytest.raises(ValueError, match="NaN"):
        MotionContext(SKELETON).fit(X_nan)
    with pytest.raises(ValueError, match="the skeleton has 7 channels"):
        MotionContext(SKELETON).fit(X[:, :5])
    with pytest.raises(ValueError, match="X has 1 feature\\(s\\).*needs 2"):
        MotionContext().fit(X[:, :1])
    with pytest.raises(ValueError, match="root 'knee' lacks the channels"):
        MotionContext(SKELETON, root="knee").fit(X)
    frame = pd.DataFrame(X, columns=SKELETON.feature_names)
    with pytest.raises(ValueError, match="for raw channels pass skeleton="):
        MotionContext().fit(frame)
    with pytest.raises(ValueError, match="lacks the skeleton's channels \\['knee_rx'"):
        MotionContext(SKELETON).fit(frame.drop(columns="knee_rx"))
    track = pd.DataFrame(X[:, :2], columns=["root_dforward", "root_dsideways"])
    with pytest.raises(ValueError, match="lacks the columns \\['root_dheading'\\]"):
        MotionContext().fit(track)
    two = pd.DataFrame(X[:, :2], columns=["a_dforward", "b_dforward"])
    with pytest.raises(ValueError, match="pass root= to choose one"):
        MotionContext().fit(two)
    with pytest.raises(ValueError, match="sequence_ids"):
        MotionContext(SKELETON).fit(X, sequence_ids=np.zeros(5))
    context = MotionContext(SKELETON).fit(X)
    with pytest.raises(ValueError, match="features"):
        context.transform(X[:, :6])
    with pytest.raises(TypeError, match="skeleton must be"):
        MotionContext("35.asf").fit(X)


def test_cmu35_walks_are_slower_than_jogs(data_home):
    cmu = load_cmu35(data_home)
    context = MotionContext(cmu.skeleton, frame_rate=cmu.frame_rate)
    C = context.fit_transform(cmu.data, sequence_ids=cmu.sequence_ids)
    motion = cmu.motion[cmu.sequence_ids]
    walk_speed = C[motion == "walk", 0].mean()
    jog_speed = C[motion == "jog", 0].mean()
    assert 0 < walk_speed < jog_speed
    # the trials go mostly straight
    assert np.abs(C[:, 1]).mean() < 0.5


def test_forward_speed_is_the_metric_times_the_frame_rate():
    # one definition of forward speed: MotionContext's signal (per second,
    # unsmoothed with a one-frame window) is metrics.forward_speed's per-frame
    # speed times the frame rate, frame by frame and on average
    rng = np.random.default_rng(0)
    X = rng.normal(size=(50, 3))  # plain deltas: dforward, dheading, dsideways
    ids = np.repeat([0, 1], [20, 30])
    context = MotionContext(
        signals=["turning_rate", "forward_speed"], window=1 / 25, frame_rate=25.0
    ).fit_transform(X, sequence_ids=ids)
    np.testing.assert_allclose(context[:, 1], X[:, 0] * 25.0, rtol=1e-12, atol=1e-12)
    per_sequence = [context[ids == k, 1].mean() for k in (0, 1)]
    np.testing.assert_allclose(
        np.array(per_sequence) / 25.0,
        forward_speed(X, sequence_ids=ids, feature=0),
        rtol=1e-12,
    )
