"""The command line: the demo, fetch, fit and sample, help and error messages."""

import argparse
import io
import re
import sys
import warnings
from contextlib import redirect_stdout
from pathlib import Path

import joblib
import numpy as np
import pytest
import sklearn
from numpy.testing import assert_allclose, assert_array_equal
from PIL import Image

from sklearn_crbm.cli import _main as _cli
from sklearn_crbm.cli import _style_demo, main
from sklearn_crbm.datasets import (
    bone_columns,
    load_bandai_dataset2,
    load_bandai_walks,
    load_cmu35,
    make_walker,
    read_amc,
    read_bvh,
    write_bvh,
)
from sklearn_crbm.metrics import StyleJudge
from sklearn_crbm.preprocessing import make_motion_preprocessor

TINY = ["--n-components", "12", "--n-iter", "3"]


def demo_args(data_home, output, *extra):
    return [
        "demo",
        "--data-home",
        str(data_home),
        "--output",
        str(output),
        *TINY,
        "--n-repeats",
        "1",
        "--n-frames",
        "40",
        *extra,
    ]


def test_demo_prints_the_tables_and_writes_figures(data_home, tmp_path, capsys):
    status = main(demo_args(data_home, tmp_path, "--n-particles", "2"))
    out = capsys.readouterr().out
    assert status == 0
    assert "preprocessed to 62 dimensions" in out
    for row in ("walk 35_29", "jog 35_18", "left leg", "upper body", "8.78 / 11.68"):
        assert row in out
    # every baseline beside the CRBM, in both tables
    header = "CRBM NN KNN(5) KNN(10) AR ratio"
    assert " ".join(out.split()).count(" ".join(header.split())) == 2
    # what the columns mean, and their units
    for explained in ("KNNImputer", "AutoregressiveImputer", "in degrees"):
        assert explained in out
    assert "length units" in out and out.count("keeps its style") <= 6
    # every table says which encoding its numbers are in
    assert out.count("the paper's encoding") == 4
    assert f"go to {tmp_path}" in out and f"wrote to {tmp_path}" in out
    for name in (
        "generated_walk.png",
        "generated_jog.png",
        "fillin_left_hip.png",
        "hidden_activations.png",
    ):
        assert (tmp_path / name).stat().st_size > 1000
    # real beside generated, moving: every frame of the 40 generated, halved
    gif = Image.open(tmp_path / "real_and_generated.gif")
    assert gif.n_frames == 20
    skeleton = load_cmu35(data_home, subset="test").skeleton
    data, names = read_amc(tmp_path / "generated_walk.amc", skeleton)
    assert data.shape == (40, 62) and np.isfinite(data).all()
    _, bvh, _, rate = read_bvh(tmp_path / "generated_walk.bvh")
    assert bvh.shape[0] == 40 and rate == 30.0


def test_getting_started_shows_a_small_gif_of_the_demo():
    doc = Path(__file__).parents[1] / "doc"
    page = (doc / "getting_started.rst").read_text(encoding="utf-8")
    (name,) = re.findall(r"\.\. figure:: (_static/\S+\.gif)", page)
    gif = Image.open(doc / name)
    assert gif.n_frames >= 60  # it moves: at least 4 s at 15 frames/s
    assert (doc / name).stat().st_size < 400_000


def test_demo_table_rows_are_compare_imputers_numbers(data_home, tmp_path, capsys):
    main(demo_args(data_home, tmp_path, "--no-figures"))
    lines = capsys.readouterr().out.splitlines()
    rows = [line for line in lines if line.startswith(("walk 35_29", "jog 35_18"))]
    assert len(rows) == 8  # 4 cases, 2 tables
    for row in rows:
        numbers = [float(v) for v in row.split()[4:10]]
        crbm, *baselines, ratio = numbers
        assert ratio == pytest.approx(crbm / min(baselines), abs=0.011)


def test_demo_speeds_are_in_length_units_per_frame(data_home, tmp_path, capsys):
    main(demo_args(data_home, tmp_path, "--no-figures"))
    out = capsys.readouterr().out
    real = {
        line.split()[1]: float(line.split()[2])
        for line in out.splitlines()
        if line.startswith("real ")
    }
    # the mean forward displacement per frame of the training trials, by hand
    train = load_cmu35(data_home, subset="train")
    styles = np.asarray(train.motion)
    per_trial = {}
    for k in np.unique(train.sequence_ids):
        root = train.data[train.sequence_ids == k][:, :3]  # root_tx, ty, tz
        step = np.diff(root[:, [0, 2]], axis=0)  # along the ground plane
        per_trial.setdefault(styles[k], []).append(np.linalg.norm(step, axis=1).mean())
    for style in ("walk", "jog"):
        assert real[style] == pytest.approx(np.mean(per_trial[style]), rel=0.05)


@pytest.mark.parametrize("how", ["--no-figures", "no matplotlib"])
def test_demo_writes_the_motion_without_figures(
    data_home, tmp_path, capsys, monkeypatch, how
):
    extra = [how] if how.startswith("--") else []
    if how == "no matplotlib":
        monkeypatch.setitem(sys.modules, "matplotlib", None)  # import fails
    assert main(demo_args(data_home, tmp_path, *extra)) == 0
    out = capsys.readouterr().out
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "generated_jog.amc",
        "generated_jog.bvh",
        "generated_walk.amc",
        "generated_walk.bvh",
    ]
    if how == "no matplotlib":
        assert "matplotlib is not installed" in out


