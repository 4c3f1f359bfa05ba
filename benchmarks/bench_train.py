"""Training speed of ConditionalRBM against the machine's matrix-multiply peak.

The paper's configuration: CMU subject 35 after preprocessing (2644 training
frames in 31 trials, 62 dimensions), 200 hidden units, order 3, minibatches
of 100 frames, CD-1, in float64 and float32, with 1 and 2 BLAS threads.  For
each row the script times ``ConditionalRBM.fit`` over ``--epochs`` epochs
(best and median of ``--repeats``), counts the FLOPs of the matrix products
of one epoch from their shapes (``_common.cd_epoch_flops``) and divides the
achieved rate by the rate of one large matrix product (``--peak-size``,
default 2000 x 2000) timed in the same run, with the same dtype and threads.

It also times the six matrix products of every minibatch alone
(``products_only_epoch``, same shapes and layouts): the ceiling of any
implementation that leaves these products to BLAS.  The column "/ products"
is the training time over that time (wall clock; "(CPU)": process time, less
disturbed by other work on a shared machine).

For comparison it times, in the same run, a straightforward numpy CD-1
(``naive_epoch`` below: the same update written the obvious way, with
``scipy.special.expit`` and fresh arrays for every intermediate), and the MIT
walking configuration of the original MATLAB code (3817 training frames, 49
dimensions, 200 hidden units, order 3), which took about 0.12 s per epoch
under GNU Octave on this kind of machine.

Run from the repository root::

    python benchmarks/bench_train.py                  # a few minutes
    python benchmarks/bench_train.py --epochs 50 --repeats 9 --threads 1

Prints a table and writes ``benchmarks/results/bench_train.json``.
"""

import argparse

import numpy as np
from _common import (
    PAPER,
    add_common_arguments,
    cd_epoch_flops,
    gemm_peak,
    load_training_data,
    print_table,
    summary,
    threadpool_limits,
    time_both,
    write_json,
)
from scipy.special import expit

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.utils._sequences import balanced_batches, check_sequence_ids

MATLAB_MIT_SECONDS_PER_EPOCH = 0.12  # REFERENCE.md, Octave 7.3 + OpenBLAS


def model_for(config, n_iter, dtype_name):
    return ConditionalRBM(
        n_components=config["n_components"],
        order=config["order"],
        batch_size=config["batch_size"],
        n_iter=n_iter,
        random_state=0,
    )


def naive_epoch(state, X, frames, batch_size, order, rng, momentum):
    """One epoch of a straightforward numpy CD-1 (same math, no tricks).

    ``state`` holds W, b, c, A (d, order*d), B (h, order*d) and their
    velocities.  Used only as the baseline of this benchmark.
    """
    lr, wd = 1e-3, 2e-4
    W, b, c, A, B = (state[k] for k in "WbcAB")
    for batch in balanced_batches(frames, batch_size, rng):
        n = len(batch)
        v = X[batch]
        hist = X[(batch[:, None] - np.arange(1, order + 1)).ravel()].reshape(n, -1)
        c_hat = hist @ A.T + c
        b_hat = hist @ B.T + b
        h_prob = expit(v @ W.T + b_hat)
        h_data = (rng.random(h_prob.shape, dtype=X.dtype) < h_prob).astype(X.dtype)
        v_recon = h_data @ W + c_hat
        h_recon = expit(v_recon @ W.T + b_hat)
        grads = {
            "W": h_data.T @ v - h_recon.T @ v_recon,
            "b": (h_data - h_recon).sum(axis=0),
            "c": (v - v_recon).sum(axis=0),
            "A": (v - v_recon).T @ hist,
            "B": (h_data - h_recon).T @ hist,
        }
        for key, grad in grads.items():
            velocity = state["d" + key]
            velocity *= momentum
            velocity += (lr / n) * grad
            if key in "WAB":
                velocity -= lr * wd * state[key]
            state[key] += velocity


