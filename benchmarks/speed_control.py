"""Speed control: does a model trained with its speed as context go as fast as asked?

Per seed: ``ConditionalRBM(random_state=seed)`` (``--model``) on all 33
trials of CMU 35, the default preprocessing, with every frame's forward
speed as ``context`` (``MotionContext(signals=["forward_speed"])``, 1-s
window, units per second).  Requests from ``--n-sequences`` real seed
windows, 600 frames: constant speed at the walks' mean, the jogs' mean,
their midpoint and 10% beyond the fastest jog; a ramp of 100 frames at walk
speed, 300 rising, 200 at jog speed.  Measured: generated speed over frames
200-599 and its error over jog - walk (at most 0.15); alive (leg amplitude
within 25%); blown (|z| > 10); the ramp's correlation (at least 0.9).

Run from the repository root (fitted models are cached)::

    python benchmarks/speed_control.py
"""

import json
import warnings

import _common as common
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.exceptions import GenerationWarning
from sklearn_crbm.preprocessing import MotionContext

N_FRAMES = 600
JUDGED = slice(200, N_FRAMES)  # frames the constant requests are measured over
RAMP = (100, 300, 200)  # frames at walk speed, rising, at jog speed
RAMP_JUDGED = slice(50, N_FRAMES)
ERROR_TARGET, AMPLITUDE_TOLERANCE, CORRELATION_TARGET = 0.15, 0.25, 0.9
BEYOND = 1.1  # times the fastest jog trial's mean speed


class SpeedTask:
    """CMU 35 with every frame's forward speed, and the requests to generate."""

    def __init__(self, data_home):
        self.corpus = corpus = common.MotionCorpus(data_home, "cmu")
        data = corpus.data
        self.speed = MotionContext(
            data.skeleton, signals=["forward_speed"], frame_rate=data.frame_rate
        )
        with sklearn.config_context(enable_metadata_routing=True):
            speeds = self.speed.fit_transform(data.data, sequence_ids=corpus.ids)
        self.speeds = speeds
        frame_styles = corpus.styles[corpus.ids]
        walk, jog = (float(speeds[frame_styles == s].mean()) for s in ("walk", "jog"))
        trial_speed = np.array(
            [speeds[corpus.ids == k].mean() for k in np.unique(corpus.ids)]
        )
        fastest = float(trial_speed[corpus.styles == "jog"].max())
        self.walk, self.jog = walk, jog
        self.requests = {
            "walk": (walk, "walk"),
            "midpoint": ((walk + jog) / 2, "walk"),
            "jog": (jog, "jog"),
            f"{BEYOND - 1:.0%} beyond fastest jog": (BEYOND * fastest, "jog"),
        }
        rising = np.linspace(walk, jog, RAMP[1])
        self.ramp = np.concatenate(
            [np.full(RAMP[0], walk), rising, np.full(RAMP[2], jog)]
        )

    def fit(self, seed, model_params):
        """``(model, fit seconds)``: the model trained with every frame's speed."""
        model = ConditionalRBM(random_state=seed, **model_params)
        context = np.asarray(self.speeds, dtype=float).reshape(-1, 1)
        return common.cached_fit(model, self.corpus.Z, self.corpus.ids, context=context)

    def generate(self, model, history, speed, seed):
        """``(Z, raw speed per frame)`` of sequences generated at ``speed``."""
        n = len(history)
        with warnings.catch_warnings():  # liveliness is measured below
            warnings.simplefilter("ignore", GenerationWarning)
            Z = model.sample(
                N_FRAMES,
                history=history,
                context=np.asarray(speed, dtype=float).reshape(-1, 1),
                random_state=seed,
            )
        ids = np.repeat(np.arange(n), N_FRAMES)
        with sklearn.config_context(enable_metadata_routing=True):
            raw = self.corpus.preprocessor.inverse_transform(Z, sequence_ids=ids)
            generated = self.speed.transform(raw, sequence_ids=ids)
        return Z, generated.reshape(n, N_FRAMES)

    def liveliness(self, Z, n):
        """Each sequence's leg amplitude over its nearest real style's, alive, blown."""
        ids = np.repeat(np.arange(n), N_FRAMES)
        verdict = self.corpus.judge(Z, ids, last_frames=N_FRAMES - JUDGED.start)
        real = [
            self.corpus.real[style]["amplitude"] if style else np.nan
            for style in verdict.style
        ]
        ratio = verdict.amplitude / np.array(real)
        return dict(
            amplitude=ratio,
            alive=np.abs(ratio - 1) <= AMPLITUDE_TOLERANCE,
            blown=verdict.blown,
            style=verdict.style,
        )


