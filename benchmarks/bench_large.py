"""Training and generation on a large corpus: CPU (1 and all threads) and GPU.

Issue 18's configuration: 10^6 synthetic frames x 100 channels (a real
corpus: ``bench_memory.py``); 1000 hidden units, order 3, float64 and
float32; best of ``--repeats``.  Rows: ``train`` (an epoch of
``partial_fit``, batch 100 and 1000, 1 and all threads), ``products`` (its
matrix products alone, ``/ products`` at most 1.3), ``sample`` (1000
sequences together), and the same on a CUDA GPU when PyTorch sees one.
Peak memory: ``tracemalloc`` (GPU: ``max_memory_allocated``).

Run from the repository root::

    python benchmarks/bench_large.py                       # about 10 minutes
    python benchmarks/bench_large.py --frames 100000 --train-frames 10000
"""

import argparse
import os

os.environ.setdefault("SCIPY_ARRAY_API", "1")  # before SciPy is imported

import tracemalloc  # noqa: E402
from functools import partial  # noqa: E402

import _common as common  # noqa: E402
import numpy as np  # noqa: E402
import sklearn  # noqa: E402

from sklearn_crbm import ConditionalRBM  # noqa: E402


def first_sequences(ids, n_frames):
    """Rows of the first whole sequences holding at least ``n_frames`` frames."""
    stops = np.r_[np.flatnonzero(ids[1:] != ids[:-1]) + 1, len(ids)]
    return slice(0, int(stops[min(np.searchsorted(stops, n_frames), len(stops) - 1)]))


def model(args, batch_size):
    params = dict(order=args.order, batch_size=batch_size, n_iter=1, random_state=0)
    return ConditionalRBM(args.components, **params)


def started(args, batch_size, X, sequence_ids):
    """A new model after its first epoch, on ``X``."""
    return model(args, batch_size).partial_fit(X, sequence_ids=sequence_ids)


def peak_mb(func):
    """Peak MB ``func`` allocates (tracemalloc: run apart from timed calls)."""
    tracemalloc.start()
    try:
        func()
        return tracemalloc.get_traced_memory()[1] / 1e6
    finally:
        tracemalloc.stop()


def rate_row(keys, task, frames, elapsed, flops=None, **measured):
    """A row of the table: ``frames`` (of ``flops``) processed in ``elapsed`` s."""
    rate = dict(frames=frames, seconds=elapsed, frames_per_s=frames / elapsed)
    if flops is not None:
        rate["gflops"] = flops / elapsed / 1e9
    return dict(keys, task=task, **rate, **measured)


def cpu_rows(args, X, ids, dtype, threads):
    part = first_sequences(ids, args.train_frames)
    X_train, ids_train = X[part], ids[part]
    valid = common.frames_with_history(ids_train, args.order)
    flops = common.cd_epoch_flops(len(valid), X.shape[1], args.components, args.order)
    # memory: a short run of the same call (its buffers do not grow with X)
    short = first_sequences(ids, 5000)
    keys = dict(dtype=np.dtype(dtype).name, threads=threads)
    with common.threadpool_limits(threads):  # what threads give a large product
        gflops = common.gemm_peak(dtype)[0]
    rows = [dict(keys, device="cpu", task="gemm 2000", gflops=gflops)]
    for batch_size in args.batch_sizes:
        sizes = common.epoch_batch_sizes(len(valid), batch_size)
        products = common.EpochProducts(
            X.shape[1], args.components, args.order, batch_size, dtype
        )
        start = partial(started, args, batch_size, X[short], ids[short])
        with common.threadpool_limits(threads):
            estimator = start()  # warmed up: started on a few frames, timed on many
            products.epoch(sizes[:5])
            train = partial(estimator.partial_fit, X_train, sequence_ids=ids_train)
            epoch = partial(products.epoch, sizes)
            # interleaved: load changes hit both
            pairs = [
                (common.seconds(train), common.seconds(epoch))
                for _ in range(args.repeats)
            ]
            train_s, products_s = (min(t) for t in zip(*pairs, strict=True))
            peak = peak_mb(start)
        batch, n = dict(keys, batch=batch_size, device="cpu"), len(valid)
        over = train_s / products_s
        extra = dict(peak_mb=peak, over_products=over)
        rows.append(rate_row(batch, "train", n, train_s, flops, **extra))
        rows.append(rate_row(batch, "products", n, products_s, flops))
    generate = partial(estimator.sample, n_sequences=args.sequences, random_state=0)
    with common.threadpool_limits(threads):
        elapsed = common.seconds(partial(generate, args.gen_frames), args.repeats)
        peak = peak_mb(partial(generate, 1))
    frames = args.gen_frames * args.sequences
    cpu = dict(keys, device="cpu")
    rows.append(rate_row(cpu, "sample", frames, elapsed, peak_mb=peak))
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
    cuda = torch.cuda
    part = first_sequences(ids, args.gpu_train_frames)
    ids_train = ids[part]
    valid = common.frames_with_history(ids_train, args.order)
    keys = dict(dtype=np.dtype(dtype).name, threads=None)
    rows = []
    with sklearn.config_context(array_api_dispatch=True):
        X_gpu = torch.asarray(X[part], device="cuda")
        started(args, 100, X_gpu[:5000], ids_train[:5000])  # warm up
        for batch_size in args.batch_sizes:
            cuda.reset_peak_memory_stats()
            estimator = model(args, batch_size)
            train = partial(estimator.partial_fit, X_gpu, sequence_ids=ids_train)
            elapsed = common.seconds(train, args.repeats, cuda.synchronize)
            batch = dict(keys, batch=batch_size, device=cuda.get_device_name())
            peak = cuda.max_memory_allocated() / 1e6
            rows.append(rate_row(batch, "train", len(valid), elapsed, peak_mb=peak))
        cuda.reset_peak_memory_stats()
        generate = partial(estimator.sample, n_sequences=args.sequences, random_state=0)
        generate = partial(generate, args.gen_frames)
        elapsed = common.seconds(generate, args.repeats, cuda.synchronize)
    frames, peak = args.gen_frames * args.sequences, cuda.max_memory_allocated() / 1e6
    device = dict(keys, device=cuda.get_device_name())
    rows.append(rate_row(device, "sample", frames, elapsed, peak_mb=peak))
    return rows


