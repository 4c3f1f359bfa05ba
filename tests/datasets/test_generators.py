"""make_oscillations and make_walker."""

import numpy as np
import pytest

from sklearn_crbm.datasets import make_oscillations, make_walker


def test_make_oscillations_shapes_and_ids():
    X, ids = make_oscillations(n_sequences=3, n_frames=20, n_features=5, random_state=0)
    assert X.shape == (60, 5) and X.dtype == np.float64
    np.testing.assert_array_equal(ids, np.repeat([0, 1, 2], 20))
    assert np.issubdtype(ids.dtype, np.integer)


def test_make_oscillations_is_deterministic():
    X1, _ = make_oscillations(random_state=42)
    X2, _ = make_oscillations(random_state=np.random.RandomState(42))
    X3, _ = make_oscillations(random_state=43)
    np.testing.assert_array_equal(X1, X2)
    assert not np.allclose(X1, X3)


def test_make_oscillations_roughly_standardised():
    X, _ = make_oscillations(n_sequences=20, n_frames=200, n_features=4, random_state=0)
    np.testing.assert_allclose(X.mean(axis=0), 0, atol=0.1)
    np.testing.assert_allclose(X.std(axis=0), 1, atol=0.1)


def test_make_oscillations_is_predictable_from_the_past():
    # without noise, each frame is a fixed function of the two before
    X, _ = make_oscillations(n_sequences=1, n_frames=60, noise=0.0, random_state=0)
    past = np.hstack([X[1:-1], X[:-2]])
    coef, *_ = np.linalg.lstsq(past, X[2:], rcond=None)
    np.testing.assert_allclose(past @ coef, X[2:], atol=1e-8)
    assert np.abs(X).max() <= np.sqrt(2) + 1e-12


@pytest.mark.parametrize(
    "kwargs",
    [{"n_sequences": 0}, {"n_frames": 2.5}, {"n_features": -1}, {"noise": -0.1}],
)
def test_make_oscillations_invalid(kwargs):
    with pytest.raises(ValueError):
        make_oscillations(**kwargs)


def test_make_walker_looks_like_load_cmu35():
    walker = make_walker(n_sequences=3, n_frames=50, random_state=0)
    assert set(walker) >= {
        "data", "sequence_ids", "sequence_names", "motion", "feature_names",
        "skeleton", "frame_rate", "DESCR",
    }  # fmt: skip
    assert walker.data.shape == (150, len(walker.feature_names)) == (150, 33)
    np.testing.assert_array_equal(walker.sequence_ids, np.repeat([0, 1, 2], 50))
    assert list(walker.sequence_names) == ["walk_0", "walk_1", "walk_2"]
    assert list(walker.motion) == ["walk"] * 3
    assert walker.frame_rate == 30.0
    np.testing.assert_array_equal(walker.feature_names, walker.skeleton.feature_names)
    sk = walker.skeleton
    assert (sk.up_axis, sk.angle_unit, sk.convention) == ("y", "deg", "acclaim")


def test_make_walker_is_deterministic():
    a = make_walker(n_sequences=1, n_frames=30, random_state=7).data
    b = make_walker(n_sequences=1, n_frames=30, random_state=7).data
    c = make_walker(n_sequences=1, n_frames=30, random_state=8).data
    np.testing.assert_array_equal(a, b)
    assert not np.allclose(a, c)


def test_make_walker_walks():
    walker = make_walker(n_sequences=2, n_frames=120, random_state=0)
    sk = walker.skeleton
    positions = sk.forward_kinematics(walker.data)
    names = sk.bone_names
    # bones keep their lengths
    parents = sk.parent_indices
    lengths = np.linalg.norm(positions[:, 1:] - positions[:, parents[1:]], axis=-1)
    np.testing.assert_allclose(
        lengths, np.broadcast_to([b.length for b in sk.bones[1:]], lengths.shape)
    )
    # upright, feet near the ground
    y = positions[..., 1]
    assert np.all(y[:, names.index("head")] > y[:, names.index("lfoot")] + 20)
    assert -1.0 < y[:, [names.index("lfoot"), names.index("rfoot")]].min() < 2.0
    # the root moves forward about 0.5-0.7 units per frame and turns a little
    for seq in range(2):
        rows = walker.sequence_ids == seq
        ground = walker.data[rows][:, [0, 2]]
        step = np.linalg.norm(np.diff(ground, axis=0), axis=1)
        assert np.all((step > 0.45) & (step < 0.75))
        heading = walker.data[rows][:, list(walker.feature_names).index("root_ry")]
        assert 0 < abs(heading[-1] - heading[0]) < 40
    # legs swing in opposition
    lf = walker.data[:, list(walker.feature_names).index("lfemur_rx")]
    rf = walker.data[:, list(walker.feature_names).index("rfemur_rx")]
    assert np.corrcoef(lf, rf)[0, 1] < -0.9
