"""Generation and fill-in speed of the paper's model: ``sample`` and ``CRBMImputer``.

The paper's model size (62 dimensions, 200 hidden units, order 3) briefly
trained on CMU 35, float64 and float32, one BLAS thread; "x real time" is
against 30 frames per second.  ``generate``: ``--n-frames`` frames, 30 Gibbs
steps each, for 1 and ``--n-sequences`` sequences, against a plain numpy
loop ("x naive").  ``fillin``: ``CRBMImputer`` at its defaults fills the
left leg or upper body of the two test trials on-line, ``--n-draws`` draws.

Run from the repository root (about two minutes)::

    python benchmarks/bench_generate.py --parts fillin --n-draws 1 10
"""

from functools import partial

import _common as common
import numpy as np
from scipy.special import expit

from sklearn_crbm.impute import CRBMImputer
from sklearn_crbm.model_selection import erasure_mask, paper_body_parts


def naive_generate(model, seed, n_samples, n_gibbs, random_state):
    """The original generation, plainly; ``seed``: (n, order, d), oldest first."""
    rng = np.random.default_rng(random_state)
    W, b, c = model.components_, model.intercept_hidden_, model.intercept_visible_
    A, B = model.autoregressive_, model.past_to_hidden_
    frames = list(np.moveaxis(seed, 1, 0))
    for _ in range(n_samples):
        c_hat = c + sum(frames[-q] @ A[q - 1].T for q in range(1, len(A) + 1))
        b_hat = b + sum(frames[-q] @ B[q - 1].T for q in range(1, len(B) + 1))
        v = frames[-1] + 0.01 * rng.standard_normal(frames[-1].shape).astype(W.dtype)
        for _ in range(n_gibbs):
            p = expit(v @ W.T + b_hat)
            v = (rng.random(p.shape, dtype=W.dtype) < p).astype(W.dtype) @ W + c_hat
        frames.append(expit(v @ W.T + b_hat) @ W + c_hat)
    return np.stack(frames[seed.shape[1] :], axis=1)


def generation(args):
    X, ids, source = common.load_training_data("cmu35", args.data_home)
    rows = []
    for dtype in args.dtypes:
        model = common.paper_model(n_iter=20, random_state=0)
        model.fit(X.astype(dtype), sequence_ids=ids)
        for threads in args.threads:
            for n_seq in args.n_sequences:
                picks = np.random.default_rng(0).integers(
                    len(model.seed_windows_), size=n_seq
                )
                seed = model.seed_windows_[picks]
                steps = dict(n_gibbs=args.n_gibbs, random_state=0)
                ours = partial(model.sample, args.n_frames, history=seed, **steps)
                naive = partial(naive_generate, model, seed, args.n_frames, **steps)
                with common.threadpool_limits(threads):
                    ours()  # warm up
                    pairs = [
                        (common.seconds(ours), common.seconds(naive))
                        for _ in range(args.repeats)
                    ]
                ts, tn = zip(*pairs, strict=True)  # interleaved, so load hits both
                n_new = n_seq * args.n_frames
                real_time = n_new / min(ts) / common.REAL_TIME_FPS
                rows.append(dict(dtype=dtype, threads=threads, n_sequences=n_seq,
                    frames=n_new, seconds=min(ts), frames_per_s=n_new / min(ts),
                    naive_frames_per_s=n_new / min(tn), x_naive=min(tn) / min(ts),
                    x_real_time=real_time if n_seq == 1 else None,
                    times=common.summary(list(ts)),
                    naive_times=common.summary(list(tn))))  # fmt: skip
    print(f"data: {source}; {args.n_gibbs} Gibbs steps per frame")
    columns = ["dtype", "threads", ("n_sequences", "sequences", "d"),
               ("frames", "new frames", "d"), ("seconds", "seconds (best)", ".3f"),
               ("frames_per_s", "frames/s", ",.0f"),
               ("naive_frames_per_s", "naive frames/s", ",.0f"),
               ("x_naive", "x naive", ".2f"),
               ("x_real_time", "x real time", ",.0f")]  # fmt: skip
    table = common.print_table(rows, columns, title="\nGeneration, 62-200 order 3")
    return dict(data=source, rows=rows, table=table)


def fillin(args):
    split = common.Split(args.data_home, "paper")
    names = split.preprocessor.get_feature_names_out()
    masks = {
        part: erasure_mask(
            split.X_test, bones=bones, feature_names=names, start=0, strict=False
        )
        for part, bones in paper_body_parts(split.cmu.skeleton).items()
    }
    rows = []
    for dtype in args.dtypes:
        model = common.paper_model(n_iter=20)
        for threads, n_draws in ((t, n) for t in args.threads for n in args.n_draws):
            imputer = CRBMImputer(model, n_draws=n_draws, random_state=0)
            imputer.fit(split.X_train.astype(dtype), sequence_ids=split.train_ids)
            for part, mask in masks.items():
                X = np.where(mask, np.nan, split.X_test).astype(dtype)
                ids = split.test_ids
                fill = partial(imputer.transform, X, sequence_ids=ids)
                with common.threadpool_limits(threads):
                    imputer.transform(X[:20], sequence_ids=ids[:20])  # warm up
                    times = [common.seconds(fill) for _ in range(args.repeats)]
                rows.append(dict(dtype=dtype, threads=threads, missing=part,
                    channels=int(mask.any(axis=0).sum()), n_draws=n_draws,
                    frames=len(X), seconds=min(times),
                    frames_per_s=len(X) / min(times),
                    x_real_time=len(X) / min(times) / common.REAL_TIME_FPS,
                    times=common.summary(times)))  # fmt: skip
    columns = ["dtype", "threads", "missing", "channels", ("n_draws", "draws", "d"),
               "frames", ("seconds", "seconds (best)", ".3f"),
               ("frames_per_s", "frames/s", ",.0f"),
               ("x_real_time", "x real time", ",.1f")]  # fmt: skip
    title = "\nFill-in with CRBMImputer's defaults, 62-200 order 3"
    table = common.print_table(rows, columns, title=title)
    return dict(rows=rows, table=table)


def main(argv=None):
    p = common.speed_parser(__doc__, threads=(1,))
    p.add_argument("--parts", nargs="+", default=list(PARTS), choices=PARTS)
    p.add_argument("--n-frames", type=int, default=100, help="new frames per sequence")
    p.add_argument("--n-sequences", type=int, nargs="+", default=[1, 100])
    p.add_argument("--n-gibbs", type=int, default=30)
    p.add_argument("--n-draws", type=int, nargs="+", default=[1, 10])
    args = p.parse_args(argv)
    common.announce()
    results = {part: PARTS[part](args) for part in args.parts}
    common.write_json("bench_generate", args.output, args=vars(args), **results)


PARTS = {"generate": generation, "fillin": fillin}


if __name__ == "__main__":
    main()