def speedups(rows):
    """GPU frames/s over the best CPU row of the same task, dtype and batch."""

    def kind(row):
        return dict(task=row["task"], dtype=row["dtype"], batch=row.get("batch"))

    cpu = [row for row in rows if row["device"] == "cpu" and "frames_per_s" in row]
    return [
        dict(kind(gpu), speedup=gpu["frames_per_s"] / max(fast))
        for gpu in rows
        if gpu["device"] != "cpu"
        and (fast := [r["frames_per_s"] for r in cpu if kind(r) == kind(gpu)])
    ]


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add = parser.add_argument
    add("--frames", type=int, default=1_000_000)
    add("--features", type=int, default=100)
    add("--components", type=int, default=1000)
    add("--order", type=int, default=3)
    add("--batch-sizes", type=int, nargs="+", default=[100, 1000])
    add("--train-frames", type=int, default=20_000, help="CPU training frames")
    add("--gpu-train-frames", type=int, default=1_000_000, help="GPU training frames")
    add("--sequences", type=int, default=1000)
    add("--gen-frames", type=int, default=3)
    all_cores = sorted({1, os.cpu_count() or 1})
    add("--threads", type=int, nargs="+", default=all_cores, help="of the CPU rows")
    add("--dtypes", nargs="+", default=["float64", "float32"])
    add("--repeats", type=int, default=3, help="timed calls per row (best is kept)")
    add("--output", default=None)
    args = parser.parse_args(argv)
    common.announce()
    torch, no_gpu = cuda_device()
    rows, corpora = [], {}
    for dtype_name in args.dtypes:
        dtype = np.dtype(dtype_name).type
        n_sequences = max(1, args.frames // 1000)
        X, ids = common.synthetic_motion(args.frames, args.features, n_sequences, dtype)
        corpora[dtype_name] = f"synthetic, {args.frames} x {args.features}"
        for threads in args.threads:
            rows.extend(cpu_rows(args, X, ids, dtype, threads))
        if torch is not None:
            rows.extend(gpu_rows(args, torch, X, ids, dtype))
    columns = ["task", "device", "dtype", "threads", "batch", "frames",
               ("seconds", "s", ".2f"), ("frames_per_s", "frames/s", ",.0f"),
               ("gflops", "GFLOP/s", ".1f"), ("over_products", "/ products", ".2f"),
               ("peak_mb", "peak MB", ",.0f")]  # fmt: skip
    title = (
        f"{corpora[args.dtypes[0]]}, {args.components} hidden units, order "
        f"{args.order}; {args.sequences} sequences generated together"
    )
    common.print_table(rows, columns, title=title)
    gains = speedups(rows)
    if no_gpu:
        print(f"No GPU rows: {no_gpu}.")
    else:
        common.print_table(
            gains, ["task", "dtype", "batch", ("speedup", "GPU / best CPU", ".1f")]
        )
    gpu = no_gpu or torch.cuda.get_device_name()
    payload = dict(config=vars(args), corpus=corpora, gpu=gpu, rows=rows)
    common.write_json("bench_large", args.output, **payload, gpu_over_cpu=gains)


if __name__ == "__main__":
    main()
