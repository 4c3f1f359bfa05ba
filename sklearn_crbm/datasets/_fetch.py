"""Download the public originals of the data sets, with SHA-256 checks."""

import hashlib
import os
import shutil
import sys
import urllib.request
from dataclasses import dataclass

from ._bandai import (
    BANDAI_COMMIT,
    BANDAI_FOLDER,
    BANDAI_REPOSITORY,
    BANDAI_SHA256,
    DATASET2_FOLDER,
    DATASET2_SHA256,
    bandai_source_path,
    dataset2_filenames,
    dataset2_selection,
)
from ._base import CMU35_FOLDER, MIT_FOLDER, get_data_home

__all__ = [
    "BANDAI_DATASET2_FILES",
    "BANDAI_WALK_FILES",
    "CMU35_FILES",
    "MIT_WALK_FILES",
    "RemoteFile",
    "fetch_bandai_dataset2",
    "fetch_bandai_walks",
    "fetch_cmu35",
    "fetch_mit_walk",
]

GITHUB_RAW = "https://raw.githubusercontent.com"

_GPMAT = ("SheffieldML/GPmat", "4b5914a38ecbad9fb7a13a3392970bfc28c9d911")
_MHMUBLV = ("uoguelph-mlrg/mhmublv", "eed9cc925ba90ab692d9c1bba1ff1cd98432048d")
_CRBM = ("taneishi/CRBM", "baa0c21f489c82b7a88e70ddb2555ee713fb74d4")
_TSBN = ("zhegan27/TSBN_code_NIPS2015", "029c9955f963918c6e2d2e60d1402645a8ea78a9")


@dataclass(frozen=True)
class RemoteFile:
    """One data file: where it goes under ``data_home`` and where it comes from.

    The URL is ``{base_url}/{repository}/{commit}/{path}``, which for the
    default base URL is the file in the GitHub repository at that commit.
    """

    folder: str
    filename: str
    repository: str
    commit: str
    path: str
    sha256: str

    def url(self, base_url=GITHUB_RAW):
        return f"{base_url.rstrip('/')}/{self.repository}/{self.commit}/{self.path}"


CMU35_FILES = (
    RemoteFile(CMU35_FOLDER, "cmu35WalkJog.mat", *_GPMAT,
               "datasets/data/cmu35WalkJog.mat",
               "50db534501bdfb1611153e3b5d122fc08b0c42ea159e875d5656ec13fa11a353"),
    RemoteFile(CMU35_FOLDER, "cmu35TaylorScaleBias.mat", *_GPMAT,
               "datasets/data/cmu35TaylorScaleBias.mat",
               "e6533fa9ba17de0d095e4c63aba0ef17c85289cf6a820f8e01b5548891e08408"),
    RemoteFile(CMU35_FOLDER, "35.asf", *_GPMAT,
               "datasets/data/mocap/cmu/35/35.asf",
               "2a8e2eda3c0d7d828566b2a9a8ab36b2b8b3864110574e8b73c8f069fded416c"),
    RemoteFile(CMU35_FOLDER, "35_01.amc", *_GPMAT,
               "datasets/data/mocap/cmu/35/35_01.amc",
               "0743f4ea48e7e199cd56b2810b5ce81f8ede08d32ff79aa4e363c44cc4fe33aa"),
)  # fmt: skip

MIT_WALK_FILES = (
    RemoteFile(MIT_FOLDER, "data.mat", *_MHMUBLV, "Data/data.mat",
               "a864e18e92db67c877fe9fdd9619e57883e55f04bdbeffc7cf94cd47a8b0ff80"),
    RemoteFile("taylor_theano_motion", "motion.mat", *_CRBM, "data/motion.mat",
               "378bf28e6f3ac4f9b7271bd793b4fd03f0cc406f92e6525c0026a931df38a6e9"),
    RemoteFile("mit_tsbn", "mit_mocap.mat", *_TSBN, "mocap/mit_data/mit_mocap.mat",
               "d91828a48afe679eee20215b7657a0f54258654d3a2c9d6e943fec41dc7a0ddf"),
)  # fmt: skip


def _bandai_files(folder, table):
    return tuple(
        RemoteFile(
            folder,
            filename,
            BANDAI_REPOSITORY,
            BANDAI_COMMIT,
            bandai_source_path(filename),
            sha256,
        )
        for filename, sha256 in table.items()
    )


BANDAI_WALK_FILES = _bandai_files(BANDAI_FOLDER, BANDAI_SHA256)
BANDAI_DATASET2_FILES = _bandai_files(DATASET2_FOLDER, DATASET2_SHA256)