def measure_seed(task, seed, model_params, n_sequences):
    """Every request's measures, per sequence, for one training seed."""
    model, fit_seconds = task.fit(seed, model_params)
    windows, styles = task.corpus.seed_windows(model, n_sequences, seed)
    results = {"fit seconds": fit_seconds}
    for name, (speed, style) in task.requests.items():
        Z, generated = task.generate(model, windows[styles == style], speed, seed)
        mean_speed = generated[:, JUDGED].mean(axis=1)
        results[name] = dict(
            requested=speed,
            speed=mean_speed,
            error=(mean_speed - speed) / (task.jog - task.walk),
            **task.liveliness(Z, n_sequences),
        )
    Z, generated = task.generate(model, windows[styles == "walk"], task.ramp, seed)
    correlation = [
        np.corrcoef(task.ramp[RAMP_JUDGED], g[RAMP_JUDGED])[0, 1] for g in generated
    ]
    results["ramp"] = dict(
        correlation=np.array(correlation),
        trace=generated.mean(axis=0),
        **task.liveliness(Z, n_sequences),
    )
    return results


def interval(per_seed, key):
    """Mean over seeds (of each seed's mean over sequences) and its interval."""
    values = [np.mean(result[key]) for result in per_seed]
    return common.bootstrap_mean(values)


def summary_row(name, per_seed, task):
    """One table row: the request's measures over seeds."""
    alive = sum(int(np.sum(r["alive"])) for r in per_seed)
    blown = sum(int(np.sum(r["blown"])) for r in per_seed)
    n = sum(len(r["alive"]) for r in per_seed)
    amplitude = interval(per_seed, "amplitude")
    row = dict(request=name, amplitude=amplitude[0],
               amplitude_ci=f"{amplitude[1]:.2f}-{amplitude[2]:.2f}",
               alive=f"{alive} of {n}", blown=f"{blown} of {n}")  # fmt: skip
    lively = abs(amplitude[0] - 1) <= AMPLITUDE_TOLERANCE and blown == 0
    if name == "ramp":
        correlation = interval(per_seed, "correlation")
        row.update(requested=f"{task.walk:.1f} to {task.jog:.1f}",
                   correlation=correlation[0],
                   ci=f"{correlation[1]:.3f}-{correlation[2]:.3f}",
                   met=lively and correlation[0] >= CORRELATION_TARGET)  # fmt: skip
    else:
        speed, error = interval(per_seed, "speed"), interval(per_seed, "error")
        row.update(requested=f"{per_seed[0]['requested']:.1f}", speed=speed[0],
                   speed_ci=f"{speed[1]:.1f}-{speed[2]:.1f}", error=error[0],
                   ci=f"{error[1]:+.3f} to {error[2]:+.3f}",
                   met=lively and abs(error[0]) <= ERROR_TARGET)  # fmt: skip
    row["met"] = "yes" if row["met"] else "no"
    return row


COLUMNS = ["request", ("requested", "requested units/s", "s"),
           ("speed", "generated", ".1f"), ("speed_ci", "95%", "s"),
           ("error", "error / (jog - walk)", "+.3f"),
           ("correlation", "ramp correlation", ".3f"), ("ci", "95%", "s"),
           ("amplitude", "leg amplitude / real", ".2f"),
           ("amplitude_ci", "95%", "s"), "alive", "blown", "met"]  # fmt: skip


def main(argv=None):
    p = common.parser(__doc__)
    p.add_argument("--model", default="{}", help="ConditionalRBM parameters, JSON")
    p.add_argument("--n-sequences", type=int, default=6, help="per request")
    args = p.parse_args(argv)
    common.announce()
    task = SpeedTask(args.data_home)
    speeds = f"walks {task.walk:.1f}, jogs {task.jog:.1f}"
    print(f"real forward speed (units/s): {speeds}", flush=True)
    model_params = json.loads(args.model)
    per_seed = {}
    for seed in args.seeds:
        per_seed[seed] = measure_seed(task, seed, model_params, args.n_sequences)
        print(f"  seed {seed}: fitted in {per_seed[seed]['fit seconds']:.0f} s")
    names = [*task.requests, "ramp"]
    rows = [
        summary_row(name, [r[name] for r in per_seed.values()], task) for name in names
    ]
    table = common.print_table(
        rows,
        COLUMNS,
        title=f"\nSpeed control, seeds "
        f"{args.seeds}, {args.n_sequences} sequences per request and seed",
    )
    payload = dict(
        args=vars(args),
        walk_speed=task.walk,
        jog_speed=task.jog,
        ramp=task.ramp,
        rows=rows,
        seeds={str(seed): result for seed, result in per_seed.items()},
    )
    common.write_json("speed_control", args.output, **payload, table=table)
    return rows


if __name__ == "__main__":
    main()
