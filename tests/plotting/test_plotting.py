"""Tests of the plotting functions on small synthetic motion (Agg backend)."""

import builtins

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from numpy.testing import assert_allclose  # noqa: E402

from sklearn_crbm.datasets import make_walker  # noqa: E402
from sklearn_crbm.plotting import (  # noqa: E402
    animate_motion,
    motion_to_html,
    plot_filled_channels,
    plot_hidden_activations,
    plot_motion_strip,
    plot_skeleton,
    plot_style_probabilities,
    save_animation,
)


@pytest.fixture(autouse=True)
def close_figures():
    yield
    plt.close("all")


@pytest.fixture(scope="module")
def walker():
    return make_walker(n_sequences=1, n_frames=40, random_state=0)


def test_plot_skeleton_draws_one_line_per_bone_with_up_axis_vertical(walker):
    skeleton = walker.skeleton
    ax = plot_skeleton(skeleton, walker.data[0])
    (lines,) = ax.collections
    assert isinstance(lines, LineCollection)
    segments = lines.get_segments()
    assert len(segments) == len(skeleton.bones) - 1
    # the vertical coordinate of every joint is its height (y up for the walker)
    positions = skeleton.forward_kinematics(walker.data[:1])[0]
    parents = skeleton.parent_indices
    heights = np.array([seg[1, 1] for seg in segments])
    assert_allclose(heights, positions[1:, 1])
    assert_allclose([seg[0, 1] for seg in segments], positions[parents[1:], 1])
    # the head is above the feet
    names = skeleton.bone_names
    assert positions[names.index("head"), 1] > positions[names.index("lfoot"), 1]
    assert ax.get_aspect() == 1.0


def test_plot_skeleton_3d_and_horizontal(walker):
    ax = plot_skeleton(walker.skeleton, walker.data[0], view="3d")
    assert ax.name == "3d"
    assert ax.get_zlabel() == "y (up)"
    fig, side = plt.subplots()
    plot_skeleton(walker.skeleton, walker.data[0], horizontal=(0, 0, 1), ax=side)
    positions = walker.skeleton.forward_kinematics(walker.data[:1])[0]
    across = np.array([seg[1, 0] for seg in side.collections[0].get_segments()])
    assert_allclose(across, positions[1:, 2])  # z drawn left to right
    with pytest.raises(ValueError, match="view"):
        plot_skeleton(walker.skeleton, walker.data[0], view="top")
    with pytest.raises(ValueError, match="horizontal"):
        plot_skeleton(walker.skeleton, walker.data[0], horizontal=(0, 1, 0))


def test_motion_strip_keeps_long_sequences_readable():
    long_walk = make_walker(n_sequences=1, n_frames=300, random_state=0)
    skeleton, data = long_walk.skeleton, long_walk.data
    # step 6 would be 50 figures: 30 instead, frames 0, 10, ..., 290
    ax = plot_motion_strip(skeleton, data, step=6, spacing=0)
    every_10th = plot_motion_strip(skeleton, data, step=10, max_figures=None, spacing=0)
    assert len(ax.collections) == 30
    for a, b in zip(ax.collections, every_10th.collections, strict=True):
        assert_allclose(np.asarray(a.get_segments()), np.asarray(b.get_segments()))
    ax = plot_motion_strip(skeleton, data, step=6, max_figures=None)
    assert len(ax.collections) == 50
    with pytest.raises(ValueError, match="max_figures"):
        plot_motion_strip(skeleton, data, max_figures=0)
    plt.close("all")