def fetch_cmu35(data_home=None, *, base_url=None, timeout=60.0, verbose=True):
    """Download the CMU subject 35 files used by :func:`load_cmu35`.

    Fetches ``cmu35WalkJog.mat``, ``cmu35TaylorScaleBias.mat``, ``35.asf``
    and ``35_01.amc`` from the GPmat repository (SheffieldML/GPmat, a fixed
    commit) into ``data_home/cmu_subject35/``.  Files already there with the
    right SHA-256 are not downloaded again.

    The data used in this project was obtained from mocap.cs.cmu.edu.
    The database was created with funding from NSF EIA-0196217.

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`; created if needed.
    base_url : str, default=None
        Where the repositories are served; default
        ``"https://raw.githubusercontent.com"``.  A file is fetched from
        ``{base_url}/{owner}/{repository}/{commit}/{path}``.
    timeout : float, default=60.0
        Seconds to wait for the server.
    verbose : bool, default=True
        Print each file as it is downloaded, with its size, to standard
        error.

    Returns
    -------
    data_home : pathlib.Path
        The folder, ready for :func:`load_cmu35`.

    Raises
    ------
    OSError
        If a download fails or a file does not have the expected SHA-256
        (the bad file is deleted).

    Examples
    --------
    >>> from sklearn_crbm.datasets import fetch_cmu35, load_cmu35
    >>> cmu = load_cmu35(fetch_cmu35())  # doctest: +SKIP
    """
    return _fetch_files(CMU35_FILES, data_home, base_url, timeout, verbose)


def fetch_mit_walk(data_home=None, *, base_url=None, timeout=60.0, verbose=True):
    """Download Taylor's MIT walking data used by :func:`load_mit_walk`.

    Fetches ``taylor_mhmublv_mit/data.mat`` (uoguelph-mlrg/mhmublv) and, for
    comparisons with published preprocessing, ``taylor_theano_motion/motion.mat``
    (taneishi/CRBM) and ``mit_tsbn/mit_mocap.mat``
    (zhegan27/TSBN_code_NIPS2015), each at a fixed commit.  Files already
    there with the right SHA-256 are not downloaded again.

    The data were provided by Eugene Hsu (Hsu, Pulli & Popovic, "Style
    Translation for Human Motion", SIGGRAPH 2005).

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`; created if needed.
    base_url : str, default=None
        See :func:`fetch_cmu35`.
    timeout : float, default=60.0
        Seconds to wait for the server.
    verbose : bool, default=True
        See :func:`fetch_cmu35`.

    Returns
    -------
    data_home : pathlib.Path
        The folder, ready for :func:`load_mit_walk`.

    Raises
    ------
    OSError
        If a download fails or a file does not have the expected SHA-256
        (the bad file is deleted).

    Examples
    --------
    >>> from sklearn_crbm.datasets import fetch_mit_walk, load_mit_walk
    >>> mit = load_mit_walk(fetch_mit_walk())  # doctest: +SKIP
    """
    return _fetch_files(MIT_WALK_FILES, data_home, base_url, timeout, verbose)


def fetch_bandai_walks(data_home=None, *, base_url=None, timeout=60.0, verbose=True):
    """Download the Bandai Namco walks in seven styles for :func:`load_bandai_walks`.

    Fetches the walks of the second set of the Bandai Namco Research Motion
    dataset (BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset, a
    fixed commit) in the styles active, elderly, exhausted, feminine,
    masculine, normal and youthful, takes 001-006 of each: 42 BVH files,
    the JSON label file of each, ``style_label.txt`` and
    ``content_label.txt`` (the label names) and the licence, into
    ``data_home/bandai_walk_styles/`` (15 MB).  Files already there with
    the right SHA-256 are not downloaded again.

    The data are licensed under Creative Commons Attribution-NonCommercial
    4.0 (``LICENSE``); cite Kobayashi et al., "Motion Capture Dataset for
    Practical Use of AI-based Motion Editing and Stylization" (2023,
    arXiv:2306.08861), as the repository asks.

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`; created if needed.
    base_url : str, default=None
        See :func:`fetch_cmu35`.
    timeout : float, default=60.0
        Seconds to wait for the server.
    verbose : bool, default=True
        See :func:`fetch_cmu35`.

    Returns
    -------
    data_home : pathlib.Path
        The folder, ready for :func:`load_bandai_walks`.

    Raises
    ------
    OSError
        If a download fails or a file does not have the expected SHA-256
        (the bad file is deleted).

    Examples
    --------
    >>> from sklearn_crbm.datasets import fetch_bandai_walks, load_bandai_walks
    >>> walks = load_bandai_walks(fetch_bandai_walks())  # doctest: +SKIP
    """
    return _fetch_files(BANDAI_WALK_FILES, data_home, base_url, timeout, verbose)


