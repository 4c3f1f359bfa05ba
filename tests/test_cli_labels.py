"""The command line on a corpus of several labels per take (issue 47):
``fit --labels content,style`` and ``sample --label run,elderly``."""

import io
from contextlib import redirect_stdout

import joblib
import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.cli import _labels, main
from sklearn_crbm.cli import _main as _cli
from sklearn_crbm.datasets import load_bandai_dataset2, read_bvh

CONTENTS, STYLES = ("run", "wave-left-hand"), ("elderly", "normal")
# the training takes: every pair but an elderly run, asked for below
TAKES = [(c, s) for c in CONTENTS for s in STYLES if (c, s) != ("run", "elderly")]
TINY = ["--n-components", "12", "--n-iter", "3", "--order", "2"]


def _corpus_folder(data_home, folder, cells=TAKES, takes=(1,)):
    """Real Bandai dataset-2 takes with their labels, linked into ``folder``."""
    source = data_home / "bandai_dataset2"
    folder.mkdir()
    for name in ("style_label.txt", "content_label.txt"):
        (folder / name).symlink_to(source / name)
    for content, style in cells:
        for take in takes:
            for suffix in (".bvh", ".json"):
                name = f"dataset-2_{content}_{style}_{take:03d}{suffix}"
                (folder / name).symlink_to(source / name)
    return folder


@pytest.fixture(scope="module")
def corpus_folder(data_home, tmp_path_factory):
    return _corpus_folder(data_home, tmp_path_factory.mktemp("corpus") / "takes")


@pytest.mark.parametrize(
    "text, keys",
    [
        ("style", ["style"]),
        ("content,style", ["content", "style"]),
        ("content, style", ["content", "style"]),
        ("walk_([a-z]{1,9})_", ["walk_([a-z]{1,9})_"]),  # a pattern, comma and all
        (None, None),
    ],
)
def test_labels_is_one_key_a_pattern_or_keys_separated_by_commas(text, keys):
    assert _labels.label_keys(text) == keys


@pytest.mark.parametrize("text", ["content,", "style,style", ",style"])
def test_labels_with_empty_or_repeated_keys_say_how_to_write_them(text):
    with pytest.raises(ValueError, match="several different keys separated by"):
        _labels.label_keys(text)


def test_a_folder_read_with_two_keys_has_both_names_of_every_frame(
    corpus_folder, data_home
):
    data = _cli._read_motion_folder(corpus_folder, labels="content,style")
    assert data.label_keys == ["content", "style"]
    assert data.target.shape == (len(data.data), 2)
    assert [list(names) for names in data.target_names] == [
        list(CONTENTS),
        list(STYLES),
    ]
    expected = load_bandai_dataset2(
        data_home,
        contents=list(CONTENTS),
        styles=list(STYLES),
        takes=1,
    )
    keep = [
        k for k, name in enumerate(expected.sequence_names)
        if tuple(name.split("_")[1:3]) in TAKES
    ]  # fmt: skip
    rows = np.isin(expected.sequence_ids, keep)
    assert_array_equal(data.data, expected.data[rows])
    assert_array_equal(data.target, expected.target[rows])


def test_a_label_with_a_comma_is_refused(tmp_path, data_home):
    folder = _corpus_folder(data_home, tmp_path / "odd", cells=TAKES[:2])
    (folder / "style_label.txt").unlink()
    (folder / "style_label.txt").write_text("\n".join(f"s{k},x" for k in range(7)))
    with pytest.raises(ValueError, match="'s1,x' holds a comma"):
        _cli._read_motion_folder(folder, labels="content,style")


def test_label_request_checks_the_names_against_the_model():
    keys, classes = ["content", "style"], [np.array(CONTENTS), np.array(STYLES)]
    assert _labels.label_request("run,elderly", keys, classes) == ("run", "elderly")
    with pytest.raises(ValueError, match="fitted on 2 labels .*--label run,elderly"):
        _labels.label_request("run", keys, classes)
    with pytest.raises(ValueError, match="no style 'proud'; its style labels are"):
        _labels.label_request("run,proud", keys, classes)


def test_an_unseen_pair_is_seeded_from_its_content_in_other_styles():
    windows = {
        ("run", "normal"): np.zeros((2, 3, 1)),
        ("run", "active"): np.ones((2, 3, 1)),
        ("walk", "elderly"): np.full((2, 3, 1), 2.0),
    }
    seeds, name = _labels.seed_windows_for(windows, ("run", "normal"))
    assert name == "run,normal" and seeds.shape == (2, 3, 1)
    seeds, name = _labels.seed_windows_for(windows, ("run", "elderly"))
    assert name == "run,normal or run,active"
    assert sorted(seeds[:, 0, 0].tolist()) == [0, 0, 1, 1]
    seeds, name = _labels.seed_windows_for(windows, ("wave", "elderly"))
    assert name == "walk,elderly"
    assert _labels.seed_windows_for(windows, ("wave", "proud")) == (None, None)


