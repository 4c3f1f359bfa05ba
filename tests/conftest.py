"""Shared fixtures: where the real motion-capture data lives.

Tests read the data from ``../shared/data`` beside the repository (or from
``$SKLEARN_CRBM_DATA``).  A missing data folder is an error, not a skip: CI
always has it.
"""

import os
from pathlib import Path

import pytest

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
