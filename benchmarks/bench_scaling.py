"""How the cost of a training epoch grows with frames, order and hidden units.

Three sweeps around the paper's configuration (62 dimensions, 200 hidden
units, order 3, minibatches of 100, CD-1, one BLAS thread):

- frames: 10^3 ... 10^6 synthetic standardised frames in sequences of 100
  (``--frames``); the cost per frame should stay flat (minibatches gather
  their history by indexing; nothing grows with the data but the data);
- order: 1 ... 12 (``--orders``) on CMU-35-sized data (2644 frames);
- hidden units: 50 ... 800 (``--components``) on CMU-35-sized data.

Each row gives ms per epoch (best of ``--repeats`` fits of ``--epochs``
epochs, the one-off input checks of ``fit`` included) in wall-clock and
process CPU time, and from the CPU time (steadier on a shared machine, one
BLAS thread) microseconds per training frame, GFLOP/s from the shapes of
the matrix products, and the fraction of a large matrix product's rate
measured in the same run with the same clock.

Run from the repository root::

    python benchmarks/bench_scaling.py                       # about two minutes
    python benchmarks/bench_scaling.py --dtypes float64 float32 --repeats 5

Prints a table and writes ``benchmarks/results/bench_scaling.json``.
"""

import argparse

from _common import (
    PAPER,
    add_common_arguments,
    cd_epoch_flops,
    gemm_peak,
    print_table,
    summary,
    synthetic_motion,
    threadpool_limits,
    time_both,
    write_json,
)

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.utils._sequences import check_sequence_ids


def time_epochs(X, ids, n_components, order, epochs, repeats):
    n_train = len(check_sequence_ids(ids, len(X)).valid_frames(order))
    walls, cpus = [], []
    for _ in range(repeats):
        model = ConditionalRBM(n_components, order=order, n_iter=epochs, random_state=0)
        wall, cpu = time_both(lambda model=model: model.fit(X, sequence_ids=ids))
        walls.append(wall / epochs)
        cpus.append(cpu / epochs)
    flops = cd_epoch_flops(n_train, X.shape[1], n_components, order)
    best, best_cpu = min(walls), min(cpus)
    return {
        "n_train_frames": n_train,
        "ms_per_epoch": 1e3 * best,
        "cpu_ms_per_epoch": 1e3 * best_cpu,
        "cpu_us_per_frame": 1e6 * best_cpu / n_train,
        "cpu_gflops": flops / best_cpu / 1e9,
        "times": {"wall": summary(walls), "cpu": summary(cpus)},
    }


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_common_arguments(parser)
    parser.set_defaults(threads=[1], dtypes=["float32"], repeats=2)
    parser.add_argument(
        "--frames", type=int, nargs="+", default=[1_000, 10_000, 100_000, 1_000_000]
    )
    parser.add_argument("--orders", type=int, nargs="+", default=[1, 2, 3, 6, 12])
    parser.add_argument(
        "--components", type=int, nargs="+", default=[50, 100, 200, 400, 800]
    )
    parser.add_argument(
        "--epochs", type=int, default=3, help="epochs per fit (small data)"
    )
    args = parser.parse_args(argv)

    d, h, order = PAPER["n_features"], PAPER["n_components"], PAPER["order"]
    rows = []
    for dtype in args.dtypes:
        for threads in args.threads:
            with threadpool_limits(threads):
                peak = gemm_peak(dtype, clock="both")[1]  # CPU clock, like the rows

                def add(
                    sweep,
                    value,
                    X,
                    ids,
                    n_components,
                    order,
                    epochs,
                    repeats,
                    dtype=dtype,
                    threads=threads,
                    peak=peak,
                ):
                    row = time_epochs(X, ids, n_components, order, epochs, repeats)
                    row.update(
                        sweep=sweep,
                        value=value,
                        dtype=dtype,
                        threads=threads,
                        n_components=n_components,
                        order=order,
                        percent_of_peak=100 * row["cpu_gflops"] / peak,
                        peak_gflops=peak,
                    )
                    rows.append(row)
                    print(
                        f"  {sweep}={value}: {row['ms_per_epoch']:.1f} ms/epoch",
                        flush=True,
                    )

                for n in args.frames:
                    X, ids = synthetic_motion(n, d, max(1, n // 100), dtype=dtype)
                    big = n >= 100_000  # one epoch, one fit: seconds each
                    add(
                        "frames",
                        n,
                        X,
                        ids,
                        h,
                        order,
                        1 if big else args.epochs,
                        1 if big else args.repeats,
                    )
                    del X, ids
                X, ids = synthetic_motion(2644, d, 31, dtype=dtype)
                for q in args.orders:
                    add("order", q, X, ids, h, q, args.epochs, args.repeats)
                for k in args.components:
                    add("n_components", k, X, ids, k, order, args.epochs, args.repeats)
    columns = [
        ("sweep", "sweep", "s"),
        ("value", "value", ",d"),
        ("dtype", "dtype", "s"),
        ("n_train_frames", "train frames", ",d"),
        ("ms_per_epoch", "ms/epoch", ",.1f"),
        ("cpu_ms_per_epoch", "CPU ms/epoch", ",.1f"),
        ("cpu_us_per_frame", "CPU us/frame", ".2f"),
        ("cpu_gflops", "GFLOP/s (CPU)", ".1f"),
        ("percent_of_peak", "% of peak (CPU)", ".0f"),
    ]
    table = print_table(
        rows,
        columns,
        title="Training cost per epoch (62 dims; 200 hidden, order 3 unless swept)",
    )
    write_json(
        "bench_scaling", {"args": vars(args), "rows": rows, "table": table}, args.output
    )


if __name__ == "__main__":
    main()
