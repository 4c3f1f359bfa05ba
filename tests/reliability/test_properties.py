"""Property-based tests: round trips, sequence handling, sampling, imputation.

The models of styles (FactoredCRBM, LabelledCRBM) are driven through their
own API: every frame's style as the second argument, ``style=`` in sample.
"""

import copy
import itertools

import numpy as np
import pytest
import sklearn
from hypothesis import HealthCheck, assume, given, note, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from sklearn_crbm.datasets import Bone, Skeleton
from sklearn_crbm.impute import NearestNeighborImputer
from sklearn_crbm.preprocessing import ExpMapEncoder, RootRelativeEncoder
from sklearn_crbm.utils._rotations import (
    euler_to_matrix,
    expmap_to_matrix,
    matrix_to_expmap,
)

SETTINGS = dict(
    deadline=None,
    suppress_health_check=[HealthCheck.function_scoped_fixture],
)

# Angles in degrees, with the troublesome ones often: +-180 (the branch cut),
# +-90 (gimbal lock when it is the middle angle), 0, and values just off them.
SPECIAL_DEGREES = [0.0, 90.0, -90.0, 180.0, -180.0, 89.9999999, -179.9999999, 360.0]
degrees = st.one_of(
    st.sampled_from(SPECIAL_DEGREES),
    st.floats(-720.0, 720.0, allow_nan=False, allow_infinity=False),
)

ORDERS = [
    "".join(p)
    for k in (1, 2, 3)
    for axes in itertools.combinations("xyz", k)
    for p in itertools.permutations(axes)
]  # all 15 Tait-Bryan orders of 1, 2 and 3 axes


@st.composite
def skeletons(draw):
    """A skeleton of 1-4 bones, each with its own Euler order; channels in any
    column order; a root with translation."""
    n_bones = draw(st.integers(1, 4))
    bones = [Bone("root", None, np.zeros(3), 0.0, ("tx", "ty", "tz"), "")]
    for i in range(n_bones):
        order = draw(st.sampled_from(ORDERS))
        channels = list(draw(st.permutations([f"r{a}" for a in order])))
        if draw(st.booleans()):
            channels.insert(draw(st.integers(0, len(channels))), "tx")
        bones.append(
            Bone(f"b{i}", "root", [0.0, 1.0, 0.0], 1.0, tuple(channels), order)
        )
    return Skeleton(bones)


def _rotations(skeleton, X, unit):
    """Rotation matrix of every Euler bone, from raw channels."""
    names = list(skeleton.feature_names)
    out = {}
    for bone in skeleton.bones:
        if bone.rotation_order:
            cols = [names.index(f"{bone.name}_r{a}") for a in bone.rotation_order]
            angles = X[:, cols]
            out[bone.name] = euler_to_matrix(
                np.deg2rad(angles) if unit == "deg" else angles, bone.rotation_order
            )
    return out


@settings(max_examples=60, **SETTINGS)
@given(data=st.data(), unit=st.sampled_from(["deg", "rad"]))
def test_expmap_round_trip_on_random_skeletons(data, unit):
    skeleton = data.draw(skeletons())
    names = list(skeleton.feature_names)
    n_frames = data.draw(st.integers(1, 4))
    values = data.draw(
        st.lists(
            degrees, min_size=n_frames * len(names), max_size=n_frames * len(names)
        )
    )
    X = np.array(values).reshape(n_frames, len(names))
    if unit == "rad":
        X = np.deg2rad(X)
    encoder = ExpMapEncoder(skeleton, angle_unit=unit).fit(X)
    Z = encoder.transform(X)
    back = encoder.inverse_transform(Z)
    names_out = list(encoder.get_feature_names_out())
    assert (
        len(names_out)
        == Z.shape[1]
        == len(names)
        + sum(3 - len(b.rotation_order) for b in skeleton.bones if b.rotation_order)
    )
    # passthrough columns are copied exactly, in and out
    for j, name in enumerate(names):
        if not name.split("_")[-1].startswith("r"):
            assert_array_equal(Z[:, names_out.index(name)], X[:, j])
            assert_array_equal(back[:, j], X[:, j])
    # each bone's map is its rotation, with angle at most pi
    original = _rotations(skeleton, X, unit)
    returned = _rotations(skeleton, back, unit)
    for bone, R in original.items():
        cols = [names_out.index(f"{bone}_e{a}") for a in "xyz"]
        r = Z[:, cols]
        assert np.all(np.linalg.norm(r, axis=1) <= np.pi + 1e-12)
        assert_allclose(expmap_to_matrix(r), R, atol=1e-9)
        assert_allclose(returned[bone], R, atol=1e-9)
    # the angles that come back lie in (-180, 180]
    half_turn = 180.0 if unit == "deg" else np.pi
    euler = [j for j, n in enumerate(names) if n.split("_")[-1].startswith("r")]
    assert np.all(np.abs(back[:, euler]) <= half_turn + 1e-9)


