"""Held-out takes of the same motion stay in the training range after preprocessing.

Bandai Namco dataset-2, wave-left-hand, normal style: a toe barely moves in
takes 001-008, and without the scaler's floor it comes out of takes 009-012
tens of standard deviations away.
"""

import numpy as np
import pytest
import sklearn

from sklearn_crbm.datasets import load_cmu35, load_mit_walk, read_bvh_folder
from sklearn_crbm.preprocessing import make_motion_preprocessor


@pytest.fixture(scope="module")
def waves(data_home):
    folder = data_home / "bandai_contents"
    return read_bvh_folder(folder, pattern="dataset-2_wave-left-hand_normal_*.bvh")


def _held_out_z(waves, **params):
    takes = np.array([int(name[-3:]) for name in waves.sequence_names])
    train = takes[waves.sequence_ids] <= 8
    ids = waves.sequence_ids
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(waves.skeleton, **params)
        pre.fit(waves.data[train], sequence_ids=ids[train])
        Z = pre.transform(waves.data[~train], sequence_ids=ids[~train])
    return dict(zip(pre.get_feature_names_out(), np.abs(Z).max(axis=0), strict=True))


def test_a_still_toe_stays_within_the_range_of_the_moving_channels(waves):
    unfloored = _held_out_z(waves, scale_floor=0.0)
    toes = ["Toes_L_ex", "Toes_L_ey", "Toes_L_ez"]
    assert min(unfloored[name] for name in toes) > 25
    floored = _held_out_z(waves)
    assert max(floored[name] for name in toes) < 6
    # what remains is how far the moving channels of one take go (a hand, 12.9)
    assert max(floored.values()) < 15


def test_the_floor_leaves_cmu35_and_mit_as_they_were(data_home):
    """No channel of CMU subject 35 or the MIT walks moves less than 1% of the
    typical channel: their preprocessing, and every model on it, is unchanged."""
    for data in (load_cmu35(data_home), load_mit_walk(data_home)):
        for encoding in ({}, dict(reference="rest", roll="taylor")):
            with sklearn.config_context(enable_metadata_routing=True):
                Z = [
                    make_motion_preprocessor(
                        data.skeleton, scale_floor=floor, **encoding
                    ).fit_transform(data.data, sequence_ids=data.sequence_ids)
                    for floor in (0.0, 0.01)
                ]
            assert np.array_equal(Z[0], Z[1])