@pytest.mark.parametrize("command", ["demo", "styles", "sample"])
def test_output_is_a_folder_of_the_current_folder_by_default(command):
    """Not one folder of the temporary directory shared by every user and
    run of the machine (issue 50.3)."""
    argv = [command] + ["m.joblib"] * (command == "sample")
    output = _cli._parser().parse_args(argv).output
    assert output == Path("sklearn_crbm_output") / command
    assert not output.is_absolute()


def test_sample_writes_into_its_output_folder_and_says_where(
    data_home, tmp_path, capsys, monkeypatch
):
    model = tmp_path / "model.joblib"
    main(["fit", "--data-home", str(data_home), "--output", str(model), *TINY])
    monkeypatch.chdir(tmp_path)
    assert main(["sample", str(model), "--n-frames", "12"]) == 0
    out = capsys.readouterr().out
    folder = tmp_path / "sklearn_crbm_output" / "sample"
    assert f"generated motion goes to {folder}" in out
    assert sorted(p.name for p in folder.iterdir()) == [
        "generated_0.amc",
        "generated_0.bvh",
    ]


def test_fit_then_sample_needs_no_data(data_home, tmp_path, capsys, monkeypatch):
    model = tmp_path / "model.joblib"
    assert (
        main(["fit", "--data-home", str(data_home), "--output", str(model), *TINY]) == 0
    )
    skeleton = load_cmu35(data_home, subset="test").skeleton
    # sample reads no data: point every data location nowhere
    monkeypatch.setenv("SKLEARN_CRBM_DATA", str(tmp_path / "nowhere"))
    monkeypatch.setenv("HOME", str(tmp_path / "nohome"))
    for style in ("jog", None):
        prefix = tmp_path / str(style)
        status = main(
            ["sample", str(model), "--n-frames", "25", "--n-sequences", "2"]
            + ["--output", str(prefix)]
            + (["--style", style] if style else [])
        )
        assert status == 0, capsys.readouterr().err
        for k in (0, 1):
            data, _ = read_amc(prefix / f"generated_{k}.amc", skeleton)
            assert data.shape == (25, 62)
            # the BVH file holds the same motion
            written, bvh, _, rate = read_bvh(prefix / f"generated_{k}.bvh")
            assert rate == 30.0
            ends = skeleton.forward_kinematics(data)
            joints = written.forward_kinematics(bvh)
            gaps = np.linalg.norm(joints[:, None] - ends[:, :, None], axis=-1)
            assert gaps.min(axis=2).max() < 1e-3
    status = main(["sample", str(model), "--style", "skip", "--output", str(prefix)])
    assert status == 1
    assert "no seed frames of style 'skip' (its styles: walk, jog)" in (
        capsys.readouterr().err
    )


def test_sample_seeds_each_style_from_that_style(data_home, tmp_path, capsys):
    model = tmp_path / "model.joblib"
    main(["fit", "--data-home", str(data_home), "--output", str(model), *TINY])
    saved = _cli._load_model(model)
    pipeline = saved.pipeline
    train = load_cmu35(data_home, subset="train")
    with sklearn.config_context(enable_metadata_routing=True):
        Z = pipeline[:-1].transform(train.data, sequence_ids=train.sequence_ids)
    styles = np.asarray(train.motion)[train.sequence_ids]
    assert list(saved.seed_windows) == ["walk", "jog"]
    for style, windows in saved.seed_windows.items():
        assert windows.shape == (_cli.N_STYLE_WINDOWS, pipeline[-1].history_length, 62)
        for window in windows[:5]:  # each window is real frames of that style
            match = np.flatnonzero(np.all(np.isclose(Z, window[0]), axis=1))
            assert len(match) == 1 and styles[match[0]] == style


def _fit_and_sample(folder, tmp_path, capsys):
    """Fit on ``folder``, sample 12 frames; the fit's report and the output."""
    model = tmp_path / "mine.joblib"
    assert main(["fit", str(folder), "--output", str(model), *TINY]) == 0
    report = capsys.readouterr().out
    prefix = tmp_path / "generated"
    argv = ["sample", str(model), "--n-frames", "12", "--output", str(prefix)]
    assert main(argv) == 0
    return report, prefix