# ---------------------------------------------------------- sequence_ids
@st.composite
def splits(draw, n_frames, min_length=1):
    """Per-frame ids cutting ``n_frames`` into contiguous runs, with arbitrary
    distinct labels (negative, unordered, large)."""
    max_runs = n_frames // min_length
    n_runs = draw(st.integers(1, min(max_runs, 6)))
    spare = n_frames - n_runs * min_length
    cuts = sorted(
        draw(st.lists(st.integers(0, spare), min_size=n_runs - 1, max_size=n_runs - 1))
    )
    lengths = np.diff([0, *cuts, spare]) + min_length
    labels = draw(
        st.lists(
            st.integers(-(2**40), 2**40), min_size=n_runs, max_size=n_runs, unique=True
        )
    )
    return np.repeat(labels, lengths)


def _per_sequence(method, X, ids, *per_frame, **kwargs):
    """``method`` called on each run of ``ids`` alone, results stacked.

    ``per_frame`` arguments (such as every frame's style) are split with ``X``.
    """
    change = np.flatnonzero(np.diff(ids)) + 1
    parts = [
        method(part, *[a[rows] for a in per_frame], **kwargs)
        for rows, part in zip(
            np.split(np.arange(len(X)), change), np.split(X, change), strict=True
        )
    ]
    return np.concatenate(parts)


CRBM_METHODS = ["transform", "score_samples", "predict_next"]


@settings(max_examples=25, **SETTINGS)
@given(data=st.data())
def test_conditional_rbm_sequences_are_independent(data, fitted, oscillations):
    X, _ = oscillations
    ids = data.draw(splits(len(X)))
    model = fitted["crbm"]
    for name in CRBM_METHODS:
        method = getattr(model, name)
        together = method(X, sequence_ids=ids)
        assert_allclose(together, _per_sequence(method, X, ids), rtol=1e-10, atol=1e-12)


@settings(max_examples=15, **SETTINGS)
@given(data=st.data())
def test_stacked_crbm_sequences_are_independent(data, fitted, oscillations):
    X, _ = oscillations
    ids = data.draw(splits(len(X)))
    for name in ["transform", "predict_next"]:
        method = getattr(fitted["stack"], name)
        together = method(X, sequence_ids=ids)
        assert_allclose(together, _per_sequence(method, X, ids), rtol=1e-10, atol=1e-12)


@pytest.mark.parametrize("key", ["factored", "labelled"])
@settings(max_examples=15, **SETTINGS)
@given(data=st.data())
def test_style_model_sequences_are_independent(key, data, fitted, oscillations):
    """With every frame's style given, and unknown (each sequence's posterior)."""
    X, _ = oscillations
    ids = data.draw(splits(len(X)))
    styles = np.array(
        data.draw(
            st.lists(st.sampled_from(["high", "low"]), min_size=len(X), max_size=len(X))
        )
    )
    model = fitted[key]
    for name in CRBM_METHODS:

        def method(X, style=None, *, sequence_ids=None, name=name):
            return getattr(model, name)(X, sequence_ids=sequence_ids, style=style)

        for style_args in ((styles,), ()):
            together = method(X, *style_args, sequence_ids=ids)
            alone = _per_sequence(method, X, ids, *style_args)
            assert_allclose(together, alone, rtol=1e-10, atol=1e-12)
    together = model.predict_proba(X, sequence_ids=ids)
    assert_allclose(
        together, _per_sequence(model.predict_proba, X, ids), rtol=1e-10, atol=1e-12
    )


