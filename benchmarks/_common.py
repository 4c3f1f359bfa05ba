"""What the benchmark scripts share; not part of the package.

Options and paths, the package under test (the one Python imports: set
``PYTHONPATH``) and the machine, data (CMU 35's splits, synthetic motion),
the cache of fitted models, the bootstrap over training seeds, timing,
tables and JSON.  The scripts import this module and the package's public
API only.
"""

import argparse
import ast
import ctypes
import hashlib
import json
import os
import platform
import statistics
import subprocess
import sys
import time
from contextlib import contextmanager
from functools import partial
from pathlib import Path

import joblib
import numpy as np
import sklearn
import threadpoolctl
from sklearn.frozen import FrozenEstimator
from sklearn.impute import KNNImputer

import sklearn_crbm
from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35, load_mit_walk
from sklearn_crbm.impute import (
    AutoregressiveImputer,
    CRBMImputer,
    NearestNeighborImputer,
)
from sklearn_crbm.metrics import judge_generated_motion
from sklearn_crbm.model_selection import compare_imputers, make_fillin_cases
from sklearn_crbm.preprocessing import MotionPipeline, make_motion_preprocessor

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
DATA_HOME = os.environ.get("SKLEARN_CRBM_DATA", str(REPO.parent / "shared" / "data"))
CACHE = Path(os.environ.get("SKLEARN_CRBM_BENCH_CACHE", RESULTS / "cache"))
PACKAGE = Path(sklearn_crbm.__file__).resolve().parent

# The paper's model on CMU subject 35 after preprocessing (62 channels).
PAPER = dict(n_features=62, n_components=200, order=3, batch_size=100)


def paper_model(**params):
    """``ConditionalRBM`` of the paper's size (200 hidden units, order 3)."""
    return ConditionalRBM(PAPER["n_components"], order=PAPER["order"], **params)


# CMU 35 train/test splits: one walk and one jog held out.  "paper" is the
# paper's §4.4 split; "second" holds out trials of similar lengths.
SPLITS = {"paper": ("35_29", "35_18"), "second": ("35_05", "35_22")}
CELLS = ("walk/leg", "walk/upper", "jog/leg", "jog/upper")
# The paper's joint encoding (rest-pose reference, Taylor's root roll), in
# which the quality tables are measured.
PAPER_ENCODING = dict(reference="rest", roll="taylor")
REAL_TIME_FPS = 30.0  # the frame rate of the mocap, for "x real time"
# The paper's §4.4 on its walk: the error of its CRBM and nearest neighbour.
PAPER_ERRORS = {
    "paper: CRBM": (8.78, 20.52),
    "paper: nearest neighbour": (11.68, 22.20),
}


