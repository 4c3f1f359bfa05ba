"""Helpers shared by the speed and memory benchmarks (``bench_*.py``).

Timing, the matrix-multiply peak of this machine, FLOP counts of one CD epoch,
the paper's data (with a synthetic stand-in of the same shape when the data
is missing), tables and JSON.  Not part of the package.
"""

import json
import os
import platform
import statistics
import sys
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import sklearn
import threadpoolctl
from threadpoolctl import threadpool_info

import sklearn_crbm

REPO = Path(__file__).resolve().parents[1]
RESULTS = REPO / "benchmarks" / "results"
DEFAULT_DATA_HOME = REPO.parent / "shared" / "data"

# The paper's configuration (CMU 35 after preprocessing).
PAPER = dict(n_features=62, n_components=200, order=3, batch_size=100)
CMU_TRAIN_FRAMES, CMU_TRAIN_SEQUENCES = 2644, 31


def add_common_arguments(parser):
    parser.add_argument(
        "--data-home",
        default=os.environ.get("SKLEARN_CRBM_DATA", str(DEFAULT_DATA_HOME)),
        help="folder holding the mocap data (default: ../shared/data)",
    )
    parser.add_argument(
        "--repeats", type=int, default=5, help="timed repetitions (best and median)"
    )
    parser.add_argument(
        "--threads", type=int, nargs="+", default=[1, 2], help="BLAS thread counts"
    )
    parser.add_argument(
        "--dtypes", nargs="+", default=["float64", "float32"], help="dtypes to run"
    )
    parser.add_argument("--output", default=None, help="JSON file to write")
    return parser


# ------------------------------------------------------------------ timing


@contextmanager
def threadpool_limits(threads):
    """``threads`` BLAS threads, for the libraries and the package's loops alike.

    The package picks its own thread count inside its methods
    (``sklearn_crbm.set_config``); a benchmark row that says 2 threads must
    run them with 2.
    """
    with (
        threadpoolctl.threadpool_limits(threads),
        sklearn_crbm.config_context(blas_threads=threads),
    ):
        yield


def time_call(func, repeats, timer=time.perf_counter):
    """Run ``func`` ``repeats`` times; return the list of durations (seconds)."""
    times = []
    for _ in range(repeats):
        start = timer()
        func()
        times.append(timer() - start)
    return times


def summary(times):
    return {"best": min(times), "median": statistics.median(times), "all": times}


def time_both(func):
    """Wall-clock and process CPU seconds of one call of ``func``.

    With one BLAS thread the CPU time leaves out the time the process waited
    for a core, which makes it the steadier measure on a shared machine.
    """
    wall, cpu = time.perf_counter(), time.process_time()
    func()
    return time.perf_counter() - wall, time.process_time() - cpu


def gemm_peak(dtype, n=2000, repeats=3, clock="wall"):
    """GFLOP/s of one large ``n x n`` matrix product (best of ``repeats``).

    Run it under the same ``threadpool_limits`` as what it is compared with.
    ``clock="both"`` returns ``(wall_gflops, cpu_gflops)``.
    """
    rng = np.random.default_rng(0)
    a = rng.standard_normal((n, n)).astype(dtype)
    b = rng.standard_normal((n, n)).astype(dtype)
    out = np.empty((n, n), dtype)
    np.matmul(a, b, out=out)  # warm up
    times = [time_both(lambda: np.matmul(a, b, out=out)) for _ in range(repeats)]
    wall, cpu = (2.0 * n**3 / min(t) / 1e9 for t in zip(*times, strict=True))
    return (wall, cpu) if clock == "both" else wall


def cd_epoch_flops(n_train_frames, n_features, n_components, order, cd_steps=1):
    """FLOPs of the matrix products of one CD-k epoch (2 m n k per product).

    Per frame: the dynamic biases (history x [A; B]), the positive hidden
    input (v W^T), per step the reconstruction (h W) and the negative hidden
    input (v_recon W^T), the W statistics (two products) and the directed
    statistics ([v - v_recon, h_data - h_recon]^T x history).  Elementwise
    work, random numbers and updates are not counted.
    """
    d, h, k = n_features, n_components, order * n_features
    per_frame = 2 * (
        k * (d + h) + d * h + cd_steps * 2 * d * h + 2 * d * h + (d + h) * k
    )
    return per_frame * n_train_frames


