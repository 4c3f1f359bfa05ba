"""Generation on users' own corpora: lively, smooth and varied from one seed?

Per content of Bandai dataset-2 (takes 001-012 in one ``--style``) and
training seed: ``ConditionalRBM`` (``--model``; sampler-only parameters set
after the cached fit) on the preprocessed takes; 4 sequences of 600 frames
from the real window ending half-way through the first take, frames 300-599
judged against the real takes: liveliness of the 12 most-moving angles
(cycle: the takes' middle halves), divergence, jitter (body, root) and
skating over the real, frequency, blown (|z| beyond twice the training
data's), warned (``GenerationWarning``), fit time.  Means over seeds [95%
bootstrap interval]; the JSON keeps every sequence::

    python benchmarks/corpora.py
    python benchmarks/corpora.py --contents run wave-both-hands --seeds 0 1
    python benchmarks/corpora.py --style exhausted --seeds 0 1
    python benchmarks/corpora.py --model '{"n_mean_field": 1, "hidden_drift": 0}'
"""

import json
import re
import time
import warnings
from pathlib import Path

import _common as common
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import read_bvh_folder
from sklearn_crbm.exceptions import GenerationWarning
from sklearn_crbm.metrics import (
    divergence,
    foot_skating,
    jitter,
    liveliness,
    most_moving_channels,
    step_frequency,
)
from sklearn_crbm.preprocessing import make_motion_preprocessor

CYCLIC = ("walk", "walk-turn-left", "walk-turn-right", "run") + tuple(
    f"wave-{part}" for part in ("both-hands", "left-hand", "right-hand")
)
ONE_SHOT = tuple(
    f"raise-up-{part}" for part in ("both-hands", "left-hand", "right-hand")
)
LOCOMOTION = CYCLIC[:4]
N_SEQUENCES, N_FRAMES, JUDGED = 4, 600, slice(300, 600)
N_CHANNELS = 12
FEET = ("Toes_L", "Toes_R")
ANGLES = ("_ex", "_ey", "_ez")
# Parameters that only sample reads: set after the fit, not part of its cache key.
SAMPLING_PARAMETERS = ("n_mean_field", "hidden_drift")