def test_motion_strip_draws_every_step_frames_left_to_right(walker):
    ax = plot_motion_strip(walker.skeleton, walker.data, step=5)
    assert len(ax.collections) == 8
    roots = [
        c.get_segments()[0][0] for c in ax.collections
    ]  # first bone starts at root
    assert np.all(np.diff([r[0] for r in roots]) > 0)
    assert len(ax.get_lines()) == 1  # the ground line
    # spacing=0 puts them where they are: the root moves by the walker's speed
    ax0 = plot_motion_strip(
        walker.skeleton, walker.data, step=5, spacing=0, ground=False
    )
    roots0 = np.array([c.get_segments()[0][0][0] for c in ax0.collections])
    positions = walker.skeleton.forward_kinematics(walker.data[::5])[:, 0]
    travel = np.linalg.norm(positions[-1, [0, 2]] - positions[0, [0, 2]])
    assert roots0[-1] - roots0[0] == pytest.approx(travel, rel=0.05)
    assert len(ax0.get_lines()) == 0
    with pytest.raises(ValueError, match="step"):
        plot_motion_strip(walker.skeleton, walker.data, step=0)
    with pytest.raises(ValueError, match="spacing"):
        plot_motion_strip(walker.skeleton, walker.data, spacing=-1)
    with pytest.raises(ValueError, match="NaN"):
        plot_motion_strip(walker.skeleton, np.full_like(walker.data, np.nan))


def test_animation_has_one_frame_per_data_frame_and_saves(walker, tmp_path):
    data = walker.data[:6]
    animation = animate_motion(walker.skeleton, data, title="walk")
    assert len(list(animation.new_frame_seq())) == 6
    gif = save_animation(animation, tmp_path / "walk.gif", dpi=30)
    assert gif.read_bytes()[:6] in (b"GIF89a", b"GIF87a")
    html_file = save_animation(animation, tmp_path / "walk.html")
    assert "<script" in html_file.read_text()
    with pytest.raises(ValueError, match="gif"):
        save_animation(animation, tmp_path / "walk.avi")
    html = motion_to_html(walker.skeleton, data, follow=False)
    assert "<script" in html and "animation" in html.lower()


def test_hidden_activations_image_and_sequence_boundaries():
    hidden = np.random.default_rng(0).random((30, 6))
    ax = plot_hidden_activations(hidden, sequence_ids=np.repeat([4, 2, 9], 10))
    (image,) = ax.images
    assert image.get_array().shape == (6, 30)
    assert image.get_clim() == (0.0, 1.0)
    boundaries = [line.get_xdata()[0] for line in ax.get_lines()]
    assert_allclose(boundaries, [9.5, 19.5])
    ax_s = plot_hidden_activations(hidden, frame_rate=30.0, colorbar=False)
    assert ax_s.get_xlabel() == "time (s)"
    with pytest.raises(ValueError, match="n_components"):
        plot_hidden_activations(np.zeros(5))


def test_filled_channels_have_true_model_and_nearest_curves():
    t = np.linspace(0, 6, 40)
    true = np.column_stack([np.sin(t), np.cos(t), t])
    axes = plot_filled_channels(
        true,
        true + 0.1,
        true - 0.1,
        features=["b", 0],
        feature_names=["a", "b", "c"],
        missing_from=20,
    )
    assert len(axes) == 2
    assert [ax.get_title() for ax in axes] == ["b", "a"]
    curves = axes[0].get_lines()
    assert [line.get_linestyle() for line in curves[:3]] == ["-", "--", ":"]
    assert_allclose(curves[0].get_ydata(), true[:, 1])
    assert_allclose(curves[1].get_ydata(), true[:, 1] + 0.1)
    assert axes[0].get_legend() is not None
    only_model = plot_filled_channels(true[:, 0], true[:, 0])
    assert len(only_model[0].get_lines()) == 2
    with pytest.raises(ValueError, match="frames"):
        plot_filled_channels(true, true[:10])
    with pytest.raises(ValueError, match="named"):
        plot_filled_channels(true, true, features=["z"], feature_names=["a", "b", "c"])