def test_fit_reads_a_folder_of_bvh_files(tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    for seed in (0, 1):
        walker = make_walker(n_sequences=1, n_frames=80, random_state=seed)
        write_bvh(folder / f"walk_{seed}.bvh", walker.data, walker.skeleton, 60.0)
    report, prefix = _fit_and_sample(folder, tmp_path, capsys)
    assert "training on 80 frames of 2 sequences at 30 frames/s" in report
    skeleton, data, _, rate = read_bvh(prefix / "generated_0.bvh")
    assert data.shape[0] == 12 and rate == 30.0
    assert not (prefix / "generated_0.amc").exists()  # BVH skeletons: no AMC


def test_fit_reads_a_folder_of_asf_amc_files(data_home, tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    for name in ("35.asf", "35_01.amc"):
        (folder / name).write_bytes((data_home / "cmu_subject35" / name).read_bytes())
    report, prefix = _fit_and_sample(folder, tmp_path, capsys)
    assert "training on 90 frames of 1 sequence at 30 frames/s" in report
    skeleton = load_cmu35(data_home, subset="test").skeleton
    assert read_amc(prefix / "generated_0.amc", skeleton)[0].shape == (12, 62)
    assert (prefix / "generated_0.bvh").exists()


def test_fit_says_what_a_folder_lacks(tmp_path, capsys):
    assert main(["fit", str(tmp_path), *TINY]) == 1
    assert "holds no *.bvh or *.amc file" in capsys.readouterr().err


def test_failed_fetch_leaves_no_empty_data_folder(tmp_path, capsys, monkeypatch):
    def failing_fetch(home):
        (Path(home) / "cmu_subject35").mkdir(parents=True)
        (Path(home) / "cmu_subject35" / "35.asf.part").write_text("partial")
        raise OSError("network unreachable")

    monkeypatch.setattr(_cli, "fetch_cmu35", failing_fetch)
    new = tmp_path / "new_home"
    assert main(["fetch", "--data-home", str(new)]) == 1
    assert "network unreachable" in capsys.readouterr().err
    assert not new.exists()
    existing = tmp_path / "existing_home"
    existing.mkdir()
    (existing / "mine.txt").write_text("kept")
    assert main(["fetch", "--data-home", str(existing)]) == 1
    assert (existing / "mine.txt").read_text() == "kept"


def test_every_command_and_option_has_help_and_shows_its_default():
    parser = _cli._parser()
    (commands,) = [
        a for a in parser._actions if isinstance(a, argparse._SubParsersAction)
    ]
    summaries = {a.dest: a.help for a in commands._choices_actions}
    for name, command in commands.choices.items():
        assert summaries[name] and len(command.description) > 80, name
        text = command.format_help()
        for action in command._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            assert action.help, (name, action.dest)
            if action.option_strings and action.default not in (None, False):
                shown = f"(default: {action.default})"
                assert shown in " ".join(text.split()), (name, action.dest)


def test_hidden_noise_help_describes_the_option():
    parser = _cli._parser()
    (commands,) = [
        a for a in parser._actions if isinstance(a, argparse._SubParsersAction)
    ]
    text = " ".join(commands.choices["sample"].format_help().split())
    assert "standard deviation of Gaussian noise on the hidden biases" in text
    (option,) = [
        a
        for a in commands.choices["sample"]._actions
        if "--hidden-noise" in a.option_strings
    ]
    # what it did on one corpus belongs to the user guide, not the help
    assert "CMU" not in option.help and "measured" not in option.help


def test_missing_data_says_how_to_fetch(tmp_path, capsys):
    status = main(["demo", "--data-home", str(tmp_path / "nowhere"), *TINY])
    err = capsys.readouterr().err
    assert status == 1
    assert "python -m sklearn_crbm fetch --data-home" in err


def test_no_command_prints_help(capsys):
    assert main([]) == 2
    assert "demo" in capsys.readouterr().out


# -- styles: many styles from one FactoredCRBM on the Bandai walks ------------

STYLES = ["active", "elderly", "exhausted", "feminine", "masculine", "normal"]
STYLES += ["youthful"]
STYLES_TINY = ["--n-components", "16", "--n-factors", "8", "--n-style-features"]
STYLES_TINY += ["4", "--n-iter", "2", "--n-frames", "240", "--n-gibbs", "3"]
WRITTEN = STYLES + ["blend_elderly_youthful", "transition_active_elderly"]


def styles_args(data_home, output, *extra):
    return ["styles", "--data-home", str(data_home), "--output", str(output)] + [
        *STYLES_TINY,
        *extra,
    ]


@pytest.fixture(scope="module")
def styles_run(data_home, tmp_path_factory):
    """One tiny run of the styles command: ``(status, stdout, output folder)``."""
    output = tmp_path_factory.mktemp("styles")
    printed = io.StringIO()
    with redirect_stdout(printed):
        status = main(styles_args(data_home, output, "--n-sequences", "1"))
    return status, printed.getvalue(), output


def test_styles_writes_every_style_a_blend_and_a_transition(styles_run, data_home):
    status, out, output = styles_run
    assert status == 0
    expected = sorted(
        [f"{name}{suffix}" for name in WRITTEN for suffix in (".bvh", ".png")]
        + ["styles.gif", "transition_active_elderly.gif"]
    )
    assert sorted(p.name for p in output.iterdir()) == expected
    # the last 180 of 240 frames of every style, every other frame
    assert Image.open(output / "styles.gif").n_frames == 90
    assert Image.open(output / "transition_active_elderly.gif").n_frames == 120
    walks = load_bandai_walks(data_home)
    for name in WRITTEN:
        raw = _read_raw_channels(output / f"{name}.bvh", walks)
        assert raw.shape == (240, walks.data.shape[1]) and np.isfinite(raw).all()
        assert (output / f"{name}.png").stat().st_size > 1000
    assert f"wrote to {output}: active.bvh" in out


def _read_raw_channels(path, walks):
    """A written BVH file in the channels of the Bandai files.

    The file keeps every rotation and the root's position; the other joints'
    position channels, constant in the Bandai files, are its offsets.
    """
    _, data, names, rate = read_bvh(path)
    assert rate == 30.0
    columns = [list(walks.feature_names).index(name) for name in names]
    raw = np.tile(walks.data[0], (len(data), 1))
    assert np.ptp(np.delete(walks.data, columns, axis=1), axis=0).max() == 0
    raw[:, columns] = data
    return raw


def _table_rows(out, styles=STYLES):
    """``{style: row}`` of the printed table, numbers parsed."""
    rows = {}
    for line in out.splitlines():
        words = line.replace("%", "").replace("(", "").replace(")", "").split()
        if len(words) == 6 and words[0] in styles:
            rows[words[0]] = [float(w.replace("-", "nan")) for w in words[1:]]
    return rows


def test_styles_table_is_the_judge_on_the_written_files(styles_run, data_home):
    """Each row, recomputed from the BVH file read back (no pipeline shared)."""
    _, out, output = styles_run
    walks = load_bandai_walks(data_home)
    labels = walks.target_names[walks.target]
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(walks.skeleton)
        Z = pre.fit_transform(walks.data, sequence_ids=walks.sequence_ids)
    moving = _style_demo.moving_joint_channels(pre, Z, walks.sequence_ids)
    judge = StyleJudge(legs=moving).fit(Z, labels, sequence_ids=walks.sequence_ids)
    rows = _table_rows(out)
    assert sorted(rows) == STYLES
    for k, style in enumerate(STYLES):
        generated = pre.transform(_read_raw_channels(output / f"{style}.bvh", walks))
        verdict = judge.verdict(generated, style)
        judged = verdict.starts >= 100  # the windows from frame 100 on
        assert judged.sum() == 6  # starts 105, 120, ..., 180
        share, alive, amplitude, frequency, real = rows[style]
        assert share == round(100 * verdict.correct[judged].mean())
        assert alive == round(100 * verdict.alive[judged].mean())
        assert amplitude == pytest.approx(
            np.median(verdict.amplitude_ratio[judged]), abs=0.006
        )
        real_frequency = judge.reference_frequency_[k] * 30.0
        assert real == pytest.approx(real_frequency, abs=0.006)
        ratio = verdict.frequency_ratio[judged]
        if np.isfinite(ratio).any():
            median = np.median(ratio[np.isfinite(ratio)])
            assert frequency == pytest.approx(median * real_frequency, abs=0.006)
        else:  # legs that do not move
            assert np.isnan(frequency)


def test_styles_transition_is_judged_before_and_after_the_switch(styles_run):
    _, out, _ = styles_run
    (line,) = [x for x in out.splitlines() if x.startswith("transition active")]
    assert "at frame 120: windows before it judged as active: " in line
    assert "windows after it judged as elderly: " in line
    (line,) = [x for x in out.splitlines() if x.startswith("blend elderly + youthful")]
    assert "of the windows judged as one of the two (elderly " in line


def test_style_requests_weights():
    classes = ["a", "b", "c"]
    requests = _style_demo.style_requests(
        classes, 6, blend=("c", "a"), transition=("b", "c")
    )
    assert list(requests) == ["a", "b", "c", "blend_c_a", "transition_b_c"]
    for k, style in enumerate(classes):
        assert_array_equal(requests[style], np.tile(np.eye(3)[k], (6, 1)))
    assert_array_equal(requests["blend_c_a"], np.tile([0.5, 0, 0.5], (6, 1)))
    switch = [[0, 1, 0]] * 3 + [[0, 0, 1]] * 3
    assert_array_equal(requests["transition_b_c"], switch)


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--blend", "feminine", "robotic"], "--blend: the walks have no style "),
        (["--seed-style", "jog"], "--seed-style: the walks have no style 'jog'"),
        (["--transition", "active", "active"], "two different styles"),
        (["--n-frames", "100"], "--n-frames must be at least 120"),
    ],
)
def test_styles_checks_its_options_before_training(
    data_home, tmp_path, capsys, monkeypatch, extra, message
):
    def no_training(*args, **kwargs):
        raise AssertionError("trained before checking the options")

    monkeypatch.setattr(_cli.FactoredCRBM, "fit", no_training)
    assert main(styles_args(data_home, tmp_path / "out", *extra)) == 1
    err = capsys.readouterr().err
    assert message in err
    if "no style" in message:
        assert "their styles are active, elderly, exhausted" in err
    assert not (tmp_path / "out").exists()


