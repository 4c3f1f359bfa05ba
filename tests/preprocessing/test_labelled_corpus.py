"""The default preprocessing on the labelled Bandai walks: an exact round trip.

Their skeleton has a static ``joint_Root`` above the moving ``Hips`` and
position channels on every joint (30 frames per second); the root encoder
must take ``Hips`` as the body's root and every take must come back exactly,
up to the documented start pose (heading 0, ground position (0, 0)).
"""

import numpy as np
import pytest
import sklearn

from sklearn_crbm.datasets import load_bandai_walks
from sklearn_crbm.preprocessing import make_motion_preprocessor

from .test_real_files import round_trip_errors


@pytest.fixture(scope="module")
def walks(data_home):
    return load_bandai_walks(data_home)


def test_every_take_round_trips_exactly(walks):
    for k, name in enumerate(walks.sequence_names):
        take = walks.data[walks.sequence_ids == k]
        rotation_error, position_error = round_trip_errors(walks.skeleton, take)
        assert rotation_error < 1e-9 and position_error < 1e-9, name


def test_the_corpus_round_trips_through_one_preprocessor(walks):
    ids = walks.sequence_ids
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(walks.skeleton)
        Z = pre.fit_transform(walks.data, sequence_ids=ids)
        back = pre.inverse_transform(Z, sequence_ids=ids)
        again = pre.transform(back, sequence_ids=ids)
    assert pre.named_steps["root"].root_ == "Hips"
    # 6 root channels and 3 per moving joint: positions and joint_Root are constant
    assert Z.shape == (11337, 66)
    np.testing.assert_allclose(again, Z, rtol=0, atol=1e-9)
    # every joint's own rotation, and the static joint_Root, come back as read
    local, local_back = (walks.skeleton.local_rotations(x) for x in (walks.data, back))
    hips = walks.skeleton.bone_names.index("Hips")
    joints = np.delete(np.arange(len(walks.skeleton.bones)), hips)
    np.testing.assert_allclose(local_back[:, joints], local[:, joints], atol=1e-12)
