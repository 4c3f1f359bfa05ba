"""The command line: the demo, fetch, fit and sample, help and error messages."""

import argparse
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest
import sklearn

from sklearn_crbm import _cli
from sklearn_crbm._cli import main
from sklearn_crbm.datasets import load_cmu35, read_amc

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
    assert out.count("classified as") == 1
    # what the columns mean, and their units
    for explained in ("CRBM, NN ", "CRBM°, NN°", "in degrees", "length units"):
        assert explained in out
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
        "generated_walk.amc",
    ]
    if how == "no matplotlib":
        assert "matplotlib is not installed" in out


def test_demo_writes_outside_the_current_folder_by_default():
    output = _cli._parser().parse_args(["demo"]).output
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
    for style in ("jog", "any"):
        prefix = tmp_path / style
        status = main(
            [
                "sample",
                str(model),
                "--style",
                style,
                "--n-frames",
                "25",
                "--n-sequences",
                "2",
                "--output",
                str(prefix),
            ]
        )
        assert status == 0, capsys.readouterr().err
        for k in (0, 1):
            data, _ = read_amc(f"{prefix}_{k}.amc", skeleton)
            assert data.shape == (25, 62)


def test_sample_seeds_each_style_from_that_style(data_home, tmp_path, capsys):
    model = tmp_path / "model.joblib"
    main(["fit", "--data-home", str(data_home), "--output", str(model), *TINY])
    pipeline = _cli._load_model(model)
    train = load_cmu35(data_home, subset="train")
    with sklearn.config_context(enable_metadata_routing=True):
        Z = pipeline[:-1].transform(train.data, sequence_ids=train.sequence_ids)
    styles = np.asarray(train.motion)[train.sequence_ids]
    for style, windows in pipeline.style_windows_.items():
        assert windows.shape == (_cli.N_STYLE_WINDOWS, pipeline[-1].history_length, 62)
        for window in windows[:5]:  # each window is real frames of that style
            match = np.flatnonzero(np.all(np.isclose(Z, window[0]), axis=1))
            assert len(match) == 1 and styles[match[0]] == style


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


def test_every_option_has_help_and_shows_its_default():
    parser = _cli._parser()
    (commands,) = [
        a for a in parser._actions if isinstance(a, argparse._SubParsersAction)
    ]
    for name, command in commands.choices.items():
        text = command.format_help()
        for action in command._actions:
            if isinstance(action, argparse._HelpAction):
                continue
            assert action.help, (name, action.dest)
            if action.option_strings and action.default not in (None, False):
                shown = f"(default: {action.default})"
                assert shown in " ".join(text.split()), (name, action.dest)


def test_missing_data_says_how_to_fetch(tmp_path, capsys):
    status = main(["demo", "--data-home", str(tmp_path / "nowhere"), *TINY])
    err = capsys.readouterr().err
    assert status == 1
    assert "python -m sklearn_crbm fetch --data-home" in err


def test_no_command_prints_help(capsys):
    assert main([]) == 2
    assert "demo" in capsys.readouterr().out
