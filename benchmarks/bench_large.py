"""Training and generation on a large corpus: CPU (1 and all threads) and GPU.

Issue 18's configuration: a synthetic corpus of 10^6 frames x 100 channels
(``_common.synthetic_motion``, 1000 sequences of 1000 frames, standardised),
or a real corpus from ``--corpus FOLDER`` (every BVH file of the folder, or
every AMC file with its ASF; preprocessed as the demo does), a CRBM with
1000 hidden units and order 3, in float64 and float32.

Rows, the best of ``--repeats`` timed calls (a run takes minutes, not hours):

- ``train``: ``partial_fit`` (one epoch, CD-1) on the first ``--train-frames``
  frames of the corpus, in whole sequences, batch sizes 100 and 1000, with 1
  BLAS thread and with all of them (``sklearn_crbm.config_context(
  blas_threads=...)``): frames per second;
- ``products``: the six matrix products of the same minibatches alone
  (as in ``bench_train.py``), the ceiling of any implementation
  that leaves them to BLAS; ``train / products`` is the overhead the issue
  bounds at 1.3;
- ``sample``: ``sample`` of ``--gen-frames`` frames for 1000 sequences
  together (30 Gibbs steps per frame): generated frames per second;
- the same on a CUDA GPU through scikit-learn's array API (PyTorch tensors,
  ``sklearn.set_config(array_api_dispatch=True)``) when PyTorch sees one;
  the table says so when none is there.

Peak memory: the largest traced allocation (``tracemalloc``; numpy and the
package report theirs) above what was held before each row, and for GPU rows
``torch.cuda.max_memory_allocated``.

Run from the repository root (``SCIPY_ARRAY_API=1`` is set here for the GPU
rows)::

    python benchmarks/bench_large.py                       # about 10 minutes
    python benchmarks/bench_large.py --frames 100000 --train-frames 10000
    python benchmarks/bench_large.py --corpus ../shared/data/cmu_subject35

Prints a table and writes ``benchmarks/results/bench_large.json``.
"""

import argparse
import os

os.environ.setdefault("SCIPY_ARRAY_API", "1")  # before SciPy is imported

import math  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402

import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from _common import (  # noqa: E402
    EpochProducts,
    announce,
    cd_epoch_flops,
    epoch_batch_sizes,
    frames_with_history,
    gemm_peak,
    print_table,
    synthetic_motion,
    threadpool_limits,
    write_json,
)

from sklearn_crbm import ConditionalRBM  # noqa: E402