@settings(max_examples=25, **SETTINGS)
@given(data=st.data())
def test_expmap_continuous_sequences_are_independent(data, walker):
    X = walker.data.copy()
    X[:, 3:] *= 6.0  # big swings, so the maps pass through pi and unwrap
    ids = data.draw(splits(len(X)))
    encoder = ExpMapEncoder(walker.skeleton, continuous=True).fit(X)
    together = encoder.transform(X, sequence_ids=ids)
    assert_allclose(together, _per_sequence(encoder.transform, X, ids), atol=1e-12)


@st.composite
def root_motion(draw, n_frames):
    """Global root channels (tx, ty, tz, exp map) of an upright-ish body."""
    heading = np.cumsum(
        draw(st.lists(st.floats(-0.3, 0.3), min_size=n_frames, max_size=n_frames))
    )
    tilt = draw(
        st.lists(st.floats(-1.2, 1.2), min_size=2 * n_frames, max_size=2 * n_frames)
    )
    tilt = np.reshape(tilt, (n_frames, 2))
    step = draw(
        st.lists(st.floats(-3.0, 3.0), min_size=2 * n_frames, max_size=2 * n_frames)
    )
    ground = np.cumsum(np.reshape(step, (n_frames, 2)), axis=0)
    height = np.array(
        draw(st.lists(st.floats(5.0, 20.0), min_size=n_frames, max_size=n_frames))
    )
    # y up: heading about y, then tilts about x and z
    R = euler_to_matrix(np.column_stack([tilt[:, 0], heading, tilt[:, 1]]), "xyz")
    X = np.column_stack([ground[:, 0], height, ground[:, 1], matrix_to_expmap(R)])
    return X


@settings(max_examples=25, **SETTINGS)
@given(data=st.data())
def test_root_encoder_sequences_are_independent(data):
    n = data.draw(st.integers(1, 30))
    X = data.draw(root_motion(n))
    ids = data.draw(splits(n))
    encoder = RootRelativeEncoder(up_axis="y").fit(X)
    encoded = encoder.transform(X, sequence_ids=ids)
    assert_allclose(encoded, _per_sequence(encoder.transform, X, ids), atol=1e-12)
    back = encoder.inverse_transform(encoded, sequence_ids=ids)
    assert_allclose(
        back, _per_sequence(encoder.inverse_transform, encoded, ids), atol=1e-12
    )
    # the encoding forgets only heading and ground position: encoding the
    # decoded motion gives the same encoding
    assert_allclose(encoder.transform(back, sequence_ids=ids), encoded, atol=1e-8)


@settings(max_examples=15, **SETTINGS)
@given(data=st.data())
def test_preprocessor_sequences_are_independent(data, fitted, walker):
    X = walker.data
    ids = data.draw(splits(len(X)))
    pipeline = fitted["preprocessor"]
    with sklearn.config_context(enable_metadata_routing=True):
        together = pipeline.transform(X, sequence_ids=ids)
        alone = _per_sequence(pipeline.transform, X, ids)
        assert_allclose(together, alone, atol=1e-10)
        back = pipeline.inverse_transform(together, sequence_ids=ids)
        assert_allclose(
            back, _per_sequence(pipeline.inverse_transform, together, ids), atol=1e-9
        )


