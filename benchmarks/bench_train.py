"""Training speed of ConditionalRBM against the machine's matrix-multiply peak.

The paper's configuration (CMU 35's 2644 training frames, 62 dimensions, 200
hidden units, order 3, batch 100, CD-1), float64 and float32, 1 and 2 BLAS
threads: ``fit`` over ``--epochs`` (best and median of ``--repeats``, wall
and CPU clock), GFLOP/s from the products' shapes against a 2000 x 2000
product in the same run.  Interleaved: the six matrix products of every
minibatch alone ("/ products") and a straightforward numpy CD-1 ("x
naive").  The MIT configuration is compared with the original MATLAB code
(about 0.12 s per epoch under GNU Octave 7.3 on a like machine).

Run from the repository root (a few minutes)::

    python benchmarks/bench_train.py
    python benchmarks/bench_train.py --epochs 50 --repeats 9 --threads 1
"""

from functools import partial

import _common as common
import numpy as np
from scipy.special import expit

from sklearn_crbm import ConditionalRBM

MATLAB_MIT_SECONDS_PER_EPOCH = 0.12


class NaiveCD:
    """A straightforward numpy CD-1 of the same model (no buffers, no tricks)."""

    def __init__(self, n_features, n_components, order, dtype, seed=0):
        rng = np.random.default_rng(seed)
        shapes = {
            "W": (n_components, n_features),
            "b": (n_components,),
            "c": (n_features,),
            "A": (n_features, order * n_features),
            "B": (n_components, order * n_features),
        }
        self.params = {
            k: (0.01 * rng.standard_normal(s)).astype(dtype) for k, s in shapes.items()
        }
        self.params["b"] -= 1
        self.velocity = {k: np.zeros(s, dtype) for k, s in shapes.items()}
        self.order = order

    def epoch(self, X, frames, batch_size, rng, momentum, lr=1e-3, decay=2e-4):
        p, order = self.params, self.order
        shuffled = rng.permutation(frames)
        for batch in np.array_split(shuffled, -(-len(frames) // batch_size)):
            n, v = len(batch), X[batch]
            hist = X[(batch[:, None] - np.arange(1, order + 1)).ravel()].reshape(n, -1)
            c_hat, b_hat = hist @ p["A"].T + p["c"], hist @ p["B"].T + p["b"]
            h_prob = expit(v @ p["W"].T + b_hat)
            h_data = (rng.random(h_prob.shape, dtype=X.dtype) < h_prob).astype(X.dtype)
            v_recon = h_data @ p["W"] + c_hat
            h_recon = expit(v_recon @ p["W"].T + b_hat)
            grads = {
                "W": h_data.T @ v - h_recon.T @ v_recon,
                "b": (h_data - h_recon).sum(axis=0),
                "c": (v - v_recon).sum(axis=0),
                "A": (v - v_recon).T @ hist,
                "B": (h_data - h_recon).T @ hist,
            }
            for key, grad in grads.items():
                velocity = self.velocity[key]
                velocity *= momentum
                velocity += (lr / n) * grad
                if key in "WAB":
                    velocity -= lr * decay * p[key]
                p[key] += velocity


def run_config(name, X, ids, dtype, threads, args):
    X, d = X.astype(dtype), X.shape[1]
    h, order, bs = (common.PAPER[k] for k in ("n_components", "order", "batch_size"))
    frames = common.frames_with_history(ids, order)
    flops = common.cd_epoch_flops(len(frames), d, h, order)
    sizes = common.epoch_batch_sizes(len(frames), bs)
    products = common.EpochProducts(d, h, order, bs, dtype)
    naive = NaiveCD(d, h, order, dtype)

    model = partial(ConditionalRBM, h, order=order, batch_size=bs, random_state=0)

    def naive_fit():
        rng = np.random.default_rng(0)
        for epoch in range(args.epochs):
            naive.epoch(X, frames, bs, rng, 0.9 if epoch >= 5 else 0.0)

    timed = {
        "sklearn_crbm": lambda: model(n_iter=args.epochs).fit(X, sequence_ids=ids),
        "naive numpy": naive_fit,
        "matrix products alone": lambda: [
            products.epoch(sizes) for _ in range(args.epochs)
        ],
    }
    times, peaks = {k: [] for k in timed}, []
    with common.threadpool_limits(threads):
        model(n_iter=1).fit(X, sequence_ids=ids)  # warm up
        for _ in range(args.repeats):  # interleaved: load changes hit all alike
            peaks.append(common.gemm_peak(dtype))
            for key, func in timed.items():
                times[key].append(common.time_both(func))
    peak_wall, peak_cpu = (max(p) for p in zip(*peaks, strict=True))
    rows = []
    for impl, ts in times.items():
        wall, cpu = (np.array(t) / args.epochs for t in zip(*ts, strict=True))
        cpu_percent = 100 * flops / cpu.min() / 1e9 / peak_cpu
        spread = {"wall": common.summary(list(wall)), "cpu": common.summary(list(cpu))}
        rows.append(dict(config=name, impl=impl, dtype=np.dtype(dtype).name,
            threads=threads, ms_per_epoch=1e3 * wall.min(),
            ms_per_epoch_median=1e3 * float(np.median(wall)),
            cpu_ms_per_epoch=1e3 * cpu.min(), frames_per_s=len(frames) / wall.min(),
            gflops=flops / wall.min() / 1e9,
            percent_of_peak=100 * flops / wall.min() / 1e9 / peak_wall,
            cpu_percent_of_peak=cpu_percent if threads == 1 else None,
            times=spread))  # fmt: skip
    ours, naive_row, alone = rows
    ours["x_naive"] = naive_row["ms_per_epoch"] / ours["ms_per_epoch"]
    ours["vs_products"] = ours["ms_per_epoch"] / alone["ms_per_epoch"]
    ours["cpu_vs_products"] = ours["cpu_ms_per_epoch"] / alone["cpu_ms_per_epoch"]
    return rows


def main(argv=None):
    p = common.speed_parser(__doc__)
    p.add_argument("--epochs", type=int, default=10, help="epochs per timed fit")
    p.add_argument("--no-mit", action="store_true", help="skip the MIT configuration")
    args = p.parse_args(argv)
    common.announce()
    rows, sources = [], {}
    datasets = {"cmu35": "CMU 35, 62-200, order 3", "mit": "MIT walk, 49-200, order 3"}
    for data_name, label in datasets.items():
        if data_name == "mit" and args.no_mit:
            continue
        X, ids, sources[data_name] = common.load_training_data(
            data_name, args.data_home
        )
        for dtype in args.dtypes:
            for threads in args.threads:
                if data_name == "mit" and (dtype, threads) != ("float64", 1):
                    continue  # the MATLAB comparison: one row is enough
                rows += run_config(label, X, ids, np.dtype(dtype), threads, args)
    for row in rows:
        if row["config"].startswith("MIT") and row["impl"] == "sklearn_crbm":
            row["x_matlab"] = MATLAB_MIT_SECONDS_PER_EPOCH / (row["ms_per_epoch"] / 1e3)
    print(f"data: {sources}")
    columns = [("config", "configuration", "s"), ("impl", "implementation", "s"),
               "dtype", "threads", ("ms_per_epoch", "ms/epoch (best)", ".2f"),
               ("ms_per_epoch_median", "median", ".2f"),
               ("cpu_ms_per_epoch", "CPU ms/epoch", ".2f"),
               ("frames_per_s", "frames/s", ",.0f"), ("gflops", "GFLOP/s", ".1f"),
               ("percent_of_peak", "% of peak", ".0f"),
               ("cpu_percent_of_peak", "% of peak (CPU)", ".0f"),
               ("x_naive", "x naive", ".2f"), ("vs_products", "/ products", ".2f"),
               ("cpu_vs_products", "/ products (CPU)", ".2f"),
               ("x_matlab", "x MATLAB", ".1f")]  # fmt: skip
    title = "\nTraining, CD-1, batch 100"
    table = common.print_table(rows, columns, title=title)
    payload = dict(args=vars(args), data=sources, rows=rows, table=table)
    common.write_json("bench_train", args.output, **payload)


if __name__ == "__main__":
    main()