def products_only_epoch(buffers, batch_sizes):
    """Only the six matrix products of every minibatch of one CD-1 epoch.

    The same shapes and memory layouts as ``cd_gradients`` (W and the
    directed weights in Fortran order, as during ``fit``), into preallocated
    outputs: the time no implementation that calls BLAS for these products
    can beat, whatever it does between them.
    """
    W, dynamic, v, h, hist, vs, hs, delta, out_dyn, out_h, out_v, out_w, out_d = buffers
    for n in batch_sizes:
        np.matmul(hist[:n], dynamic.T, out=out_dyn[:n])
        np.matmul(v[:n], W.T, out=out_h[:n])
        np.matmul(h[:n], W, out=out_v[:n])
        np.matmul(v[:n], W.T, out=out_h[:n])
        np.matmul(hs[: 2 * n].T, vs[: 2 * n], out=out_w)
        np.matmul(delta[:n].T, hist[:n], out=out_d)


def products_buffers(n_features, n_components, order, batch_size, dtype):
    rng = np.random.default_rng(0)
    d, h, k, n = n_features, n_components, order * n_features, batch_size

    def random(*shape, order="C"):
        return np.asarray(rng.standard_normal(shape).astype(dtype), order=order)

    return (
        random(h, d, order="F"),
        random(d + h, k, order="F"),
        random(n, d),
        random(n, h),
        random(n, k),
        random(2 * n, d),
        random(2 * n, h),
        random(n, d + h),
        np.empty((n, d + h), dtype),
        np.empty((n, h), dtype),
        np.empty((n, d), dtype),
        np.empty((h, d), dtype, order="F"),
        np.empty((d + h, k), dtype, order="F"),
    )


def naive_state(n_features, n_components, order, dtype, seed=0):
    rng = np.random.default_rng(seed)
    shapes = {
        "W": (n_components, n_features),
        "b": (n_components,),
        "c": (n_features,),
        "A": (n_features, order * n_features),
        "B": (n_components, order * n_features),
    }
    state = {
        k: (0.01 * rng.standard_normal(s)).astype(dtype) for k, s in shapes.items()
    }
    state["b"] -= 1
    state.update({"d" + k: np.zeros(s, dtype) for k, s in shapes.items()})
    return state