def parser(doc, seeds=(0, 1, 2, 3, 4)):
    """An argument parser with the options every script has."""
    p = argparse.ArgumentParser(
        description=doc.split("\n")[0],
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--data-home", default=DATA_HOME, help="the mocap data folder")
    p.add_argument("--output", default=None, help="JSON file to write")
    if seeds is not None:
        p.add_argument("--seeds", type=int, nargs="+", default=list(seeds))
    return p


def speed_parser(doc, threads=(1, 2)):
    """The parser of the speed benchmarks: repeats, BLAS threads and dtypes too."""
    p = parser(doc, seeds=None)
    p.add_argument("--repeats", type=int, default=5, help="timed repetitions")
    p.add_argument("--threads", type=int, nargs="+", default=list(threads))
    p.add_argument("--dtypes", nargs="+", default=["float64", "float32"])
    return p


# -------------------------------------------------------- package, machine
def package_description():
    """Where the package under test lives and which commit it is."""
    try:
        commit = subprocess.run(
            ["git", "-C", str(PACKAGE), "describe", "--always", "--dirty"],
            capture_output=True,
            text=True,
            timeout=30,
        ).stdout.strip()
    except OSError:
        commit = ""
    return {"path": str(PACKAGE), "commit": commit or "unknown"}


def announce():
    """Print the package under test (the first line of every script's output)."""
    info = package_description()
    print(f"sklearn_crbm from {info['path']} at {info['commit']}", flush=True)


def machine():
    return {
        "platform": platform.platform(),
        "processor": _cpu_name(),
        "cpu_count": os.cpu_count(),
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "scikit-learn": sklearn.__version__,
        "blas": [
            {k: e.get(k) for k in ("internal_api", "version", "num_threads")}
            for e in threadpoolctl.threadpool_info()
        ],
        "load_average": os.getloadavg(),
        "date": time.strftime("%Y-%m-%d %H:%M:%S %Z"),
    }


def _cpu_name():
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


# -------------------------------------------------------------------- data
class Split:
    """One split of CMU subject 35, preprocessed (the paper's encoding) as
    fitted on its training trials; ``cases``: ``"walk/leg"`` ... ``"jog/upper"``
    (``make_fillin_cases``); ``X_test``/``test_ids``: the held-out walk, jog."""

    def __init__(self, data_home, name):
        self.cmu = cmu = load_cmu35(data_home)
        walk, jog = self.trials = SPLITS[name]
        names = list(cmu.sequence_names)
        held_out = np.isin(cmu.sequence_ids, [names.index(walk), names.index(jog)])
        self.name = name
        self.train_ids = cmu.sequence_ids[~held_out]
        self.preprocessor = make_motion_preprocessor(cmu.skeleton, **PAPER_ENCODING)
        with sklearn.config_context(enable_metadata_routing=True):
            self.X_train = self.preprocessor.fit_transform(
                cmu.data[~held_out], sequence_ids=self.train_ids
            )
        cases = make_fillin_cases(
            cmu, self.preprocessor, trials={"walk": walk, "jog": jog}
        )
        parts = {"left leg": "leg", "upper body": "upper"}
        self.cases = {f"{m}/{parts[p]}": case for (m, p), case in cases.items()}
        walk_X, jog_X = self.cases["walk/leg"].X, self.cases["jog/leg"].X
        self.X_test = np.concatenate([walk_X, jog_X])
        self.test_ids = np.repeat([0, 1], [len(walk_X), len(jog_X)])


class MotionCorpus:
    """Real motion of known styles (``name``: ``"cmu"``, all 33 trials of CMU 35,
    or ``"mit"``), preprocessed (``encoding``), the judge of generated motion,
    and ``real``: each style's mean leg amplitude and step frequency."""

    LEGS = {
        "cmu": ("lfemur", "rfemur", "ltibia", "rtibia"),
        "mit": ("lhip", "rhip", "lknee", "rknee"),
    }

    def __init__(self, data_home, name="cmu", encoding=None):
        loader = load_cmu35 if name == "cmu" else load_mit_walk
        self.data = data = loader(data_home)
        self.legs = self.LEGS[name]
        self.ids = data.sequence_ids
        self.styles = np.asarray(data.motion, dtype=object)
        self.style_names = tuple(dict.fromkeys(self.styles.tolist()))
        self.preprocessor = make_motion_preprocessor(data.skeleton, **(encoding or {}))
        with sklearn.config_context(enable_metadata_routing=True):
            self.Z = self.preprocessor.fit_transform(data.data, sequence_ids=self.ids)
        verdict = self.judge(self.Z, self.ids)
        self.real = {
            style: dict(
                amplitude=float(np.mean(verdict.amplitude[self.styles == style])),
                frequency=float(np.nanmean(verdict.frequency[self.styles == style])),
            )
            for style in self.style_names
        }

    def judge(self, Z, sequence_ids, expected_styles=None, last_frames=None):
        """``metrics.judge_generated_motion`` of ``Z`` against the real motion."""
        return judge_generated_motion(
            Z,
            self.Z,
            reference_styles=self.styles,
            preprocessor=self.preprocessor,
            expected_styles=expected_styles,
            sequence_ids=sequence_ids,
            reference_sequence_ids=self.ids,
            legs=self.legs,
            frame_rate=self.data.frame_rate,
            last_frames=last_frames,
        )

    def seed_windows(self, model, n_per_style, seed):
        """``(history, styles)``: ``n_per_style`` real windows of every style."""
        pipeline = MotionPipeline([*self.preprocessor.steps, ("model", model)])
        with sklearn.config_context(enable_metadata_routing=True):
            windows = pipeline.style_windows(
                self.data.data,
                self.styles[self.ids],
                sequence_ids=self.ids,
                n_windows=n_per_style,
                random_state=seed,
            )
        styles = np.repeat(np.array(self.style_names, dtype=object), n_per_style)
        return np.concatenate([windows[s] for s in self.style_names]), styles


def synthetic_motion(n_frames, n_features, n_sequences, dtype=np.float64, seed=0):
    """Standardised smooth random motion in long format (a stand-in for mocap)."""
    rng = np.random.default_rng(seed)
    lengths = np.full(n_sequences, n_frames // n_sequences)
    lengths[: n_frames - lengths.sum()] += 1
    X = np.empty((n_frames, n_features), dtype=dtype)
    freq = rng.uniform(0.05, 0.4, n_features).astype(dtype)
    step = 100_000
    for lo in range(0, n_frames, step):  # sinusoids plus noise, chunk by chunk
        t = np.arange(lo, min(lo + step, n_frames), dtype=dtype)[:, None]
        block = np.sin(t * freq + np.arange(n_features, dtype=dtype))
        block += 0.1 * rng.standard_normal(block.shape).astype(dtype)
        X[lo : lo + len(t)] = block
    X -= X.mean(axis=0)
    X /= X.std(axis=0)
    return X, np.repeat(np.arange(n_sequences), lengths)


def load_training_data(name, data_home, dtype=np.float64):
    """``(X, sequence_ids, source)``: "cmu35" or "mit", preprocessed, or
    (``source`` says so) a synthetic stand-in of its shape where it is missing."""
    try:
        bunch = (
            load_cmu35(data_home, subset="train")
            if name == "cmu35"
            else load_mit_walk(data_home)
        )
    except OSError as exc:
        shape = (2644, 62, 31) if name == "cmu35" else (3826, 49, 3)
        X, ids = synthetic_motion(*shape, dtype=dtype)
        return X, ids, f"synthetic stand-in ({type(exc).__name__}: no real data)"
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(bunch.skeleton)
        X = pre.fit_transform(bunch.data, sequence_ids=bunch.sequence_ids)
    source = "CMU subject 35, 31 training trials" if name == "cmu35" else "MIT walk"
    return np.asarray(X, dtype=dtype), np.asarray(bunch.sequence_ids), source


# ------------------------------------------------------------- model cache
# A fit runs the models' modules and utils/, never these (nor the packages'
# __init__ files, which only re-export): they are left out of the cache key,
# so that changing them does not refit.
_NOT_IN_A_FIT = set(
    "datasets preprocessing impute metrics model_selection plotting cli "
    "__main__.py".split()
)
# What fit keeps to judge generated motion by is computed in metrics.
_IN_A_FIT = {"metrics/_liveliness.py", "metrics/_generation.py"}


def model_code_digest():
    """A digest of the package's modules a fit can run, without docstrings."""
    digest = hashlib.sha1()
    for path in sorted(PACKAGE.rglob("*.py")):
        relative = path.relative_to(PACKAGE)
        in_a_fit = relative.parts[0] not in _NOT_IN_A_FIT
        if (
            in_a_fit or relative.as_posix() in _IN_A_FIT
        ) and path.name != "__init__.py":
            digest.update(str(relative).encode() + _code(path).encode())
    return digest.hexdigest()


def _code(path):
    """The module's syntax tree without its docstrings, as text."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if (
            isinstance(body, list)
            and body
            and isinstance(body[0], ast.Expr)
            and isinstance(body[0].value, ast.Constant)
            and isinstance(body[0].value.value, str)
        ):
            node.body = body[1:] or [ast.Pass()]
    return ast.dump(tree)


def cached_fit(model, X, sequence_ids, *, memory=False, **fit_params):
    """``(fitted model, fit seconds)``, cached (README.md: the key); with
    ``memory``, also the MB the fit added to the peak RSS (None: unknown)."""
    key = hashlib.sha1(model_code_digest().encode())
    key.update(type(model).__name__.encode())
    key.update(repr(sorted(model.get_params().items())).encode())
    key.update(np.ascontiguousarray(X).tobytes())
    key.update(np.ascontiguousarray(sequence_ids).tobytes())
    for name, value in sorted(fit_params.items()):
        key.update(name.encode() + np.ascontiguousarray(value).tobytes())
    path = CACHE / f"{type(model).__name__}_{key.hexdigest()[:24]}.joblib"
    memory_path = path.with_suffix(".MB")  # apart: older code reads the fit
    if path.exists():
        result = joblib.load(path)
    else:
        fit = partial(model.fit, X, sequence_ids=sequence_ids, **fit_params)
        with peak_memory() as added:
            result = (model, seconds(fit))
        path.parent.mkdir(parents=True, exist_ok=True)
        joblib.dump(result, path)
        memory_path.write_text(str(added.get("MB")))
    if not memory:
        return result
    added = memory_path.read_text() if memory_path.exists() else "None"
    return (*result, None if added == "None" else float(added))


@contextmanager
def peak_memory():
    """A dict whose ``"MB"`` is, on leaving, how far the block raised the peak
    resident memory above the memory at its start (Linux; absent elsewhere)."""
    added = {}
    try:  # freed heap pages back to the system, so that new ones count
        ctypes.CDLL("libc.so.6").malloc_trim(0)
        Path("/proc/self/clear_refs").write_text("5")  # the peak := the current

        def status(key):
            text = Path("/proc/self/status").read_text()
            return int(text.split(key + ":")[1].split()[0]) / 1024

        start = status("VmRSS")
    except (OSError, IndexError, AttributeError):
        yield added
        return
    yield added
    added["MB"] = status("VmHWM") - start


# ----------------------------------------------------------------- fill-in
def fitted_baselines(X, sequence_ids):
    """The simple imputers a user tries first, fitted on ``X``, by name."""
    ids = {"sequence_ids": sequence_ids}
    diagonal = AutoregressiveImputer(order=3, covariance_type="diag")
    return {
        "NearestNeighborImputer": NearestNeighborImputer().fit(X),
        "KNNImputer(1)": KNNImputer(n_neighbors=1).fit(X),
        "KNNImputer(5)": KNNImputer(n_neighbors=5).fit(X),
        "KNNImputer(10)": KNNImputer(n_neighbors=10).fit(X),
        "AR(3), full covariance": AutoregressiveImputer(order=3).fit(X, **ids),
        "AR(3), diagonal": diagonal.fit(X, **ids),
    }


def crbm_imputer(X, sequence_ids, seed, model_params=None, imputer_params=None):
    """``(CRBMImputer, fit seconds)`` around a cached ``ConditionalRBM`` fit;
    ``model_params``, ``imputer_params`` change the two's defaults."""
    model = ConditionalRBM(random_state=seed, **(model_params or {}))
    fitted, fit_seconds = cached_fit(model, X, sequence_ids)
    imputer = frozen_imputer(fitted, X, sequence_ids, seed, **(imputer_params or {}))
    return imputer, fit_seconds


def frozen_imputer(model, X, sequence_ids, seed, *labels, **params):
    """``CRBMImputer(**params)`` around the fitted ``model``, fitted on ``X``."""
    imputer = CRBMImputer(FrozenEstimator(model), random_state=seed, **params)
    return imputer.fit(X, *labels, sequence_ids=sequence_ids)


def fill_errors(imputers, cases):
    """The paper's error of every imputer (by name) on every case (by key)."""
    scores = compare_imputers(imputers, cases)
    return {
        name: {key: score["error"] for key, score in per_case.items()}
        for name, per_case in scores.items()
    }


def print_errors(errors, title, with_paper=False):
    """Print ``{method: {cell: fill-in error}}``, after the paper's if asked."""
    paper = PAPER_ERRORS.items() if with_paper else ()
    rows = [dict(method=m, **dict(zip(CELLS, e, strict=False))) for m, e in paper]
    rows += [dict(method=method, **cells) for method, cells in errors.items()]
    print_table(rows, ["method", *((c, c, ".2f") for c in CELLS)], title=title)


def log_ratio_row(name, log_ratios):
    """Mean over seeds (rows) of ``log(CRBM error / reference error)``, its
    interval, the verdict and the cells won."""
    mean, low, high = bootstrap_mean(log_ratios)
    verdict = "better" if high < 0 else "worse" if low > 0 else "not significant"
    won, of = int(np.sum(np.asarray(log_ratios) < 0)), int(np.size(log_ratios))
    return dict(
        cells=name, mean=mean, low=low, high=high, verdict=verdict, won=won, of=of
    )


def log_ratio_columns(reference="best baseline"):
    """The columns of :func:`log_ratio_row`'s table."""
    return [
        "cells",
        ("mean", f"mean log(CRBM / {reference})", "+.3f"),
        ("low", "95% low", "+.3f"),
        ("high", "95% high", "+.3f"),
        ("verdict", f"than the {reference}", "s"),
        ("won", "cells won", "d"),
        "of",
    ]


# ------------------------------------------------------------- statistics
def bootstrap_mean(values, n_resamples=10_000, level=0.95, seed=0):
    """``(mean, low, high)``: the mean of ``values`` and its percentile bootstrap
    interval, resampling the rows (seeds) with ``seed`` (an int or Generator)."""
    n = len(values)
    values = np.asarray(values, dtype=float).reshape(n, -1)
    rows = np.random.default_rng(seed).integers(n, size=(n_resamples, n))
    means = values[rows].mean(axis=(1, 2))
    low, high = np.quantile(means, [(1 - level) / 2, (1 + level) / 2])
    return float(values.mean()), float(low), float(high)


def interval_text(values, percent=False, spec=".2f", seed=0):
    """:func:`bootstrap_mean` as text: ``0.12 [0.10, 0.14]`` or ``12% [10, 14]``."""
    scale, spec = (100, ".0f") if percent else (1, spec)
    mean, low, high = (scale * v for v in bootstrap_mean(values, seed=seed))
    return f"{mean:{spec}}{'%' if percent else ''} [{low:{spec}}, {high:{spec}}]"


# ------------------------------------------------------------------ timing
@contextmanager
def threadpool_limits(threads):
    """``threads`` BLAS threads, for the libraries and the package's loops."""
    with (
        threadpoolctl.threadpool_limits(threads),
        sklearn_crbm.config_context(blas_threads=threads),
    ):
        yield


def seconds(func, repeats=1, sync=lambda: None):
    """Best wall-clock seconds of ``repeats`` calls (``sync``: wait for a device)."""
    times = []
    for _ in range(repeats):
        sync()
        start = time.perf_counter()
        func()
        sync()
        times.append(time.perf_counter() - start)
    return min(times)


def time_both(func):
    """Wall-clock and CPU seconds of ``func()`` (CPU: steadier when shared)."""
    wall, cpu = time.perf_counter(), time.process_time()
    func()
    return time.perf_counter() - wall, time.process_time() - cpu


def summary(times):
    return {"best": min(times), "median": statistics.median(times), "all": times}


def gemm_peak(dtype, n=2000, repeats=3):
    """``(wall, cpu)`` GFLOP/s of an ``n x n`` matrix product, best of ``repeats``."""
    rng = np.random.default_rng(0)
    a, b = (rng.standard_normal((n, n)).astype(dtype) for _ in range(2))
    out = np.empty((n, n), dtype)
    np.matmul(a, b, out=out)  # warm up
    times = [time_both(lambda: np.matmul(a, b, out=out)) for _ in range(repeats)]
    return tuple(2.0 * n**3 / min(t) / 1e9 for t in zip(*times, strict=True))


def cd_epoch_flops(n_frames, n_features, n_components, order, cd_steps=1):
    """FLOPs (2 m n k a product) of one CD-k epoch's matrix products, per frame
    dynamic biases, hidden input, k reconstructions and statistics."""
    d, h, k = n_features, n_components, order * n_features
    per_frame = k * (d + h) + d * h + cd_steps * 2 * d * h + 2 * d * h + (d + h) * k
    return 2 * n_frames * per_frame


def frames_with_history(sequence_ids, order):
    """The frames with ``order`` past frames in their sequence (runs of ids)."""
    ids = np.asarray(sequence_ids)
    starts = np.r_[0, np.flatnonzero(ids[1:] != ids[:-1]) + 1]
    lengths = np.diff(np.r_[starts, len(ids)])
    position = np.arange(len(ids)) - np.repeat(starts, lengths)
    return np.flatnonzero(position >= order)


def epoch_batch_sizes(n_frames, batch_size):
    """Minibatch sizes of one epoch: ``ceil(n / batch_size)`` batches, near-equal."""
    n_batches = -(-n_frames // batch_size)
    size, extra = divmod(n_frames, n_batches)
    return [size + 1] * extra + [size] * (n_batches - extra)


class EpochProducts:
    """The six matrix products of every minibatch of one CD-1 epoch, alone, in
    training's shapes and layouts: the time no BLAS-based fit can beat."""

    def __init__(self, n_features, n_components, order, batch_size, dtype):
        rng = np.random.default_rng(0)
        d, h, k, n = n_features, n_components, order * n_features, batch_size

        def random(*shape, order="C"):
            return np.asarray(rng.standard_normal(shape).astype(dtype), order=order)

        self.W, self.dynamic = random(h, d, order="F"), random(d + h, k, order="F")
        self.v, self.h, self.hist = random(n, d), random(n, h), random(n, k)
        self.vs, self.hs = random(2 * n, d), random(2 * n, h)
        self.delta = random(n, d + h)
        self.out_dyn, self.out_h = np.empty((n, d + h), dtype), np.empty((n, h), dtype)
        self.out_v = np.empty((n, d), dtype)
        self.out_w = np.empty((h, d), dtype, order="F")
        self.out_d = np.empty((d + h, k), dtype, order="F")

    def epoch(self, batch_sizes):
        for n in batch_sizes:
            np.matmul(self.hist[:n], self.dynamic.T, out=self.out_dyn[:n])
            np.matmul(self.v[:n], self.W.T, out=self.out_h[:n])
            np.matmul(self.h[:n], self.W, out=self.out_v[:n])
            np.matmul(self.v[:n], self.W.T, out=self.out_h[:n])
            np.matmul(self.hs[: 2 * n].T, self.vs[: 2 * n], out=self.out_w)
            np.matmul(self.delta[:n].T, self.hist[:n], out=self.out_d)


def child_json(arguments, env=None):
    """Run ``python *arguments`` in a fresh process; the JSON its last line prints."""
    result = subprocess.run(
        [sys.executable, *arguments], env=env, capture_output=True, text=True
    )
    if result.returncode != 0:
        raise RuntimeError(result.stderr[-3000:])
    return json.loads(result.stdout.strip().splitlines()[-1])


# ------------------------------------------------------------------ output
def print_table(rows, columns, title=None):
    """Print ``rows`` (dicts) as a Markdown table and return its text;
    ``columns``: ``(key, header, format)`` or a key (as header, unformatted)."""
    columns = [(c, c, "") if isinstance(c, str) else c for c in columns]
    header = [(name, str.ljust) for _, name, _ in columns]
    body = [[_cell(row.get(key), spec) for key, _, spec in columns] for row in rows]
    columns_text = zip(header, *body, strict=True)
    widths = [max(len(text) for text, _ in column) for column in columns_text]
    lines = [title] if title else []
    for i, line in enumerate([header, *body]):
        padded = (align(text, w) for (text, align), w in zip(line, widths, strict=True))
        lines.append("| " + " | ".join(padded) + " |")
        if i == 0:
            lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    text = "\n".join(lines)
    print(text, flush=True)
    return text


def _cell(value, spec):
    """The text of a table's cell and its alignment: text left, numbers right."""
    if value is None:
        return "", str.ljust
    return format(value, spec), str.ljust if isinstance(value, str) else str.rjust


def write_json(name, output, **payload):
    """Write ``payload``, the machine and package to ``output`` (or results/)."""
    path = Path(output) if output else RESULTS / f"{name}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    package = package_description()
    payload = dict(benchmark=name, package=package, machine=machine(), **payload)
    path.write_text(json.dumps(payload, indent=2, default=_jsonable))
    print(f"wrote {path}")
    return path


def _jsonable(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)
