"""Tests of the plotting functions on small synthetic motion (Agg backend)."""

import builtins

import matplotlib
import numpy as np
import pytest

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.collections import LineCollection  # noqa: E402
from numpy.testing import assert_allclose  # noqa: E402
from PIL import Image  # noqa: E402

from sklearn_crbm.datasets import make_walker  # noqa: E402
from sklearn_crbm.plotting import (  # noqa: E402
    animate_motion,
    animate_motions,
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
        plot_skeleton(walker.skeleton, walker.data[0], view="bottom")
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


# -- views: the camera chosen from the motion --------------------------------


def _bandai_take(data_home, name):
    from sklearn_crbm.datasets import read_bvh

    path = data_home / "bandai_contents" / f"dataset-2_{name}_normal_001.bvh"
    skeleton, data, _, _ = read_bvh(path)
    return skeleton, data


def _joint_track(ax, skeleton, bone):
    """Where ``bone`` is drawn in each figure of a strip (its body lacks the
    static joint_Root: segment ``i`` ends at bone ``i + 2``)."""
    index = skeleton.bone_names.index(bone) - 2
    return np.array([c.get_segments()[index][1] for c in ax.collections])


def test_auto_view_faces_the_plane_the_motion_moves_in(data_home, walker):
    """A lateral hand wave is seen from the front, a walk from the side, a
    turn from above; ``view=`` names the camera."""
    skeleton, wave = _bandai_take(data_home, "wave-left-hand")
    every = dict(step=1, max_figures=None, spacing=0, ground=False)
    drawn = {
        view: plot_motion_strip(skeleton, wave, view=view, **every)
        for view in ("auto", "front", "side")
    }
    tracks = {view: _joint_track(ax, skeleton, "Hand_L") for view, ax in drawn.items()}
    assert_allclose(tracks["auto"], tracks["front"])
    # seen from the front, the waving hand sweeps across twice as far ...
    assert np.ptp(tracks["front"][:, 0]) > 1.8 * np.ptp(tracks["side"][:, 0])
    # ... and the left hand is on the right, as seen facing the body
    right = _joint_track(drawn["front"], skeleton, "Hand_R")
    assert np.all(tracks["front"][:, 0] > right[:, 0])
    for view, take in (("side", walker.data), ("top", None)):
        if take is None:
            skeleton, take = _bandai_take(data_home, "walk-turn-left")
        else:
            skeleton = walker.skeleton
        auto = plot_motion_strip(skeleton, take, step=8, spacing=0)
        chosen = plot_motion_strip(skeleton, take, step=8, spacing=0, view=view)
        for a, b in zip(auto.collections, chosen.collections, strict=True):
            assert_allclose(a.get_segments(), b.get_segments())
    assert len(chosen.get_lines()) == 0  # no ground line seen from above
    with pytest.raises(ValueError, match="view must be one of 'auto', 'front'"):
        plot_motion_strip(walker.skeleton, walker.data, view="back")


def test_top_view_draws_the_ground_plane(walker):
    data = walker.data[:1]
    ax = plot_skeleton(walker.skeleton, data, view="top", horizontal=(1, 0, 0))
    positions = walker.skeleton.forward_kinematics(data)[0]
    ends = np.array([seg[1] for seg in ax.collections[0].get_segments()])
    # forward +x with y up: x left to right, the body's left (u x f = y x x
    # = -z) bottom to top
    assert_allclose(ends[:, 0], positions[1:, 0])
    assert_allclose(ends[:, 1], -positions[1:, 2])


def test_horizontal_direction_keeps_the_side_view(walker):
    ax = plot_motion_strip(walker.skeleton, walker.data, horizontal=(0, 0, 1))
    side = plot_motion_strip(
        walker.skeleton, walker.data, horizontal=(0, 0, 1), view="side"
    )
    for a, b in zip(ax.collections, side.collections, strict=True):
        assert_allclose(a.get_segments(), b.get_segments())


def test_animate_motions_sees_every_panel_from_one_side(data_home, tmp_path):
    skeleton, wave = _bandai_take(data_home, "wave-left-hand")
    still = np.repeat(wave[:1], 40, axis=0)  # a figure that came to rest
    animation = animate_motions(skeleton, [wave[:40], still], view="auto")
    panels = animation._fig.axes[:2]
    save_animation(animation, tmp_path / "two.gif", dpi=10)
    animation._func(0)
    front = plot_skeleton(skeleton, wave[0], view="front")
    for panel in panels:
        assert_allclose(
            panel.collections[0].get_segments(), front.collections[0].get_segments()
        )


def test_animate_motions_fills_a_grid_row_by_row(walker, tmp_path):
    """Contents down, styles across: five sequences in rows of two, the
    probabilities below them all."""
    sequences = [walker.data[:6] + k for k in range(5)]
    titles = [f"panel {k}" for k in range(5)]
    proba = np.full((6, 2), 0.5)
    animation = animate_motions(
        walker.skeleton, sequences, titles=titles, ncols=2, proba=proba
    )
    *panels, below = animation._fig.axes
    assert [ax.get_title() for ax in panels] == titles
    spans = [ax.get_subplotspec() for ax in panels]
    assert [(s.rowspan.start, s.colspan.start) for s in spans] == [
        (0, 0), (0, 1), (1, 0), (1, 1), (2, 0)
    ]  # fmt: skip
    assert below.get_subplotspec().rowspan.start == 3
    assert below.get_subplotspec().colspan == range(0, 2)
    save_animation(animation, tmp_path / "grid.gif", dpi=10)
    assert Image.open(tmp_path / "grid.gif").n_frames == 6
    one_row = animate_motions(walker.skeleton, sequences[:3])
    assert [ax.get_subplotspec().rowspan.start for ax in one_row._fig.axes] == [0] * 3
    save_animation(one_row, tmp_path / "row.gif", dpi=10)
    with pytest.raises(ValueError, match="ncols must be a positive integer"):
        animate_motions(walker.skeleton, sequences, ncols=0)


@pytest.mark.parametrize("frame_rate", [15.0, 30.0, 24.0, 12.5])
def test_gif_lasts_its_frames_over_the_frame_rate(walker, tmp_path, frame_rate):
    """GIF delays are whole hundredths: they alternate so that every stretch
    of frames lasts its time (at 15 frames/s: 70, 70, 60 ms in some order)."""
    n = 12
    animation = animate_motion(walker.skeleton, walker.data[:n], title="walk")
    path = save_animation(
        animation, tmp_path / "walk.gif", frame_rate=frame_rate, dpi=20
    )
    gif = Image.open(path)
    delays = []
    for k in range(gif.n_frames):
        gif.seek(k)
        delays.append(gif.info["duration"])
    assert len(delays) == n
    elapsed = np.cumsum(delays) / 1000.0
    ideal = np.arange(1, n + 1) / frame_rate
    assert np.abs(elapsed - ideal).max() <= 0.005 + 1e-9
    if frame_rate == 15.0:
        assert sorted(delays[:3]) == [60, 70, 70]
