"""How the cost of a training epoch grows with frames, order and hidden units.

Around the paper's configuration (62 dimensions, 200 hidden units, order 3,
batch 100, CD-1, one BLAS thread) on synthetic motion: frames 10^3-10^6
(``--frames``), order 1-12 (``--orders``) and hidden units 50-800
(``--components``): ms per epoch (best of ``--repeats``), us per frame,
GFLOP/s and the fraction of a 2000 x 2000 product's rate.

Run from the repository root (about two minutes)::

    python benchmarks/bench_scaling.py
    python benchmarks/bench_scaling.py --dtypes float64 float32 --repeats 5
"""

import _common as common

from sklearn_crbm import ConditionalRBM


def epoch_cost(X, ids, n_components, order, epochs, repeats, peak):
    n_train = len(common.frames_with_history(ids, order))
    walls, cpus = [], []
    for _ in range(repeats):
        model = ConditionalRBM(n_components, order=order, n_iter=epochs, random_state=0)
        wall, cpu = common.time_both(lambda model=model: model.fit(X, sequence_ids=ids))
        walls.append(wall / epochs)
        cpus.append(cpu / epochs)
    flops = common.cd_epoch_flops(n_train, X.shape[1], n_components, order)
    gflops = flops / min(cpus) / 1e9
    return dict(
        n_train_frames=n_train,
        ms_per_epoch=1e3 * min(walls),
        cpu_ms_per_epoch=1e3 * min(cpus),
        cpu_us_per_frame=1e6 * min(cpus) / n_train,
        cpu_gflops=gflops,
        percent_of_peak=100 * gflops / peak,
        times={"wall": common.summary(walls), "cpu": common.summary(cpus)},
    )


def main(argv=None):
    p = common.speed_parser(__doc__, threads=(1,))
    p.set_defaults(dtypes=["float32"], repeats=2)
    p.add_argument(
        "--frames", type=int, nargs="+", default=[10**3, 10**4, 10**5, 10**6]
    )
    p.add_argument("--orders", type=int, nargs="+", default=[1, 2, 3, 6, 12])
    p.add_argument(
        "--components", type=int, nargs="+", default=[50, 100, 200, 400, 800]
    )
    p.add_argument("--epochs", type=int, default=3, help="epochs per fit (small data)")
    args = p.parse_args(argv)
    common.announce()
    d, h, order = (common.PAPER[k] for k in ("n_features", "n_components", "order"))
    rows = []
    for dtype in args.dtypes:
        for threads in args.threads:
            with common.threadpool_limits(threads):
                peak = common.gemm_peak(dtype)[1]  # CPU clock, like the rows
                sweeps = [("frames", n, n, h, order) for n in args.frames]
                sweeps += [("order", q, 2644, h, q) for q in args.orders]
                sweeps += [("n_components", k, 2644, k, order) for k in args.components]
                for sweep, value, n, n_components, q in sweeps:
                    n_sequences = max(1, n // 100)
                    X, ids = common.synthetic_motion(n, d, n_sequences, dtype=dtype)
                    big = n >= 100_000  # one epoch, one fit: seconds each
                    epochs, repeats = (1, 1) if big else (args.epochs, args.repeats)
                    row = epoch_cost(X, ids, n_components, q, epochs, repeats, peak)
                    rows.append(dict(sweep=sweep, value=value, dtype=dtype, **row))
                    ms = row["ms_per_epoch"]
                    print(f"  {sweep}={value}: {ms:.1f} ms/epoch", flush=True)
    columns = ["sweep", ("value", "value", ",d"), "dtype",
               ("n_train_frames", "train frames", ",d"),
               ("ms_per_epoch", "ms/epoch", ",.1f"),
               ("cpu_ms_per_epoch", "CPU ms/epoch", ",.1f"),
               ("cpu_us_per_frame", "CPU us/frame", ".2f"),
               ("cpu_gflops", "GFLOP/s (CPU)", ".1f"),
               ("percent_of_peak", "% of peak (CPU)", ".0f")]  # fmt: skip
    title = "\nTraining cost per epoch (62 dims; 200 hidden, order 3 unless swept)"
    table = common.print_table(rows, columns, title=title)
    payload = dict(args=vars(args), rows=rows, table=table)
    common.write_json("bench_scaling", args.output, **payload)


if __name__ == "__main__":
    main()