def load_corpus(args, dtype):
    """``(X, sequence_ids, description)`` of the corpus, in ``dtype``."""
    if args.corpus is None:
        n_sequences = max(1, args.frames // 1000)
        X, ids = synthetic_motion(args.frames, args.features, n_sequences, dtype)
        return X, ids, f"synthetic, {args.frames} x {args.features}"
    from sklearn_crbm.datasets import read_amc_folder, read_bvh_folder
    from sklearn_crbm.preprocessing import make_motion_preprocessor

    folder = os.path.expanduser(args.corpus)
    try:
        bunch = read_bvh_folder(folder, pattern="**/*.bvh")
    except FileNotFoundError:
        bunch = read_amc_folder(folder, pattern="**/*.amc", frame_rate=30.0)
    with sklearn.config_context(enable_metadata_routing=True):
        pre = make_motion_preprocessor(bunch.skeleton)
        X = pre.fit_transform(bunch.data, sequence_ids=bunch.sequence_ids)
    X = np.ascontiguousarray(X, dtype=dtype)
    return X, np.asarray(bunch.sequence_ids), f"{folder}, {X.shape[0]} x {X.shape[1]}"


def first_sequences(ids, n_frames):
    """Rows of the first whole sequences holding at least ``n_frames`` frames."""
    stops = np.r_[np.flatnonzero(ids[1:] != ids[:-1]) + 1, len(ids)]
    return slice(0, int(stops[min(np.searchsorted(stops, n_frames), len(stops) - 1)]))


def model(args, batch_size, random_state=0):
    return ConditionalRBM(
        args.components,
        order=args.order,
        batch_size=batch_size,
        n_iter=1,
        random_state=random_state,
    )


def peak_mb(func):
    """Peak memory that ``func`` allocates, in MB (numpy reports to tracemalloc).

    Run apart from the timed call: tracing slows allocation.
    """
    tracemalloc.start()
    try:
        func()
        return tracemalloc.get_traced_memory()[1] / 1e6
    finally:
        tracemalloc.stop()


def timed(func, repeats=1, sync=lambda: None):
    """Best wall-clock seconds of ``repeats`` calls of ``func``."""
    times = []
    for _ in range(repeats):
        sync()
        start = time.perf_counter()
        func()
        sync()
        times.append(time.perf_counter() - start)
    return min(times)


def cpu_rows(args, X, ids, dtype, threads):
    part = first_sequences(ids, args.train_frames)
    X_train, ids_train = X[part], ids[part]
    # memory: a short run of the same call (its buffers do not grow with X)
    short = first_sequences(ids, 5000)
    with threadpool_limits(threads):  # how much the threads give on a large product
        gemm = gemm_peak(dtype, 2000)[0]
    rows = [
        dict(
            dtype=np.dtype(dtype).name,
            threads=threads,
            device="cpu",
            task="gemm 2000",
            gflops=gemm,
        )
    ]
    trained = None
    for batch_size in args.batch_sizes:
        valid = frames_with_history(ids_train, args.order)
        sizes = epoch_batch_sizes(len(valid), batch_size)
        products = EpochProducts(
            X.shape[1], args.components, args.order, batch_size, dtype
        )
        with threadpool_limits(threads):
            # warmed up: started on a few frames, then timed on many
            estimator = model(args, batch_size)
            estimator.partial_fit(X[short], sequence_ids=ids[short])
            products.epoch(sizes[:5])
            seconds = products_seconds = math.inf
            for _ in range(args.repeats):  # interleaved: load changes hit both
                seconds = min(
                    seconds,
                    timed(
                        lambda e=estimator: e.partial_fit(
                            X_train, sequence_ids=ids_train
                        )
                    ),
                )
                products_seconds = min(
                    products_seconds, timed(lambda p=products, s=sizes: p.epoch(s))
                )
            peak = peak_mb(
                lambda b=batch_size: model(args, b).partial_fit(
                    X[short], sequence_ids=ids[short]
                )
            )
        common = dict(dtype=np.dtype(dtype).name, threads=threads, batch=batch_size)
        flops = cd_epoch_flops(len(valid), X.shape[1], args.components, args.order)
        rows.append(
            dict(
                common,
                device="cpu",
                task="train",
                frames=len(valid),
                seconds=seconds,
                frames_per_s=len(valid) / seconds,
                gflops=flops / seconds / 1e9,
                peak_mb=peak,
                over_products=seconds / products_seconds,
            )
        )
        rows.append(
            dict(
                common,
                device="cpu",
                task="products",
                frames=len(valid),
                seconds=products_seconds,
                frames_per_s=len(valid) / products_seconds,
                gflops=flops / products_seconds / 1e9,
            )
        )
        trained = estimator
    with threadpool_limits(threads):
        seconds = timed(
            lambda: trained.sample(
                args.gen_frames, n_sequences=args.sequences, random_state=0
            ),
            args.repeats,
        )
        peak = peak_mb(
            lambda: trained.sample(1, n_sequences=args.sequences, random_state=0)
        )
    rows.append(
        dict(
            dtype=np.dtype(dtype).name,
            threads=threads,
            device="cpu",
            task="sample",
            frames=args.gen_frames * args.sequences,
            seconds=seconds,
            frames_per_s=args.gen_frames * args.sequences / seconds,
            peak_mb=peak,
        )
    )
    return rows


def cuda_device():
    """``(torch, None)`` with a CUDA device, else ``(None, why not)``."""
    try:
        import torch
    except ImportError:
        return None, "PyTorch is not installed"
    if not torch.cuda.is_available():
        return None, f"PyTorch {torch.__version__} sees no CUDA device"
    return torch, None


def gpu_rows(args, torch, X, ids, dtype):
    rows = []
    sync = torch.cuda.synchronize
    part = first_sequences(ids, args.gpu_train_frames)
    ids_train = ids[part]
    valid = frames_with_history(ids_train, args.order)
    with sklearn.config_context(array_api_dispatch=True):
        X_gpu = torch.asarray(X[part], device="cuda")
        model(args, 100).partial_fit(X_gpu[:5000], sequence_ids=ids_train[:5000])
        trained = None
        for batch_size in args.batch_sizes:
            torch.cuda.reset_peak_memory_stats()
            estimator = model(args, batch_size)
            seconds = timed(
                lambda e=estimator: e.partial_fit(X_gpu, sequence_ids=ids_train),
                args.repeats,
                sync,
            )
            rows.append(
                dict(
                    dtype=np.dtype(dtype).name,
                    threads=None,
                    batch=batch_size,
                    device=torch.cuda.get_device_name(),
                    task="train",
                    frames=len(valid),
                    seconds=seconds,
                    frames_per_s=len(valid) / seconds,
                    peak_mb=torch.cuda.max_memory_allocated() / 1e6,
                )
            )
            trained = estimator
        torch.cuda.reset_peak_memory_stats()
        seconds = timed(
            lambda: trained.sample(
                args.gen_frames, n_sequences=args.sequences, random_state=0
            ),
            args.repeats,
            sync,
        )
    rows.append(
        dict(
            dtype=np.dtype(dtype).name,
            threads=None,
            device=torch.cuda.get_device_name(),
            task="sample",
            frames=args.gen_frames * args.sequences,
            seconds=seconds,
            frames_per_s=args.gen_frames * args.sequences / seconds,
            peak_mb=torch.cuda.max_memory_allocated() / 1e6,
        )
    )
    return rows


def speedups(rows):
    """GPU frames/s over the best CPU row of the same task, dtype and batch."""
    result = []
    for gpu in (r for r in rows if r["device"] != "cpu"):
        cpu = [
            r["frames_per_s"]
            for r in rows
            if r["device"] == "cpu"
            and r["task"] == gpu["task"]
            and r["dtype"] == gpu["dtype"]
            and r.get("batch") == gpu.get("batch")
        ]
        if cpu:
            result.append(
                dict(
                    task=gpu["task"],
                    dtype=gpu["dtype"],
                    batch=gpu.get("batch"),
                    speedup=gpu["frames_per_s"] / max(cpu),
                )
            )
    return result


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--frames", type=int, default=1_000_000)
    parser.add_argument("--features", type=int, default=100)
    parser.add_argument("--corpus", default=None, help="folder of BVH or AMC files")
    parser.add_argument("--components", type=int, default=1000)
    parser.add_argument("--order", type=int, default=3)
    parser.add_argument("--batch-sizes", type=int, nargs="+", default=[100, 1000])
    parser.add_argument(
        "--train-frames",
        type=int,
        default=20_000,
        help="CPU training is timed on the first sequences holding this many frames",
    )
    parser.add_argument(
        "--gpu-train-frames",
        type=int,
        default=1_000_000,
        help="GPU training is timed on this many frames (an epoch of the corpus)",
    )
    parser.add_argument("--sequences", type=int, default=1000)
    parser.add_argument("--gen-frames", type=int, default=3)
    parser.add_argument(
        "--threads",
        type=int,
        nargs="+",
        default=sorted({1, os.cpu_count() or 1}),
        help="BLAS thread counts of the CPU rows (default: 1 and all cores)",
    )
    parser.add_argument("--dtypes", nargs="+", default=["float64", "float32"])
    parser.add_argument(
        "--repeats", type=int, default=3, help="timed calls per row (best is kept)"
    )
    parser.add_argument("--output", default=None)
    args = parser.parse_args(argv)
    announce()
    torch, no_gpu = cuda_device()
    rows, corpora = [], {}
    for dtype_name in args.dtypes:
        dtype = np.dtype(dtype_name).type
        X, ids, corpora[dtype_name] = load_corpus(args, dtype)
        for threads in args.threads:
            rows.extend(cpu_rows(args, X, ids, dtype, threads))
        if torch is not None:
            rows.extend(gpu_rows(args, torch, X, ids, dtype))
    columns = [
        ("task", "task", "s"),
        ("device", "device", "s"),
        ("dtype", "dtype", "s"),
        ("threads", "threads", "d"),
        ("batch", "batch", "d"),
        ("frames", "frames", "d"),
        ("seconds", "s", ".2f"),
        ("frames_per_s", "frames/s", ",.0f"),
        ("gflops", "GFLOP/s", ".1f"),
        ("over_products", "/ products", ".2f"),
        ("peak_mb", "peak MB", ",.0f"),
    ]
    title = (
        f"{corpora[args.dtypes[0]]}, {args.components} hidden units, order "
        f"{args.order}; {args.sequences} sequences generated together"
    )
    print_table(rows, columns, title=title)
    gains = speedups(rows)
    if no_gpu:
        print(f"No GPU rows: {no_gpu}.")
    else:
        print_table(
            gains,
            [
                ("task", "task", "s"),
                ("dtype", "dtype", "s"),
                ("batch", "batch", "d"),
                ("speedup", "GPU / best CPU", ".1f"),
            ],
        )
    write_json(
        "bench_large",
        {
            "config": vars(args),
            "corpus": corpora,
            "gpu": no_gpu or torch.cuda.get_device_name(),
            "rows": rows,
            "gpu_over_cpu": gains,
        },
        args.output,
    )


if __name__ == "__main__":
    main()
