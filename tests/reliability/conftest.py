"""Shared fixtures of the reliability tests: tiny data and tiny fitted models.

Everything here is small on purpose (a few dozen frames, a handful of hidden
units, a couple of epochs): the tests check behaviour on odd or bad input,
not the quality of a model, and must run in seconds on a busy machine.
"""

import importlib

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

import sklearn_crbm
from sklearn_crbm import ConditionalRBM, FactoredCRBM, LabelledCRBM
from sklearn_crbm.datasets import make_oscillations, make_walker
from sklearn_crbm.impute import CRBMImputer, NearestNeighborImputer
from sklearn_crbm.preprocessing import (
    ExpMapEncoder,
    RootRelativeEncoder,
    StandardScaler,
    make_motion_preprocessor,
)

# StackedCRBM is re-exported by the package once it lands; until then it is
# only in its private module.
StackedCRBM = (
    getattr(sklearn_crbm, "StackedCRBM", None)
    or importlib.import_module("sklearn_crbm.models._stacked").StackedCRBM
)

N_FEATURES = 4
ORDER = 2


SMALL = dict(order=ORDER, n_iter=2, batch_size=20, random_state=0)


def small_crbm(**params):
    """A ConditionalRBM that fits in milliseconds."""
    return ConditionalRBM(**{"n_components": 5, **SMALL, **params})


def small_stack(**params):
    return StackedCRBM(**{"n_components": (5, 3), **SMALL, **params})


def small_factored(**params):
    """A FactoredCRBM that fits in milliseconds: CD-1, a few factors."""
    defaults = dict(n_components=5, n_factors=3, n_style_features=2, cd_steps=1)
    return FactoredCRBM(**{**defaults, "n_gibbs": 3, **SMALL, **params})


def small_labelled(**params):
    return LabelledCRBM(**{"n_components": 5, "n_gibbs": 3, **SMALL, **params})


@pytest.fixture(scope="session", autouse=True)
def single_threaded_blas():
    """One BLAS thread: on a busy shared machine, BLAS threads that wait for
    each other make these small matrix products a hundred times slower."""
    with threadpool_limits(limits=1, user_api="blas"):
        yield


@pytest.fixture(scope="session")
def oscillations():
    """``(X, sequence_ids)``: three sequences of 20 frames, 4 features."""
    return make_oscillations(
        n_sequences=3, n_frames=20, n_features=N_FEATURES, random_state=0
    )


@pytest.fixture(scope="session")
def walker():
    """Two sequences of 20 frames of the synthetic walker (33 raw channels)."""
    return make_walker(n_sequences=2, n_frames=20, random_state=0)


@pytest.fixture(scope="session")
def styles(oscillations):
    """A style for every frame of ``oscillations``: low, high, low by sequence."""
    return np.where(oscillations[1] % 2 == 1, "high", "low")


@pytest.fixture(scope="session")
def context(oscillations):
    """A control signal of two columns for every frame of ``oscillations``."""
    ids = oscillations[1]
    sign = np.where(ids % 2 == 1, 1.0, -1.0)
    return np.column_stack([sign, np.linspace(-1, 1, len(ids))])


@pytest.fixture(scope="session")
def fitted(oscillations, styles, walker, context):
    """One fitted instance of every public estimator, keyed by a short name.

    Session-scoped: tests must not fit or mutate these (use
    ``sklearn.base.clone`` for that).
    """
    X, ids = oscillations
    Z = ExpMapEncoder(walker.skeleton).fit_transform(walker.data)
    return {
        "crbm": small_crbm().fit(X, sequence_ids=ids),
        "context_crbm": small_crbm().fit(X, sequence_ids=ids, context=context),
        "context_imputer": CRBMImputer(small_crbm(), n_gibbs=2, random_state=0).fit(
            X, sequence_ids=ids, context=context
        ),
        "stack": small_stack().fit(X, sequence_ids=ids),
        "factored": small_factored().fit(X, styles, sequence_ids=ids),
        "labelled": small_labelled().fit(X, styles, sequence_ids=ids),
        "crbm_imputer": CRBMImputer(small_crbm(), n_gibbs=3, random_state=0).fit(
            X, sequence_ids=ids
        ),
        "stack_imputer": CRBMImputer(small_stack(), n_gibbs=2, random_state=0).fit(
            X, sequence_ids=ids
        ),
        "factored_imputer": CRBMImputer(
            small_factored(), n_gibbs=2, n_particles=4, random_state=0
        ).fit(X, styles, sequence_ids=ids),
        "nn_imputer": NearestNeighborImputer().fit(X),
        "expmap": ExpMapEncoder(walker.skeleton).fit(walker.data),
        "root": RootRelativeEncoder(walker.skeleton).fit(Z),
        "scaler": StandardScaler().fit(X),
        "preprocessor": make_motion_preprocessor(walker.skeleton).fit(walker.data),
    }


@pytest.fixture(scope="session")
def factories():
    """Constructors of tiny unfitted estimators, for tests that fit their own."""
    return {
        "crbm": small_crbm,
        "stack": small_stack,
        "factored": small_factored,
        "labelled": small_labelled,
        "StackedCRBM": StackedCRBM,
    }


@pytest.fixture(scope="session")
def real_files(data_home):
    """Paths of the real ASF and AMC files of CMU subject 35."""
    folder = data_home / "cmu_subject35"
    return {"asf": folder / "35.asf", "amc": folder / "35_01.amc"}


@pytest.fixture
def rng():
    return np.random.default_rng(0)
