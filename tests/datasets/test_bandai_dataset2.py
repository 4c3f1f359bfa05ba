"""The Bandai Namco dataset-2 corpus: its loader and its fetcher (never the internet)."""

import csv
import functools
import shutil
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer

import numpy as np
import pytest
from numpy.testing import assert_array_equal

from sklearn_crbm.datasets import (
    fetch_bandai_dataset2,
    load_bandai_dataset2,
    read_bvh,
)
from sklearn_crbm.datasets._bandai import BANDAI_SHA256, DATASET2_SHA256
from sklearn_crbm.datasets._fetch import BANDAI_DATASET2_FILES, file_sha256

CELLS = dict(
    contents=["wave-left-hand", "run"], styles=["normal", "elderly"], takes=[2, 1]
)


@pytest.fixture(scope="module")
def corpus(data_home):
    return load_bandai_dataset2(data_home, **CELLS)


def test_every_frame_has_its_content_and_style(corpus, data_home):
    # sorted by name: run before wave, elderly before normal, take 1 before 2
    assert corpus.sequence_names.tolist() == [
        f"dataset-2_{content}_{style}_{take:03d}"
        for content in ("run", "wave-left-hand")
        for style in ("elderly", "normal")
        for take in (1, 2)
    ]
    assert corpus.takes.tolist() == [1, 2] * 4
    assert corpus.target.shape == (len(corpus.data), 2)
    assert corpus.target_columns == ("content", "style")
    # the names without the "dataset-2_" prefix, in the dataset's order
    assert [names.tolist() for names in corpus.target_names] == [
        ["run", "wave-left-hand"],
        ["elderly", "normal"],
    ]
    folder = data_home / "bandai_dataset2"
    for k, name in enumerate(corpus.sequence_names):
        _, content, style, _ = name.split("_")
        frames = corpus.sequence_ids == k
        assert set(map(tuple, corpus.target[frames].tolist())) == {(content, style)}
        _, raw, _, rate = read_bvh(folder / f"{name}.bvh")
        assert rate == corpus.frame_rate == 30.0
        assert_array_equal(corpus.data[frames], raw)
    assert corpus.skeleton.bone_names[:2] == ["joint_Root", "Hips"]
    assert "Attribution-NonCommercial" in corpus.DESCR


def test_one_name_or_number_is_a_list_of_one(data_home):
    one = load_bandai_dataset2(data_home, contents="run", styles="active", takes=3)
    assert one.sequence_names.tolist() == ["dataset-2_run_active_003"]
    assert one.target[0].tolist() == ["run", "active"]


@pytest.mark.parametrize(
    "asked, message",
    [
        (dict(contents="jog"), r"contents must be names among walk, .*got \['jog'\]"),
        (dict(styles=["normal", "angry"]), r"styles must be .*got \['angry'\]"),
        (dict(contents=[]), "contents must be names"),
        (dict(takes=13), r"takes must be take numbers from 1 to 12.*got \[13\]"),
        (dict(takes=[0, 1]), r"got \[0\]"),
        (dict(takes=[True]), r"got \[True\]"),
        (dict(takes="1"), "takes must be take numbers"),
    ],
)
def test_cells_outside_the_corpus_are_refused(tmp_path, asked, message):
    with pytest.raises(ValueError, match=message):
        load_bandai_dataset2(tmp_path, **asked)
    with pytest.raises(ValueError, match=message):
        fetch_bandai_dataset2(tmp_path, **asked)
    assert not any(tmp_path.iterdir())


def test_missing_takes_say_how_to_fetch_them(tmp_path):
    with pytest.raises(
        FileNotFoundError,
        match=r"fetch_bandai_dataset2\(data_home=\.\.\., contents=\['run'\], "
        r"takes=\[1, 2\]\)",
    ):
        load_bandai_dataset2(tmp_path, contents="run", takes=[1, 2])


