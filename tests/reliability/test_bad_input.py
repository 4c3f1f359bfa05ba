"""A catalogue of bad input for every public entry point.

Each case calls one public class or function with one kind of bad input and
checks that it fails with ValueError, TypeError or OSError (NotFittedError
before fit) and with a message that says what is wrong.  One test per case,
so a failure names the entry point and the input.
"""

import copy
import os
import re
import types
from dataclasses import dataclass
from pathlib import Path

import matplotlib
import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp
import sklearn
from sklearn.base import clone
from sklearn.exceptions import NotFittedError

from sklearn_crbm import metrics, plotting
from sklearn_crbm.datasets import (
    Bone,
    Skeleton,
    bone_columns,
    fetch_cmu35,
    get_data_home,
    load_cmu35,
    load_mit_walk,
    make_oscillations,
    make_walker,
    read_amc,
    read_bvh,
    write_amc,
    write_bvh,
)
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer
from sklearn_crbm.metrics import fillin_angle_rmse, fillin_error
from sklearn_crbm.preprocessing import (
    ExpMapEncoder,
    RootRelativeEncoder,
    StandardScaler,
    make_motion_preprocessor,
)
from sklearn_crbm.utils import (
    balanced_batches,
    check_sequence_ids,
    shuffled_batches,
)

matplotlib.use("Agg")


@pytest.fixture(autouse=True)
def _close_figures():
    yield
    import matplotlib.pyplot as plt

    plt.close("all")


@dataclass(frozen=True)
class Case:
    """One bad call: ``call(ctx)`` must raise ``exc`` with a message matching."""

    id: str
    call: object
    exc: type
    match: str


def _params(cases):
    ids = [case.id for case in cases]
    assert len(ids) == len(set(ids)), "case ids must be unique"
    return [pytest.param(case, id=case.id) for case in cases]


@pytest.fixture
def ctx(oscillations, styles, context, walker, fitted, factories, real_files, tmp_path):
    X, ids = oscillations
    Z = fitted["expmap"].transform(walker.data)
    return types.SimpleNamespace(
        X=X,
        ids=ids,
        styles=styles,
        context=context,
        n=len(X),
        walker=walker,
        skeleton=walker.skeleton,
        Z=Z,
        R=fitted["root"].transform(Z),
        P=fitted["preprocessor"].transform(walker.data),
        f=fitted,
        new=factories,
        files=real_files,
        tmp=tmp_path,
    )


def _check(case, ctx):
    with pytest.raises(case.exc, match=case.match):
        case.call(ctx)


