"""make_motion_preprocessor on the real data: dimensions, round trips, routing."""

import numpy as np
import pytest
import scipy.io
import sklearn
from sklearn.pipeline import Pipeline

from sklearn_crbm.datasets import load_cmu35, load_mit_walk, make_walker
from sklearn_crbm.preprocessing import (
    ExpMapEncoder,
    RootRelativeEncoder,
    StandardScaler,
    make_motion_preprocessor,
)
from sklearn_crbm.utils._rotations import euler_to_matrix


@pytest.fixture(scope="module")
def cmu(data_home):
    return load_cmu35(data_home)


@pytest.fixture(scope="module")
def mit(data_home):
    return load_mit_walk(data_home)


@pytest.fixture(autouse=True)
def routing():
    with sklearn.config_context(enable_metadata_routing=True):
        yield


def _align(positions, reference, ids, up):
    """Rotate each sequence of ``positions`` about the vertical and shift it so
    that its first root position and heading match ``reference``'s."""
    aligned = np.empty_like(positions)
    ground = [a for a in range(3) if a != up]
    for s in np.unique(ids):
        p, q = positions[ids == s], reference[ids == s]
        # the rotation about `up` that best maps frame 0 (about its root) onto
        # the reference frame 0: a 2-D Procrustes fit on the ground plane
        P = (p[0] - p[0, 0])[:, ground]
        Q = (q[0] - q[0, 0])[:, ground]
        angle = np.arctan2(np.sum(P[:, 0] * Q[:, 1] - P[:, 1] * Q[:, 0]), np.sum(P * Q))
        c, s_ = np.cos(angle), np.sin(angle)
        rotated = p - p[0, 0]
        g0, g1 = rotated[..., ground[0]].copy(), rotated[..., ground[1]].copy()
        rotated[..., ground[0]] = c * g0 - s_ * g1
        rotated[..., ground[1]] = s_ * g0 + c * g1
        rotated += q[0, 0]
        aligned[ids == s] = rotated
    return aligned


def test_cmu_gives_the_papers_62_dimensions(cmu):
    pre = make_motion_preprocessor(cmu.skeleton)
    Z = pre.fit_transform(cmu.data, sequence_ids=cmu.sequence_ids)
    assert Z.shape == (2813, 62)
    names = list(pre.get_feature_names_out())
    assert len(names) == 62 and names[:6] == [
        "root_pitch",
        "root_roll",
        "root_dheading",
        "root_dforward",
        "root_dsideways",
        "root_height",
    ]
    # the dropped channels: unused axes of 1-DOF joints, clavicles, fingers
    for dropped in [
        "ltibia_ey",
        "lclavicle_ex",
        "rclavicle_ez",
        "lfingers_ex",
        "lhipjoint_ex",
    ]:
        assert dropped not in names
    assert {"ltibia_ex", "lwrist_ey", "lfoot_ez", "rthumb_ex"} <= set(names)
    assert np.allclose(Z.mean(axis=0), 0.0, atol=1e-12)
    assert np.allclose(Z.std(axis=0), 1.0)


def test_mit_gives_49_dimensions_equal_to_the_tsbn_file(mit, data_home):
    # the paper's encoding: rotations from the rest pose, Taylor's roll
    pre = make_motion_preprocessor(mit.skeleton, reference="rest", roll="taylor")
    Z = pre.fit_transform(mit.data, sequence_ids=mit.sequence_ids)
    assert Z.shape == (3826, 49)
    tsbn = scipy.io.loadmat(data_home / "mit_tsbn" / "mit_mocap.mat")
    expected = np.vstack(
        [c for c in tsbn["train_data"].flat] + [c for c in tsbn["test_data"].flat]
    )
    n = len(Z)
    # the TSBN file z-scores with MATLAB's std (ddof=1); we use ddof=0
    assert np.abs(Z * np.sqrt((n - 1) / n) - expected).max() < 1e-12


def test_cmu_round_trip_joint_angles_and_forward_kinematics(cmu):
    pre = make_motion_preprocessor(cmu.skeleton)
    ids = cmu.sequence_ids
    Z = pre.fit_transform(cmu.data, sequence_ids=ids)
    back = pre.inverse_transform(Z, sequence_ids=ids)
    assert back.shape == cmu.data.shape
    names = list(cmu.feature_names)
    joints = np.arange(6, 62)
    # every joint angle to 1e-9 degrees (modulo 360); also the constant channels
    diff = (back[:, joints] - cmu.data[:, joints] + 180.0) % 360.0 - 180.0
    assert np.abs(diff).max() < 1e-9
    # the root height is absolute; the ground track starts at (0, 0)
    assert np.abs(back[:, 1] - cmu.data[:, 1]).max() < 1e-9
    starts = np.flatnonzero(np.diff(ids, prepend=-1))
    assert np.all(np.abs(back[starts][:, [0, 2]]) < 1e-12)
    # joint rotations as matrices, e.g. the 2-DOF rhand with its -327 degrees
    hand = [names.index("rhand_rx"), names.index("rhand_rz")]
    R = euler_to_matrix(np.deg2rad(cmu.data[:, hand]), "xz")
    R_back = euler_to_matrix(np.deg2rad(back[:, hand]), "xz")
    assert np.abs(R - R_back).max() < 1e-13
    # forward kinematics agree once each sequence's start pose is aligned
    positions = cmu.skeleton.forward_kinematics(cmu.data)
    positions_back = cmu.skeleton.forward_kinematics(back)
    aligned = _align(positions_back, positions, ids, up=1)
    assert np.abs(aligned - positions).max() < 1e-9


