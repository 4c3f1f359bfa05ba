"""The fill-in protocol: the erased part, the paper's body parts and cases."""

import numpy as np
import pytest
import sklearn
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import (
    Bone,
    Skeleton,
    load_cmu35,
    make_walker,
    read_bvh_folder,
)
from sklearn_crbm.metrics import fillin_angle_rmse, fillin_error
from sklearn_crbm.model_selection import (
    erasure_mask,
    make_fillin_cases,
    make_imputation_scorer,
    paper_body_parts,
)
from sklearn_crbm.preprocessing import make_motion_preprocessor


@pytest.mark.parametrize("n_frames, first", [(125, 63), (124, 62), (1, 1), (2, 1)])
def test_half_way_erases_the_last_half_rounded_down(n_frames, first):
    """An odd-length trial loses its last n // 2 frames, as in the paper."""
    X = np.zeros((n_frames, 2))
    if n_frames == 1:
        with pytest.raises(ValueError, match="erases nothing"):
            erasure_mask(X, columns=[0])
        return
    mask = erasure_mask(X, columns=[0])
    assert_array_equal(np.flatnonzero(mask[:, 0]), np.arange(first, n_frames))
    assert mask[:, 0].sum() == n_frames // 2 and not mask[:, 1].any()


def test_scorer_erases_what_erasure_mask_erases_on_an_odd_length_trial():
    X = np.zeros((125 + 44, 3))
    ids = np.repeat([0, 1], [125, 44])
    scorer = make_imputation_scorer(columns=[1], start=0.5)
    mask = scorer.missing_mask(X, sequence_ids=ids)
    assert_array_equal(mask, erasure_mask(X, columns=[1], sequence_ids=ids))
    assert_array_equal(np.flatnonzero(mask[:125, 1]), np.arange(63, 125))


def test_fractions_are_relative_positions_exactly():
    X = np.zeros((10, 1))
    # 0.3 of 10 frames is frame 3, though 0.3 * 10 > 3 in floating point
    mask = erasure_mask(X, columns=[0], start=0.3, stop=0.7)
    assert_array_equal(np.flatnonzero(mask), [3, 4, 5, 6])
    assert_array_equal(
        np.flatnonzero(erasure_mask(X, columns=[0], start=8, stop=30)), [8, 9]
    )


def test_bones_strict_or_skipped():
    X = np.zeros((4, 3))
    names = ["root_tx", "lfemur_ex", "ltibia_ex"]
    with pytest.raises(ValueError, match="No column belongs to bone 'lfoot'.*strict"):
        erasure_mask(X, bones=["lfemur", "lfoot"], feature_names=names)
    mask = erasure_mask(X, bones=["lfemur", "lfoot"], feature_names=names, strict=False)
    assert_array_equal(mask.any(axis=0), [False, True, False])
    with pytest.raises(ValueError, match="needs feature names"):
        erasure_mask(X, bones=["lfemur"])


def test_a_bvh_skeletons_descendants_need_no_strict_false(data_home):
    """The end sites of a BVH skeleton have no channels, and need none."""
    folder = data_home / "bandai_contents"
    runs = read_bvh_folder(folder, pattern="dataset-2_run_normal_00[12].bvh")
    left_leg = runs.skeleton.descendants("UpperLeg_L")
    assert left_leg[-1] == "Toes_L_end"
    names = runs.feature_names
    mask = erasure_mask(runs.data, bones=left_leg, feature_names=names)
    erased = {name.rsplit("_", 1)[0] for name in names[mask.any(axis=0)]}
    assert erased == set(left_leg[:-1])
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(runs.skeleton)
        Z = pre.fit_transform(runs.data, sequence_ids=runs.sequence_ids)
    mask = erasure_mask(Z, bones=left_leg, feature_names=pre.get_feature_names_out())
    assert mask.any(axis=0).sum() == 12  # four joints, three angles each
    # an end site alone, without its joint, is still a bone without columns
    with pytest.raises(ValueError, match="'Toes_L_end'.*strict=False"):
        erasure_mask(runs.data, bones=["Toes_L_end"], feature_names=names)


def test_paper_body_parts_on_cmu_and_a_clear_error_elsewhere(data_home):
    skeleton = load_cmu35(data_home, subset="test").skeleton
    parts = paper_body_parts(skeleton)
    assert parts["left leg"] == ["lfemur", "ltibia", "lfoot", "ltoes"]
    assert parts["upper body"][0] == "lowerback" and "rthumb" in parts["upper body"]
    channels = ("tx", "ty", "tz", "rx", "ry", "rz")
    root = Bone("Hips", None, np.zeros(3), 0.0, channels, "xyz")
    thigh = Bone("LeftUpLeg", "Hips", np.array([0.0, -1.0, 0.0]), 1.0, ("rx",), "x")
    spine = Bone("Spine", "Hips", np.array([0.0, 1.0, 0.0]), 1.0, ("rx",), "x")
    other = Skeleton([root, thigh, spine], name="mixamo")
    with pytest.raises(ValueError, match=r"'lfemur' \(left leg\), 'lowerback'"):
        paper_body_parts(other)
    named = paper_body_parts(other, left_leg="LeftUpLeg", upper_body="Spine")
    assert named == {"left leg": ["LeftUpLeg"], "upper body": ["Spine"]}


def test_paper_cases_on_cmu_35(data_home):
    """The four cases of §4.4: the last 62 of walk 35_29's 125 frames, etc."""
    train = load_cmu35(data_home, subset="train")
    test = load_cmu35(data_home, subset="test")
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(train.skeleton)
        pre.fit(train.data, sequence_ids=train.sequence_ids)
    cases = make_fillin_cases(test, pre)
    assert list(cases) == [
        ("walk", "left leg"),
        ("walk", "upper body"),
        ("jog", "left leg"),
        ("jog", "upper body"),
    ]
    names = pre.get_feature_names_out()
    for (motion, part), case in cases.items():
        n_frames = {"walk": 125, "jog": 44}[motion]
        assert case.X.shape == (n_frames, 62) and case.raw.shape == (n_frames, 62)
        erased = np.flatnonzero(case.missing_mask.any(axis=1))
        assert_array_equal(erased, np.arange(n_frames - n_frames // 2, n_frames))
        assert case.first_missing == erased[0]
        scorer = make_imputation_scorer(
            bones=case.bones, feature_names=names, start=0.5
        )
        if part == "left leg":  # every leg bone keeps a channel
            assert_array_equal(case.missing_mask, scorer.missing_mask(case.X))
        assert_array_equal(np.isnan(case.X_missing), case.missing_mask)
        raw_names = np.asarray(test.feature_names)[case.raw_missing_mask.any(axis=0)]
        assert {n.rsplit("_", 1)[0] for n in raw_names} <= set(case.bones)
    case = cases["walk", "left leg"]
    filled = np.where(case.missing_mask, 0.0, case.X)
    assert case.errors(filled) == (
        fillin_error(case.X, filled, missing_mask=case.missing_mask),
        fillin_angle_rmse(
            case.raw,
            pre.inverse_transform(filled),
            missing_mask=case.raw_missing_mask,
        ),
    )


def test_cases_name_an_unknown_trial():
    walker = make_walker(n_sequences=1, n_frames=20, random_state=0)
    pre = make_motion_preprocessor(walker.skeleton).fit(walker.data)
    with pytest.raises(ValueError, match="No sequence is named '35_29'"):
        make_fillin_cases(walker, pre)