def run_config(name, X, ids, config, dtype, threads, epochs, repeats, peak_size, naive):
    X = X.astype(dtype)
    valid = check_sequence_ids(ids, len(X)).valid_frames(config["order"])
    flops = cd_epoch_flops(
        len(valid), X.shape[1], config["n_components"], config["order"]
    )
    times = {"sklearn_crbm": [], "naive numpy": [], "matrix products alone": []}
    batch_sizes = [
        len(b)
        for b in balanced_batches(valid, config["batch_size"], np.random.default_rng(0))
    ]
    buffers = products_buffers(
        X.shape[1], config["n_components"], config["order"], config["batch_size"], dtype
    )
    peaks = []
    with threadpool_limits(threads):
        model_for(config, 1, dtype).fit(X, sequence_ids=ids)  # warm up
        state = naive_state(X.shape[1], config["n_components"], config["order"], dtype)

        def ours():
            model_for(config, epochs, dtype).fit(X, sequence_ids=ids)

        def baseline():
            rng = np.random.default_rng(0)
            for epoch in range(epochs):
                naive_epoch(
                    state,
                    X,
                    valid,
                    config["batch_size"],
                    config["order"],
                    rng,
                    0.9 if epoch >= 5 else 0.0,
                )

        for _ in range(repeats):  # interleaved, so that load changes hit all alike
            peaks.append(gemm_peak(dtype, peak_size, clock="both"))
            times["sklearn_crbm"].append(time_both(ours))
            if naive:
                times["naive numpy"].append(time_both(baseline))
            times["matrix products alone"].append(
                time_both(
                    lambda: [
                        products_only_epoch(buffers, batch_sizes) for _ in range(epochs)
                    ]
                )
            )
    peak_wall, peak_cpu = (max(p) for p in zip(*peaks, strict=True))
    rows = []
    for impl, ts in times.items():
        if not ts:
            continue
        wall, cpu = (np.array(t) / epochs for t in zip(*ts, strict=True))
        rows.append(
            {
                "config": name,
                "impl": impl,
                "dtype": np.dtype(dtype).name,
                "threads": threads,
                "n_train_frames": len(valid),
                "ms_per_epoch": 1e3 * wall.min(),
                "ms_per_epoch_median": 1e3 * float(np.median(wall)),
                "cpu_ms_per_epoch": 1e3 * cpu.min(),
                "frames_per_s": len(valid) / wall.min(),
                "gflop_per_epoch": flops / 1e9,
                "gflops": flops / wall.min() / 1e9,
                "peak_gflops": peak_wall,
                "percent_of_peak": 100 * flops / wall.min() / 1e9 / peak_wall,
                # CPU clock for both (one thread: the time actually computing)
                "cpu_peak_gflops": peak_cpu,
                "cpu_percent_of_peak": (
                    100 * flops / cpu.min() / 1e9 / peak_cpu if threads == 1 else None
                ),
                "times": {"wall": summary(list(wall)), "cpu": summary(list(cpu))},
            }
        )
    return rows


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_common_arguments(parser)
    parser.add_argument("--epochs", type=int, default=10, help="epochs per timed fit")
    parser.add_argument(
        "--peak-size", type=int, default=2000, help="size of the peak GEMM"
    )
    parser.add_argument(
        "--no-naive", action="store_true", help="skip the naive baseline"
    )
    parser.add_argument(
        "--no-mit", action="store_true", help="skip the MIT configuration"
    )
    args = parser.parse_args(argv)

    rows = []
    sources = {}
    datasets = [("cmu35", "paper: CMU 35, 62-200, order 3")]
    if not args.no_mit:
        datasets.append(("mit", "MIT walk, 49-200, order 3"))
    for data_name, label in datasets:
        X, ids, sources[data_name] = load_training_data(data_name, args.data_home)
        config = dict(PAPER, n_features=X.shape[1])
        for dtype in args.dtypes:
            for threads in args.threads:
                if data_name == "mit" and (dtype != "float64" or threads != 1):
                    # the MATLAB comparison: one row is enough
                    continue
                rows += run_config(
                    label,
                    X,
                    ids,
                    config,
                    np.dtype(dtype),
                    threads,
                    args.epochs,
                    args.repeats,
                    args.peak_size,
                    naive=not args.no_naive,
                )
    for row in rows:
        if row["config"].startswith("MIT") and row["impl"] == "sklearn_crbm":
            row["vs_matlab"] = MATLAB_MIT_SECONDS_PER_EPOCH / (
                row["ms_per_epoch"] / 1e3
            )
    ours = {
        (r["config"], r["dtype"], r["threads"]): r
        for r in rows
        if r["impl"] == "sklearn_crbm"
    }
    for row in rows:
        ref = ours[(row["config"], row["dtype"], row["threads"])]
        if row["impl"] == "naive numpy":
            ref["speedup_vs_naive"] = row["ms_per_epoch"] / ref["ms_per_epoch"]
        elif row["impl"] == "matrix products alone":  # the issue 18 target: <= 1.3
            ref["vs_products"] = ref["ms_per_epoch"] / row["ms_per_epoch"]
            ref["cpu_vs_products"] = ref["cpu_ms_per_epoch"] / row["cpu_ms_per_epoch"]
    columns = [
        ("config", "configuration", "s"),
        ("impl", "implementation", "s"),
        ("dtype", "dtype", "s"),
        ("threads", "threads", "d"),
        ("ms_per_epoch", "ms/epoch (best)", ".2f"),
        ("ms_per_epoch_median", "median", ".2f"),
        ("frames_per_s", "frames/s", ",.0f"),
        ("gflops", "GFLOP/s", ".1f"),
        ("peak_gflops", "GEMM peak", ".1f"),
        ("percent_of_peak", "% of peak", ".0f"),
        ("cpu_ms_per_epoch", "CPU ms/epoch", ".2f"),
        ("cpu_percent_of_peak", "% of peak (CPU)", ".0f"),
        ("speedup_vs_naive", "x naive", ".2f"),
        ("vs_products", "/ products", ".2f"),
        ("cpu_vs_products", "/ products (CPU)", ".2f"),
        ("vs_matlab", "x MATLAB", ".1f"),
    ]
    print(f"data: {sources}")
    table = print_table(rows, columns, title="Training, CD-1, batch 100")
    write_json(
        "bench_train",
        {"args": vars(args), "data": sources, "rows": rows, "table": table},
        args.output,
    )


if __name__ == "__main__":
    main()