def test_hashes_and_paths_are_those_of_the_provenance_file(data_home):
    """Every file at the path its provenance names, in the commit of the
    walks, with the hash of the shared copy; the walks' table is a part."""
    folder = data_home / "bandai_dataset2"
    with open(folder / "PROVENANCE.tsv", newline="") as f:
        provenance = {row["file"]: row for row in csv.DictReader(f, delimiter="\t")}
    remotes = {remote.filename: remote for remote in BANDAI_DATASET2_FILES}
    assert sorted(remotes) == sorted(
        [*provenance, "LICENSE", "content_label.txt", "style_label.txt"]
    )
    for filename, row in provenance.items():
        remote = remotes[filename]
        assert remote.sha256 == row["sha256"]
        assert remote.url() == (
            "https://raw.githubusercontent.com/BandaiNamcoResearchInc/"
            "Bandai-Namco-Research-Motiondataset/"
            f"74ead3ba1ae4696404e6086233779f60de8bf9ef/{row['source_path']}"
        )
    for filename in ("LICENSE", "content_label.txt", "style_label.txt"):
        assert file_sha256(folder / filename) == remotes[filename].sha256
    assert BANDAI_SHA256.items() <= DATASET2_SHA256.items()
    assert len(BANDAI_SHA256) == 87


class _QuietHandler(SimpleHTTPRequestHandler):
    def log_message(self, format, *args):
        pass

    def do_GET(self):
        type(self).requests.append(self.path)
        super().do_GET()


@pytest.fixture
def server(tmp_path, data_home):
    """A server on 127.0.0.1 laid out like raw.githubusercontent.com, with the
    files of ``CELLS`` (and the licence and label names) only."""
    root = tmp_path / "remote"
    wanted = {
        f"dataset-2_{c}_{s}_{t:03d}.{suffix}"
        for c in CELLS["contents"]
        for s in CELLS["styles"]
        for t in CELLS["takes"]
        for suffix in ("bvh", "json")
    }
    for remote in BANDAI_DATASET2_FILES:
        if remote.filename in wanted or not remote.filename.startswith("dataset-2_"):
            target = root / remote.repository / remote.commit / remote.path
            target.parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(data_home / remote.folder / remote.filename, target)
    handler = type("Handler", (_QuietHandler,), {"requests": []})
    httpd = ThreadingHTTPServer(
        ("127.0.0.1", 0), functools.partial(handler, directory=str(root))
    )
    thread = threading.Thread(target=httpd.serve_forever, args=(0.05,), daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{httpd.server_address[1]}", handler.requests
    finally:
        httpd.shutdown()
        httpd.server_close()
        thread.join()


def test_fetch_the_cells_asked_for_and_load_them(tmp_path, server, corpus, capsys):
    base_url, requests = server
    home = tmp_path / "home"
    assert fetch_bandai_dataset2(home, base_url=base_url, **CELLS) == home
    # 8 takes and their labels, 2 name files, the licence
    assert len(requests) == 19
    assert capsys.readouterr().err.startswith(f"Downloading 19 files to {home}")
    assert all("/74ead3ba1ae4696404e6086233779f60de8bf9ef/" in r for r in requests)
    fetched = load_bandai_dataset2(home, **CELLS)
    assert_array_equal(fetched.data, corpus.data)
    assert_array_equal(fetched.target, corpus.target)
    # fewer cells: all there already; nothing downloaded again
    fetch_bandai_dataset2(
        home, base_url=base_url, contents="run", styles="normal", takes=1
    )
    assert len(requests) == 19
    # a cell the server lacks: the download fails, and says where from
    with pytest.raises(OSError, match="Could not download .*walk_normal_001.bvh"):
        fetch_bandai_dataset2(
            home, base_url=base_url, contents="walk", styles="normal", takes=1
        )
    assert not (home / "bandai_dataset2" / "dataset-2_walk_normal_001.bvh").exists()
    assert np.all(np.isfinite(fetched.data))
