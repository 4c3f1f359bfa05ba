"""Training with the default BLAS environment against one BLAS thread.

numpy and scipy each load their own OpenBLAS, which by default starts one
thread per core.  The package picks its own thread count for its loops
(``sklearn_crbm.set_config(blas_threads="auto")``, one thread at batch 100);
this script checks that a user who changes nothing gets one-thread speed.

It trains ``ConditionalRBM(random_state=0)`` on CMU subject 35 (the
package's preprocessing) for ``--epochs`` epochs, each run in a fresh Python
process, in three environments:

- ``default``: no ``*_NUM_THREADS`` variable set, the package's defaults;
- ``one thread``: ``OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1``, the speed to
  match;
- ``all threads``: the default environment with
  ``sklearn_crbm.set_config(blas_threads=<cores>)``, what every call did
  before the package chose (``--old-epochs`` epochs: it can be very slow).

Each is run ``--repeats`` times, alternating, on the quiet machine and again
while a busy process of this script's own spins on one core ("loaded").
Reports milliseconds per epoch (median of the repeats; a warm-up epoch is
not timed) and the ratio of default to one thread; done when it is at most
1.2 both quiet and loaded.

Run from the repository root (about two minutes)::

    python benchmarks/bench_threads.py
"""

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
from functools import partial

from _common import (
    announce,
    child_json,
    load_training_data,
    print_table,
    seconds,
    write_json,
)
from _common import parser as make_parser

THREAD_VARIABLES = (
    "OPENBLAS_NUM_THREADS OMP_NUM_THREADS MKL_NUM_THREADS BLIS_NUM_THREADS "
    "VECLIB_MAXIMUM_THREADS NUMEXPR_NUM_THREADS"
).split()
TARGET = 1.2


def environments():
    """``name -> (environment variables, package blas_threads setting)``."""
    default = {k: v for k, v in os.environ.items() if k not in THREAD_VARIABLES}
    one = {**default, "OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1"}
    return {
        "default": (default, None),
        "one thread": (one, None),
        "all threads": (default, os.cpu_count()),
    }


def train_in_child(data_home, epochs, blas_threads):
    """Child process: ms per epoch of the default model on CMU 35."""
    import sklearn_crbm
    from sklearn_crbm import ConditionalRBM

    if blas_threads is not None:
        sklearn_crbm.set_config(blas_threads=blas_threads)
    Z, ids, _ = load_training_data("cmu35", data_home)
    ConditionalRBM(n_iter=1, random_state=0).fit(Z, sequence_ids=ids)  # warm up
    model = ConditionalRBM(n_iter=epochs, random_state=0)
    elapsed = seconds(partial(model.fit, Z, sequence_ids=ids))
    print(json.dumps({"ms_per_epoch": 1000 * elapsed / epochs}))


def measure(load, args):
    """Per environment: the median and every run's ms per epoch."""
    busy = None
    if load == "loaded":
        busy = subprocess.Popen([sys.executable, "-c", "while True: pass"])
        time.sleep(1.0)
    try:
        times = {name: [] for name in environments()}
        for _ in range(args.repeats):
            for name, (env, blas_threads) in environments().items():
                epochs = args.old_epochs if name == "all threads" else args.epochs
                child = [__file__, "--child", "--data-home", str(args.data_home)]
                child += ["--epochs", str(epochs)]
                if blas_threads is not None:
                    child += ["--child-blas-threads", str(blas_threads)]
                times[name].append(child_json(child, env)["ms_per_epoch"])
    finally:
        if busy is not None:
            busy.terminate()
            busy.wait()
    return {name: statistics.median(values) for name, values in times.items()}, times


def main():
    parser = make_parser(__doc__, seeds=None)
    parser.add_argument("--epochs", type=int, default=100, help="timed epochs")
    parser.add_argument(
        "--old-epochs", type=int, default=10, help="timed epochs of 'all threads'"
    )
    parser.add_argument("--repeats", type=int, default=3, help="runs per row")
    parser.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--child-blas-threads", type=int, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        train_in_child(args.data_home, args.epochs, args.child_blas_threads)
        return

    announce()
    rows, raw, ratios = [], {}, {}
    for load in ("quiet", "loaded"):
        medians, raw[load] = measure(load, args)
        ratios[load] = medians["default"] / medians["one thread"]
        for name, ms in medians.items():
            ratio = ms / medians["one thread"]
            rows.append(dict(load=load, environment=name, ms=ms, ratio=ratio))
    print_table(
        rows,
        [
            ("load", "machine", "s"),
            ("environment", "BLAS threads", "s"),
            ("ms", "ms per epoch", ".1f"),
            ("ratio", "x one thread", ".2f"),
        ],
        title=f"The demo's training, {os.cpu_count()} cores, median of "
        f"{args.repeats} runs ({args.epochs} epochs; 'all threads': "
        f"{args.old_epochs})",
    )
    met = all(r <= TARGET for r in ratios.values())
    print(
        f"default / one thread: quiet {ratios['quiet']:.2f}, loaded "
        f"{ratios['loaded']:.2f} (target <= {TARGET}): {'met' if met else 'NOT met'}"
    )
    payload = dict(rows=rows, runs_ms_per_epoch=raw, target=TARGET, met=met)
    write_json("bench_threads", args.output, **payload)


if __name__ == "__main__":
    main()