def test_styles_without_matplotlib_writes_the_motion(
    data_home, tmp_path, capsys, monkeypatch
):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import fails
    argv = styles_args(data_home, tmp_path, "--n-sequences", "1", "--n-iter", "1")
    assert main(argv) == 0
    assert "no figures: sklearn_crbm.plotting needs matplotlib" in (
        capsys.readouterr().out
    )
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        f"{name}.bvh" for name in WRITTEN
    )


def test_styles_missing_data_says_how_to_fetch(tmp_path, capsys):
    home = tmp_path / "nowhere"
    assert main(["styles", "--data-home", str(home)]) == 1
    err = capsys.readouterr().err
    assert "The Bandai Namco walks are not in" in err
    assert f"python -m sklearn_crbm fetch --dataset bandai --data-home {home}" in err


def test_fetch_downloads_the_data_sets_asked_for(tmp_path, capsys, monkeypatch):
    fetched = []
    for name in (
        "fetch_cmu35",
        "fetch_mit_walk",
        "fetch_bandai_walks",
        "fetch_bandai_dataset2",
    ):
        monkeypatch.setattr(_cli, name, lambda home, name=name: fetched.append(name))
    home = ["--data-home", str(tmp_path)]
    assert main(["fetch", *home]) == 0
    assert fetched == ["fetch_cmu35", "fetch_mit_walk"]
    fetched.clear()
    assert main(["fetch", "--dataset", "bandai", *home]) == 0
    assert fetched == ["fetch_bandai_walks"]
    fetched.clear()
    assert main(["fetch", "--dataset", "bandai", "--dataset", "cmu35", *home]) == 0
    assert fetched == ["fetch_bandai_walks", "fetch_cmu35"]
    fetched.clear()
    assert main(["fetch", "--dataset", "bandai-dataset2", *home]) == 0
    assert fetched == ["fetch_bandai_dataset2"]


