"""Generation speed of ConditionalRBM.sample: 1 sequence and many together.

The paper's model size (62 dimensions, 200 hidden units, order 3), trained
briefly on CMU subject 35 (speed does not depend on how well it is trained),
generates ``--n-frames`` new frames with 30 alternating Gibbs steps per frame
(the original code's scheme), for 1 sequence and for ``--n-sequences``
sequences together, in float64 and float32, with one BLAS thread.

The same scheme is also written as a straightforward vectorised numpy loop
(``naive_generate`` below: ``scipy.special.expit``, fresh arrays for every
intermediate, all sequences in one matrix) and timed in the same run; the
table gives the speed-up of ``sample`` over it and, for one sequence, how
many times faster than real time (30 frames/s) generation runs.  The
original MATLAB code generated 400 frames in about 0.3-0.6 s.

Run from the repository root::

    python benchmarks/bench_generate.py                # about a minute
    python benchmarks/bench_generate.py --n-frames 400 --repeats 7

Prints a table and writes ``benchmarks/results/bench_generate.json``.
"""

import argparse
import time

import numpy as np
from _common import (
    PAPER,
    add_common_arguments,
    load_training_data,
    print_table,
    summary,
    threadpool_limits,
    write_json,
)
from scipy.special import expit

from sklearn_crbm import ConditionalRBM

REAL_TIME_FPS = 30.0


def naive_generate(model, seed, n_samples, n_gibbs, rng):
    """The original generation scheme, vectorised over sequences, written plainly.

    ``seed`` has shape (n_sequences, order, n_features), oldest first.
    """
    W = model.components_
    b, c = model.intercept_hidden_, model.intercept_visible_
    A, B = model.autoregressive_, model.past_to_hidden_
    order = len(A)
    frames = [seed[:, i] for i in range(seed.shape[1])]
    for _ in range(n_samples):
        c_hat = c + sum(frames[-q] @ A[q - 1].T for q in range(1, order + 1))
        b_hat = b + sum(frames[-q] @ B[q - 1].T for q in range(1, order + 1))
        v = frames[-1] + 0.01 * rng.standard_normal(frames[-1].shape).astype(W.dtype)
        for _ in range(n_gibbs):
            p = expit(v @ W.T + b_hat)
            h = (rng.random(p.shape, dtype=W.dtype) < p).astype(W.dtype)
            v = h @ W + c_hat
        v = expit(v @ W.T + b_hat) @ W + c_hat
        frames.append(v)
    return np.stack(frames[seed.shape[1] :], axis=1)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    add_common_arguments(parser)
    parser.set_defaults(threads=[1])
    parser.add_argument(
        "--n-frames", type=int, default=100, help="new frames per sequence"
    )
    parser.add_argument("--n-sequences", type=int, nargs="+", default=[1, 100])
    parser.add_argument("--n-gibbs", type=int, default=30)
    parser.add_argument("--no-naive", action="store_true")
    args = parser.parse_args(argv)

    X, ids, source = load_training_data("cmu35", args.data_home)
    rows = []
    for dtype in args.dtypes:
        Xd = X.astype(dtype)
        model = ConditionalRBM(
            PAPER["n_components"], order=PAPER["order"], n_iter=20, random_state=0
        ).fit(Xd, sequence_ids=ids)
        for threads in args.threads:
            with threadpool_limits(threads):
                for n_seq in args.n_sequences:
                    rng = np.random.default_rng(0)
                    picks = rng.integers(len(model.seed_windows_), size=n_seq)
                    seed = model.seed_windows_[picks]

                    def ours(seed=seed, model=model):
                        model.sample(
                            args.n_frames,
                            history=seed,
                            n_gibbs=args.n_gibbs,
                            random_state=0,
                        )

                    def naive(seed=seed, model=model):
                        naive_generate(
                            model,
                            seed,
                            args.n_frames,
                            args.n_gibbs,
                            np.random.default_rng(0),
                        )

                    ours()  # warm up
                    ts, tn = [], []
                    for _ in range(args.repeats):  # interleaved
                        start = time.perf_counter()
                        ours()
                        ts.append(time.perf_counter() - start)
                        if not args.no_naive:
                            start = time.perf_counter()
                            naive()
                            tn.append(time.perf_counter() - start)
                    n_new = n_seq * args.n_frames
                    row = {
                        "dtype": dtype,
                        "threads": threads,
                        "n_sequences": n_seq,
                        "frames": n_new,
                        "seconds": min(ts),
                        "frames_per_s": n_new / min(ts),
                        "ms_per_frame_step": 1e3 * min(ts) / args.n_frames,
                        "times": summary(ts),
                    }
                    if tn:
                        row["naive_frames_per_s"] = n_new / min(tn)
                        row["speedup_vs_naive"] = min(tn) / min(ts)
                        row["naive_times"] = summary(tn)
                    if n_seq == 1:
                        row["x_real_time"] = row["frames_per_s"] / REAL_TIME_FPS
                    rows.append(row)
    columns = [
        ("dtype", "dtype", "s"),
        ("threads", "threads", "d"),
        ("n_sequences", "sequences", "d"),
        ("frames", "new frames", "d"),
        ("seconds", "seconds (best)", ".3f"),
        ("frames_per_s", "frames/s", ",.0f"),
        ("naive_frames_per_s", "naive frames/s", ",.0f"),
        ("speedup_vs_naive", "x naive", ".2f"),
        ("x_real_time", "x real time", ",.0f"),
    ]
    print(f"data: {source}; {args.n_gibbs} Gibbs steps per frame")
    table = print_table(rows, columns, title="Generation, 62-200 order 3")
    write_json(
        "bench_generate",
        {"args": vars(args), "data": source, "rows": rows, "table": table},
        args.output,
    )


if __name__ == "__main__":
    main()