def fetch_bandai_dataset2(
    data_home=None,
    *,
    contents=None,
    styles=None,
    takes=None,
    base_url=None,
    timeout=60.0,
    verbose=True,
):
    """Download the Bandai Namco corpus of :func:`load_bandai_dataset2`.

    Fetches takes 001-012 of every content (walk, the two turns, run, three
    waves, three raises) in every style of the second set of the Bandai
    Namco Research Motion dataset
    (BandaiNamcoResearchInc/Bandai-Namco-Research-Motiondataset, a fixed
    commit): 840 BVH files with the JSON label of each, ``content_label.txt``
    and ``style_label.txt`` (the label names) and the licence, into
    ``data_home/bandai_dataset2/`` (174 MB), or only the cells and takes
    asked for.  Files already there with the right SHA-256 are not
    downloaded again.  The later takes of the dataset are not fetched.

    The data are licensed under Creative Commons Attribution-NonCommercial
    4.0 (``LICENSE``); cite Kobayashi et al., "Motion Capture Dataset for
    Practical Use of AI-based Motion Editing and Stylization" (2023,
    arXiv:2306.08861), as the repository asks.

    Parameters
    ----------
    data_home : path-like, default=None
        See :func:`get_data_home`; created if needed.
    contents : str or list of str, default=None
        The contents to fetch, such as ``"run"`` or ``["walk", "run"]``;
        ``None`` means all ten.
    styles : str or list of str, default=None
        The styles to fetch, such as ``"elderly"``; ``None`` means all seven.
    takes : int or list of int, default=None
        The take numbers to fetch, from 1 to 12; ``None`` means all twelve.
    base_url : str, default=None
        See :func:`fetch_cmu35`.
    timeout : float, default=60.0
        Seconds to wait for the server.
    verbose : bool, default=True
        See :func:`fetch_cmu35`.

    Returns
    -------
    data_home : pathlib.Path
        The folder, ready for :func:`load_bandai_dataset2`.

    Raises
    ------
    ValueError
        If a content, style or take is not one of the corpus's.
    OSError
        If a download fails or a file does not have the expected SHA-256
        (the bad file is deleted).

    Examples
    --------
    >>> from sklearn_crbm.datasets import fetch_bandai_dataset2, load_bandai_dataset2
    >>> cells = dict(contents="run", styles=["elderly", "normal"], takes=[1, 2])
    >>> home = fetch_bandai_dataset2(**cells)  # doctest: +SKIP
    >>> runs = load_bandai_dataset2(home, **cells)  # doctest: +SKIP
    """
    wanted = set(dataset2_filenames(*dataset2_selection(contents, styles, takes)))
    wanted |= {name.removesuffix(".bvh") + ".json" for name in wanted}
    files = [
        remote
        for remote in BANDAI_DATASET2_FILES
        if remote.filename in wanted or not remote.filename.startswith("dataset-2_")
    ]
    return _fetch_files(files, data_home, base_url, timeout, verbose)


def _fetch_files(files, data_home, base_url, timeout, verbose):
    home = get_data_home(data_home)
    missing = []
    for remote in files:
        target = home / remote.folder / remote.filename
        if target.is_file():
            if file_sha256(target) == remote.sha256:
                continue
            target.unlink()
        missing.append((remote, target))
    for count, (remote, target) in enumerate(missing, start=1):
        target.parent.mkdir(parents=True, exist_ok=True)
        url = remote.url(base_url or GITHUB_RAW)
        if verbose and count == 1:
            print(f"Downloading {len(missing)} files to {home}", file=sys.stderr)
        _download(url, target, remote.sha256, timeout)
        if verbose:
            kilobytes = target.stat().st_size / 1000
            print(
                f"  [{count}/{len(missing)}] {remote.folder}/{remote.filename} "
                f"({kilobytes:.0f} kB)",
                file=sys.stderr,
                flush=True,
            )
    return home


def _download(url, target, sha256, timeout):
    partial = target.with_name(target.name + ".part")
    try:
        with urllib.request.urlopen(url, timeout=timeout) as response:
            with open(partial, "wb") as out:
                shutil.copyfileobj(response, out)
    except OSError as exc:  # URLError and HTTPError are OSErrors
        partial.unlink(missing_ok=True)
        raise OSError(f"Could not download {url} to {target}: {exc}") from exc
    digest = file_sha256(partial)
    if digest != sha256:
        partial.unlink()
        raise OSError(
            f"The file downloaded from {url} has SHA-256 {digest}, expected {sha256}; "
            f"it was deleted. The server may serve a different version of the file."
        )
    os.replace(partial, target)


def file_sha256(path):
    """Hex SHA-256 of a file."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()