# -- errors in the command's terms; a user's labelled folder (issue 38) ------


@pytest.mark.parametrize(
    "argv, message",
    [
        (["fit", "--n-iter", "0"], "argument --n-iter: must be at least 1, got 0"),
        (["sample", "m.joblib", "--n-frames", "0"], "argument --n-frames: must be"),
        (["fit", "--order", "x"], "argument --order: must be a whole number, got 'x'"),
        (["styles", "--n-sequences", "0"], "argument --n-sequences: must be at"),
        (["fit", "--frame-rate", "-1"], "argument --frame-rate: must be positive"),
        (["sample", "m.joblib", "--speed", "fast"], "argument --speed: must be a"),
        (["sample", "m.joblib", "--speed", "1:2:3"], "argument --speed: must be a"),
        (["sample", "m.joblib", "--speed", "nan"], "argument --speed: must be fin"),
        (["sample", "m", "--n-mean-field", "0"], "argument --n-mean-field: must be"),
        (["fit", "--hidden-drift", "-1"], "argument --hidden-drift: must be at le"),
        (["styles", "--hidden-drift", "x"], "argument --hidden-drift: must be a nu"),
    ],
)
def test_bad_counts_are_named_by_their_flags(argv, message, capsys):
    with pytest.raises(SystemExit):
        main(argv)
    err = capsys.readouterr().err
    assert message in err and "parameter of" not in err


def _walker_folder(folder, rate, styles=("slow", "fast"), n_frames=150):
    """Two takes of every style, written with the package's BVH writer."""
    folder.mkdir()
    for k, style in enumerate(styles):
        for take in (1, 2):
            walker = make_walker(n_sequences=1, n_frames=n_frames, random_state=k)
            name = f"walk_{style}_{take:03d}"
            write_bvh(folder / f"{name}.bvh", walker.data, walker.skeleton, rate)
            (folder / f"{name}.json").write_text(f'{{"style": {k}}}')
    (folder / "style_label.txt").write_text("\n".join(styles))
    return folder


def test_order_longer_than_the_takes_names_the_flag(tmp_path, capsys):
    folder = _walker_folder(tmp_path / "mine", 30.0, n_frames=20)
    assert main(["fit", str(folder), *TINY, "--order", "200"]) == 1
    err = capsys.readouterr().err
    assert "--order 200 needs sequences of more than 200 frames" in err
    assert "longest training sequence has 20 frames" in err
    assert "sequence_ids" not in err