@settings(max_examples=20, **SETTINGS)
@given(data=st.data())
def test_nearest_neighbor_imputer_sequences_are_independent(data, fitted, oscillations):
    X, _ = oscillations
    mask = np.array(
        data.draw(st.lists(st.booleans(), min_size=X.size, max_size=X.size))
    )
    X = np.where(mask.reshape(X.shape), np.nan, X)
    ids = data.draw(splits(len(X)))
    imputer = fitted["nn_imputer"]
    together = imputer.transform(X, sequence_ids=ids)
    assert_array_equal(together, _per_sequence(imputer.transform, X, ids))


# ---------------------------------------------------------------- sampling
@st.composite
def sample_requests(draw, width, styled=False):
    """Arguments of ``sample``; with ``styled``, a style, a blend or a transition."""
    n_sequences = draw(st.integers(1, 3))
    kind = draw(st.sampled_from(["none", "2-D", "3-D"]))
    history = None
    if kind != "none":
        n_frames = draw(st.integers(width, width + 3))
        shape = (n_frames, 4) if kind == "2-D" else (n_sequences, n_frames, 4)
        seed = draw(st.integers(0, 2**16))
        history = np.random.default_rng(seed).standard_normal(shape)
    n_samples = draw(st.integers(1, 6))
    style = {}
    if styled:
        high = draw(st.lists(st.floats(0, 1), min_size=n_samples, max_size=n_samples))
        weights = np.column_stack([high, 1 - np.array(high)])
        style["style"] = draw(st.sampled_from(["high", "low", weights]))
    return dict(
        n_samples=n_samples,
        n_sequences=n_sequences,
        history=history,
        n_gibbs=draw(st.integers(0, 3)),
        hidden_noise=draw(st.sampled_from([0.0, 0.5])),
        random_state=draw(st.integers(0, 2**31 - 1)),
        **style,
    )


@pytest.mark.parametrize(
    "key, width", [("crbm", 2), ("stack", 4), ("factored", 2), ("labelled", 2)]
)
@settings(max_examples=20, **SETTINGS)
@given(data=st.data())
def test_sample_shape_dtype_and_determinism(key, width, data, fitted):
    model = fitted[key]
    request = data.draw(sample_requests(width, styled=hasattr(model, "classes_")))
    kwargs = dict(request)
    n_samples = kwargs.pop("n_samples")
    first = model.sample(n_samples, **kwargs)
    again = model.sample(n_samples, **kwargs)
    n_sequences = request["n_sequences"]
    assert first.shape == (n_sequences * n_samples, 4)
    assert first.dtype == np.float64
    assert np.isfinite(first).all()
    assert_array_equal(first, again)


# --------------------------------------------------------------- imputation
@st.composite
def missing_masks(draw, shape):
    kind = draw(st.sampled_from(["random", "frames", "channels", "first", "all"]))
    n_frames, n_features = shape
    if kind == "random":
        density = draw(st.floats(0.0, 1.0))
        seed = draw(st.integers(0, 2**16))
        return np.random.default_rng(seed).random(shape) < density
    mask = np.zeros(shape, dtype=bool)
    if kind == "frames":
        rows = draw(
            st.lists(st.integers(0, n_frames - 1), min_size=1, max_size=n_frames)
        )
        mask[rows] = True
    elif kind == "channels":
        cols = draw(
            st.lists(st.integers(0, n_features - 1), min_size=1, max_size=n_features)
        )
        mask[:, cols] = True
    elif kind == "first":
        mask[0] = True
        mask[1:, 0] = True
    else:
        mask[:] = True
    return mask


def _check_fill(X_missing, filled, mask):
    assert filled.shape == X_missing.shape
    assert not np.isnan(filled).any()
    assert np.isfinite(filled).all()
    assert_array_equal(filled[~mask], X_missing[~mask])


@settings(max_examples=30, **SETTINGS)
@given(data=st.data())
def test_nearest_neighbor_imputer_keeps_observed_and_fills_all(
    data, fitted, oscillations
):
    X, _ = oscillations
    mask = data.draw(missing_masks(X.shape))
    ids = data.draw(splits(len(X)))
    X_missing = np.where(mask, np.nan, X)
    filled = fitted["nn_imputer"].transform(X_missing, sequence_ids=ids)
    _check_fill(X_missing, filled, mask)
    # the input is not modified
    assert_array_equal(np.isnan(X_missing), mask)