class Content:
    """The takes of one content and style, preprocessed, and their statistics."""

    def __init__(self, data_home, name, style="normal"):
        folder = Path(data_home) / "bandai_dataset2"
        takes = read_bvh_folder(folder, pattern=f"dataset-2_{name}_{style}_*.bvh")
        preprocessor = make_motion_preprocessor(takes.skeleton)
        with sklearn.config_context(enable_metadata_routing=True):
            Z = preprocessor.fit_transform(takes.data, sequence_ids=takes.sequence_ids)
        self.describe(name, takes, preprocessor, Z)

    def describe(self, name, takes, preprocessor, Z):
        """Keep ``takes`` (``data``, ``sequence_ids``, ``skeleton``), ``Z`` (them
        through the fitted ``preprocessor``) and the real takes' statistics."""
        self.name, self.takes, self.Z = name, takes, Z
        self.skeleton = takes.skeleton
        self.preprocessor = preprocessor
        self.blown_z = 2 * float(np.abs(self.Z).max())
        names = self.preprocessor.get_feature_names_out()
        self.angles = [j for j, n in enumerate(names) if n.endswith(ANGLES)]
        unscaled = self.unscaled(self.Z)
        ids = takes.sequence_ids
        self.channels = most_moving_channels(
            unscaled, sequence_ids=ids, n_channels=N_CHANNELS, features=self.angles
        )
        self.unscaled_real = unscaled
        positions = self.positions(takes.data)
        self.root = _travelling_joint(positions)
        self.real = dict(
            frequency=float(np.nanmean(self.frequency(unscaled, ids))),
            skating=float(np.mean(self.skating(positions, ids))),
            **{
                key: float(np.mean(value))
                for key, value in self.jitters(positions, ids).items()
            },
        )

    def unscaled(self, Z):
        """``Z``'s joint angles and root channels in their units (before scaling;
        without the constant channels the scaler's inverse restores)."""
        scaler = self.preprocessor[-1]
        return scaler.inverse_transform(Z)[:, ~scaler.constant_mask_]

    def positions(self, raw):
        return self.skeleton.forward_kinematics(raw)

    def frequency(self, unscaled, ids):
        return step_frequency(unscaled[:, self.channels], sequence_ids=ids)

    def skating(self, positions, ids):
        feet = [self.skeleton.bone_names.index(f) for f in FEET]
        return foot_skating(positions, feet=feet, sequence_ids=ids)

    def jitters(self, positions, ids):
        """Jitter of all joints, of the body around the root, of the root."""
        root = positions[:, self.root : self.root + 1]
        return dict(
            jitter=jitter(positions, sequence_ids=ids),
            jitter_body=jitter(positions - root, sequence_ids=ids),
            jitter_root=jitter(root, sequence_ids=ids),
        )

    def seed(self, width):
        """Per sequence, the ``width`` frames ending half-way through take one."""
        rows = np.flatnonzero(self.takes.sequence_ids == self.takes.sequence_ids[0])
        end = rows[len(rows) // 2]
        window = self.Z[end - width + 1 : end + 1]
        return np.repeat(window[None], N_SEQUENCES, axis=0)

    def cycle(self):
        """Rows of the middle half of every take (the cycle, without its ends)."""
        ids = self.takes.sequence_ids
        rows = [np.flatnonzero(ids == take) for take in np.unique(ids)]
        return np.concatenate([r[len(r) // 4 : 3 * len(r) // 4] for r in rows])


def _travelling_joint(positions):
    """The first joint whose position changes (the root that carries travel)."""
    moving = np.ptp(positions, axis=0).max(axis=1) > 1e-6
    return int(np.argmax(moving))


def judge(content, model, seed, sample_params=None):
    """Every statistic of what ``model.sample(**sample_params)`` generates."""
    history = content.seed(max(model.history_length, 1))
    return describe(content, *generate(model, history, seed, sample_params))


def generate(model, history, seed, sample_params=None):
    """``(Z, warnings caught, seconds)``: ``N_FRAMES`` after each ``history``."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", GenerationWarning)
        start = time.perf_counter()
        Z = model.sample(
            N_FRAMES, history=history, random_state=seed, **(sample_params or {})
        )
    return Z, caught, time.perf_counter() - start


def describe(content, Z, caught=(), sample_seconds=None):
    """Every statistic of the generated ``Z`` against the takes of ``content``."""
    ids = np.repeat(np.arange(N_SEQUENCES), N_FRAMES)
    judged = np.tile(np.arange(N_FRAMES), N_SEQUENCES)
    judged = (judged >= JUDGED.start) & (judged < JUDGED.stop)
    finite = np.isfinite(Z).all(axis=1)
    per_sequence = np.abs(np.where(finite[:, None], Z, np.inf)).reshape(
        N_SEQUENCES, N_FRAMES, -1
    )
    blown = per_sequence.max(axis=(1, 2)) > content.blown_z
    Z = np.where(np.isfinite(Z), np.clip(Z, -1e3, 1e3), 0.0)  # judge what is left
    unscaled = content.unscaled(Z)
    with sklearn.config_context(enable_metadata_routing=True):
        raw = content.preprocessor.inverse_transform(Z, sequence_ids=ids)
    positions = content.positions(raw)[judged]
    lively, lively_whole = (
        liveliness(
            unscaled[judged],
            content.unscaled_real[rows],
            sequence_ids=ids[judged],
            reference_sequence_ids=content.takes.sequence_ids[rows],
            n_channels=N_CHANNELS,
            features=content.angles,
        )
        for rows in (content.cycle(), slice(None))
    )
    statistics = dict(
        liveliness=lively,
        whole_liveliness=lively_whole,
        divergence=[divergence(Z, sequence_ids=ids, frames=JUDGED)],
        frequency=content.frequency(unscaled[judged], ids[judged])
        / content.real["frequency"],
        blown=blown.astype(float),
        **{
            key: value / content.real[key]
            for key, value in content.jitters(positions, ids[judged]).items()
        },
    )
    statistics["warned"] = _warned(caught)
    if content.name in LOCOMOTION:
        statistics["skating"] = (
            content.skating(positions, ids[judged]) / content.real["skating"]
        )
    run = {key: np.asarray(value).tolist() for key, value in statistics.items()}
    run["sample_seconds"] = sample_seconds
    return run


# The statistics averaged over seeds, with their columns' headings.
STATISTICS = dict(
    liveliness="liveliness, cycle",
    whole_liveliness="whole takes",
    divergence="divergence",
    jitter="jitter / real",
    jitter_body="body",
    jitter_root="root",
    skating="skating / real",
    frequency="frequency / real",
)


def _warned(caught):
    """Per sequence, 1 where ``sample``'s GenerationWarning named it."""
    warned = np.zeros(N_SEQUENCES)
    for warning in caught:
        if issubclass(warning.category, GenerationWarning):
            for listed in re.findall(r"Sequences? ([\d, ]+) of", str(warning.message)):
                warned[[int(k) for k in listed.split(",")]] = 1
    return warned


def summary_row(content, runs):
    """Mean over seeds (each seed's mean over its sequences) with 95% intervals."""
    row = dict(content=content, seeds=len(runs))
    for key in STATISTICS:
        if key not in runs[0]:
            continue
        per_seed = [np.nanmean(run[key]) for run in runs]
        row[key] = common.interval_text(per_seed)
    row["blown"] = int(sum(np.sum(run["blown"]) for run in runs))
    row["warned"] = int(sum(np.sum(run["warned"]) for run in runs))
    row["fit"] = float(np.mean([run["fit_seconds"] for run in runs]))
    return row


def fitted_model(content, seed, model_params):
    """``(model, fit seconds)``: the cached fit, then the sampling parameters."""
    fit_params = {k: v for k, v in model_params.items() if k not in SAMPLING_PARAMETERS}
    sampling = {k: v for k, v in model_params.items() if k in SAMPLING_PARAMETERS}
    model = ConditionalRBM(random_state=seed, **fit_params)
    model, fit_seconds = common.cached_fit(model, content.Z, content.takes.sequence_ids)
    return model.set_params(**sampling), fit_seconds


def main(argv=None):
    p = common.parser(__doc__)
    p.add_argument("--contents", nargs="+", default=list(CYCLIC + ONE_SHOT))
    p.add_argument("--style", default="normal", help="the takes' style")
    p.add_argument("--model", default="{}", help="ConditionalRBM parameters, JSON")
    p.add_argument("--sample", default="{}", help="sample's parameters, JSON")
    args = p.parse_args(argv)
    common.announce()
    model_params = json.loads(args.model)
    sample_params = json.loads(args.sample)
    rows, runs = [], {}
    for name in args.contents:
        content = Content(args.data_home, name, args.style)
        runs[name] = []
        for seed in args.seeds:
            with common.threadpool_limits(1):
                start = time.perf_counter()
                model, fit_seconds = fitted_model(content, seed, model_params)
                run = judge(content, model, seed, sample_params)
            run.update(seed=seed, fit_seconds=fit_seconds, n_iter=model.n_iter_)
            runs[name].append(run)
            shown = (*STATISTICS, "blown", "warned")
            values = [f"{k} {np.round(run[k], 2).tolist()}" for k in shown if k in run]
            values.append(f"fit {fit_seconds:.0f} s")
            seconds = time.perf_counter() - start
            values = ", ".join(values)
            print(f"  {name} seed {seed}: {values} ({seconds:.0f} s)", flush=True)
        rows.append(summary_row(name, runs[name]))
    columns = ["content", "seeds",
               *((key, f"{heading} [95%]", "s") for key, heading in STATISTICS.items()),
               ("blown", "blown", "d"), ("warned", "warned", "d"),
               ("fit", "fit s", ".0f")]  # fmt: skip
    table = common.print_table(
        rows,
        columns,
        title=f"\n{args.style} style, {N_SEQUENCES} sequences of {N_FRAMES} frames "
        f"from one seed per training seed, frames {JUDGED.start}-{JUDGED.stop - 1} "
        "judged; means over seeds [95% interval]",
    )
    payload = dict(args=vars(args), rows=rows, runs=runs, table=table)
    common.write_json(f"corpora_{args.style}", args.output, **payload)
    return rows


if __name__ == "__main__":
    main()