def test_fit_trains_at_the_files_own_rate_and_names_frame_rate(tmp_path, capsys):
    folder = _walker_folder(tmp_path / "mine", 24.0, n_frames=30)
    model = str(tmp_path / "m.joblib")
    assert main(["fit", str(folder), *TINY, "--output", model]) == 0
    assert "at 24 frames/s" in capsys.readouterr().out
    assert main(["fit", str(folder), *TINY, "--frame-rate", "30"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("error: --frame-rate 30: Cannot bring 24 frames")
    assert "--frame-rate sets the rate to train at" in err


@pytest.mark.parametrize("labels", ["style", "walk_([a-z]+)_"])
def test_fit_labels_keep_seeds_of_each_label_for_sample(tmp_path, capsys, labels):
    folder = _walker_folder(tmp_path / "mine", 30.0)
    model = tmp_path / "m.joblib"
    argv = ["fit", str(folder), "--labels", labels, *TINY, "--output", str(model)]
    assert main(argv) == 0
    assert "labels fast, slow" in capsys.readouterr().out
    assert list(_cli._load_model(model).seed_windows) == ["fast", "slow"]
    prefix = tmp_path / "fast"
    argv = ["sample", str(model), "--style", "fast", "--n-frames", "12"]
    argv += ["--n-sequences", "2", "--output", str(prefix), "--animate"]
    assert main(argv) == 0
    assert read_bvh(prefix / "generated_1.bvh")[1].shape[0] == 12
    assert Image.open(prefix / "generated.gif").n_frames == 12


def test_styles_runs_on_a_users_labelled_folder(tmp_path, capsys):
    folder = _walker_folder(tmp_path / "mine", 30.0, styles=("slow", "fast", "odd"))
    output = tmp_path / "out"
    argv = ["styles", "--folder", str(folder), "--output", str(output)]
    argv += [*STYLES_TINY[:-4], "--n-frames", "120", "--n-gibbs", "2"]
    argv += ["--order", "2", "--n-sequences", "1"]
    assert main(argv) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert f"the takes in {folder}: 900 frames in 6 takes" in out
    assert "generated from real frames of fast take: " in out
    assert "styles fast, odd, slow" in out
    assert "transition fast -> odd at frame 60" in out  # its first two styles
    bones = read_bvh(folder / "walk_odd_001.bvh")[0].bone_names
    for name in ("fast", "odd", "slow", "blend_fast_odd", "transition_fast_odd"):
        skeleton, data, _, rate = read_bvh(output / f"{name}.bvh")
        assert data.shape[0] == 120 and rate == 30.0 and np.isfinite(data).all()
        assert skeleton.bone_names == bones
        assert (output / f"{name}.png").stat().st_size > 1000
    assert Image.open(output / "styles.gif").n_frames == 60
    assert Image.open(output / "transition_fast_odd.gif").n_frames == 60


def _wave_folder(data_home, folder, styles=("exhausted", "normal"), takes=(1, 2)):
    """Real Bandai left-hand waves of two styles, linked into ``folder`` with
    their labels and label names, as a user's folder of the dataset has them."""
    source = data_home / "bandai_dataset2"
    folder.mkdir()
    for name in ("style_label.txt", "content_label.txt"):
        (folder / name).symlink_to(source / name)
    for style in styles:
        for take in takes:
            for suffix in (".bvh", ".json"):
                name = f"dataset-2_wave-left-hand_{style}_{take:03d}{suffix}"
                (folder / name).symlink_to(source / name)
    return folder


def test_real_waves_are_judged_alive_on_their_own_moving_joints(data_home):
    """The judge of the styles command looks at the waving arm, not the legs:
    the middle windows of real takes (the cycle) are alive, where the
    amplitude and frequency of the hips and knees called most of them dead."""
    corpus = load_bandai_dataset2(
        data_home, contents="wave-left-hand", styles=["exhausted", "normal"]
    )
    ids, styles = corpus.sequence_ids, corpus.target[:, 1]
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(corpus.skeleton)
        Z = pre.fit_transform(corpus.data, sequence_ids=ids)
    moving = _style_demo.moving_joint_channels(pre, Z, ids)
    names = pre.get_feature_names_out()[moving]
    assert len(moving) == 12
    assert all(
        name.split("_")[0] in ("Shoulder", "UpperArm", "LowerArm", "Hand", "Head")
        for name in names
    )
    assert sum(name.endswith(("_L_ex", "_L_ey", "_L_ez")) for name in names[:6]) == 6
    legs = bone_columns(pre.get_feature_names_out(), ["UpperLeg_L", "UpperLeg_R"])
    alive = {}
    for name, channels in (("moving", moving), ("legs", legs)):
        judge = StyleJudge(legs=channels).fit(Z, styles, sequence_ids=ids)
        verdict = judge.verdict(Z, styles, sequence_ids=ids)
        length = np.bincount(ids)[verdict.sequence_ids]
        cycle = (verdict.starts >= length // 4) & (
            verdict.starts + judge.window <= 3 * length // 4
        )
        alive[name] = verdict.alive[cycle].mean()
    assert alive["moving"] >= 0.65 and alive["legs"] <= 0.35, alive


def test_styles_on_real_waves_names_the_content(data_home, tmp_path, capsys):
    folder = _wave_folder(data_home, tmp_path / "waves")
    output = tmp_path / "out"
    argv = ["styles", "--folder", str(folder), "--output", str(output)]
    argv += [*STYLES_TINY, "--order", "2", "--n-sequences", "1", "--no-figures"]
    assert main(argv) == 0, capsys.readouterr().err
    out = capsys.readouterr().out
    assert f"the wave-left-hand takes in {folder}: " in out
    assert "generated from real frames of normal wave-left-hand: " in out
    assert "the 12 joint angles that move most in the real takes, of UpperArm_L" in out
    assert "walk" not in out.replace(str(folder), "").replace(str(output), "")
    assert sorted(_table_rows(out, ["exhausted", "normal"])) == ["exhausted", "normal"]
    (real,) = [line for line in out.splitlines() if line.startswith("real takes")]
    assert "(the judge on the middle halves of the training takes)" in real
    assert main([*argv, "--seed-style", "elderly"]) == 1
    err = capsys.readouterr().err
    assert "--seed-style: the wave-left-hands have no style 'elderly'" in err


# -- speed as context (issue 36) ----------------------------------------------


@pytest.fixture(scope="module")
def speed_model(tmp_path_factory):
    """A model fitted on walks of different speeds with ``--speed-context``."""
    tmp_path = tmp_path_factory.mktemp("speed")
    folder = _walker_folder(tmp_path / "mine", 30.0, n_frames=60)
    model = tmp_path / "m.joblib"
    output = io.StringIO()
    with redirect_stdout(output):
        status = main(
            ["fit", str(folder), "--speed-context", *TINY, "--output", str(model)]
        )
    assert status == 0
    return model, output.getvalue(), folder


def test_fit_speed_context_saves_the_speed_measure(speed_model):
    model, report, folder = speed_model
    saved = _cli._load_model(model)
    assert saved.pipeline[-1].n_context_ == 1
    assert list(saved.speed.get_feature_names_out()) == ["forward_speed"]
    data = _cli._read_motion_folder(folder)
    speeds = saved.speed.transform(data.data, sequence_ids=data.sequence_ids)
    assert_allclose(saved.pipeline[-1].context_mean_, speeds.mean(axis=0))
    low, high = speeds.min(), speeds.max()
    assert f"forward speed as context: {low:.1f} to {high:.1f} length units" in report


def test_sample_speed_is_every_frames_context(speed_model):
    model = speed_model[0]
    saved = _cli._load_model(model)
    args = argparse.Namespace(model=model, speed=(15.0, 21.0), n_frames=7)
    context = _cli._speed_request(saved, args)["context"]
    expected = np.linspace(15.0, 21.0, 7)[:, None]
    assert_array_equal(context, expected)
    parsed = _cli._parser().parse_args(["sample", "m", "--speed", "40"]).speed
    assert parsed == (40.0, 40.0)


def test_sample_generates_at_the_speed_asked(speed_model, tmp_path, capsys):
    model = speed_model[0]
    frames = {}
    for name, speed in [("a", "15"), ("b", "15"), ("c", "21"), ("d", "15:21")]:
        prefix = tmp_path / name
        argv = ["sample", str(model), "--speed", speed, "--n-frames", "12"]
        assert main([*argv, "--output", str(prefix)]) == 0
        assert re.search(r"forward speed -?\d+\.\d\)", capsys.readouterr().out)
        frames[name] = read_bvh(prefix / "generated_0.bvh")[1]
    assert_array_equal(frames["a"], frames["b"])
    assert not np.allclose(frames["a"], frames["c"])
    assert not np.allclose(frames["a"], frames["d"])


def test_sample_speed_needs_a_model_fitted_with_it(speed_model, tmp_path, capsys):
    model = speed_model[0]
    assert main(["sample", str(model), "--output", str(tmp_path / "x")]) == 1
    assert "was fitted with speed as context: give --speed" in capsys.readouterr().err
    folder = _walker_folder(tmp_path / "mine", 30.0, n_frames=30)
    plain = tmp_path / "plain.joblib"
    assert main(["fit", str(folder), *TINY, "--output", str(plain)]) == 0
    argv = ["sample", str(plain), "--speed", "20", "--output", str(tmp_path / "y")]
    assert main(argv) == 1
    err = capsys.readouterr().err
    assert "fitted without speed as context: fit it with --speed-context" in err


# -- what the command line says: warnings, verdicts, seeds (issues 46, 48, 50) --


def test_warnings_are_the_commands_own_lines(capsys, monkeypatch):
    """Not Python's ``<frozen runpy>:88: GenerationWarning: ...`` (issue 48.3)."""
    from sklearn_crbm.exceptions import GenerationWarning

    def warn(args):
        warnings.warn("Sequence 0 of 1 died out.", GenerationWarning, stacklevel=2)
        return 0

    monkeypatch.setitem(_cli._RUNS, "fetch", warn)
    assert main(["fetch"]) == 0
    assert capsys.readouterr().err == "warning: Sequence 0 of 1 died out.\n"


@pytest.fixture(scope="module")
def walker_model(tmp_path_factory):
    """``(model, folder)``: a tiny model fitted on a folder of walker takes."""
    tmp_path = tmp_path_factory.mktemp("walker_model")
    folder = _walker_folder(tmp_path / "mine", 30.0, n_frames=60)
    model = tmp_path / "m.joblib"
    with redirect_stdout(io.StringIO()):
        assert main(["fit", str(folder), *TINY, "--output", str(model)]) == 0
    return model, folder


def test_sample_says_once_that_a_sequence_came_to_rest(walker_model, tmp_path, capsys):
    """One line per file with its verdict, no GenerationWarning repeating it,
    and advice the command line can follow (issues 50.6, 46.4)."""
    saved = joblib.load(walker_model[0])
    crbm = saved["pipeline"][-1]
    for name in ("components_", "autoregressive_", "past_to_hidden_"):
        setattr(crbm, name, np.zeros_like(getattr(crbm, name)))  # frozen
    still = tmp_path / "still.joblib"
    joblib.dump(saved, still)
    argv = ["sample", str(still), "--n-frames", "120", "--n-sequences", "2"]
    assert main([*argv, "--output", str(tmp_path / "out")]) == 0
    out, err = capsys.readouterr()
    assert (out + err).count("came to rest") == 2  # one per sequence
    assert "wrote generated_0.bvh (seeded with training frames; lively 0.00: " in out
    assert err == ""  # no warning saying it again
    assert "--seed-file PATH --seed-frame N" in out
    assert "history=" not in out


def test_fit_saves_the_sampler_parameters_and_sample_overrides_them(
    walker_model, tmp_path, capsys, monkeypatch
):
    """n_mean_field and hidden_drift, which only sample reads, from the
    command line (issue 46): fit saves them in the model, sample passes
    its own to the pipeline's sample for this run only."""
    _, folder = walker_model
    model = tmp_path / "m.joblib"
    argv = ["fit", str(folder), *TINY, "--output", str(model)]
    assert main([*argv, "--n-mean-field", "2", "--hidden-drift", "0.05"]) == 0
    crbm = _cli._load_model(model).pipeline[-1]
    assert (crbm.n_mean_field, crbm.hidden_drift) == (2, 0.05)
    asked = []
    original = _cli.MotionPipeline.sample

    def spy(self, n_frames, **params):
        asked.append(
            {k: params[k] for k in ("n_mean_field", "hidden_drift") if k in params}
        )
        return original(self, n_frames, **params)

    monkeypatch.setattr(_cli.MotionPipeline, "sample", spy)
    take = folder / "walk_fast_001.bvh"  # one seed for both sequences
    argv = ["sample", str(model), "--n-frames", "40", "--n-sequences", "2"]
    argv += ["--seed-file", str(take), "--output", str(tmp_path / "out")]
    drawn = {}
    for name, extra in [
        ("saved", []),
        ("copies", ["--n-mean-field", "30", "--hidden-drift", "0"]),
        ("apart", ["--n-mean-field", "1", "--hidden-drift", "2"]),
    ]:
        assert main([*argv, *extra]) == 0, capsys.readouterr().err
        drawn[name] = [
            read_bvh(tmp_path / "out" / f"generated_{k}.bvh")[1] for k in (0, 1)
        ]
    assert asked == [
        {},
        {"n_mean_field": 30, "hidden_drift": 0.0},
        {"n_mean_field": 1, "hidden_drift": 2.0},
    ]
    gap = {name: np.abs(a - b).mean() for name, (a, b) in drawn.items()}
    assert gap["copies"] < gap["apart"], gap


def test_styles_sampler_options_reach_the_factored_model(monkeypatch, tmp_path):
    models = []
    monkeypatch.setattr(
        _cli, "_run_styles", lambda args, walks, model: models.append(model) or 0
    )
    folder = _walker_folder(tmp_path / "mine", 30.0, n_frames=30)
    argv = ["styles", "--folder", str(folder), "--n-mean-field", "3"]
    assert main([*argv, "--hidden-drift", "0.2"]) == 0
    assert (models[0].n_mean_field, models[0].hidden_drift) == (3, 0.2)


def test_sample_seeds_from_a_take_of_ones_own(walker_model, tmp_path, capsys):
    model, folder = walker_model
    take = folder / "walk_fast_001.bvh"
    argv = ["sample", str(model), "--n-frames", "12", "--output", str(tmp_path)]
    assert main([*argv, "--seed-file", str(take), "--seed-frame", "20"]) == 0
    assert "(seeded with frames 18-20 of walk_fast_001.bvh; lively" in (
        capsys.readouterr().out
    )
    saved = _cli._load_model(model)
    args = _cli._parser().parse_args(
        [*argv, "--seed-file", str(take), "--seed-frame", "20", "--n-sequences", "2"]
    )
    history, _ = _cli._seeds(saved, args)
    Z = saved.pipeline[:-1].transform(read_bvh(take)[1])
    assert history.shape == (2, 3, Z.shape[1])
    assert_allclose(history[0], Z[18:21])
    assert_allclose(history[1], Z[18:21])
    # a take at twice the model's rate: every other frame, ending at the frame
    fast = tmp_path / "fast.bvh"
    skeleton, data, _, _ = read_bvh(take)
    write_bvh(fast, np.repeat(data, 2, axis=0), skeleton, 60.0)
    args.seed_file, args.seed_frame = fast, 41
    history, text = _cli._seeds(saved, args)
    assert text == "seeded with frames 37-41 of fast.bvh"
    assert_allclose(history[0], Z[18:21], atol=1e-8)
    # the take's middle frame by default
    args.seed_file, args.seed_frame = take, None
    assert (
        _cli._seeds(saved, args)[1] == "seeded with frames 28-30 of walk_fast_001.bvh"
    )


@pytest.mark.parametrize(
    "extra, message",
    [
        (["--seed-frame", "5"], "--seed-frame N picks a frame of --seed-file PATH"),
        (["--seed-file", "{take}", "--seed-frame", "60"], "has frames 0 to 59"),
        (["--seed-file", "{take}", "--seed-frame", "1"], "end at frame 2 of"),
        (["--seed-file", "{take}", "--style", "fast"], "give one"),
        (["--seed-file", "{other}"], "is not of the model's skeleton"),
        (["--seed-file", "{missing}"], "is not a file"),
    ],
)
def test_sample_seed_file_errors_say_what_to_do(
    walker_model, tmp_path, capsys, data_home, extra, message
):
    model, folder = walker_model
    paths = dict(
        take=folder / "walk_fast_001.bvh",
        other=data_home / "bandai_contents" / "dataset-2_walk_normal_001.bvh",
        missing=tmp_path / "none.bvh",
    )
    extra = [part.format(**paths) for part in extra]
    argv = ["sample", str(model), "--output", str(tmp_path), *extra]
    assert main(argv) == 1
    assert message in capsys.readouterr().err


def test_every_drawing_command_takes_a_view(walker_model, tmp_path, monkeypatch):
    parser = _cli._parser()
    for argv in (["demo"], ["styles"], ["sample", "m.joblib"]):
        assert parser.parse_args(argv).view == "auto"
        assert parser.parse_args([*argv, "--view", "front"]).view == "front"
    seen = []
    real = _cli.save_gif

    def spy(*args, **kwargs):
        seen.append(kwargs["view"])
        return real(*args, **kwargs)

    monkeypatch.setattr(_cli, "save_gif", spy)
    argv = ["sample", str(walker_model[0]), "--n-frames", "4", "--animate"]
    assert main([*argv, "--output", str(tmp_path), "--view", "top"]) == 0
    assert seen == ["top"]


def test_fit_on_files_of_different_rates_says_what_frame_rate_does(tmp_path, capsys):
    folder = _walker_folder(tmp_path / "mine", 30.0, n_frames=30)
    walker = make_walker(n_sequences=1, n_frames=60, random_state=0)
    write_bvh(folder / "walk_fast_003.bvh", walker.data, walker.skeleton, 60.0)
    (folder / "walk_fast_003.json").write_text('{"style": 1}')
    model = str(tmp_path / "m.joblib")
    assert main(["fit", str(folder), *TINY, "--output", model]) == 1
    err = capsys.readouterr().err
    assert "walk_fast_003.bvh has 60 frames per second, but the other 4 files" in err
    assert "--frame-rate 30 brings every file to 30 frames per second" in err
    assert "every 2nd frame of walk_fast_003.bvh" in err
    assert "leave it out" not in err
    argv = ["fit", str(folder), *TINY, "--frame-rate", "30", "--output", model]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert "warning: The files do not share one frame rate" in err
    assert "every 2nd frame of walk_fast_003.bvh" in err