# ----------------------------------------------------------------------- X
def _one(X, value):
    X = np.array(X, dtype=np.float64)
    X[len(X) // 2, 0] = value
    return X


# kind -> (make the bad X from a good one, exception, message)
BAD_X = {
    "NaN": (lambda X: _one(X, np.nan), ValueError, "NaN"),
    "inf": (lambda X: _one(X, np.inf), ValueError, "infinity"),
    "1-D": (lambda X: np.asarray(X)[:, 0], ValueError, "Expected 2D array"),
    "3-D": (lambda X: np.asarray(X)[None], ValueError, "dim 3"),
    "strings": (
        lambda X: np.full(np.shape(X), "a"),
        ValueError,
        "could not convert string to float",
    ),
    "sparse": (lambda X: sp.csr_matrix(X), TypeError, "(?i)sparse.*dense"),
    "empty": (lambda X: np.asarray(X)[:0], ValueError, r"0 sample\(s\)"),
    "no columns": (lambda X: np.asarray(X)[:, :0], ValueError, r"0 feature\(s\)"),
    "wrong column count": (
        lambda X: np.asarray(X)[:, :-1],
        ValueError,
        r"X has \d+ features, but \w+(\.inverse_transform)? (is )?expect",
    ),
}


@dataclass(frozen=True)
class Entry:
    """A public method taking ``X``: ``data(ctx)`` is good input, ``call(ctx, X)``."""

    name: str
    data: object
    call: object
    allows_nan: bool = False
    fits: bool = False  # fit-like: any number of columns is fine
    overrides: tuple = ()  # ((kind, exception, message) or (kind, None, None))


# The models of styles: key in the fixtures, class name; the methods that
# take every frame's style after X (as y in score).
STYLE_MODELS = [("factored", "FactoredCRBM"), ("labelled", "LabelledCRBM")]
STYLE_METHODS = (
    "transform",
    "score_samples",
    "predict_next",
    "score",
    "estimate_log_likelihood",
)


def _style_model_entries(key, name):
    """A model of styles' entry points, each given every frame's style ("high")."""

    def method(method_name, style=None):
        if method_name == "score":  # the labels are score's y
            return lambda c, X: c.f[key].score(X, style)
        if style is None:
            return lambda c, X: getattr(c.f[key], method_name)(X)
        return lambda c, X: getattr(c.f[key], method_name)(X, style=style)

    return [
        Entry(
            f"{name}.fit",
            lambda c: c.X,
            lambda c, X: c.new[key]().fit(X, c.styles),
            fits=True,
        ),
        Entry(
            f"{name}.partial_fit",
            lambda c: c.X,
            lambda c, X: c.new[key]().partial_fit(X, c.styles),
            fits=True,
        ),
        *[
            Entry(f"{name}.{m}", lambda c: c.X, method(m, "high"))
            for m in STYLE_METHODS
        ],
        *[
            Entry(f"{name}.{m}", lambda c: c.X, method(m))
            for m in ("predict", "predict_proba", "predict_log_proba")
        ],
    ]


ENTRIES = [
    *[entry for key, name in STYLE_MODELS for entry in _style_model_entries(key, name)],
    Entry(
        "CRBMImputer.fit(FactoredCRBM)",
        lambda c: c.X,
        lambda c, X: CRBMImputer(c.new["factored"]()).fit(X, c.styles),
        allows_nan=True,
        fits=True,
    ),
    Entry(
        "CRBMImputer.transform(FactoredCRBM)",
        lambda c: c.X,
        lambda c, X: c.f["factored_imputer"].transform(X, style="high"),
        allows_nan=True,
    ),
    Entry(
        "CRBMImputer.sample(FactoredCRBM)",
        lambda c: c.X,
        lambda c, X: c.f["factored_imputer"].sample(X, 2, style="high"),
        allows_nan=True,
    ),
    Entry(
        "ConditionalRBM.fit",
        lambda c: c.X,
        lambda c, X: c.new["crbm"]().fit(X),
        fits=True,
    ),
    Entry(
        "ConditionalRBM.partial_fit",
        lambda c: c.X,
        lambda c, X: c.new["crbm"]().partial_fit(X),
        fits=True,
    ),
    Entry(
        "ConditionalRBM.transform", lambda c: c.X, lambda c, X: c.f["crbm"].transform(X)
    ),
    Entry(
        "ConditionalRBM.score_samples",
        lambda c: c.X,
        lambda c, X: c.f["crbm"].score_samples(X),
    ),
    Entry(
        "ConditionalRBM.predict_next",
        lambda c: c.X,
        lambda c, X: c.f["crbm"].predict_next(X),
    ),
    Entry("ConditionalRBM.score", lambda c: c.X, lambda c, X: c.f["crbm"].score(X)),
    Entry(
        "StackedCRBM.fit",
        lambda c: c.X,
        lambda c, X: c.new["stack"]().fit(X),
        fits=True,
    ),
    Entry(
        "StackedCRBM.partial_fit",
        lambda c: c.X,
        lambda c, X: c.new["stack"]().partial_fit(X),
        fits=True,
    ),
    Entry(
        "StackedCRBM.transform", lambda c: c.X, lambda c, X: c.f["stack"].transform(X)
    ),
    Entry(
        "StackedCRBM.predict_next",
        lambda c: c.X,
        lambda c, X: c.f["stack"].predict_next(X),
    ),
    Entry("StackedCRBM.score", lambda c: c.X, lambda c, X: c.f["stack"].score(X)),
    Entry(
        "CRBMImputer.fit",
        lambda c: c.X,
        lambda c, X: CRBMImputer(c.new["crbm"]()).fit(X),
        allows_nan=True,
        fits=True,
    ),
    Entry(
        "CRBMImputer.transform",
        lambda c: c.X,
        lambda c, X: c.f["crbm_imputer"].transform(X),
        allows_nan=True,
    ),
    Entry(
        "CRBMImputer.sample",
        lambda c: c.X,
        lambda c, X: c.f["crbm_imputer"].sample(X, 2),
        allows_nan=True,
    ),
    Entry(
        "NearestNeighborImputer.fit",
        lambda c: c.X,
        lambda c, X: NearestNeighborImputer().fit(X),
        allows_nan=True,
        fits=True,
    ),
    Entry(
        "NearestNeighborImputer.transform",
        lambda c: c.X,
        lambda c, X: c.f["nn_imputer"].transform(X),
        allows_nan=True,
    ),
    Entry(
        "ExpMapEncoder.fit",
        lambda c: c.walker.data,
        lambda c, X: ExpMapEncoder(c.skeleton).fit(X),
        allows_nan=True,
        overrides=(
            (
                "wrong column count",
                ValueError,
                "columns but the skeleton has 33 channels",
            ),
        ),
    ),
    Entry(
        "ExpMapEncoder.transform",
        lambda c: c.walker.data,
        lambda c, X: c.f["expmap"].transform(X),
        allows_nan=True,
    ),
    Entry(
        "ExpMapEncoder.inverse_transform",
        lambda c: c.Z,
        lambda c, X: c.f["expmap"].inverse_transform(X),
        allows_nan=True,
    ),
    Entry(
        "RootRelativeEncoder.fit",
        lambda c: c.Z,
        lambda c, X: RootRelativeEncoder(c.skeleton).fit(X),
        allows_nan=True,
        overrides=(
            ("wrong column count", ValueError, "X has 44 columns but the skeleton's"),
        ),
    ),
    Entry(
        "RootRelativeEncoder.transform",
        lambda c: c.Z,
        lambda c, X: c.f["root"].transform(X),
        allows_nan=True,
    ),
    Entry(
        "RootRelativeEncoder.inverse_transform",
        lambda c: c.R,
        lambda c, X: c.f["root"].inverse_transform(X),
        allows_nan=True,
    ),
    Entry(
        "StandardScaler.fit",
        lambda c: c.X,
        lambda c, X: StandardScaler().fit(X),
        allows_nan=True,
        fits=True,
    ),
    Entry(
        "StandardScaler.partial_fit",
        lambda c: c.X,
        lambda c, X: clone(c.f["scaler"]).partial_fit(c.X).partial_fit(X),
        allows_nan=True,
    ),
    Entry(
        "StandardScaler.transform",
        lambda c: c.X,
        lambda c, X: c.f["scaler"].transform(X),
        allows_nan=True,
    ),
    Entry(
        "StandardScaler.inverse_transform",
        lambda c: c.X,
        lambda c, X: c.f["scaler"].inverse_transform(X),
        allows_nan=True,
        overrides=(
            # 0 columns is valid input where every channel is constant (one
            # frame); here 4 are kept, so it is the wrong count
            (
                "no columns",
                ValueError,
                "X has 0 features, but .* expects 4 features",
            ),
            (
                "wrong column count",
                ValueError,
                "expects 4 features \\(the non-constant ones\\)",
            ),
        ),
    ),
    Entry(
        "make_motion_preprocessor.fit",
        lambda c: c.walker.data,
        lambda c, X: make_motion_preprocessor(c.skeleton).fit(X),
        allows_nan=True,
        overrides=(
            (
                "wrong column count",
                ValueError,
                "columns but the skeleton has 33 channels",
            ),
        ),
    ),
    Entry(
        "make_motion_preprocessor.transform",
        lambda c: c.walker.data,
        lambda c, X: c.f["preprocessor"].transform(X),
        allows_nan=True,
    ),
    Entry(
        "make_motion_preprocessor.inverse_transform",
        lambda c: c.P,
        lambda c, X: c.f["preprocessor"].inverse_transform(X),
        allows_nan=True,
        overrides=(
            (
                "no columns",
                ValueError,
                "X has 0 features, but StandardScaler.inverse_transform expects 33",
            ),
        ),
    ),
    Entry(
        "fillin_error",
        lambda c: c.X,
        lambda c, X: fillin_error(X, c.X),
        fits=True,
        overrides=(
            ("sparse", TypeError, "must be an array-like"),
            ("strings", ValueError, "could not convert|dtype"),
        ),
    ),
    Entry(
        "fillin_angle_rmse",
        lambda c: c.X,
        lambda c, X: fillin_angle_rmse(c.X, X),
        fits=True,
        overrides=(
            ("sparse", TypeError, "must be an array-like"),
            ("strings", ValueError, "could not convert|dtype"),
        ),
    ),
    Entry(
        "Skeleton.forward_kinematics",
        lambda c: c.walker.data,
        lambda c, X: c.skeleton.forward_kinematics(X),
        allows_nan=True,  # NaN channels give NaN positions
        overrides=(
            ("inf", None, None),  # like NaN: non-finite in, non-finite out
            ("1-D", ValueError, r"data must be 2-D \(n_frames, n_features\)"),
            ("3-D", ValueError, r"data must be 2-D \(n_frames, n_features\)"),
            ("strings", ValueError, "data must be a numeric array"),
            ("sparse", TypeError, r"sparse matrix; convert it with \.toarray\(\)"),
            ("empty", None, None),  # no frames, no positions: valid
            ("no columns", ValueError, "Got 33 feature names for data with 0 columns"),
            ("wrong column count", ValueError, "Got 33 feature names for data with 32"),
        ),
    ),
    Entry(
        "write_amc",
        lambda c: c.walker.data,
        lambda c, X: write_amc(c.tmp / "x.amc", X, c.skeleton),
        overrides=(
            ("NaN", ValueError, "NaN or infinite values; fill them before writing"),
            ("inf", ValueError, "NaN or infinite values; fill them before writing"),
            ("1-D", ValueError, r"data must be 2-D \(n_frames, n_features\)"),
            ("3-D", ValueError, r"data must be 2-D \(n_frames, n_features\)"),
            ("strings", ValueError, "data must be a numeric array"),
            ("sparse", TypeError, r"sparse matrix; convert it with \.toarray\(\)"),
            ("empty", ValueError, "data has no frames"),
            ("no columns", ValueError, "Got 33 feature names for data with 0 columns"),
            ("wrong column count", ValueError, "Got 33 feature names for data with 32"),
        ),
    ),
    Entry(
        "write_bvh",
        lambda c: c.walker.data,
        lambda c, X: write_bvh(c.tmp / "x.bvh", X, c.skeleton, 30.0),
        overrides=(
            ("NaN", ValueError, "NaN or infinite values; fill them before writing"),
            ("inf", ValueError, "NaN or infinite values; fill them before writing"),
            ("1-D", ValueError, r"data must be 2-D \(n_frames, n_features\)"),
            ("3-D", ValueError, r"data must be 2-D \(n_frames, n_features\)"),
            ("strings", ValueError, "data must be a numeric array"),
            ("sparse", TypeError, r"sparse matrix; convert it with \.toarray\(\)"),
            ("empty", None, None),  # a BVH file of zero frames is valid
            ("no columns", ValueError, "Got 33 feature names for data with 0 columns"),
            ("wrong column count", ValueError, "Got 33 feature names for data with 32"),
        ),
    ),
    Entry(
        "metrics.forward_speed",
        lambda c: c.X,
        lambda c, X: metrics.forward_speed(X, feature=0),
        fits=True,
    ),
    Entry(
        "metrics.motion_amplitude",
        lambda c: c.X,
        lambda c, X: metrics.motion_amplitude(X),
        fits=True,
    ),
    Entry(
        "metrics.step_frequency",
        lambda c: c.X,
        lambda c, X: metrics.step_frequency(X, features=[0], frame_rate=30.0),
        fits=True,
    ),
    Entry(
        "metrics.spectral_similarity",
        lambda c: c.X,
        lambda c, X: metrics.spectral_similarity(X, c.X),
        overrides=(
            (
                "wrong column count",
                ValueError,
                "X has 3 features but X_reference has 4",
            ),
        ),
    ),
    Entry(
        "metrics.spectral_similarity(X_reference)",
        lambda c: c.X,
        lambda c, X: metrics.spectral_similarity(c.X, X),
        overrides=(
            (
                "wrong column count",
                ValueError,
                "X has 4 features but X_reference has 3",
            ),
        ),
    ),
    Entry(
        "plotting.plot_skeleton",
        lambda c: c.walker.data[:1],
        lambda c, X: plotting.plot_skeleton(c.skeleton, X),
        overrides=(
            ("NaN", ValueError, "data contains NaN or infinity"),
            ("inf", ValueError, "data contains NaN or infinity"),
            ("1-D", ValueError, "Got 33 feature names for data with 1 columns"),
            ("3-D", ValueError, r"data must be raw channels of shape \(n_frames"),
            ("sparse", TypeError, "(?i)sparse"),
            ("empty", ValueError, r"data must be raw channels of shape \(n_frames"),
            ("no columns", ValueError, "Got 33 feature names for data with 0 columns"),
            ("wrong column count", ValueError, "Got 33 feature names for data with 32"),
        ),
    ),
    Entry(
        "plotting.plot_motion_strip",
        lambda c: c.walker.data,
        lambda c, X: plotting.plot_motion_strip(c.skeleton, X),
        overrides=(
            ("NaN", ValueError, "data contains NaN or infinity"),
            ("inf", ValueError, "data contains NaN or infinity"),
            ("1-D", ValueError, "Got 33 feature names for data with 40 columns"),
            ("3-D", ValueError, r"data must be raw channels of shape \(n_frames"),
            ("sparse", TypeError, "(?i)sparse"),
            ("empty", ValueError, r"data must be raw channels of shape \(n_frames"),
            ("no columns", ValueError, "Got 33 feature names for data with 0 columns"),
            ("wrong column count", ValueError, "Got 33 feature names for data with 32"),
        ),
    ),
    Entry(
        "plotting.plot_hidden_activations",
        lambda c: c.f["crbm"].transform(c.X),
        lambda c, X: plotting.plot_hidden_activations(X),
        fits=True,
        overrides=(
            ("NaN", ValueError, "NaN"),
            ("inf", ValueError, "NaN|infinity|\\[0, 1\\]"),
            ("1-D", ValueError, r"hidden must have shape \(n_frames, n_components\)"),
            ("3-D", ValueError, r"hidden must have shape \(n_frames, n_components\)"),
            ("sparse", TypeError, "(?i)sparse"),
            ("empty", ValueError, "(?i)no frames|empty|0 frames|shape"),
            ("no columns", ValueError, "(?i)no hidden units|0 components|shape"),
        ),
    ),
    Entry(
        "plotting.plot_style_probabilities",
        lambda c: c.f["crbm"].transform(c.X),
        lambda c, X: plotting.plot_style_probabilities(X),
        fits=True,
        overrides=(
            ("NaN", ValueError, "proba contains NaN or infinity"),
            ("inf", ValueError, "proba contains NaN or infinity"),
            ("1-D", ValueError, r"proba must have shape \(n_frames, n_classes\)"),
            ("3-D", ValueError, r"proba must have shape \(n_frames, n_classes\)"),
            ("sparse", TypeError, "(?i)sparse"),
            ("empty", ValueError, "with at least one frame and one column"),
            ("no columns", ValueError, "with at least one frame and one column"),
        ),
    ),
    Entry(
        "plotting.plot_filled_channels",
        lambda c: c.X,
        lambda c, X: plotting.plot_filled_channels(c.X, X),
        allows_nan=True,
        overrides=(
            ("inf", None, None),
            ("1-D", ValueError, "X_filled must have the same shape as X_true"),
            ("3-D", ValueError, r"X_filled must be 1-D or 2-D"),
            ("sparse", TypeError, "(?i)sparse"),
            ("empty", ValueError, "X_filled has 0 frames, expected 60"),
            ("no columns", ValueError, "X_filled must have the same shape as X_true"),
            ("wrong column count", ValueError, "X_filled must have the same shape"),
        ),
    ),
]


def _x_cases():
    cases = []
    for entry in ENTRIES:
        overrides = {kind: (exc, match) for kind, exc, match in entry.overrides}
        for kind, (make, exc, match) in BAD_X.items():
            if kind in overrides:
                exc, match = overrides[kind]
                if exc is None:
                    continue
            elif kind == "NaN" and entry.allows_nan:
                continue
            elif kind == "wrong column count" and entry.fits:
                continue

            def call(c, entry=entry, make=make):
                entry.call(c, make(entry.data(c)))

            cases.append(Case(f"{entry.name}-{kind}", call, exc, match))
    return cases


@pytest.mark.parametrize("case", _params(_x_cases()))
def test_bad_X(case, ctx):
    _check(case, ctx)


def test_every_entry_point_accepts_its_good_input(ctx):
    # the catalogue is only meaningful if the good input passes
    for entry in ENTRIES:
        entry.call(ctx, entry.data(ctx))


# ------------------------------------------------------------ sequence_ids
BAD_IDS = {
    "wrong length": (
        lambda n: np.zeros(n - 1, dtype=int),
        ValueError,
        "sequence_ids has 59 entries but X has 60 frames; pass one sequence id per row",
    ),
    "non-contiguous": (
        lambda n: np.arange(n) % 2,
        ValueError,
        "sequence id 0 occurs in more than one contiguous run",
    ),
    "non-integer": (
        lambda n: np.arange(n) // 20 + 0.5,
        TypeError,
        "sequence_ids must be integers, got non-integral floats",
    ),
    "NaN": (
        lambda n: np.where(np.arange(n) < 30, 0.0, np.nan),
        ValueError,
        "sequence_ids contains NaN or infinity",
    ),
    "strings": (
        lambda n: np.array(["walk"] * n),
        TypeError,
        "sequence_ids must be integers.*np.unique",
    ),
    "booleans": (
        lambda n: np.arange(n) < 30,
        TypeError,
        "sequence_ids must be integers, got booleans",
    ),
    "2-D": (
        lambda n: np.zeros((n, 1), dtype=int),
        ValueError,
        r"sequence_ids must be 1-D .* shape \(60, 1\)",
    ),
    "scalar": (lambda n: 0, ValueError, r"sequence_ids must be 1-D .* shape \(\)"),
    "sparse": (
        lambda n: sp.csr_matrix(np.zeros((1, n))),
        TypeError,
        "sequence_ids must be a dense 1-D array of integers, got a sparse matrix",
    ),
    "huge": (
        lambda n: np.array([2**70] * n, dtype=object),
        ValueError,
        "beyond the 64-bit integer range",
    ),
}

# name -> call(ctx, sequence_ids); every one gets 60 frames
ID_ENTRIES = {
    "ConditionalRBM.fit": lambda c, s: c.new["crbm"]().fit(c.X, sequence_ids=s),
    "ConditionalRBM.partial_fit": lambda c, s: c.new["crbm"]().partial_fit(
        c.X, sequence_ids=s
    ),
    "ConditionalRBM.transform": lambda c, s: c.f["crbm"].transform(c.X, sequence_ids=s),
    "ConditionalRBM.score_samples": lambda c, s: c.f["crbm"].score_samples(
        c.X, sequence_ids=s
    ),
    "ConditionalRBM.predict_next": lambda c, s: c.f["crbm"].predict_next(
        c.X, sequence_ids=s
    ),
    "ConditionalRBM.score": lambda c, s: c.f["crbm"].score(c.X, sequence_ids=s),
    "StackedCRBM.fit": lambda c, s: c.new["stack"]().fit(c.X, sequence_ids=s),
    "StackedCRBM.partial_fit": lambda c, s: c.new["stack"]().partial_fit(
        c.X, sequence_ids=s
    ),
    "StackedCRBM.transform": lambda c, s: c.f["stack"].transform(c.X, sequence_ids=s),
    "StackedCRBM.predict_next": lambda c, s: c.f["stack"].predict_next(
        c.X, sequence_ids=s
    ),
    "StackedCRBM.score": lambda c, s: c.f["stack"].score(c.X, sequence_ids=s),
    "CRBMImputer.fit": lambda c, s: CRBMImputer(c.new["crbm"]()).fit(
        c.X, sequence_ids=s
    ),
    "CRBMImputer.transform": lambda c, s: c.f["crbm_imputer"].transform(
        c.X, sequence_ids=s
    ),
    "CRBMImputer.sample": lambda c, s: c.f["crbm_imputer"].sample(
        c.X, 2, sequence_ids=s
    ),
    "NearestNeighborImputer.transform": lambda c, s: c.f["nn_imputer"].transform(
        c.X, sequence_ids=s
    ),
    "ExpMapEncoder.fit": lambda c, s: ExpMapEncoder().fit(c.X, sequence_ids=s),
    "ExpMapEncoder.transform": lambda c, s: (
        ExpMapEncoder(continuous=True).fit(c.X).transform(c.X, sequence_ids=s)
    ),
    "ExpMapEncoder.inverse_transform": lambda c, s: (
        ExpMapEncoder().fit(c.X).inverse_transform(c.X, sequence_ids=s)
    ),
    "RootRelativeEncoder.fit": lambda c, s: RootRelativeEncoder().fit(
        np.tile(c.X, 2), sequence_ids=s
    ),
    "RootRelativeEncoder.transform": lambda c, s: (
        RootRelativeEncoder()
        .fit(np.tile(c.X, 2))
        .transform(np.tile(c.X, 2), sequence_ids=s)
    ),
    "RootRelativeEncoder.inverse_transform": lambda c, s: (
        RootRelativeEncoder()
        .fit(np.tile(c.X, 2))
        .inverse_transform(np.tile(c.X, 2), sequence_ids=s)
    ),
    "check_sequence_ids": lambda c, s: check_sequence_ids(s, c.n),
    "metrics.forward_speed": lambda c, s: metrics.forward_speed(
        c.X, feature=0, sequence_ids=s
    ),
    "metrics.motion_amplitude": lambda c, s: metrics.motion_amplitude(
        c.X, sequence_ids=s
    ),
    "metrics.step_frequency": lambda c, s: metrics.step_frequency(
        c.X, features=[0], sequence_ids=s
    ),
    "metrics.spectral_similarity": lambda c, s: metrics.spectral_similarity(
        c.X, c.X, sequence_ids=s
    ),
    "metrics.spectral_similarity(reference)": lambda c, s: metrics.spectral_similarity(
        c.X, c.X, reference_sequence_ids=s
    ),
    "plotting.plot_hidden_activations": lambda c, s: plotting.plot_hidden_activations(
        c.f["crbm"].transform(c.X), sequence_ids=s
    ),
}


for _key, _name in STYLE_MODELS:
    ID_ENTRIES.update(
        {
            f"{_name}.fit": lambda c, s, k=_key: c.new[k]().fit(
                c.X, c.styles, sequence_ids=s
            ),
            f"{_name}.partial_fit": lambda c, s, k=_key: c.new[k]().partial_fit(
                c.X, c.styles, sequence_ids=s
            ),
            **{
                f"{_name}.{m}": lambda c, s, k=_key, m=m: getattr(c.f[k], m)(
                    c.X, sequence_ids=s, **{"y" if m == "score" else "style": "high"}
                )
                for m in STYLE_METHODS
            },
            f"{_name}.predict_proba": lambda c, s, k=_key: c.f[k].predict_proba(
                c.X, sequence_ids=s
            ),
        }
    )
ID_ENTRIES.update(
    {
        "CRBMImputer.fit(FactoredCRBM)": lambda c, s: CRBMImputer(
            c.new["factored"]()
        ).fit(c.X, c.styles, sequence_ids=s),
        "CRBMImputer.transform(FactoredCRBM)": lambda c, s: c.f[
            "factored_imputer"
        ].transform(c.X, sequence_ids=s),
    }
)


def _routed_fit(c, s):
    X = np.tile(c.walker.data, (2, 1))[:60]
    with sklearn.config_context(enable_metadata_routing=True):
        make_motion_preprocessor(c.skeleton).fit(X, sequence_ids=s)


ID_ENTRIES["make_motion_preprocessor.fit (routed)"] = _routed_fit


def _id_cases():
    cases = []
    for name, call in ID_ENTRIES.items():
        for kind, (make, exc, match) in BAD_IDS.items():
            cases.append(
                Case(
                    f"{name}-{kind}",
                    lambda c, call=call, make=make: call(c, make(c.n)),
                    exc,
                    match,
                )
            )
    return cases


@pytest.mark.parametrize("case", _params(_id_cases()))
def test_bad_sequence_ids(case, ctx):
    assert ctx.n == 60
    _check(case, ctx)


# ------------------------------------------- sequences shorter than history
ONE_FRAME_EACH = np.arange(60)
SHORT_CASES = [
    Case(
        "ConditionalRBM.fit",
        lambda c: c.new["crbm"]().fit(c.X, sequence_ids=ONE_FRAME_EACH),
        ValueError,
        "No frame has 2 past frames in its own sequence.*lower order",
    ),
    Case(
        "ConditionalRBM.partial_fit",
        lambda c: c.new["crbm"]().partial_fit(c.X, sequence_ids=ONE_FRAME_EACH),
        ValueError,
        "No frame has 2 past frames in its own sequence",
    ),
    Case(
        "ConditionalRBM.fit-too-short-for-order",
        lambda c: c.new["crbm"](order=25).fit(c.X, sequence_ids=c.ids),
        ValueError,
        "longest sequence has 20 samples, but a model of order 25 needs",
    ),
    Case(
        "ConditionalRBM.score",
        lambda c: c.f["crbm"].score(c.X, sequence_ids=ONE_FRAME_EACH),
        ValueError,
        "score needs frames with 2 past frames in their own sequence",
    ),
    Case(
        "StackedCRBM.fit",
        lambda c: c.new["stack"]().fit(c.X, sequence_ids=np.arange(60) // 3),
        ValueError,
        "needs sequences of at least 5 frames",
    ),
    Case(
        "StackedCRBM.score",
        lambda c: c.f["stack"].score(c.X, sequence_ids=np.arange(60) // 3),
        ValueError,
        "score needs frames with 4 past frames in their own sequence",
    ),
    *[
        case
        for key, name in STYLE_MODELS
        for case in (
            Case(
                f"{name}.fit",
                lambda c, k=key: c.new[k]().fit(
                    c.X, c.styles, sequence_ids=ONE_FRAME_EACH
                ),
                ValueError,
                "No frame has 2 past frames in its own sequence.*lower order",
            ),
            Case(
                f"{name}.score",
                lambda c, k=key: c.f[k].score(
                    c.X, c.styles, sequence_ids=ONE_FRAME_EACH
                ),
                ValueError,
                "score needs frames with 2 past frames in their own sequence",
            ),
        )
    ],
    Case(
        "CRBMImputer.fit",
        lambda c: CRBMImputer(c.new["crbm"]()).fit(c.X, sequence_ids=ONE_FRAME_EACH),
        ValueError,
        "No frame has 2 past frames in its own sequence",
    ),
    Case(
        "CRBMImputer.fit-only-incomplete-frames",
        lambda c: CRBMImputer(c.new["crbm"]()).fit(np.full_like(c.X, np.nan)),
        ValueError,
        "fit needs complete frames, but every frame of X holds a missing value",
    ),
    Case(
        "NearestNeighborImputer.fit-only-incomplete-frames",
        lambda c: NearestNeighborImputer().fit(np.full_like(c.X, np.nan)),
        ValueError,
        "fit needs complete frames, but every frame of X holds a missing value",
    ),
]


@pytest.mark.parametrize("case", _params(SHORT_CASES))
def test_sequences_shorter_than_the_history(case, ctx):
    _check(case, ctx)


# ------------------------------------------------------------------ history
BAD_HISTORY = {
    "too few frames": (
        lambda w: np.zeros((w - 1, 4)),
        ValueError,
        "history must hold at least {w} frames",
    ),
    "wrong feature count": (
        lambda w: np.zeros((w, 3)),
        ValueError,
        "history must hold at least {w} frames .*of 4 features",
    ),
    "1-D": (lambda w: np.zeros(4), ValueError, "history must have shape"),
    "4-D": (lambda w: np.zeros((1, 1, w, 4)), ValueError, "history must have shape"),
    "NaN": (
        lambda w: np.full((w, 4), np.nan),
        ValueError,
        "history contains NaN or infinity",
    ),
    "inf": (
        lambda w: np.full((w, 4), np.inf),
        ValueError,
        "history contains NaN or infinity",
    ),
    "strings": (
        lambda w: np.full((w, 4), "a"),
        TypeError,
        "history must be an array of numbers",
    ),
    "sparse": (
        lambda w: sp.csr_matrix(np.zeros((w, 4))),
        TypeError,
        "history must be a dense array",
    ),
    "seeds do not match n_sequences": (
        lambda w: np.zeros((2, w, 4)),
        ValueError,
        "history holds 2 seeds but n_sequences=3",
    ),
}


def _style_of(model):
    """``style=`` for the sample of a model of styles; nothing for the others."""
    return {"style": "high"} if hasattr(model, "classes_") else {}


def _history_cases():
    cases = []
    for key, name, width in [
        ("crbm", "ConditionalRBM", 2),
        ("stack", "StackedCRBM", 4),
        *[(key, name, 2) for key, name in STYLE_MODELS],
    ]:
        for kind, (make, exc, match) in BAD_HISTORY.items():
            n_sequences = 3 if kind == "seeds do not match n_sequences" else 1

            def call(c, key=key, make=make, width=width, n_sequences=n_sequences):
                c.f[key].sample(
                    3,
                    history=make(width),
                    n_sequences=n_sequences,
                    **_style_of(c.f[key]),
                )

            cases.append(
                Case(f"{name}.sample-{kind}", call, exc, match.format(w=width))
            )
    return cases


@pytest.mark.parametrize("case", _params(_history_cases()))
def test_bad_history(case, ctx):
    _check(case, ctx)


# ------------------------------------------------------------------- styles
# kind -> (the bad styles of n frames, (exception, message) where they are the
# y of a first fit, or None where they are valid there, (exception, message)
# anywhere else); {name} is the argument's name, y or style.
# A 2-D y of fit holds label factors, one a column: label weights are refused.
WEIGHTS_IN_FIT = (
    ValueError,
    r"holds the labels of \d label factors.*{{label: weight}}",
)
BAD_STYLES = {
    "unseen label": (
        lambda n: np.full(n, "medium"),
        None,
        (
            ValueError,
            r"{name} holds the style .*'medium'.*, not seen in fit; the styles",
        ),
    ),
    "NaN label": (
        lambda n: np.where(np.arange(n) == 5, np.nan, 1.0),
        (ValueError, "y contains NaN: every frame needs a style label"),
        (ValueError, "{name} contains NaN: give a style for every frame"),
    ),
    "strings and numbers": (
        lambda n: np.array(["high"] * (n - 1) + [1], dtype=object),
        (TypeError, "y holds style labels that cannot be compared"),
        (TypeError, "{name} holds style labels that cannot be compared"),
    ),
    "None labels": (
        lambda n: np.array([None] * n, dtype=object),
        (TypeError, "y holds style labels that cannot be compared.*give labels of"),
        (TypeError, "{name} holds style labels that cannot be compared"),
    ),
    "wrong length": (
        lambda n: np.full(n - 1, "high"),
        (ValueError, r"y must hold one style label per frame of X \(60\); got an"),
        (ValueError, r"{name} gives 59 frames' styles but 60 are needed"),
    ),
    "a label too many": (
        lambda n: np.full(n + 1, "high"),
        (ValueError, r"y must hold one style label per frame of X \(60\); got an"),
        (ValueError, r"{name} gives 61 frames' styles but 60 are needed"),
    ),
    "weights not summing to 1": (
        lambda n: np.full((n, 2), 0.4),
        WEIGHTS_IN_FIT,
        (ValueError, "{name} weights must sum to 1 in every frame; a frame's sum"),
    ),
    "negative weights": (
        lambda n: np.tile([-0.5, 1.5], (n, 1)),
        WEIGHTS_IN_FIT,
        (ValueError, "{name} weights must be non-negative"),
    ),
    "infinite weights": (
        lambda n: np.tile([np.inf, 0.0], (n, 1)),
        WEIGHTS_IN_FIT,
        (ValueError, "{name} weights contain NaN or infinity"),
    ),
    "weights of 3 styles": (
        lambda n: np.full((n, 3), 1 / 3),
        WEIGHTS_IN_FIT,
        (ValueError, r"{name} weights must have shape \(n_frames, 2\)"),
    ),
    "text weights": (
        lambda n: np.full((n, 2), "a"),
        (  # two label factors, of one class each (a refit: one factor)
            ValueError,
            r"y\[:, 0\] holds one class|y must be one style label per frame.*"
            r"shape \(60, 2\)",
        ),
        (TypeError, "{name} weights must be numbers"),
    ),
    "3-D": (
        lambda n: np.zeros((n, 2, 1)),
        (ValueError, r"y must hold one style label per frame .*shape \(60, 2, 1\)"),
        (ValueError, r"{name} must be a style label, one label per frame or label"),
    ),
}


def _style_calls():
    """Every entry point taking styles: (id, call(c, styles), where, name).

    ``where`` is "fit" (a first fit), "refit" (fitting a fitted model
    further) or "use".
    """
    calls = []
    for key, name in STYLE_MODELS:

        def use(m, k=key):
            labels = "y" if m == "score" else "style"
            return lambda c, s: getattr(c.f[k], m)(
                c.X, sequence_ids=c.ids, **{labels: s}
            )

        calls += [
            (
                f"{name}.fit",
                lambda c, s, k=key: c.new[k]().fit(c.X, s, sequence_ids=c.ids),
                "fit",
                "y",
            ),
            (
                f"{name}.partial_fit(fitted)",
                lambda c, s, k=key: copy.deepcopy(c.f[k]).partial_fit(
                    c.X, s, sequence_ids=c.ids
                ),
                "refit",
                "y",
            ),
            *[
                (f"{name}.{m}", use(m), "use", "y" if m == "score" else "style")
                for m in STYLE_METHODS
            ],
            (
                f"{name}.sample",
                lambda c, s, k=key: c.f[k].sample(c.n, style=s),
                "use",
                "style",
            ),
        ]
    return calls + [
        (
            "CRBMImputer.fit(FactoredCRBM)",
            lambda c, s: CRBMImputer(c.new["factored"]()).fit(
                c.X, s, sequence_ids=c.ids
            ),
            "fit",
            "y",
        ),
        (
            "CRBMImputer.transform(FactoredCRBM)",
            lambda c, s: c.f["factored_imputer"].transform(
                _one(c.X, np.nan), style=s, sequence_ids=c.ids
            ),
            "use",
            "style",
        ),
        (
            "CRBMImputer.sample(FactoredCRBM)",
            lambda c, s: c.f["factored_imputer"].sample(
                _one(c.X, np.nan), 2, style=s, sequence_ids=c.ids
            ),
            "use",
            "style",
        ),
    ]


def _style_cases():
    cases = []
    for call_id, call, where, name in _style_calls():
        for kind, (make, at_fit, elsewhere) in BAD_STYLES.items():
            spec = elsewhere if where == "use" else at_fit
            if where == "refit" and at_fit is None:
                spec = elsewhere
            if spec is None:  # valid styles for a first fit
                continue
            exc, match = spec
            cases.append(
                Case(
                    f"{call_id}-{kind}",
                    lambda c, call=call, make=make: call(c, make(c.n)),
                    exc,
                    match.format(name=name),
                )
            )
    return cases


OTHER_STYLE_CASES = [
    *[
        case
        for key, name in STYLE_MODELS
        for case in (
            Case(
                f"{name}.fit-no y",
                lambda c, k=key: c.new[k]().fit(c.X, sequence_ids=c.ids),
                ValueError,
                f"{name} requires y to be passed.*give the style label of every",
            ),
            *[
                Case(
                    f"{name}(priors={priors!r}).predict_proba",
                    lambda c, k=key, p=priors: (
                        c.new[k](priors=p)
                        .fit(c.X, c.styles, sequence_ids=c.ids)
                        .predict_proba(c.X, sequence_ids=c.ids)
                    ),
                    ValueError,
                    r"priors must hold one non-negative number per style \(2\)",
                )
                for priors in ([0.2, 0.3, 0.5], [-1.0, 2.0], [0.0, 0.0])
            ],
        )
    ],
    Case(
        "CRBMImputer(FactoredCRBM).fit-no y",
        lambda c: CRBMImputer(c.new["factored"]()).fit(c.X, sequence_ids=c.ids),
        ValueError,
        "CRBMImputer around FactoredCRBM needs y in fit",
    ),
    Case(
        "CRBMImputer(ConditionalRBM).transform-a style",
        lambda c: c.f["crbm_imputer"].transform(_one(c.X, np.nan), style="high"),
        ValueError,
        "ConditionalRBM has no styles: give context= instead of style=",
    ),
]


@pytest.mark.parametrize("case", _params(_style_cases() + OTHER_STYLE_CASES))
def test_bad_styles(case, ctx):
    _check(case, ctx)


@pytest.mark.parametrize("key", [key for key, _ in STYLE_MODELS])
def test_bad_styles_leave_a_fitted_model_as_it_was(key, ctx):
    model = copy.deepcopy(ctx.f[key])
    before = model._fitted_layers()[0].flat.copy()
    with pytest.raises(ValueError, match="not seen in fit"):
        model.partial_fit(ctx.X, np.full(ctx.n, "medium"), sequence_ids=ctx.ids)
    assert model.n_iter_ == ctx.f[key].n_iter_
    np.testing.assert_array_equal(model._fitted_layers()[0].flat, before)
    assert model.classes_.tolist() == ["high", "low"]


# --------------------------------------------------------- invalid parameters
PARAMS = [
    ("ConditionalRBM", dict(n_components=0), "'n_components' parameter"),
    ("ConditionalRBM", dict(n_components=2.5), "'n_components' parameter"),
    ("ConditionalRBM", dict(order=-1), "'order' parameter"),
    ("ConditionalRBM", dict(hidden_order=-1), "'hidden_order' parameter"),
    ("ConditionalRBM", dict(visible_type="poisson"), "'visible_type' parameter"),
    ("ConditionalRBM", dict(learning_rate=0.0), "'learning_rate' parameter"),
    ("ConditionalRBM", dict(learning_rate=np.nan), "'learning_rate' parameter"),
    ("ConditionalRBM", dict(learning_rate=np.inf), "'learning_rate' parameter"),
    ("ConditionalRBM", dict(momentum=1.0), "'momentum' parameter"),
    ("ConditionalRBM", dict(weight_decay=-1e-3), "'weight_decay' parameter"),
    ("ConditionalRBM", dict(cd_steps=0), "'cd_steps' parameter"),
    ("ConditionalRBM", dict(batch_size=0), "'batch_size' parameter"),
    ("ConditionalRBM", dict(batching="random"), "'batching' parameter"),
    ("ConditionalRBM", dict(n_iter=0), "'n_iter' parameter"),
    ("ConditionalRBM", dict(random_state="seed"), "'random_state' parameter"),
    ("StackedCRBM", dict(n_components=()), "n_components must be a positive int"),
    ("StackedCRBM", dict(n_components=(5, 0)), "n_components must be a positive int"),
    ("StackedCRBM", dict(n_components="big"), "'n_components' parameter"),
    ("StackedCRBM", dict(order=-1), "'order' parameter"),
    ("StackedCRBM", dict(learning_rate=-1.0), "'learning_rate' parameter"),
    ("FactoredCRBM", dict(n_factors=0), "'n_factors' parameter"),
    ("FactoredCRBM", dict(n_style_features=0), "'n_style_features' parameter"),
    ("FactoredCRBM", dict(momentum_ramp=-1), "'momentum_ramp' parameter"),
    ("FactoredCRBM", dict(shared_style_weights="yes"), "'shared_style_weights'"),
    ("FactoredCRBM", dict(n_gibbs=-1), "'n_gibbs' parameter"),
    ("FactoredCRBM", dict(learning_rate=np.nan), "'learning_rate' parameter"),
    ("FactoredCRBM", dict(priors="equal"), "'priors' parameter"),
    ("LabelledCRBM", dict(n_components=0), "'n_components' parameter"),
    ("LabelledCRBM", dict(hidden_order=-1), "'hidden_order' parameter"),
    ("LabelledCRBM", dict(n_gibbs=2.5), "'n_gibbs' parameter"),
    ("LabelledCRBM", dict(batching="random"), "'batching' parameter"),
    ("CRBMImputer", dict(estimator="crbm"), "'estimator' parameter"),
    ("CRBMImputer", dict(n_gibbs=-1), "'n_gibbs' parameter"),
    ("CRBMImputer", dict(n_draws=0), "'n_draws' parameter"),
    ("CRBMImputer", dict(missing_values=[1.0]), "'missing_values' parameter"),
    (
        "NearestNeighborImputer",
        dict(missing_values=[1.0]),
        "'missing_values' parameter",
    ),
    ("ExpMapEncoder", dict(angle_unit="grad"), "'angle_unit' parameter"),
    ("ExpMapEncoder", dict(continuous="yes"), "'continuous' parameter"),
    ("RootRelativeEncoder", dict(up_axis="w"), "'up_axis' parameter"),
    ("RootRelativeEncoder", dict(root=3), "'root' parameter"),
    ("StandardScaler", dict(constant_tol=-1.0), "'constant_tol' parameter"),
    ("StandardScaler", dict(with_std="no"), "'with_std' parameter"),
]


def _estimator(c, name, params):
    styled = dict((name, key) for key, name in STYLE_MODELS)
    if name in styled:
        return c.new[styled[name]](**params)
    if name == "ConditionalRBM":
        return c.new["crbm"](**params)
    if name == "StackedCRBM":
        return c.new["stack"](**params)
    if name == "CRBMImputer":
        return CRBMImputer(**{"estimator": c.new["crbm"](), **params})
    cls = {
        "NearestNeighborImputer": NearestNeighborImputer,
        "ExpMapEncoder": ExpMapEncoder,
        "RootRelativeEncoder": RootRelativeEncoder,
        "StandardScaler": StandardScaler,
    }[name]
    return cls(**params)


def _param_cases():
    cases = []
    for name, params, match in PARAMS:
        label = ",".join(f"{k}={v!r}" for k, v in params.items())
        cases.append(
            Case(
                f"{name}({label})",
                lambda c, name=name, params=params: _estimator(c, name, params).fit(
                    np.tile(c.X, 2), c.styles
                ),
                ValueError,
                match,
            )
        )
    return cases


SAMPLE_PARAMS = [
    (dict(n_samples=0), "n_samples must be an integer >= 1"),
    (dict(n_samples=-3), "n_samples must be an integer >= 1"),
    (dict(n_samples=2.5), "n_samples must be an integer >= 1"),
    (dict(n_samples=True), "n_samples must be an integer >= 1"),
    (dict(n_gibbs=-1), "n_gibbs must be an integer >= 0"),
    (dict(n_sequences=0), "n_sequences must be an integer >= 1"),
    (dict(hidden_noise=-0.5), "hidden_noise must be a non-negative number"),
    (dict(hidden_noise=np.nan), "hidden_noise must be a non-negative number"),
    (dict(hidden_noise="a"), "hidden_noise must be a non-negative number"),
    (dict(random_state="seed"), "cannot be used to seed"),
]


def _sample_cases():
    cases = []
    for key, name in [("crbm", "ConditionalRBM"), ("stack", "StackedCRBM")] + (
        STYLE_MODELS
    ):
        for params, match in SAMPLE_PARAMS:
            label = ",".join(f"{k}={v!r}" for k, v in params.items())

            def call(c, key=key, params=params):
                kwargs = {"n_samples": 3, **params, **_style_of(c.f[key])}
                c.f[key].sample(kwargs.pop("n_samples"), **kwargs)

            cases.append(Case(f"{name}.sample({label})", call, ValueError, match))
    cases += [
        Case(
            "CRBMImputer.sample(n_samples=0)",
            lambda c: c.f["crbm_imputer"].sample(c.X, 0),
            ValueError,
            "n_samples must be an integer >= 1",
        ),
        Case(
            "CRBMImputer.sample(n_samples=1.5)",
            lambda c: c.f["crbm_imputer"].sample(c.X, 1.5),
            ValueError,
            "n_samples must be an integer >= 1",
        ),
    ]
    return cases


OTHER_PARAMS = [
    Case(
        "make_oscillations(n_sequences=0)",
        lambda c: make_oscillations(n_sequences=0),
        ValueError,
        "n_sequences must be a positive integer",
    ),
    Case(
        "make_oscillations(noise=nan)",
        lambda c: make_oscillations(noise=np.nan),
        ValueError,
        "noise must be a non-negative number",
    ),
    Case(
        "make_oscillations(noise=inf)",
        lambda c: make_oscillations(noise=np.inf),
        ValueError,
        "noise must be a non-negative number",
    ),
    Case(
        "make_oscillations(random_state='seed')",
        lambda c: make_oscillations(random_state="seed"),
        ValueError,
        "cannot be used to seed",
    ),
    Case(
        "make_walker(n_frames=True)",
        lambda c: make_walker(n_frames=True),
        ValueError,
        "n_frames must be a positive integer",
    ),
    Case(
        "make_walker(random_state='seed')",
        lambda c: make_walker(random_state="seed"),
        ValueError,
        "cannot be used to seed",
    ),
    Case(
        "load_cmu35(subset='valid')",
        lambda c: load_cmu35(subset="valid"),
        ValueError,
        "subset must be 'all', 'train' or 'test'",
    ),
    Case(
        "write_bvh(frame_rate=0)",
        lambda c: write_bvh(c.tmp / "x.bvh", c.walker.data, c.skeleton, 0),
        ValueError,
        "frame_rate must be positive",
    ),
    Case(
        "write_bvh(frame_rate=nan)",
        lambda c: write_bvh(c.tmp / "x.bvh", c.walker.data, c.skeleton, np.nan),
        ValueError,
        "frame_rate must be positive",
    ),
    Case(
        "write_bvh(frame_rate='30')",
        lambda c: write_bvh(c.tmp / "x.bvh", c.walker.data, c.skeleton, "30"),
        ValueError,
        "frame_rate must be positive, a number of frames per second",
    ),
    Case(
        "write_bvh(frame_rate=None)",
        lambda c: write_bvh(c.tmp / "x.bvh", c.walker.data, c.skeleton, None),
        ValueError,
        "frame_rate must be positive",
    ),
    Case(
        "fillin_angle_rmse(period=0)",
        lambda c: fillin_angle_rmse(c.X, c.X, period=0),
        ValueError,
        "'period' parameter",
    ),
    Case(
        "fillin_error(missing_mask=ints)",
        lambda c: fillin_error(c.X, c.X, missing_mask=np.ones(c.X.shape, dtype=int)),
        TypeError,
        "missing_mask must be an array of booleans",
    ),
    Case(
        "fillin_error(missing_mask=wrong shape)",
        lambda c: fillin_error(c.X, c.X, missing_mask=np.ones((60, 3), dtype=bool)),
        ValueError,
        "missing_mask must have the shape of y_true",
    ),
    Case(
        "fillin_error(missing_mask=nothing marked)",
        lambda c: fillin_error(c.X, c.X, missing_mask=np.zeros(c.X.shape, dtype=bool)),
        ValueError,
        "missing_mask marks no entry",
    ),
    Case(
        "fillin_error(y_pred of another shape)",
        lambda c: fillin_error(c.X, c.X[:, :3]),
        ValueError,
        "y_true and y_pred must have the same shape",
    ),
    Case(
        "utils.balanced_batches(batch_size=0)",
        lambda c: balanced_batches(np.arange(10), 0, np.random.default_rng(0)),
        ValueError,
        "batch_size must be at least 1, got 0",
    ),
    Case(
        "utils.shuffled_batches(batch_size=0)",
        lambda c: shuffled_batches(np.arange(10), 0, np.random.default_rng(0)),
        ValueError,
        "batch_size must be at least 1, got 0",
    ),
    Case(
        "utils.shuffled_batches(batch_size=2.5)",
        lambda c: shuffled_batches(np.arange(10), 2.5, np.random.default_rng(0)),
        TypeError,
        "batch_size must be an integer, got 2.5",
    ),
    Case(
        "metrics.forward_speed(feature by name without names)",
        lambda c: metrics.forward_speed(c.X, feature="root_dforward"),
        ValueError,
        "Feature 'root_dforward' is given by name, but X has no feature names",
    ),
    Case(
        "metrics.forward_speed(default feature without names)",
        lambda c: metrics.forward_speed(c.X),
        ValueError,
        r"forward_speed needs the forward-displacement channel: pass feature=",
    ),
    Case(
        "metrics.motion_amplitude(features=[unknown name])",
        lambda c: metrics.motion_amplitude(
            c.walker.data, features=["tail_rx"], feature_names=c.skeleton.feature_names
        ),
        ValueError,
        "No feature is named 'tail_rx'",
    ),
    Case(
        "metrics.motion_amplitude(features=[out of range])",
        lambda c: metrics.motion_amplitude(c.X, features=[7]),
        ValueError,
        "Column 7 is out of range for 4 features",
    ),
    Case(
        "metrics.motion_amplitude(feature_names of wrong length)",
        lambda c: metrics.motion_amplitude(c.X, feature_names=["a", "b"]),
        ValueError,
        "feature_names has 2 names but X has 4 columns",
    ),
    Case(
        "metrics.step_frequency(frame_rate=-1)",
        lambda c: metrics.step_frequency(c.X, frame_rate=-1),
        ValueError,
        "frame_rate must be a positive number",
    ),
    Case(
        "metrics.motion_amplitude(last_frames=0)",
        lambda c: metrics.motion_amplitude(c.X, last_frames=0),
        ValueError,
        "last_frames must be a positive integer",
    ),
    Case(
        "metrics.nearest_style(features of another width)",
        lambda c: metrics.nearest_style(np.zeros((2, 3)), np.zeros((2, 4)), ["a", "b"]),
        ValueError,
        "features has 3 statistics but reference_features has 4",
    ),
    Case(
        "metrics.nearest_style(too few styles)",
        lambda c: metrics.nearest_style(np.zeros((2, 3)), np.zeros((2, 3)), ["a"]),
        ValueError,
        "reference_features has 2 rows but reference_styles has 1 labels",
    ),
    Case(
        "plotting.plot_skeleton(view='bottom')",
        lambda c: plotting.plot_skeleton(c.skeleton, c.walker.data[0], view="bottom"),
        ValueError,
        "view must be one of 'front', 'side', 'top', '3d', got 'bottom'",
    ),
    Case(
        "plotting.plot_motion_strip(step=0)",
        lambda c: plotting.plot_motion_strip(c.skeleton, c.walker.data, step=0),
        ValueError,
        "step must be a positive integer",
    ),
    Case(
        "plotting.plot_skeleton(skeleton is a string)",
        lambda c: plotting.plot_skeleton("walker", c.walker.data[0]),
        TypeError,
        "(?i)skeleton",
    ),
    Case(
        "plotting.plot_hidden_activations(values above 1)",
        lambda c: plotting.plot_hidden_activations(c.f["crbm"].transform(c.X) * 5),
        ValueError,
        r"\[0, 1\]",
    ),
    Case(
        "plotting.plot_filled_channels(features=[unknown name])",
        lambda c: plotting.plot_filled_channels(
            c.walker.data,
            c.walker.data,
            features=["tail_rx"],
            feature_names=c.skeleton.feature_names,
        ),
        ValueError,
        "No feature is named 'tail_rx'",
    ),
    Case(
        "datasets.bone_columns(unknown bone)",
        lambda c: bone_columns(c.skeleton.feature_names, ["lfemur", "tail"]),
        ValueError,
        "No column belongs to bone 'tail'",
    ),
    Case(
        "ConditionalRBM(visible_type='binary') on real-valued data",
        lambda c: c.new["crbm"](visible_type="binary").fit(c.X),
        ValueError,
        "visible_type='binary' needs data in \\[0, 1\\]",
    ),
    Case(
        "ConditionalRBM.score(sample_weight of wrong length)",
        lambda c: c.f["crbm"].score(c.X, sample_weight=np.ones(3)),
        ValueError,
        "sample_weight",
    ),
    Case(
        "ConditionalRBM.partial_fit(other feature count)",
        lambda c: c.new["crbm"]().partial_fit(c.X).partial_fit(c.X[:, :3]),
        ValueError,
        "X has 3 features, but ConditionalRBM is expecting 4",
    ),
    Case(
        "ExpMapEncoder.get_feature_names_out(wrong length)",
        lambda c: c.f["expmap"].get_feature_names_out(["a", "b"]),
        ValueError,
        "input_features should have length equal to number of features",
    ),
    Case(
        "ExpMapEncoder.get_feature_names_out(other names)",
        lambda c: c.f["expmap"].get_feature_names_out([f"c{i}" for i in range(33)]),
        ValueError,
        "input_features do not match the channel names seen in fit",
    ),
]


@pytest.mark.parametrize(
    "case", _params(_param_cases() + _sample_cases() + OTHER_PARAMS)
)
def test_invalid_parameters(case, ctx):
    _check(case, ctx)


# --------------------------------------------------------------- before fit
UNFITTED = [
    ("ConditionalRBM.transform", lambda c: c.new["crbm"]().transform(c.X)),
    ("ConditionalRBM.score_samples", lambda c: c.new["crbm"]().score_samples(c.X)),
    ("ConditionalRBM.predict_next", lambda c: c.new["crbm"]().predict_next(c.X)),
    ("ConditionalRBM.score", lambda c: c.new["crbm"]().score(c.X)),
    ("ConditionalRBM.sample", lambda c: c.new["crbm"]().sample(3)),
    (
        "ConditionalRBM.get_feature_names_out",
        lambda c: c.new["crbm"]().get_feature_names_out(),
    ),
    ("StackedCRBM.transform", lambda c: c.new["stack"]().transform(c.X)),
    ("StackedCRBM.predict_next", lambda c: c.new["stack"]().predict_next(c.X)),
    ("StackedCRBM.score", lambda c: c.new["stack"]().score(c.X)),
    ("StackedCRBM.sample", lambda c: c.new["stack"]().sample(3)),
    *[
        (f"{name}.{method}", lambda c, k=key, call=call: call(c.new[k](), c))
        for key, name in STYLE_MODELS
        for method, call in [
            ("transform", lambda m, c: m.transform(c.X, style="high")),
            ("score_samples", lambda m, c: m.score_samples(c.X, style="high")),
            ("predict_next", lambda m, c: m.predict_next(c.X, style="high")),
            ("score", lambda m, c: m.score(c.X, c.styles)),
            (
                "estimate_log_likelihood",
                lambda m, c: m.estimate_log_likelihood(c.X, style="high"),
            ),
            ("predict", lambda m, c: m.predict(c.X)),
            ("predict_proba", lambda m, c: m.predict_proba(c.X)),
            ("sample", lambda m, c: m.sample(3, style="high")),
        ]
    ],
    ("CRBMImputer.transform", lambda c: CRBMImputer().transform(c.X)),
    ("CRBMImputer.sample", lambda c: CRBMImputer().sample(c.X)),
    (
        "NearestNeighborImputer.transform",
        lambda c: NearestNeighborImputer().transform(c.X),
    ),
    ("ExpMapEncoder.transform", lambda c: ExpMapEncoder().transform(c.X)),
    (
        "ExpMapEncoder.inverse_transform",
        lambda c: ExpMapEncoder().inverse_transform(c.X),
    ),
    (
        "ExpMapEncoder.get_feature_names_out",
        lambda c: ExpMapEncoder().get_feature_names_out(),
    ),
    ("RootRelativeEncoder.transform", lambda c: RootRelativeEncoder().transform(c.X)),
    (
        "RootRelativeEncoder.inverse_transform",
        lambda c: RootRelativeEncoder().inverse_transform(c.X),
    ),
    ("StandardScaler.transform", lambda c: StandardScaler().transform(c.X)),
    (
        "StandardScaler.inverse_transform",
        lambda c: StandardScaler().inverse_transform(c.X),
    ),
    (
        "make_motion_preprocessor.transform",
        lambda c: make_motion_preprocessor(c.skeleton).transform(c.walker.data),
    ),
]


@pytest.mark.parametrize(
    "case",
    _params(
        [Case(name, call, NotFittedError, "not fitted") for name, call in UNFITTED]
    ),
)
def test_calls_before_fit(case, ctx):
    _check(case, ctx)


# -------------------------------------------------------- files and folders
def _write(c, name, text):
    path = c.tmp / name
    path.write_text(text)
    return path


def _asf(c, old, new, count=1):
    text = c.files["asf"].read_text()
    assert old in text, old
    return _write(c, "bad.asf", text.replace(old, new, count))


def _amc(c, old, new, n_frames=2):
    lines = c.files["amc"].read_text().splitlines()[: 3 + 30 * n_frames]
    text = "\n".join(lines) + "\n"
    assert old in text, old
    return _write(c, "bad.amc", text.replace(old, new, 1))


def _bvh(c, old, new):
    path = c.tmp / "good.bvh"
    write_bvh(path, c.walker.data[:3], c.skeleton, 30.0)
    text = path.read_text()
    assert old in text, old
    return _write(c, "bad.bvh", text.replace(old, new, 1))


def _chain(n_bones):
    """A skeleton whose bones form one chain ``b0 -> b1 -> ...``."""
    bones = [
        Bone(f"b{i}", f"b{i - 1}" if i else None, [0, 1, 0], 1.0, ("rx",), "x")
        for i in range(n_bones)
    ]
    return Skeleton(bones, convention="bvh")


def _read_amc(path, c):
    return read_amc(path, Skeleton.from_asf(c.files["asf"]))


FILE_CASES = [
    # ASF
    Case(
        "asf-NaN length",
        lambda c: Skeleton.from_asf(_asf(c, "length 2.63917", "length nan")),
        ValueError,
        r"bad\.asf, line \d+: bad length 'nan', expected a finite number",
    ),
    Case(
        "asf-infinite direction",
        lambda c: Skeleton.from_asf(
            _asf(c, "direction 0.673618 -0.716094 0.182886", "direction 1e999 0 0")
        ),
        ValueError,
        r"line \d+: bad direction '1e999', expected a finite number",
    ),
    Case(
        "asf-negative length",
        lambda c: Skeleton.from_asf(_asf(c, "length 2.63917", "length -2.63917")),
        ValueError,
        r"line \d+: Bone 'lhipjoint': length must be >= 0",
    ),
    Case(
        "asf-NaN axis angle",
        lambda c: Skeleton.from_asf(_asf(c, "axis 0 0 20  XYZ", "axis 0 nan 20 XYZ")),
        ValueError,
        r"line \d+: bad axis angle 'nan'",
    ),
    Case(
        "asf-bad axis order",
        lambda c: Skeleton.from_asf(_asf(c, "axis 0 0 20  XYZ", "axis 0 0 20 XXZ")),
        ValueError,
        r"line \d+: bad axis order 'XXZ'",
    ),
    Case(
        "asf-unknown dof (a channel the skeleton cannot have)",
        lambda c: Skeleton.from_asf(_asf(c, "dof rx ry rz", "dof rx ry rw")),
        ValueError,
        r"line \d+: unsupported degree of freedom 'rw'",
    ),
    Case(
        "asf-empty file",
        lambda c: Skeleton.from_asf(_write(c, "empty.asf", "")),
        ValueError,
        r"empty\.asf is empty: the file has no content",
    ),
    Case(
        "asf-a binary file",
        lambda c: Skeleton.from_asf(
            _write(c, "binary.asf", "\x00\x01\x02MATLAB 5.0 MAT-file")
        ),
        ValueError,
        r"line 1: unexpected text",
    ),
    # AMC
    Case(
        "amc-NaN value",
        lambda c: _read_amc(_amc(c, "root 4.40047", "root nan"), c),
        ValueError,
        r"bad\.amc, line 5: bad value 'nan', expected a finite number",
    ),
    Case(
        "amc-overflowing value",
        lambda c: _read_amc(_amc(c, "root 4.40047", "root 1e999"), c),
        ValueError,
        r"line 5: bad value '1e999', expected a finite number",
    ),
    Case(
        "amc-empty file",
        lambda c: _read_amc(_write(c, "empty.amc", ""), c),
        ValueError,
        r"empty\.amc is empty: the file has no content",
    ),
    Case(
        "amc-truncated after the header",
        lambda c: _read_amc(_write(c, "head.amc", ":FULLY-SPECIFIED\n:DEGREES\n"), c),
        ValueError,
        r"head\.amc, line 2: no frames",
    ),
    Case(
        "amc-truncated in the middle of a line",
        lambda c: _read_amc(_write(c, "cut.amc", c.files["amc"].read_text()[:400]), c),
        ValueError,
        r"cut\.amc, line \d+: (bone '\w+' has \d+ values|the frame starting here lacks)",
    ),
    Case(
        "amc-header after the first frame",
        lambda c: _read_amc(_amc(c, "lowerback", ":DEGREES\nlowerback"), c),
        ValueError,
        r"line \d+: header line ':DEGREES' after the first frame",
    ),
    Case(
        "amc-angles in radians, skeleton in degrees",
        lambda c: _read_amc(_amc(c, ":DEGREES", ":RADIANS"), c),
        ValueError,
        r"bad\.amc, line 3: the file's angles are in radians but the skeleton's "
        r"\(angle_unit='deg'\)",
    ),
    Case(
        "amc-skeleton is neither a Skeleton nor a path",
        lambda c: read_amc(c.files["amc"], None),
        TypeError,
        "read_amc needs a Skeleton or the path of an ASF file, got NoneType",
    ),
    Case(
        "amc-skeleton of another subject",
        lambda c: read_amc(c.files["amc"], c.skeleton),
        ValueError,
        r"line 7: unknown bone 'upperback'",
    ),
    # BVH
    Case(
        "bvh-NaN offset",
        lambda c: read_bvh(_bvh(c, "OFFSET 0 0 0", "OFFSET nan 0 0")),
        ValueError,
        r"bad OFFSET value 'nan', expected a finite number",
    ),
    Case(
        "bvh-huge offset",
        lambda c: read_bvh(_bvh(c, "OFFSET 0 0 0", "OFFSET 1.5e308 1.5e308 0")),
        ValueError,
        r"bad\.bvh, line \d+: Bone 'root': length must be finite",
    ),
    Case(
        "bvh-NaN in the motion",
        lambda c: read_bvh(_bvh(c, "\n1.0850199126129378 ", "\nnan ")),
        ValueError,
        r"bad\.bvh, line \d+: bad value 'nan', expected a finite number",
    ),
    Case(
        "bvh-infinite frame time",
        lambda c: read_bvh(
            _bvh(c, "Frame Time: 0.03333333333333333", "Frame Time: inf")
        ),
        ValueError,
        r"line \d+: bad Frame Time: 'inf', expected a finite number",
    ),
    Case(
        "bvh-denormal frame time",
        lambda c: read_bvh(
            _bvh(c, "Frame Time: 0.03333333333333333", "Frame Time: 1e-320")
        ),
        ValueError,
        r"line \d+: expected a positive frame time",
    ),
    Case(
        "bvh-non-ASCII channel count",
        lambda c: read_bvh(_bvh(c, "CHANNELS 6", "CHANNELS \u00b2")),
        ValueError,
        r"bad\.bvh, line 5: bad number of channels",
    ),
    Case(
        "bvh-a repeated channel",
        lambda c: read_bvh(_bvh(c, "Xrotation", "Yrotation")),
        ValueError,
        r"bad\.bvh, line \d+: Bone 'root' repeats a channel",
    ),
    Case(
        "bvh-unknown channel",
        lambda c: read_bvh(_bvh(c, "Xrotation", "Wrotation")),
        ValueError,
        r"line \d+: unknown channel 'Wrotation'",
    ),
    Case(
        "bvh-joints nested without end",
        lambda c: read_bvh(
            _write(
                c,
                "deep.bvh",
                "HIERARCHY\nROOT a\n{\nOFFSET 0 0 0\n"
                + "".join(f"JOINT j{i}\n{{\nOFFSET 0 0 1\n" for i in range(3000))
                + "MOTION\nFrames: 0\nFrame Time: 0.1\n",
            )
        ),
        ValueError,
        r"deep\.bvh, line \d+: (joints are nested too deeply|file ends where)",
    ),
    Case(
        "bvh-an ASF file",
        lambda c: read_bvh(c.files["asf"]),
        ValueError,
        r"35\.asf, line \d+: no 'MOTION' section",
    ),
    Case(
        "bvh skeleton-an empty file",
        lambda c: Skeleton.from_bvh(_write(c, "empty.bvh", "")),
        ValueError,
        r"empty\.bvh is empty: the file has no content \(0 bytes\)",
    ),
    # paths
    Case(
        "read_amc-missing file",
        lambda c: read_amc(c.tmp / "missing.amc", c.skeleton),
        FileNotFoundError,
        "No such file",
    ),
    Case(
        "read_bvh-missing file",
        lambda c: read_bvh(c.tmp / "missing.bvh"),
        FileNotFoundError,
        "No such file",
    ),
    Case(
        "Skeleton.from_asf-missing file",
        lambda c: Skeleton.from_asf(c.tmp / "missing.asf"),
        FileNotFoundError,
        "No such file",
    ),
    Case(
        "Skeleton.from_bvh-a folder",
        lambda c: Skeleton.from_bvh(c.tmp),
        OSError,
        "directory",
    ),
    Case(
        "Skeleton.from_asf-None",
        lambda c: Skeleton.from_asf(None),
        TypeError,
        r"Expected the path of a file \(str or os.PathLike\), got NoneType",
    ),
    Case(
        "read_bvh-a number",
        lambda c: read_bvh(3),
        TypeError,
        "Expected the path of a file",
    ),
    Case(
        "Skeleton.from_mit-missing file",
        lambda c: Skeleton.from_mit(c.tmp / "missing.mat"),
        FileNotFoundError,
        "No such file",
    ),
    Case(
        "Skeleton.from_mit-not a struct",
        lambda c: Skeleton.from_mit({"type": "mit"}),
        TypeError,
        "skel must be the 'skel' struct of Taylor's MIT data",
    ),
    Case(
        "Skeleton.from_mit-a MATLAB file without skel",
        lambda c: (
            scipy.io.savemat(c.tmp / "other.mat", {"Y": np.zeros(3)}),
            Skeleton.from_mit(c.tmp / "other.mat"),
        ),
        ValueError,
        r"lacks the variables \['skel', 'Motion'\].*fetch_mit_walk",
    ),
    Case(
        "write_amc-skeleton is a path",
        lambda c: write_amc(c.tmp / "x.amc", c.walker.data, str(c.files["asf"])),
        TypeError,
        "write_amc needs a Skeleton, got str",
    ),
    Case(
        "write_bvh-skeleton is None",
        lambda c: write_bvh(c.tmp / "x.bvh", c.walker.data, None, 30.0),
        TypeError,
        "write_bvh needs a Skeleton, got NoneType",
    ),
    Case(
        "write_bvh-a chain of 1500 bones",
        lambda c: write_bvh(c.tmp / "x.bvh", np.zeros((2, 1500)), _chain(1500), 30.0),
        ValueError,
        "The skeleton nests 1500 bones too deeply to be written as a BVH file",
    ),
    Case(
        "write_amc-folder does not exist",
        lambda c: write_amc(c.tmp / "no" / "x.amc", c.walker.data, c.skeleton),
        FileNotFoundError,
        "No such file or directory",
    ),
]


def _damaged(c, folder, name, content):
    (c.tmp / folder).mkdir(exist_ok=True)
    if folder == "cmu_subject35":
        (c.tmp / folder / "35.asf").write_bytes(c.files["asf"].read_bytes())
    path = c.tmp / folder / name
    if isinstance(content, dict):
        scipy.io.savemat(path, content)
    else:
        path.write_bytes(content)
    return c.tmp


DATA_CASES = [
    Case(
        "load_cmu35-missing folder",
        lambda c: load_cmu35(c.tmp),
        FileNotFoundError,
        r"cmu35WalkJog\.mat not found\. Download the data with "
        r"sklearn_crbm\.datasets\.fetch_cmu35",
    ),
    Case(
        "load_cmu35-folder without the ASF file",
        lambda c: (
            (c.tmp / "cmu_subject35").mkdir(),
            (c.tmp / "cmu_subject35" / "cmu35WalkJog.mat").write_bytes(b""),
            load_cmu35(c.tmp),
        ),
        FileNotFoundError,
        r"35\.asf not found.*fetch_cmu35",
    ),
    Case(
        "load_mit_walk-missing folder",
        lambda c: load_mit_walk(c.tmp),
        FileNotFoundError,
        r"data\.mat not found.*fetch_mit_walk",
    ),
    Case(
        "load_cmu35-folder does not exist",
        lambda c: load_cmu35(c.tmp / "nowhere"),
        FileNotFoundError,
        "fetch_cmu35",
    ),
    Case(
        "load_cmu35-environment points nowhere",
        lambda c: _with_env(c.tmp / "nowhere", load_cmu35),
        FileNotFoundError,
        r"nowhere.*SKLEARN_CRBM_DATA",
    ),
    Case(
        "load_cmu35-truncated MATLAB file",
        lambda c: load_cmu35(
            _damaged(
                c,
                "cmu_subject35",
                "cmu35WalkJog.mat",
                (c.files["asf"].parent / "cmu35WalkJog.mat").read_bytes()[:4000],
            )
        ),
        ValueError,
        r"not a readable MATLAB file.*fetch_cmu35\(\)",
    ),
    Case(
        "load_cmu35-text instead of MATLAB",
        lambda c: load_cmu35(
            _damaged(c, "cmu_subject35", "cmu35WalkJog.mat", b"hello")
        ),
        ValueError,
        r"not a readable MATLAB file.*fetch_cmu35\(\)",
    ),
    Case(
        "load_cmu35-MATLAB file of other data",
        lambda c: load_cmu35(
            _damaged(c, "cmu_subject35", "cmu35WalkJog.mat", {"Z": np.zeros(3)})
        ),
        ValueError,
        r"lacks the variables \['Y', 'lbls', 'Ytest', 'lblstest'\]",
    ),
    Case(
        "load_mit_walk-damaged MATLAB file",
        lambda c: load_mit_walk(
            _damaged(c, "taylor_mhmublv_mit", "data.mat", b"\x00" * 200)
        ),
        ValueError,
        # scipy before 1.15 reads 200 zero bytes as a MATLAB file of nothing
        r"(not a readable MATLAB file|lacks the variables).*fetch_mit_walk\(\)",
    ),
    Case(
        "get_data_home-a number",
        lambda c: get_data_home(3),
        TypeError,
        "os.PathLike",
    ),
    Case(
        "fetch_cmu35-server unreachable",
        lambda c: fetch_cmu35(
            c.tmp / "home", base_url=(c.tmp / "no_server").as_uri(), timeout=1.0
        ),
        OSError,
        r"Could not download file:.*35",
    ),
]


def _with_env(value, function):
    old = os.environ.get("SKLEARN_CRBM_DATA")
    os.environ["SKLEARN_CRBM_DATA"] = str(value)
    try:
        return function()
    finally:
        if old is None:
            del os.environ["SKLEARN_CRBM_DATA"]
        else:
            os.environ["SKLEARN_CRBM_DATA"] = old


@pytest.mark.parametrize("case", _params(FILE_CASES + DATA_CASES))
def test_bad_files_and_folders(case, ctx):
    _check(case, ctx)


# ------------------------------------------------------- skeletons, channels
SKELETON_CASES = [
    Case(
        "Bone-unknown channel",
        lambda c: Bone("knee", None, [0, 1, 0], 1.0, ("rx", "qq"), "x"),
        ValueError,
        r"Bone 'knee' has unknown channels \['qq'\]; known channels are",
    ),
    Case(
        "Bone-channels as one string",
        lambda c: Bone("knee", None, [0, 1, 0], 1.0, "rx", "x"),
        TypeError,
        r"channels must be a sequence of channel names such as \('rx', 'ry', 'rz'\)",
    ),
    Case(
        "Bone-direction of two numbers",
        lambda c: Bone("knee", None, [0, 1], 1.0),
        ValueError,
        r"Bone 'knee': direction must be three numbers, got shape \(2,\)",
    ),
    Case(
        "Bone-direction of strings",
        lambda c: Bone("knee", None, "up", 1.0),
        ValueError,
        "Bone 'knee': direction must be three numbers, got 'up'",
    ),
    Case(
        "Bone-NaN direction",
        lambda c: Bone("knee", None, [np.nan, 1, 0], 1.0),
        ValueError,
        "Bone 'knee': direction must be finite",
    ),
    Case(
        "Bone-NaN length",
        lambda c: Bone("knee", None, [0, 1, 0], np.nan),
        ValueError,
        "Bone 'knee': length must be finite",
    ),
    Case(
        "Bone-negative length",
        lambda c: Bone("knee", None, [0, 1, 0], -1.0),
        ValueError,
        "Bone 'knee': length must be >= 0",
    ),
    Case(
        "Bone-length of a string",
        lambda c: Bone("knee", None, [0, 1, 0], "long"),
        ValueError,
        "Bone 'knee': length must be a number, got 'long'",
    ),
    Case(
        "Bone-bad axis order",
        lambda c: Bone("knee", None, [0, 1, 0], 1.0, axis=(10, 0, 0), axis_order="xxz"),
        ValueError,
        "Bone 'knee': axis_order must hold each of 'x', 'y', 'z' once",
    ),
    Case(
        "Bone-axis of two numbers",
        lambda c: Bone("knee", None, [0, 1, 0], 1.0, axis=(10, 0)),
        ValueError,
        "Bone 'knee': axis must be three numbers",
    ),
    Case(
        "Bone-rotation order of other axes",
        lambda c: Bone("knee", None, [0, 1, 0], 1.0, ("rx", "ry"), "xz"),
        ValueError,
        "rotation_order 'xz' must name exactly the axes of its Euler channels",
    ),
    Case(
        "Skeleton-not bones",
        lambda c: Skeleton(["root", "knee"]),
        TypeError,
        "A skeleton is built from Bone objects, got 'root'",
    ),
    Case(
        "Skeleton-no bones",
        lambda c: Skeleton([]),
        ValueError,
        "A skeleton needs at least one bone",
    ),
    Case(
        "Skeleton-bad up axis",
        lambda c: Skeleton(c.skeleton.bones, up_axis="w"),
        ValueError,
        "up_axis must be 'x', 'y' or 'z'",
    ),
    Case(
        "Skeleton.bone-unknown name",
        lambda c: c.skeleton.bone("tail"),
        ValueError,
        "Skeleton 'walker' has no bone 'tail'; its bones are",
    ),
    Case(
        "forward_kinematics-channels the skeleton does not know",
        lambda c: c.skeleton.forward_kinematics(
            c.walker.data, feature_names=[f"tail_r{i}" for i in range(33)]
        ),
        ValueError,
        r"The data lack these channels of the skeleton: \['root_tx'",
    ),
    Case(
        "forward_kinematics-a repeated channel name",
        lambda c: c.skeleton.forward_kinematics(
            c.walker.data,
            feature_names=["root_tx"] + list(c.skeleton.feature_names[:-1]),
        ),
        ValueError,
        "Feature name 'root_tx' occurs more than once",
    ),
    Case(
        "write_amc-channels the skeleton does not know",
        lambda c: write_amc(
            c.tmp / "x.amc",
            c.walker.data,
            c.skeleton,
            feature_names=["tail_rx"] + list(c.skeleton.feature_names[1:]),
        ),
        ValueError,
        r"The data lack these channels of the skeleton: \['root_tx'\]",
    ),
    Case(
        "ExpMapEncoder-skeleton is a path",
        lambda c: ExpMapEncoder(str(c.files["asf"])).fit(c.walker.data),
        TypeError,
        "skeleton must be a sklearn_crbm.datasets.Skeleton",
    ),
    Case(
        "RootRelativeEncoder-skeleton is a number",
        lambda c: RootRelativeEncoder(3).fit(c.Z),
        TypeError,
        "skeleton must be a sklearn_crbm.datasets.Skeleton",
    ),
    Case(
        "make_motion_preprocessor-skeleton is a string",
        lambda c: make_motion_preprocessor("walker").fit(c.walker.data),
        TypeError,
        "skeleton must be a sklearn_crbm.datasets.Skeleton",
    ),
    Case(
        "RootRelativeEncoder-root still in Euler angles",
        lambda c: RootRelativeEncoder().fit(c.walker.data[:, :5]),
        ValueError,
        "X has 5 feature.*needs the 6 root channels.*pass channels=",
    ),
]


@pytest.mark.parametrize("case", _params(SKELETON_CASES))
def test_bad_skeletons_and_channels(case, ctx):
    _check(case, ctx)


# ------------------------------------------------------- a fit that failed
def _diverging(c, key="crbm"):
    return c.new[key](n_components=8, learning_rate=50.0, momentum_delay=0, n_iter=60)


def _failed(fit, use):
    """Run a fit that must fail, then the call that must say "not fitted"."""

    def call(c):
        with np.errstate(all="ignore"):
            estimator = fit(c)
        use(c, estimator)

    return call


def _fit_fails(make, *args, **kwargs):
    def fit(c):
        estimator = make(c)
        with pytest.raises((ValueError, FloatingPointError)):
            estimator.fit(*[a(c) if callable(a) else a for a in args], **kwargs)
        return estimator

    return fit


FAILED_FITS = [
    Case(
        "ConditionalRBM-short sequences, then transform",
        _failed(
            _fit_fails(
                lambda c: c.new["crbm"](), lambda c: c.X, sequence_ids=ONE_FRAME_EACH
            ),
            lambda c, e: e.transform(c.X),
        ),
        NotFittedError,
        "not fitted",
    ),
    Case(
        "ConditionalRBM-diverged, then sample",
        _failed(
            _fit_fails(_diverging, lambda c: c.X * 100),
            lambda c, e: e.sample(3),
        ),
        NotFittedError,
        "not fitted",
    ),
    Case(
        "ConditionalRBM-diverged, then score_samples",
        _failed(
            _fit_fails(_diverging, lambda c: c.X * 100),
            lambda c, e: e.score_samples(c.X),
        ),
        NotFittedError,
        "not fitted",
    ),
    *[
        case
        for key, name in STYLE_MODELS
        for case in (
            Case(
                f"{name}-short sequences, then transform",
                _failed(
                    _fit_fails(
                        lambda c, k=key: c.new[k](),
                        lambda c: c.X,
                        lambda c: c.styles,
                        sequence_ids=ONE_FRAME_EACH,
                    ),
                    lambda c, e: e.transform(c.X, style="high"),
                ),
                NotFittedError,
                "not fitted",
            ),
            Case(
                f"{name}-diverged, then sample",
                _failed(
                    _fit_fails(
                        lambda c, k=key: _diverging(c, k),
                        lambda c: c.X * 100,
                        lambda c: c.styles,
                    ),
                    lambda c, e: e.sample(3, style="high"),
                ),
                NotFittedError,
                "not fitted",
            ),
        )
    ],
    Case(
        "StackedCRBM-short sequences, then transform",
        _failed(
            _fit_fails(
                lambda c: c.new["stack"](),
                lambda c: c.X,
                sequence_ids=np.arange(60) // 3,
            ),
            lambda c, e: e.transform(c.X),
        ),
        NotFittedError,
        "not fitted",
    ),
    Case(
        "CRBMImputer-short sequences, then transform",
        _failed(
            _fit_fails(
                lambda c: CRBMImputer(c.new["crbm"]()),
                lambda c: c.X,
                sequence_ids=ONE_FRAME_EACH,
            ),
            lambda c, e: e.transform(_one(c.X, np.nan)),
        ),
        NotFittedError,
        "not fitted",
    ),
    Case(
        "NearestNeighborImputer-no complete frame, then transform",
        _failed(
            _fit_fails(
                lambda c: NearestNeighborImputer(), lambda c: np.full_like(c.X, np.nan)
            ),
            lambda c, e: e.transform(_one(c.X, np.nan)),
        ),
        NotFittedError,
        "not fitted",
    ),
    Case(
        "ExpMapEncoder-wrong column count, then transform",
        _failed(
            _fit_fails(
                lambda c: ExpMapEncoder(c.skeleton), lambda c: c.walker.data[:, :5]
            ),
            lambda c, e: e.transform(c.walker.data[:, :5]),
        ),
        NotFittedError,
        "not fitted",
    ),
    Case(
        "RootRelativeEncoder-no root channels, then transform",
        _failed(
            _fit_fails(lambda c: RootRelativeEncoder(), lambda c: c.X),
            lambda c, e: e.transform(c.X),
        ),
        NotFittedError,
        "not fitted",
    ),
]


@pytest.mark.parametrize("case", _params(FAILED_FITS))
def test_a_failed_fit_leaves_the_estimator_unfitted(case, ctx):
    """Not half-fitted: later calls say "not fitted", never AttributeError."""
    _check(case, ctx)


# ------------------------------------------------------------ command line
CLI_CASES = {
    "fit-missing data folder": (
        lambda tmp: ["fit", "--data-home", str(tmp / "nowhere")],
        r"error: .*cmu35WalkJog\.mat not found.*python -m sklearn_crbm fetch",
    ),
    "sample-missing model file": (
        lambda tmp: ["sample", str(tmp / "missing.joblib")],
        r"error: .*No such file or directory: .*missing\.joblib",
    ),
    "sample-a model pickled before the layer redesign": (
        lambda tmp: [
            "sample",
            str(Path(__file__).parents[1] / "data" / "crbm_08bf639.pkl"),
        ],
        r"error: .*crbm_08bf639\.pkl.*before the layer redesign.*Refit the model",
    ),
    "sample-a file that is not a model": (
        lambda tmp: (
            (tmp / "garbage.joblib").write_text("garbage"),
            ["sample", str(tmp / "garbage.joblib")],
        )[1],
        r"error: .*garbage\.joblib",
    ),
}


@pytest.mark.parametrize("name", list(CLI_CASES))
def test_command_line_reports_bad_input_without_a_traceback(name, tmp_path, capsys):
    from sklearn_crbm.cli import main

    argv, message = CLI_CASES[name]
    status = main(argv(tmp_path))
    assert status == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    assert re.search(message, err, flags=re.DOTALL), err


# ----------------------------------------------------------------- context
# Every entry point of a model of a context, given a context ``c`` (the
# frames': ``c.context``, or a bad one).
CONTEXT_ENTRIES = {
    "ConditionalRBM.fit": lambda c, k: c.new["crbm"]().fit(c.X, context=k),
    "ConditionalRBM.partial_fit(fitted)": lambda c, k: copy.deepcopy(
        c.f["context_crbm"]
    ).partial_fit(c.X, context=k),
    **{
        f"ConditionalRBM.{m}": lambda c, k, m=m: getattr(c.f["context_crbm"], m)(
            c.X, context=k
        )
        for m in (
            "transform",
            "predict_next",
            "score_samples",
            "score",
            "estimate_log_likelihood",
        )
    },
    "ConditionalRBM.sample": lambda c, k: c.f["context_crbm"].sample(c.n, context=k),
    "CRBMImputer.fit": lambda c, k: CRBMImputer(c.new["crbm"]()).fit(c.X, context=k),
    "CRBMImputer.transform": lambda c, k: c.f["context_imputer"].transform(
        _one(c.X, np.nan), context=k
    ),
    "CRBMImputer.sample": lambda c, k: c.f["context_imputer"].sample(
        _one(c.X, np.nan), 2, context=k
    ),
}
FITTED_WITH_CONTEXT = [name for name in CONTEXT_ENTRIES if ".fit" not in name]
BAD_CONTEXTS = {
    "NaN": (lambda k: np.where(k > 0.5, np.nan, k), ValueError, "NaN or infinity"),
    "infinity": (lambda k: np.where(k > 0.5, np.inf, k), ValueError, "NaN or infinity"),
    "text": (lambda k: np.full(k.shape, "fast"), TypeError, "array of numbers"),
    "sparse": (
        lambda k: sp.csr_matrix(k),
        TypeError,
        "dense array, got a sparse",
    ),
    "one signal as 1-D": (lambda k: k[:, 0], ValueError, r"reshape\(-1, 1\)"),
    "a row too few": (lambda k: k[:-1], ValueError, "one row of context per frame"),
    "no columns": (lambda k: k[:, :0], ValueError, "one row of context per frame"),
}


def _context_cases():
    cases = [
        Case(
            f"{name}-{kind}",
            lambda c, call=call, make=make: call(c, make(c.context)),
            exc,
            match,
        )
        for name, call in CONTEXT_ENTRIES.items()
        for kind, (make, exc, match) in BAD_CONTEXTS.items()
    ]
    cases += [
        Case(
            f"{name}-no context",
            lambda c, call=CONTEXT_ENTRIES[name]: call(c, None),
            ValueError,
            r"fitted with a context of 2 columns per frame.*pass context=",
        )
        for name in FITTED_WITH_CONTEXT
    ]
    cases += [
        Case(
            f"{name}-3 columns",
            lambda c, call=CONTEXT_ENTRIES[name]: call(
                c, np.hstack([c.context, c.context[:, :1]])
            ),
            ValueError,
            r"context must have shape \(n, 2\)",
        )
        for name in FITTED_WITH_CONTEXT
    ]
    return cases + [
        Case(
            "ConditionalRBM without context.transform-a context",
            lambda c: c.f["crbm"].transform(c.X, context=c.context),
            ValueError,
            "fitted without context, so it takes none",
        ),
        Case(
            "ConditionalRBM.transform-a style",
            lambda c: c.f["context_crbm"].transform(c.X, style="high"),
            ValueError,
            "ConditionalRBM has no styles: give context= instead of style=",
        ),
        Case(
            "LabelledCRBM.fit-labels and context",
            lambda c: c.new["labelled"]().fit(c.X, c.styles, context=c.context),
            ValueError,
            "got both y and context=: give the labels",
        ),
        Case(
            "FactoredCRBM.transform-style and context",
            lambda c: c.f["factored"].transform(c.X, style="high", context=c.context),
            ValueError,
            "got both style= and context=",
        ),
        Case(
            "CRBMImputer.fit-context of another length",
            lambda c: CRBMImputer(c.new["crbm"]()).fit(c.X, context=c.context[:-1]),
            ValueError,
            r"with n = 60: one row of context per frame; got shape \(59, 2\)",
        ),
    ]


@pytest.mark.parametrize("case", _params(_context_cases()))
def test_bad_context(case, ctx):
    _check(case, ctx)