def test_the_styles_command_refuses_several_keys(tmp_path, capsys):
    argv = ["styles", "--folder", str(tmp_path), "--labels", "content,style"]
    assert main(argv) == 1
    assert "sample MODEL --label" in capsys.readouterr().err


def test_speed_context_and_several_labels_are_one_too_many(corpus_folder, capsys):
    argv = ["fit", str(corpus_folder), "--labels", "content,style", *TINY]
    assert main([*argv, "--speed-context"]) == 1
    assert "give one of the two" in capsys.readouterr().err


@pytest.fixture(scope="module")
def one_label_model(corpus_folder, tmp_path_factory):
    model = tmp_path_factory.mktemp("one") / "m.joblib"
    argv = ["fit", str(corpus_folder), "--labels", "style", *TINY]
    with redirect_stdout(io.StringIO()):
        assert main([*argv, "--output", str(model)]) == 0
    return model


def test_label_asks_a_model_of_several_labels(one_label_model, tmp_path, capsys):
    argv = ["sample", str(one_label_model), "--output", str(tmp_path)]
    assert main([*argv, "--label", "run,elderly"]) == 1
    assert "fitted on several (fit --labels content,style)" in capsys.readouterr().err
    # a model of several labels (its keys saved by fit) needs --label
    saved = joblib.load(one_label_model)
    saved.update(label_keys=["content", "style"], seed_windows={("run", "normal"): 0})
    several = tmp_path / "several.joblib"
    joblib.dump(saved, several)
    argv = ["sample", str(several), "--output", str(tmp_path)]
    assert main(argv) == 1
    assert (
        "say which to generate with --label, one of each (such as --label "
        "run,normal)" in capsys.readouterr().err
    )
    assert main([*argv, "--style", "normal"]) == 1
    assert "ask for them with --label" in capsys.readouterr().err


def test_fit_two_keys_then_sample_any_pair(corpus_folder, tmp_path, capsys):
    """One model of content and style; an elderly run asked for although
    the takes hold none, seeded with runs of the other style."""
    model = tmp_path / "corpus.joblib"
    argv = ["fit", str(corpus_folder), "--labels", "content,style", *TINY]
    assert main([*argv, "--output", str(model)]) == 0, capsys.readouterr().err
    assert (
        "labels content: run, wave-left-hand; style: elderly, normal (3 of their "
        "4 combinations)"
    ) in capsys.readouterr().out
    saved = _cli._load_model(model)
    assert saved.label_keys == ["content", "style"]
    fitted = saved.pipeline[-1]
    assert type(fitted).__name__ == "LabelledCRBM" and fitted.n_outputs_ == 2
    assert [list(names) for names in fitted.classes_] == [list(CONTENTS), list(STYLES)]
    assert sorted(saved.seed_windows) == sorted(TAKES)
    out = tmp_path / "out"
    argv = ["sample", str(model), "--n-frames", "30", "--n-sequences", "2"]
    argv += ["--output", str(out)]
    drawn = {}
    for label in ("run,elderly", "wave-left-hand,elderly"):
        assert main([*argv, "--label", label]) == 0, capsys.readouterr().err
        printed = capsys.readouterr().out
        drawn[label] = read_bvh(out / "generated_1.bvh")[1]
        assert drawn[label].shape[0] == 30
    assert (
        "wrote generated_0.bvh (wave-left-hand,elderly, seeded with "
        "wave-left-hand,elderly frames; " in printed
    )
    # the labels reach the model: from one seed, other labels, other motion
    take = corpus_folder / "dataset-2_run_normal_001.bvh"
    for label in ("run,elderly", "wave-left-hand,normal"):
        assert main([*argv, "--label", label, "--seed-file", str(take)]) == 0
        drawn[label] = read_bvh(out / "generated_1.bvh")[1]
    assert "(wave-left-hand,normal, seeded with frame" in capsys.readouterr().out
    assert not np.allclose(drawn["run,elderly"], drawn["wave-left-hand,normal"])
    assert main([*argv, "--label", "run,proud"]) == 1
    assert "the model knows no style 'proud'" in capsys.readouterr().err


def test_sample_seeds_a_pair_never_seen_from_its_content(
    corpus_folder, tmp_path, capsys
):
    model = tmp_path / "corpus.joblib"
    argv = ["fit", str(corpus_folder), "--labels", "content,style", *TINY]
    with redirect_stdout(io.StringIO()):
        assert main([*argv, "--output", str(model)]) == 0
    argv = ["sample", str(model), "--n-frames", "10", "--label", "run,elderly"]
    assert main([*argv, "--output", str(tmp_path / "out")]) == 0
    assert "(run,elderly, seeded with run,normal frames; " in capsys.readouterr().out