def test_mit_round_trip_and_forward_kinematics(mit):
    pre = make_motion_preprocessor(mit.skeleton)
    ids = mit.sequence_ids
    back = pre.inverse_transform(
        pre.fit_transform(mit.data, sequence_ids=ids), sequence_ids=ids
    )
    assert np.abs(back[:, 6:] - mit.data[:, 6:]).max() < 1e-12
    positions = mit.skeleton.forward_kinematics(mit.data)
    aligned = _align(mit.skeleton.forward_kinematics(back), positions, ids, up=2)
    assert np.abs(aligned - positions).max() < 1e-8  # mm over 3128 frames


def test_sequence_ids_are_routed_to_every_method():
    walker = make_walker(n_sequences=3, n_frames=20, random_state=0)
    X, ids = walker.data, walker.sequence_ids
    pre = make_motion_preprocessor(walker.skeleton)
    Z = pre.fit_transform(X, sequence_ids=ids)
    assert np.allclose(pre.fit(X, sequence_ids=ids).transform(X, sequence_ids=ids), Z)
    # the deltas of each sequence's last frame repeat the frame before: only
    # true when the ids reached the RootRelativeEncoder
    last = np.flatnonzero(np.diff(ids, append=-1))
    assert np.array_equal(Z[last, 2:5], Z[last - 1, 2:5])
    assert not np.allclose(pre.transform(X)[last[:-1], 2:5], Z[last[:-1], 2:5])
    # inverse_transform restarts the ground track at every sequence
    back = pre.inverse_transform(Z, sequence_ids=ids)
    starts = np.flatnonzero(np.diff(ids, prepend=-1))
    assert np.allclose(back[starts][:, [0, 2]], 0.0)
    assert not np.allclose(pre.inverse_transform(Z)[starts[1:]][:, [0, 2]], 0.0)


def test_steps_and_requests():
    walker = make_walker(n_sequences=1, n_frames=10, random_state=0)
    pre = make_motion_preprocessor(walker.skeleton, continuous=True)
    assert isinstance(pre, Pipeline)
    expmap, root, scale = (step for _, step in pre.steps)
    assert isinstance(expmap, ExpMapEncoder) and expmap.continuous
    assert isinstance(root, RootRelativeEncoder) and isinstance(scale, StandardScaler)
    routing = pre.get_metadata_routing()
    for method in ["fit", "fit_transform", "transform", "inverse_transform"]:
        assert "sequence_ids" in routing.consumes(method, ["sequence_ids"])


def test_select_a_limb_by_name(cmu):
    pre = make_motion_preprocessor(cmu.skeleton).fit(
        cmu.data, sequence_ids=cmu.sequence_ids
    )
    names = pre.get_feature_names_out()
    left_leg = [
        i
        for i, n in enumerate(names)
        if n.split("_")[0] in {"lfemur", "ltibia", "lfoot", "ltoes"}
    ]
    assert [names[i] for i in left_leg] == [
        "lfemur_ex", "lfemur_ey", "lfemur_ez", "ltibia_ex",
        "lfoot_ex", "lfoot_ey", "lfoot_ez", "ltoes_ex",
    ]  # fmt: skip


def test_works_without_metadata_routing(cmu):
    with sklearn.config_context(enable_metadata_routing=False):
        pre = make_motion_preprocessor(cmu.skeleton)
        Z = pre.fit_transform(cmu.data)  # one sequence
        assert Z.shape == (2813, 62)
        assert pre.inverse_transform(Z).shape == cmu.data.shape


def test_sequence_ids_without_routing_says_how_to_turn_it_on():
    walker = make_walker(n_sequences=2, n_frames=20, random_state=0)
    pre = make_motion_preprocessor(walker.skeleton)
    with sklearn.config_context(enable_metadata_routing=False):
        for method in (pre.fit, pre.fit_transform):
            with pytest.raises(
                ValueError, match=r"sklearn\.set_config\(enable_metadata_routing=True\)"
            ):
                method(walker.data, sequence_ids=walker.sequence_ids)
        # without sequence_ids: one sequence, no routing needed
        assert pre.fit_transform(walker.data).shape == walker.data.shape
    with sklearn.config_context(enable_metadata_routing=True):
        Z = pre.fit_transform(walker.data, sequence_ids=walker.sequence_ids)
    assert Z.shape == walker.data.shape
