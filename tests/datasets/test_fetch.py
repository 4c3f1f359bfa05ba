"""The fetch_* helpers against a local HTTP server (never the internet)."""

import functools
import shutil
import threading
from http.server import SimpleHTTPRequestHandler, ThreadingHTTPServer

import numpy as np
import pytest

from sklearn_crbm.datasets import (
    fetch_bandai_walks,
    fetch_cmu35,
    fetch_mit_walk,
    load_bandai_walks,
    load_cmu35,
    load_mit_walk,
)
from sklearn_crbm.datasets._fetch import (
    BANDAI_WALK_FILES,
    CMU35_FILES,
    MIT_WALK_FILES,
    file_sha256,
)


class _QuietHandler(SimpleHTTPRequestHandler):
    requests = []

    def log_message(self, format, *args):
        pass

    def do_GET(self):
        type(self).requests.append(self.path)
        super().do_GET()


@pytest.fixture
def server(tmp_path, data_home):
    """A server on 127.0.0.1 laid out like raw.githubusercontent.com.

    Yields ``(base_url, root, requests)``: files live at
    ``root/{owner}/{repository}/{commit}/{path}``, copied from the test data.
    """
    root = tmp_path / "remote"
    for remote in CMU35_FILES + MIT_WALK_FILES + BANDAI_WALK_FILES:
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
        yield f"http://127.0.0.1:{httpd.server_address[1]}", root, handler.requests
    finally:
        httpd.shutdown()
        httpd.server_close()
        thread.join()


def test_fetch_cmu35_downloads_checks_and_skips(tmp_path, server):
    base_url, _, requests = server
    home = tmp_path / "home"
    assert fetch_cmu35(home, base_url=base_url) == home
    for remote in CMU35_FILES:
        assert file_sha256(home / "cmu_subject35" / remote.filename) == remote.sha256
    assert len(requests) == 4
    assert all(
        "/SheffieldML/GPmat/4b5914a38ecbad9fb7a13a3392970bfc28c9d911/" in r
        for r in requests
    )
    assert load_cmu35(home).data.shape == (2813, 62)
    # a second call finds everything in place
    fetch_cmu35(home, base_url=base_url)
    assert len(requests) == 4
    # a damaged file is downloaded again
    (home / "cmu_subject35" / "35.asf").write_text("damaged")
    fetch_cmu35(home, base_url=base_url)
    assert len(requests) == 5 and requests[-1].endswith("/35.asf")
    assert file_sha256(home / "cmu_subject35" / "35.asf") == CMU35_FILES[2].sha256


def test_fetch_bandai_walks_shows_progress_and_loads(
    tmp_path, server, capsys, data_home
):
    base_url, _, requests = server
    home = tmp_path / "home"
    assert fetch_bandai_walks(home, base_url=base_url) == home
    assert len(requests) == 87  # 42 takes and their labels, 2 name files, licence
    progress = capsys.readouterr().err.splitlines()
    assert progress[0] == f"Downloading 87 files to {home}"
    assert progress[1].startswith("  [1/87] bandai_walk_styles/LICENSE (")
    assert progress[-1].startswith("  [87/87] bandai_walk_styles/dataset-2_walk_")
    assert len(progress) == 88
    walks = load_bandai_walks(home)
    shared = load_bandai_walks(data_home)
    np.testing.assert_array_equal(walks.data, shared.data)
    np.testing.assert_array_equal(walks.target, shared.target)
    # nothing to do the second time, and nothing printed; a damaged file again
    fetch_bandai_walks(home, base_url=base_url)
    assert len(requests) == 87 and capsys.readouterr().err == ""
    (home / "bandai_walk_styles" / "style_label.txt").write_text("damaged")
    fetch_bandai_walks(home, base_url=base_url, verbose=False)
    assert requests[-1].endswith("/cfg/style_label.txt")
    assert len(requests) == 88 and capsys.readouterr().err == ""


