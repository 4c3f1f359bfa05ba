"""CRBMImputer fills blocks of sequences in parallel without changing the fills."""

import numpy as np
import pytest
from numpy.testing import assert_array_equal
from sklearn.utils._param_validation import InvalidParameterError

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import make_oscillations
from sklearn_crbm.impute import CRBMImputer
from sklearn_crbm.utils._parallel import BLOCK_SEQUENCES

# 70 short sequences: more than one block of 32, so the work splits in three.
X, IDS = make_oscillations(n_sequences=70, n_frames=12, random_state=0)
X_MISSING = X.copy()
X_MISSING[np.tile(np.arange(12), 70) >= 6, :2] = np.nan
X_MISSING[::5, 3] = np.nan


@pytest.fixture(scope="module")
def imputer():
    model = ConditionalRBM(8, order=2, n_iter=5, random_state=0)
    return CRBMImputer(model, n_gibbs=3, n_draws=2, random_state=0).fit(
        X, sequence_ids=IDS
    )


def test_many_sequences_are_split_into_blocks():
    assert 70 > 2 * BLOCK_SEQUENCES


@pytest.mark.parametrize("n_jobs", [2, -1])
def test_transform_with_n_jobs_equals_one_job(imputer, n_jobs):
    serial = imputer.set_params(n_jobs=1).transform(X_MISSING, sequence_ids=IDS)
    parallel = imputer.set_params(n_jobs=n_jobs).transform(X_MISSING, sequence_ids=IDS)
    imputer.set_params(n_jobs=None)
    assert_array_equal(parallel, serial)
    assert not np.isnan(parallel).any()
    observed = ~np.isnan(X_MISSING)
    assert_array_equal(parallel[observed], X_MISSING[observed])


def test_sample_with_n_jobs_equals_one_job(imputer):
    draws = [
        imputer.set_params(n_jobs=n_jobs).sample(
            X_MISSING, n_samples=2, sequence_ids=IDS, random_state=3
        )
        for n_jobs in (None, 2)
    ]
    imputer.set_params(n_jobs=None)
    assert_array_equal(draws[1], draws[0])
    assert not np.array_equal(draws[0][0], draws[0][1])  # independent fills


def test_blocks_are_filled_independently(imputer):
    # A sequence's fill depends only on its own block: changing a sequence in
    # the last block leaves the first block's fills as they were.
    full = imputer.transform(X_MISSING, sequence_ids=IDS)
    changed = X_MISSING.copy()
    changed[IDS == 69] += 0.5
    other = imputer.transform(changed, sequence_ids=IDS)
    first_block = IDS < 24  # 70 sequences in 3 blocks: 24, 23, 23
    assert_array_equal(other[first_block], full[first_block])


def test_few_sequences_form_one_block_whatever_n_jobs(imputer):
    few = IDS < 5
    serial = imputer.transform(X_MISSING[few], sequence_ids=IDS[few])
    parallel = imputer.set_params(n_jobs=2).transform(
        X_MISSING[few], sequence_ids=IDS[few]
    )
    imputer.set_params(n_jobs=None)
    assert_array_equal(parallel, serial)


def test_n_jobs_is_validated():
    with pytest.raises(InvalidParameterError, match="n_jobs"):
        CRBMImputer(ConditionalRBM(4, n_iter=1), n_jobs="two").fit(X)
