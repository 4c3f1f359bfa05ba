"""The command line: the demo, fit and sample, and the missing-data message."""

import numpy as np

from sklearn_crbm._cli import main
from sklearn_crbm.datasets import load_cmu35, read_amc

TINY = ["--n-components", "12", "--n-iter", "3"]


def test_demo_prints_the_tables_and_writes_figures(data_home, tmp_path, capsys):
    status = main(
        [
            "demo",
            "--data-home",
            str(data_home),
            "--output",
            str(tmp_path),
            *TINY,
            "--n-repeats",
            "1",
            "--n-particles",
            "2",
            "--n-frames",
            "40",
        ]
    )
    out = capsys.readouterr().out
    assert status == 0
    assert "preprocessed to 62 dimensions" in out
    for row in ("walk 35_29", "jog 35_18", "left leg", "upper body", "8.78 / 11.68"):
        assert row in out
    assert out.count("classified as") == 1
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


def test_fit_then_sample_writes_amc(data_home, tmp_path, capsys):
    model = tmp_path / "model.joblib"
    assert (
        main(["fit", "--data-home", str(data_home), "--output", str(model), *TINY]) == 0
    )
    prefix = tmp_path / "jog"
    status = main(
        [
            "sample",
            str(model),
            "--data-home",
            str(data_home),
            "--style",
            "jog",
            "--n-frames",
            "25",
            "--n-sequences",
            "2",
            "--output",
            str(prefix),
        ]
    )
    assert status == 0
    skeleton = load_cmu35(data_home, subset="test").skeleton
    for k in (0, 1):
        data, _ = read_amc(f"{prefix}_{k}.amc", skeleton)
        assert data.shape == (25, 62)


def test_missing_data_says_how_to_fetch(tmp_path, capsys):
    status = main(["demo", "--data-home", str(tmp_path / "nowhere"), *TINY])
    err = capsys.readouterr().err
    assert status == 1
    assert "python -m sklearn_crbm fetch --data-home" in err


def test_no_command_prints_help(capsys):
    assert main([]) == 2
    assert "demo" in capsys.readouterr().out
