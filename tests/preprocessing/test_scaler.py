"""StandardScaler: z-scores that drop constant channels and restore them."""

import numpy as np
import pytest
import sklearn.preprocessing

from sklearn_crbm.preprocessing import StandardScaler


@pytest.fixture
def data():
    rng = np.random.default_rng(0)
    X = rng.normal(loc=3.0, scale=2.0, size=(40, 6))
    X[:, 1] = 7.5  # constant
    X[:, 4] = 1e-16 * rng.normal(size=40)  # rounding noise around zero
    return X


def test_matches_sklearn_on_the_kept_features(data):
    scaler = StandardScaler().fit(data)
    keep = [0, 2, 3, 5]
    assert scaler.constant_mask_.tolist() == [False, True, False, False, True, False]
    reference = sklearn.preprocessing.StandardScaler().fit(data[:, keep])
    assert np.allclose(scaler.transform(data), reference.transform(data[:, keep]))
    assert np.allclose(scaler.mean_[keep], reference.mean_)
    assert np.allclose(scaler.var_[keep], reference.var_)
    assert np.allclose(scaler.scale_[keep], reference.scale_)
    assert scaler.scale_[1] == 1.0 and scaler.n_samples_seen_ == 40


def test_inverse_restores_constants(data):
    scaler = StandardScaler().fit(data)
    Z = scaler.transform(data)
    assert Z.shape == (40, 4)
    back = scaler.inverse_transform(Z)
    assert np.allclose(back, data, rtol=0, atol=1e-14)
    assert np.all(back[:, 1] == 7.5)
    assert np.all(np.abs(back[:, 4]) < 1e-15)


def test_feature_names_out_are_the_kept_ones(data):
    scaler = StandardScaler().fit(data)
    assert list(scaler.get_feature_names_out()) == ["x0", "x2", "x3", "x5"]
    names = [f"c{i}" for i in range(6)]
    assert list(scaler.get_feature_names_out(names)) == ["c0", "c2", "c3", "c5"]


def test_constant_tol(data):
    assert StandardScaler(constant_tol=None).fit(data).constant_mask_.sum() == 0
    # relative to the mean: std 1e-9 around 1e3 is constant at tol 1e-10 * 1e3
    X = np.column_stack([1e3 + 1e-9 * np.arange(5.0), np.arange(5.0)])
    assert StandardScaler(constant_tol=1e-10).fit(X).constant_mask_.tolist() == [
        True,
        False,
    ]
    assert StandardScaler(constant_tol=1e-15).fit(X).constant_mask_.tolist() == [
        False,
        False,
    ]


def test_partial_fit_equals_fit(data):
    whole = StandardScaler().fit(data)
    parts = StandardScaler()
    for chunk in np.array_split(data, 3):
        assert parts.partial_fit(chunk) is parts
    assert np.allclose(parts.mean_, whole.mean_)
    assert np.allclose(parts.var_, whole.var_)
    assert np.array_equal(parts.constant_mask_, whole.constant_mask_)
    assert parts.n_samples_seen_ == 40
    assert np.allclose(parts.transform(data), whole.transform(data))


@pytest.mark.parametrize("with_mean", [True, False])
@pytest.mark.parametrize("with_std", [True, False])
def test_with_mean_with_std(data, with_mean, with_std):
    scaler = StandardScaler(with_mean=with_mean, with_std=with_std).fit(data)
    Z = scaler.transform(data)
    kept = data[:, ~scaler.constant_mask_]
    expected = kept - (kept.mean(axis=0) if with_mean else 0.0)
    if with_std:
        expected = expected / kept.std(axis=0)
    assert np.allclose(Z, expected)
    assert (scaler.scale_ is None) == (not with_std)
    assert np.allclose(scaler.inverse_transform(Z), data, atol=1e-14)


def test_float32_is_preserved(data):
    X = data.astype(np.float32)
    scaler = StandardScaler().fit(X)
    assert scaler.transform(X).dtype == np.float32
    assert scaler.inverse_transform(scaler.transform(X)).dtype == np.float32


def test_nan_is_ignored_in_fit_and_kept(data):
    X = data.copy()
    X[3, 0] = np.nan
    scaler = StandardScaler().fit(X)
    assert np.isclose(scaler.mean_[0], np.nanmean(X[:, 0]))
    assert scaler.n_samples_seen_.tolist() == [39, 40, 40, 40, 40, 40]
    Z = scaler.transform(X)
    assert np.isnan(Z[3, 0]) and np.isnan(Z).sum() == 1


def test_inverse_with_wrong_width_raises(data):
    scaler = StandardScaler().fit(data)
    with pytest.raises(ValueError, match="expects 4 features"):
        scaler.inverse_transform(data)
    with pytest.raises(ValueError, match="X has 5 features"):
        scaler.transform(data[:, :5])


def test_a_single_frame_drops_every_channel_and_comes_back():
    X = np.array([[1.0, -2.0, 3.5]])
    scaler = StandardScaler().fit(X)
    Z = scaler.transform(X)
    assert Z.shape == (1, 0)
    assert np.array_equal(scaler.inverse_transform(Z), X)
    assert scaler.get_feature_names_out().shape == (0,)


def test_scale_floor_is_a_fraction_of_the_median_scale():
    rng = np.random.default_rng(0)
    X = rng.standard_normal((200, 5)) * [1.0, 2.0, 3.0, 1e-6, 0.0]
    scaler = StandardScaler(scale_floor=0.1).fit(X)
    std = X.std(axis=0)
    assert scaler.constant_mask_.tolist() == [False] * 3 + [False, True]
    floor = 0.1 * np.median(std[:4])
    assert np.allclose(scaler.scale_, [std[0], std[1], std[2], floor, 1.0])
    Z = scaler.transform(X)
    assert np.allclose(Z[:, :3].std(axis=0), 1.0)
    assert Z[:, 3].std() < 1e-4
    assert np.allclose(scaler.inverse_transform(Z)[:, :4], X[:, :4])


def test_scale_floor_zero_gives_unit_variance_to_every_kept_feature():
    rng = np.random.default_rng(0)
    X = rng.standard_normal((200, 3)) * [1.0, 2.0, 1e-6]
    Z = StandardScaler(scale_floor=0.0).fit_transform(X)
    assert np.allclose(Z.std(axis=0), 1.0)


def test_a_barely_moving_channel_keeps_held_out_motion_in_range():
    # a toe that stood still in training moves a little in a held-out take
    rng = np.random.default_rng(0)
    train = rng.standard_normal((300, 4)) * [1.0, 1.0, 1.0, 1e-5]
    held_out = rng.standard_normal((100, 4)) * [1.0, 1.0, 1.0, 1e-3]
    unfloored = StandardScaler(scale_floor=0.0).fit(train).transform(held_out)
    floored = StandardScaler().fit(train).transform(held_out)
    assert np.abs(unfloored[:, 3]).max() > 100
    assert np.abs(floored[:, 3]).max() < 1
