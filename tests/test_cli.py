"""The command line: the demo, fetch, fit and sample, help and error messages."""

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
import sklearn

from sklearn_crbm import _cli, _cli_options
from sklearn_crbm._cli import main
from sklearn_crbm.datasets import load_cmu35, make_walker, read_amc, read_bvh, write_bvh

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
    skeleton = load_cmu35(data_home, subset="test").skeleton
    data, names = read_amc(tmp_path / "generated_walk.amc", skeleton)
    assert data.shape == (40, 62) and np.isfinite(data).all()
    _, bvh, _, rate = read_bvh(tmp_path / "generated_walk.bvh")
    assert bvh.shape[0] == 40 and rate == 30.0


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


def test_demo_writes_outside_the_current_folder_by_default():
    output = _cli._parser().parse_args(["demo"]).output
    assert output == _cli_options.DEMO_OUTPUT
    assert output == Path(tempfile.gettempdir()) / "sklearn_crbm_demo"
    assert Path.cwd().resolve() not in output.resolve().parents


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
            data, _ = read_amc(f"{prefix}_{k}.amc", skeleton)
            assert data.shape == (25, 62)
            # the BVH file holds the same motion
            written, bvh, _, rate = read_bvh(f"{prefix}_{k}.bvh")
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
    """Fit on ``folder``, sample 12 frames; the fit's report and the prefix."""
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
    skeleton, data, _, rate = read_bvh(f"{prefix}_0.bvh")
    assert data.shape[0] == 12 and rate == 30.0
    assert not (tmp_path / "generated_0.amc").exists()  # BVH skeletons: no AMC


def test_fit_reads_a_folder_of_asf_amc_files(data_home, tmp_path, capsys):
    folder = tmp_path / "mine"
    folder.mkdir()
    for name in ("35.asf", "35_01.amc"):
        (folder / name).write_bytes((data_home / "cmu_subject35" / name).read_bytes())
    report, prefix = _fit_and_sample(folder, tmp_path, capsys)
    assert "training on 90 frames of 1 sequence at 30 frames/s" in report
    skeleton = load_cmu35(data_home, subset="test").skeleton
    assert read_amc(f"{prefix}_0.amc", skeleton)[0].shape == (12, 62)
    assert (tmp_path / "generated_0.bvh").exists()


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


def test_hidden_noise_help_gives_the_measured_transitions():
    parser = _cli._parser()
    (commands,) = [
        a for a in parser._actions if isinstance(a, argparse._SubParsersAction)
    ]
    text = " ".join(commands.choices["sample"].format_help().split())
    assert "no walk-to-jog transition up to 2.0, a few from 2.5" in text
    assert "about 1" not in text


def test_missing_data_says_how_to_fetch(tmp_path, capsys):
    status = main(["demo", "--data-home", str(tmp_path / "nowhere"), *TINY])
    err = capsys.readouterr().err
    assert status == 1
    assert "python -m sklearn_crbm fetch --data-home" in err


def test_no_command_prints_help(capsys):
    assert main([]) == 2
    assert "demo" in capsys.readouterr().out