def blas_description():
    info = threadpool_info()
    return [
        {
            k: entry.get(k)
            for k in ("internal_api", "version", "architecture", "num_threads")
        }
        for entry in info
    ]


def machine():
    return {
        "platform": platform.platform(),
        "processor": _cpu_name(),
        "cpu_count": os.cpu_count(),
        "python": sys.version.split()[0],
        "numpy": np.__version__,
        "scikit-learn": sklearn.__version__,
        "blas": blas_description(),
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


def synthetic_motion(n_frames, n_features, n_sequences, dtype=np.float64, seed=0):
    """Standardised smooth random motion in long format (a stand-in for mocap)."""
    rng = np.random.default_rng(seed)
    lengths = np.full(n_sequences, n_frames // n_sequences)
    lengths[: n_frames - lengths.sum()] += 1
    X = np.empty((n_frames, n_features), dtype=dtype)
    # sinusoids with random phases and frequencies plus noise, chunk by chunk
    freq = rng.uniform(0.05, 0.4, n_features).astype(dtype)
    step = 100_000
    for lo in range(0, n_frames, step):
        t = np.arange(lo, min(lo + step, n_frames), dtype=dtype)[:, None]
        block = np.sin(t * freq + np.arange(n_features, dtype=dtype))
        block += 0.1 * rng.standard_normal(block.shape).astype(dtype)
        X[lo : lo + len(t)] = block
    X -= X.mean(axis=0)
    X /= X.std(axis=0)
    return X, np.repeat(np.arange(n_sequences), lengths)


def load_training_data(name, data_home, dtype=np.float64):
    """The preprocessed training data of ``name`` ("cmu35" or "mit").

    Returns ``(X, sequence_ids, source)``; ``source`` says whether real data
    was used or, when it is missing, a synthetic stand-in of the same shape.
    """
    try:
        import sklearn as sk

        from sklearn_crbm.datasets import load_cmu35, load_mit_walk
        from sklearn_crbm.preprocessing import make_motion_preprocessor

        bunch = (
            load_cmu35(data_home, subset="train")
            if name == "cmu35"
            else load_mit_walk(data_home)
        )
        with sk.config_context(enable_metadata_routing=True):
            pre = make_motion_preprocessor(bunch.skeleton)
            X = pre.fit_transform(bunch.data, sequence_ids=bunch.sequence_ids)
        source = (
            "CMU subject 35, 31 training trials" if name == "cmu35" else "MIT walking"
        )
        return np.asarray(X, dtype=dtype), np.asarray(bunch.sequence_ids), source
    except (ImportError, OSError) as exc:
        shape = (2644, 62, 31) if name == "cmu35" else (3826, 49, 3)
        X, ids = synthetic_motion(*shape, dtype=dtype)
        return (
            X,
            ids,
            f"synthetic stand-in ({exc.__class__.__name__}: real data missing)",
        )


# ----------------------------------------------------------------- output


def print_table(rows, columns, title=None):
    """Print ``rows`` (dicts) as an aligned text table with the given columns.

    ``columns`` is a list of ``(key, header, format)``.
    """
    cells = [[header for _, header, _ in columns]]
    for row in rows:
        cells.append(
            [
                ("" if row.get(key) is None else format(row[key], fmt))
                for key, _, fmt in columns
            ]
        )
    widths = [max(len(r[i]) for r in cells) for i in range(len(columns))]
    lines = []
    if title:
        lines.append(title)
    for i, r in enumerate(cells):
        lines.append(
            "| "
            + " | ".join(
                c.rjust(w) if i else c.ljust(w) for c, w in zip(r, widths, strict=True)
            )
            + " |"
        )
        if i == 0:
            lines.append("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    text = "\n".join(lines)
    print(text, flush=True)
    return text


def write_json(name, payload, output=None):
    path = Path(output) if output else RESULTS / f"{name}.json"
    path.parent.mkdir(parents=True, exist_ok=True)
    payload = {"benchmark": name, "machine": machine(), **payload}
    path.write_text(json.dumps(payload, indent=2, default=_jsonable))
    print(f"wrote {path}")
    return path


def _jsonable(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)


__all__ = [
    "PAPER",
    "add_common_arguments",
    "cd_epoch_flops",
    "gemm_peak",
    "load_training_data",
    "machine",
    "print_table",
    "summary",
    "synthetic_motion",
    "threadpool_limits",
    "time_both",
    "time_call",
    "write_json",
]