def test_fetch_mit_walk(tmp_path, server, monkeypatch):
    base_url, _, requests = server
    monkeypatch.setenv("SKLEARN_CRBM_DATA", str(tmp_path / "env_home"))
    home = fetch_mit_walk(base_url=base_url)
    assert home == tmp_path / "env_home"
    assert sorted(p.relative_to(home).as_posix() for p in home.rglob("*.mat")) == [
        "mit_tsbn/mit_mocap.mat",
        "taylor_mhmublv_mit/data.mat",
        "taylor_theano_motion/motion.mat",
    ]
    assert len(requests) == 3
    mit = load_mit_walk()
    assert mit.data.shape == (3826, 108)


def test_fetch_hash_mismatch_deletes_the_file(tmp_path, server):
    base_url, root, _ = server
    remote = CMU35_FILES[3]  # 35_01.amc
    served = root / remote.repository / remote.commit / remote.path
    served.write_bytes(served.read_bytes().replace(b"4.40047", b"4.40048", 1))
    home = tmp_path / "home"
    with pytest.raises(OSError, match=f"SHA-256.*expected {remote.sha256}"):
        fetch_cmu35(home, base_url=base_url)
    folder = home / "cmu_subject35"
    assert not (folder / "35_01.amc").exists()
    assert not any(p.name.endswith(".part") for p in folder.iterdir())
    # the files before it were kept, with the right hashes
    for good in CMU35_FILES[:3]:
        assert file_sha256(folder / good.filename) == good.sha256


def test_fetch_missing_file_on_server(tmp_path, server):
    base_url, root, _ = server
    remote = MIT_WALK_FILES[0]
    (root / remote.repository / remote.commit / remote.path).unlink()
    with pytest.raises(OSError, match="Could not download .*data.mat.*404"):
        fetch_mit_walk(tmp_path / "home", base_url=base_url)
    assert not (tmp_path / "home" / remote.folder / "data.mat").exists()


def test_default_urls_point_at_the_listed_commits():
    urls = [remote.url() for remote in CMU35_FILES + MIT_WALK_FILES]
    assert urls[0] == (
        "https://raw.githubusercontent.com/SheffieldML/GPmat/"
        "4b5914a38ecbad9fb7a13a3392970bfc28c9d911/datasets/data/cmu35WalkJog.mat"
    )
    assert urls[4] == (
        "https://raw.githubusercontent.com/uoguelph-mlrg/mhmublv/"
        "eed9cc925ba90ab692d9c1bba1ff1cd98432048d/Data/data.mat"
    )
    assert len(set(urls)) == 7
    assert np.all([len(remote.sha256) == 64 for remote in CMU35_FILES + MIT_WALK_FILES])


def test_bandai_urls_are_those_of_the_provenance_file(data_home):
    """Every BVH file at the repository, path and commit its provenance names,
    every other file (JSON labels, label names, licence) in the same commit,
    and every hash that of the shared copy."""
    folder = data_home / "bandai_walk_styles"
    provenance = {}
    for line in (folder / "PROVENANCE.tsv").read_text().splitlines():
        filename, repository, path, commit = line.split("\t")
        provenance[filename] = (
            f"https://raw.githubusercontent.com/{repository}/{commit}/{path}"
        )
    remotes = {remote.filename: remote for remote in BANDAI_WALK_FILES}
    assert sorted(remotes) == sorted(
        p.name
        for p in folder.iterdir()
        if p.name not in ("README.md", "PROVENANCE.tsv")
    )
    for filename, url in provenance.items():
        assert remotes[filename].url() == url
        json_url = remotes[filename.replace(".bvh", ".json")].url()
        assert json_url == url.replace(".bvh", ".json")
    assert (
        remotes["style_label.txt"]
        .url()
        .endswith(
            "/74ead3ba1ae4696404e6086233779f60de8bf9ef/dataset/"
            "Bandai-Namco-Research-Motiondataset-2/cfg/style_label.txt"
        )
    )
    for filename, remote in remotes.items():
        assert file_sha256(folder / filename) == remote.sha256, filename
