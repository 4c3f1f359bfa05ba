"""Shared fixtures: where the real motion-capture data lives, and small subsets.

Tests read the data from ``../shared/data`` beside the repository (or from
``$SKLEARN_CRBM_DATA``).  A missing data folder is an error, not a skip: CI
always has it.
"""

import importlib
import importlib.util
import os
from pathlib import Path

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from sklearn_crbm.datasets import load_cmu35

REPO_ROOT = Path(__file__).resolve().parents[1]


def _find_data_home():
    candidates = [
        os.environ.get("SKLEARN_CRBM_DATA"),
        REPO_ROOT.parent / "shared" / "data",
    ]
    for candidate in candidates:
        if candidate and (Path(candidate) / "cmu_subject35").is_dir():
            return Path(candidate)
    raise RuntimeError(
        "The motion-capture test data was not found. Put the shared data folder at "
        f"{REPO_ROOT.parent / 'shared' / 'data'} or point $SKLEARN_CRBM_DATA at it."
    )


@pytest.fixture(scope="session")
def data_home():
    """Folder holding ``cmu_subject35/``, ``taylor_mhmublv_mit/`` and friends."""
    return _find_data_home()


# 6 walks (35_01 ... 35_06) and 3 jogs (35_19 ... 35_21) of the training set:
# with GroupKFold(3) every fold holds out 2 walks and 1 jog.
SEARCH_TRIALS = [0, 1, 2, 3, 4, 5, 16, 17, 18]


@pytest.fixture(scope="session")
def cmu_search_trials(data_home):
    """``(X, sequence_ids, skeleton)``: raw frames of 9 CMU 35 training trials."""
    bunch = load_cmu35(data_home, subset="train")
    keep = np.isin(bunch.sequence_ids, SEARCH_TRIALS)
    return bunch.data[keep], bunch.sequence_ids[keep], bunch.skeleton


@pytest.fixture
def one_blas_thread():
    """One BLAS thread: on small matrices on a busy machine threads only contend."""
    with threadpool_limits(limits=1, user_api="blas"):
        yield


# array-api-strict comes with the test extra; PyTorch (CPU build) is installed by
# .ci/run, being too heavy for the extra.  Tests run on those present.
OTHER_NAMESPACES = [
    name for name in ("array_api_strict", "torch") if importlib.util.find_spec(name)
]


@pytest.fixture(params=OTHER_NAMESPACES)
def other_namespace(request):
    """An array API namespace other than numpy's, as a module."""
    return importlib.import_module(request.param)