@settings(max_examples=15, **SETTINGS)
@given(data=st.data())
def test_nearest_neighbor_imputer_with_a_numeric_marker(data, oscillations):
    X, _ = oscillations
    X = np.round(X, 3)
    mask = data.draw(missing_masks(X.shape))
    imputer = NearestNeighborImputer(missing_values=-999.0).fit(X)
    X_missing = np.where(mask, -999.0, X)
    filled = imputer.transform(X_missing)
    _check_fill(X_missing, filled, mask)
    assert not (filled == -999.0).any()


@pytest.mark.parametrize("key", ["crbm_imputer", "stack_imputer", "factored_imputer"])
@settings(max_examples=15, **SETTINGS)
@given(data=st.data(), n_draws=st.integers(1, 2))
def test_crbm_imputer_keeps_observed_and_fills_all(
    key, data, n_draws, fitted, oscillations
):
    X, _ = oscillations
    mask = data.draw(missing_masks(X.shape))
    ids = data.draw(splits(len(X)))
    imputer = copy.deepcopy(fitted[key]).set_params(n_draws=n_draws)
    # a model of styles fills in given the style, or inferring it
    style = {}
    if key == "factored_imputer":
        style["style"] = data.draw(st.sampled_from(["high", "low", None]))
    X_missing = np.where(mask, np.nan, X)
    original = X_missing.copy()
    filled = imputer.transform(X_missing, sequence_ids=ids, **style)
    _check_fill(X_missing, filled, mask)
    assert_array_equal(X_missing, original)  # the input is not modified
    # and a repeated call with the same random_state fills identically
    again = imputer.transform(X_missing, sequence_ids=ids, **style)
    assert_array_equal(again, filled)


@settings(max_examples=10, **SETTINGS)
@given(data=st.data())
def test_crbm_imputer_samples_keep_observed_values(data, fitted, oscillations):
    X, _ = oscillations
    mask = data.draw(missing_masks(X.shape))
    assume(mask.any())
    X_missing = np.where(mask, np.nan, X)
    draws = fitted["crbm_imputer"].sample(X_missing, 2, random_state=0)
    assert draws.shape == (2, *X.shape)
    for fill in draws:
        _check_fill(X_missing, fill, mask)


@pytest.mark.parametrize("key", ["crbm", "factored", "labelled"])
@settings(max_examples=10, **SETTINGS)
@given(data=st.data())
def test_only_the_runs_of_sequence_ids_matter(
    key, data, factories, oscillations, styles
):
    """Relabelling the runs (any distinct integers, or whole floats) trains the
    same model."""
    X, ids = oscillations
    style_args = () if key == "crbm" else (styles,)
    change = np.flatnonzero(np.diff(ids)) + 1
    lengths = np.diff([0, *change, len(ids)])
    labels = data.draw(
        st.lists(st.integers(-(2**40), 2**40), min_size=3, max_size=3, unique=True)
    )
    relabelled = np.repeat(labels, lengths)
    as_floats = relabelled.astype(np.float64)  # exact: |labels| < 2**53
    reference = factories[key]().fit(X, *style_args, sequence_ids=ids)
    for other_ids in (relabelled, as_floats):
        model = factories[key]().fit(X, *style_args, sequence_ids=other_ids)
        assert_array_equal(
            model._fitted_layers()[0].flat, reference._fitted_layers()[0].flat
        )