def test_style_probabilities_one_curve_per_style_over_time():
    rng = np.random.default_rng(0)
    proba = rng.dirichlet(np.ones(3), size=24)
    ax = plot_style_probabilities(proba, classes=["a", "b", "c"], frame_rate=30.0)
    lines = ax.get_lines()
    assert [line.get_label() for line in lines] == ["a", "b", "c"]
    for column, line in enumerate(lines):
        assert_allclose(line.get_xdata(), np.arange(24) / 30.0)
        assert_allclose(line.get_ydata(), proba[:, column])
    assert ax.get_xlabel() == "time (s)" and ax.get_legend() is not None
    unnamed = plot_style_probabilities(proba[:, :2])
    assert [line.get_label() for line in unnamed.get_lines()] == [
        "style 0",
        "style 1",
    ]
    assert unnamed.get_xlabel() == "frame"
    with pytest.raises(ValueError, match="shape \\(n_frames, n_classes\\)"):
        plot_style_probabilities(proba[:, 0])
    with pytest.raises(ValueError, match="in \\[0, 1\\]"):
        plot_style_probabilities(proba * 2)
    with pytest.raises(ValueError, match="the 3 styles"):
        plot_style_probabilities(proba, classes=["a", "b"])


def test_missing_matplotlib_names_the_plot_extra(monkeypatch, walker):
    real_import = builtins.__import__

    def fake_import(name, *args, **kwargs):
        if name.startswith("matplotlib"):
            raise ImportError("No module named 'matplotlib'")
        return real_import(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", fake_import)
    with pytest.raises(ImportError, match=r"sklearn_crbm\[plot\]"):
        plot_skeleton(walker.skeleton, walker.data[0])


def test_facing_view_follows_a_turning_body():
    # a walker that turns by 90 degrees over the sequence
    turning = make_walker(n_sequences=1, n_frames=40, random_state=0)
    data = turning.data.copy()
    names = list(turning.feature_names)
    data[:, names.index("root_ry")] = np.linspace(0.0, 90.0, len(data))
    ax = plot_motion_strip(turning.skeleton, data, step=8, horizontal="facing")
    assert len(ax.collections) == 5
    # each figure seen from its side: its hips nearly overlap in the drawing
    positions = turning.skeleton.forward_kinematics(data[::8])
    bones = turning.skeleton.bone_names
    for figure, collection in enumerate(ax.collections):
        segments = collection.get_segments()
        ends = {bones[i + 1]: seg[1] for i, seg in enumerate(segments)}
        hip_gap = abs(ends["lhipjoint"][0] - ends["rhipjoint"][0])
        true_gap = np.linalg.norm(
            positions[figure, bones.index("lhipjoint")]
            - positions[figure, bones.index("rhipjoint")]
        )
        assert hip_gap < 0.05 * true_gap
    with pytest.raises(ValueError, match="facing"):
        plot_motion_strip(turning.skeleton, data, horizontal="front")


def test_a_static_dummy_root_is_not_drawn(data_home):
    """Bandai Namco files put joint_Root, fixed at the origin, above the moving
    Hips: the figure is the Hips and the bones below it, placed where they walk."""
    from sklearn_crbm.datasets import read_bvh

    path = data_home / "external_dev" / "bandai_walk_normal_train"
    skeleton, data, _, _ = read_bvh(path / "dataset-2_walk_normal_001.bvh")
    assert skeleton.bone_names[:2] == ["joint_Root", "Hips"]
    assert np.ptp(skeleton.forward_kinematics(data)[:, 0]) == 0.0
    ax = plot_skeleton(skeleton, data[0])  # the hips are 5.4 m from the origin
    segments = np.array(ax.collections[0].get_segments())
    assert len(segments) == len(skeleton.bones) - 2  # no joint_Root, no link to it
    # one figure (1.4 m from toes to head joint), no line back to the origin
    assert np.ptp(segments[..., 0]) < 100.0 and 100.0 < np.ptp(segments[..., 1]) < 200.0
    strip = plot_motion_strip(skeleton, data[:120], step=8)
    assert len(strip.collections) >= 15
