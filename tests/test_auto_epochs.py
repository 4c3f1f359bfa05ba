"""n_iter="auto": as many minibatch updates for a small corpus as for CMU 35."""

import math

import numpy as np
import pytest

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, make_oscillations
from sklearn_crbm.models._one_layer import AUTO_EPOCHS, AUTO_UPDATES


def _trainable(sequence_ids, order=3):
    lengths = np.unique(sequence_ids, return_counts=True)[1]
    return int(np.sum(np.maximum(lengths - order, 0)))


@pytest.mark.parametrize("subset", ["all", "train"])
def test_cmu35_trains_the_1000_epochs_it_always_did(data_home, subset):
    cmu = load_cmu35(data_home, subset=subset)
    frames = _trainable(cmu.sequence_ids)
    assert math.ceil(frames / 100) >= 26  # 26 (train) or 28 (all) minibatches
    assert ConditionalRBM()._n_epochs(frames) == 1000


@pytest.mark.parametrize(
    "n_frames, epochs",
    [(2500, 1000), (2400, 1042), (876, 2778), (40, 25000)],
)
def test_small_corpora_get_25000_updates(n_frames, epochs):
    assert ConditionalRBM()._n_epochs(n_frames) == epochs
    batches = math.ceil(n_frames / 100)
    assert epochs * batches >= AUTO_UPDATES or epochs == AUTO_EPOCHS


def test_fit_and_early_stopping_train_the_auto_epochs():
    X, ids = make_oscillations(n_sequences=2, n_frames=40, random_state=0)
    model = ConditionalRBM(4, batch_size=1000, random_state=0)
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr("sklearn_crbm.models._one_layer.AUTO_UPDATES", 1200)
        model.fit(X, sequence_ids=ids)
        early = ConditionalRBM(
            4,
            batch_size=1000,
            early_stopping=True,
            validation_interval=600,
            random_state=0,
        ).fit(np.vstack([X, X]), sequence_ids=np.r_[ids, ids + 2])
    assert model.n_iter_ == 1200  # one minibatch an epoch
    assert early.n_iter_ == 1200


def test_an_explicit_n_iter_is_kept():
    X, ids = make_oscillations(n_sequences=2, n_frames=40, random_state=0)
    model = ConditionalRBM(4, n_iter=7, random_state=0).fit(X, sequence_ids=ids)
    assert model.n_iter_ == 7