@settings(max_examples=25, **SETTINGS)
@given(data=st.data())
def test_motion_preprocessor_round_trip_on_random_skeletons(data):
    """Raw channels -> paper's preprocessing -> back: every bone rotation and
    the root height come back; only the heading and ground position of each
    sequence are free, so encoding the decoded motion gives the same code."""
    from sklearn_crbm.preprocessing import make_motion_preprocessor

    root_order = data.draw(st.sampled_from([o for o in ORDERS if len(o) == 3]))
    limbs = data.draw(skeletons())
    root = Bone(
        "root",
        None,
        np.zeros(3),
        0.0,
        ("tx", "ty", "tz", *(f"r{a}" for a in root_order)),
        root_order,
    )
    skeleton = Skeleton([root, *limbs.bones[1:]])
    names = list(skeleton.feature_names)
    n_frames = data.draw(st.integers(2, 12))
    X = np.empty((n_frames, len(names)))
    for j, name in enumerate(names):
        if name.startswith("root_t"):
            column = st.floats(-50.0, 50.0)
        elif name == "root_ry":  # heading (y is up): any start, then turns
            column = None  # below 180 degrees per frame (a half-turn in one
            # frame would be a left or a right turn: ambiguous)
        elif name.startswith("root_r"):  # small tilts: the body stays upright
            column = st.floats(-30.0, 30.0)
        else:
            column = degrees
        if column is None:
            start = data.draw(degrees)
            turns = data.draw(
                st.lists(st.floats(-150.0, 150.0), min_size=n_frames, max_size=n_frames)
            )
            X[:, j] = start + np.cumsum(turns) - turns[0]
        else:
            X[:, j] = data.draw(st.lists(column, min_size=n_frames, max_size=n_frames))
    ids = data.draw(splits(n_frames))
    note(f"bones: {[(b.name, b.channels, b.rotation_order) for b in skeleton.bones]}")
    note(f"X: {X.tolist()}")
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(skeleton, constant_tol=None)
        Z = pre.fit_transform(X, sequence_ids=ids)
        back = pre.inverse_transform(Z, sequence_ids=ids)
        assert np.isfinite(Z).all() and np.isfinite(back).all()
        # compared before standard scaling, which would blow rounding noise in
        # a (nearly) constant channel up to unit size
        encode = pre[:-1]
        assert_allclose(
            encode.transform(back, sequence_ids=ids),
            encode.transform(X, sequence_ids=ids),
            atol=1e-9,
        )
    limbs_before = _rotations(skeleton, X, "deg")
    limbs_after = _rotations(skeleton, back, "deg")
    for bone in limbs_before:
        if bone != "root":
            assert_allclose(limbs_after[bone], limbs_before[bone], atol=1e-9)
    height = names.index("root_ty")
    assert_allclose(back[:, height], X[:, height], atol=1e-9)


quarter_turns = st.integers(-4, 4).map(lambda k: 90.0 * k)


@settings(max_examples=60, **SETTINGS)
@given(
    order=st.sampled_from([o for o in ORDERS if len(o) == 3]),
    angles=st.tuples(quarter_turns, quarter_turns, quarter_turns),
    turns=st.tuples(*[st.integers(-2, 2)] * 3),
)
def test_equal_rotations_get_equal_maps_even_at_half_turns(order, angles, turns):
    """Angle triples of one rotation -- +-180, +-360, the mirrored triple --
    encode to the same exponential map, half-turns (rotation by pi) included."""
    a, b, c = angles
    same = np.array(
        [
            [a, b, c],
            [a + 360.0 * turns[0], b + 360.0 * turns[1], c + 360.0 * turns[2]],
            [a + 180.0, 180.0 - b, c + 180.0],  # the other Tait-Bryan solution
        ]
    )
    skeleton = Skeleton(
        [Bone("b", None, np.zeros(3), 0.0, tuple(f"r{x}" for x in "xyz"), order)]
    )
    columns = ["xyz".index(x) for x in order]
    X = np.empty_like(same)
    X[:, columns] = same  # channels rx ry rz hold the angles of `order`
    R = euler_to_matrix(np.deg2rad(same), order)
    assert_allclose(R[1:], np.broadcast_to(R[0], (2, 3, 3)), atol=1e-12)
    Z = ExpMapEncoder(skeleton).fit_transform(X)
    assert_allclose(Z[1:], np.broadcast_to(Z[0], (2, 3)), atol=1e-9)
