"""Many styles from one model: the factored CRBM and its alternatives (issues 29, 35).

Data: the Bandai Namco walks in seven styles (``load_bandai_walks``: takes
001-006 of active, elderly, exhausted, feminine, masculine, normal and
youthful, 30 frames per second), through the default
``make_motion_preprocessor`` fitted on each split's training frames.  Splits:
``held-out`` trains on takes 001-005 of every style and holds out the takes
006; ``one take``, for each style in turn, trains on its take 001 and all
six takes of the other styles and holds out its takes 002-006.

Candidates (``--candidates``), each trained per seed of ``--seeds`` with the
package's defaults (``--n-iter`` shortens training); each is a subclass of
:class:`Candidate` and an entry in ``CANDIDATES``:

- ``factored``: ``FactoredCRBM``, the labels gate every interaction;
- ``unlabelled``: (a) one ``ConditionalRBM`` on every style, without the
  labels: its style is the style of the frames that seed it;
- ``separate``: (b) seven ``ConditionalRBM``, one per style; a transition
  switches from one model to the other, a blend is beyond it;
- ``labelled``: (c) ``LabelledCRBM``, the labels as additive inputs to the
  dynamic biases.

Measurements (the issue's "Done when"), each of ``--parts``:

- ``style``: per style, ``--n-sequences`` sequences of ``--n-frames``
  frames seeded with real frames of a *normal* walk and asked for the style
  (the unlabelled model, which cannot be asked, also seeded with frames of
  the style itself): the share of 2-s windows from frame 100 on that the
  judge (``StyleJudge`` trained on all 42 real takes) calls the style
  ("kept"), the share also alive, and over the last 100 frames the leg
  amplitude and step frequency of every sequence as a ratio to the style's
  real 100-frame windows (pass: within 25% and 15%); blow-ups (a channel
  beyond twice its largest magnitude in the real takes, whose toes reach
  13.5 standard deviations).
- ``blends``: the 21 pairs of styles at 50/50: windows judged as one of the
  two; forward speed and step frequency between the two styles' real ones
  (within 10% of their difference).
- ``transitions``: the 42 ordered pairs, seeded with frames of the first
  style, switched to the second at half the sequence: windows from 60
  frames after the switch judged as the new style, alive, and both.
- ``likelihood``: held-out log-likelihood per frame of the takes 006 with
  their labels (frames from the 13th of each take, so that every order up
  to 12 has a full history), with the standard error of the annealed
  estimate and the gap to the reverse (conservative) estimate.
- ``recognition``: the style of the first 300 frames of every take 006: by
  Bayes' rule from the per-frame log-likelihoods under each style, equal
  priors.
- ``fillin``: the left leg (``UpperLeg_L`` down) or the upper body
  (``Spine`` up) of every take 006 erased from half-way: the log ratio of
  the paper's fill-in error to the best of ``KNNImputer(5)``,
  ``KNNImputer(10)`` and ``AutoregressiveImputer()``, averaged over styles,
  parts and seeds, with a 95% bootstrap interval.
- ``one-take``: the one-take split: for every style (or those of
  ``--one-take-styles``; runs of different styles merge in ``--tabulate``),
  the share of windows kept and alive (the unlabelled model seeded with
  frames of its take 001, the others with a normal walk's), and the
  held-out log-likelihood of its takes 002-006 (for ``separate``: of the
  CRBM trained on that one take).
- ``speed``: training seconds per epoch (``separate``: its seven models
  together); generation frames per second for one sequence and per sequence
  of 100 generated together (the default Gibbs steps); for the labelled
  models, one epoch against its matrix products alone, and the time of the
  matrix products alone of 100 sequences generated together as a fraction
  of the generation's (the batch criterion: at least 0.6).

Run from the repository root, e.g.::

    python benchmarks/styles.py --seeds 0 --n-iter 50
    python benchmarks/styles.py --parts style likelihood --candidates separate
    python benchmarks/styles.py --tabulate seed0.json seed1.json

Prints one table of the issue's measures over the seeds (shares kept and
alive, transitions and fill-in as means with a 95% bootstrap interval over
the seeds) and the share kept and alive per style, and writes JSON to
``benchmarks/results/styles.json``; ``--tabulate`` prints the tables of
earlier runs' JSON files (seeds run in separate processes) merged;
``--models`` saves the fitted candidates, to look at what they generate.
"""

import os

# One BLAS thread per process: the matrices are small, and threads only
# fight on a shared machine.  Must be set before numpy is imported.
for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import hashlib  # noqa: E402
import itertools  # noqa: E402
import json  # noqa: E402
from abc import ABC, abstractmethod  # noqa: E402
from functools import partial  # noqa: E402
from pathlib import Path  # noqa: E402

import joblib  # noqa: E402
import numpy as np  # noqa: E402
import sklearn  # noqa: E402
from _common import (  # noqa: E402
    CACHE,
    PACKAGE,
    RESULTS,
    bootstrap_mean,
    frames_with_history,
    frozen_imputer,
    parser,
    print_table,
    seconds,
)
from sklearn.impute import KNNImputer  # noqa: E402
from sklearn.utils import Bunch  # noqa: E402

from sklearn_crbm import ConditionalRBM, FactoredCRBM, LabelledCRBM  # noqa: E402
from sklearn_crbm.datasets import bone_columns, load_bandai_walks  # noqa: E402
from sklearn_crbm.impute import AutoregressiveImputer  # noqa: E402
from sklearn_crbm.metrics import StyleJudge, forward_speed, step_frequency  # noqa: E402
from sklearn_crbm.model_selection import make_fillin_cases, paper_body_parts  # noqa: E402
from sklearn_crbm.preprocessing import make_motion_preprocessor  # noqa: E402
from sklearn_crbm.utils import random_windows  # noqa: E402

FRAME_RATE = 30.0
NORMAL = "normal"
LEGS = ("UpperLeg_L", "UpperLeg_R", "LowerLeg_L", "LowerLeg_R")
BODY_PARTS = dict(left_leg="UpperLeg_L", upper_body="Spine")
JUDGED_FROM = 100  # first frame of the windows judged
AFTER_SWITCH = 60  # frames after a transition's switch before windows count
LAST_FRAMES = 100  # frames of the amplitude and frequency check
SCORED_FROM = 12  # frames of each held-out take not scored (full histories)
RECOGNITION_FRAMES = 300
BLOWN_UP = 2.0  # a channel beyond this times its largest real |z| has blown up
PARTS = tuple(
    "style blends transitions likelihood recognition fillin one-take speed".split()
)


# ------------------------------------------------------------------- data
class Split:
    """One split of ``walks``, preprocessed, with the instruments that judge motion.

    ``train`` and ``test`` are masks of the frames (rows of ``walks.data``);
    ``Z`` is every take preprocessed; ``styles`` are the style names in the
    order of the label weights; ``judge`` calls the style of 2-s windows and
    whether they are alive, ``pace`` gives the amplitude and frequency of
    100-frame windows against the real ones; ``limit`` is the |z| per channel
    beyond which motion has blown up; ``real_speed`` and ``real_frequency``
    (Hz) are the means of the real takes of every style.
    """

    def __init__(self, walks, train):
        self.walks, self.train, self.test = walks, train, ~train
        self.styles = styles = sorted(walks.target_names)
        ids = walks.sequence_ids
        with sklearn.config_context(enable_metadata_routing=True):
            self.pre = make_motion_preprocessor(walks.skeleton)
            self.pre.fit(walks.data[train], sequence_ids=ids[train])
            self.Z = Z = self.pre.transform(walks.data, sequence_ids=ids)
        names = self.pre.get_feature_names_out()
        self.legs = legs = bone_columns(names, LEGS)
        labels = walks.target_names[walks.target]
        self.judge = StyleJudge(legs=legs).fit(Z, labels, sequence_ids=ids)
        self.pace = StyleJudge(window=LAST_FRAMES, stride=10, legs=legs)
        self.pace.fit(Z, labels, sequence_ids=ids)
        self.limit = BLOWN_UP * np.abs(Z).max(axis=0)
        speed = forward_speed(Z, sequence_ids=ids, feature_names=names)
        frequency = step_frequency(
            Z, sequence_ids=ids, features=legs, frame_rate=FRAME_RATE
        )
        take_styles = labels[np.searchsorted(ids, np.arange(ids.max() + 1))]
        self.real_speed = {s: float(speed[take_styles == s].mean()) for s in styles}
        self.real_frequency = {
            s: float(frequency[take_styles == s].mean()) for s in styles
        }

    def frames(self, rows):
        """``(Z, styles, sequence_ids)`` of the given rows."""
        walks = self.walks
        styles = walks.target_names[walks.target[rows]]
        return self.Z[rows], styles, walks.sequence_ids[rows]

    def seed_windows(self, style, width, n_windows, rng):
        """``n_windows`` windows of ``width`` real training frames of ``style``."""
        Z, styles, ids = self.frames(self.train)
        return random_windows(
            Z,
            sequence_ids=ids,
            width=width,
            n_windows=n_windows,
            sequences=np.unique(ids[styles == style]),
            random_state=rng,
        )


def label_weights(styles, n_frames, first, second=None, switch=None, blend=None):
    """Per-frame label weights: one style, a 50/50 ``blend``, or a switch."""
    weights = np.zeros((n_frames, len(styles)))
    weights[:, styles.index(first)] = 1.0
    if blend is not None:
        weights[:, styles.index(first)] = 1.0 - blend
        weights[:, styles.index(second)] = blend
    if switch is not None:
        weights[switch:] = 0.0
        weights[switch:, styles.index(second)] = 1.0
    return weights


# ------------------------------------------------------------- candidates
CRBM_PARAMETERS = (
    "components_ intercept_hidden_ intercept_visible_ autoregressive_ past_to_hidden_"
).split()


def _new(estimator, seed, n_iter, params=None):
    """``estimator`` with the package's defaults but ``params`` (and ``n_iter``
    if given)."""
    model = estimator(random_state=seed).set_params(**(params or {}))
    return model if n_iter is None else model.set_params(n_iter=n_iter)


def _n_parameters(model, names=CRBM_PARAMETERS):
    return sum(getattr(model, name).size for name in names if hasattr(model, name))


def _estimate(model, Z, sequence_ids, seed, style=None):
    """Per frame ``(estimate, standard error, reverse estimate)``."""
    result = model.estimate_log_likelihood(
        Z, sequence_ids=sequence_ids, style=style, reverse=True, random_state=seed
    )
    return result.log_likelihood, result.standard_error, result.lower


def _filler(model, Z, sequence_ids, seed, labels=(), **transform_params):
    """``frozen_imputer(model, Z, ...).transform``, with ``transform_params``."""
    imputer = frozen_imputer(model, Z, sequence_ids, seed, *labels)
    return partial(imputer.transform, **transform_params)


class Candidate(ABC):
    """A model of many styles, as the benchmark drives it.

    ``fit(Z, styles, sequence_ids, seed=, n_iter=, only=)`` trains on
    labelled frames; ``only``: the styles that will be asked for.  The
    columns of the label weights that generation follows are the sorted
    styles, as a classifier's ``classes_``.
    """

    name = ""
    controls_style = True  # False: its style is that of the frames seeding it

    def __init__(self, params=None):
        self.params = params  # estimator parameters other than the defaults

    @abstractmethod
    def fit(self, Z, styles, sequence_ids, *, seed, n_iter, only=None):
        """Train on labelled frames; returns ``self``."""

    def history_length(self):
        """Seed frames that generation needs."""
        return self.model.history_length

    def n_epochs(self):
        """Epochs each of its models trained."""
        return self.model.n_iter_

    def can_generate(self, weights):
        """Whether it can follow these per-frame label weights."""
        return True

    @abstractmethod
    def generate(self, weights, history, random_state):
        """Frames (n_sequences * n_frames, n_features) following ``weights``."""

    @abstractmethod
    def log_likelihood(self, Z, styles, sequence_ids, seed):
        """Per frame ``(estimate, standard error, reverse estimate)`` given labels."""

    def recognise(self, Z, sequence_ids, styles, seed):
        """The style of every sequence, or None if it cannot tell."""
        return None

    def filler(self, style, Z, sequence_ids, seed):
        """Fills sequences of ``style``: ``filler(X_missing)`` (trained on ``Z``)."""
        return _filler(self.model, Z, sequence_ids, seed)

    def n_parameters(self):
        """Number of trained parameters."""
        return _n_parameters(self.model)


class Unlabelled(Candidate):
    """(a) One ConditionalRBM on every style, without the labels."""

    name = "unlabelled"
    controls_style = False

    def fit(self, Z, styles, sequence_ids, *, seed, n_iter, only=None):
        self.model = _new(ConditionalRBM, seed, n_iter, self.params)
        self.model.fit(Z, sequence_ids=sequence_ids)
        return self

    def can_generate(self, weights):
        # it ignores them, so it only makes sense for one style throughout
        return bool(np.all(weights == weights[:1]) and weights.max() == 1.0)

    def generate(self, weights, history, random_state):
        return self.model.sample(
            len(weights), history=history, random_state=random_state
        )

    def log_likelihood(self, Z, styles, sequence_ids, seed):
        return _estimate(self.model, Z, sequence_ids, seed)


class Separate(Candidate):
    """(b) One ConditionalRBM per style; a transition switches models."""

    name = "separate"

    def fit(self, Z, styles, sequence_ids, *, seed, n_iter, only=None):
        self.classes_ = np.unique(styles)
        self.models = {
            style: _new(ConditionalRBM, seed, n_iter, self.params).fit(
                Z[styles == style], sequence_ids=sequence_ids[styles == style]
            )
            for style in (self.classes_ if only is None else only)
        }
        return self

    def history_length(self):
        return max(model.history_length for model in self.models.values())

    def n_epochs(self):
        return max(model.n_iter_ for model in self.models.values())

    def can_generate(self, weights):
        return bool(np.all(weights.max(axis=1) == 1.0))  # one style at every frame

    def generate(self, weights, history, random_state):
        """Each run of frames of one style from that style's model."""
        styles = np.argmax(weights, axis=1)
        runs = np.flatnonzero(np.diff(styles)) + 1
        parts, past = [], history
        for start, stop in zip(np.r_[0, runs], np.r_[runs, len(styles)], strict=True):
            model = self.models[self.classes_[styles[start]]]
            new = model.sample(stop - start, history=past, random_state=random_state)
            new = new.reshape(len(history), stop - start, -1)
            parts.append(new)
            past = np.concatenate([past, new], axis=1)[:, -self.history_length() :]
        return np.concatenate(parts, axis=1).reshape(-1, history.shape[2])

    def log_likelihood(self, Z, styles, sequence_ids, seed):
        estimate, error, lower = (np.empty(len(Z)) for _ in range(3))
        for style in np.unique(styles):
            rows = styles == style
            estimate[rows], error[rows], lower[rows] = _estimate(
                self.models[style], Z[rows], sequence_ids[rows], seed
            )
        return estimate, error, lower

    def recognise(self, Z, sequence_ids, styles, seed):
        scored = frames_with_history(sequence_ids, SCORED_FROM)
        takes = np.unique(sequence_ids)
        totals = []
        for style in styles:
            estimate = _estimate(self.models[style], Z, sequence_ids, seed)[0]
            estimate, ids = estimate[scored], sequence_ids[scored]
            totals.append([estimate[ids == k].sum() for k in takes])
        return np.asarray(styles, dtype=object)[np.argmax(totals, axis=0)]

    def filler(self, style, Z, sequence_ids, seed):
        return _filler(self.models[style], Z, sequence_ids, seed)

    def n_parameters(self):
        return sum(_n_parameters(model) for model in self.models.values())


class StyleModel(Candidate):
    """A model that takes the labels (FactoredCRBM, LabelledCRBM)."""

    estimator = None
    parameters = ()  # its fitted arrays, for the count of parameters

    def fit(self, Z, styles, sequence_ids, *, seed, n_iter, only=None):
        self.model = _new(self.estimator, seed, n_iter, self.params)
        self.model.fit(Z, styles, sequence_ids=sequence_ids)
        self.styles = styles
        return self

    def generate(self, weights, history, random_state):
        return self.model.sample(
            len(weights), history=history, style=weights, random_state=random_state
        )

    def log_likelihood(self, Z, styles, sequence_ids, seed):
        return _estimate(self.model, Z, sequence_ids, seed, style=styles)

    def recognise(self, Z, sequence_ids, styles, seed):
        named = self.model.set_params(random_state=seed).predict(
            Z, sequence_ids=sequence_ids
        )
        return np.asarray(
            [named[sequence_ids == k][0] for k in np.unique(sequence_ids)], dtype=object
        )

    def filler(self, style, Z, sequence_ids, seed):
        labels = (self.styles,)
        return _filler(self.model, Z, sequence_ids, seed, labels, style=style)

    def n_parameters(self):
        return _n_parameters(self.model, self.parameters)


class Factored(StyleModel):
    """The factored CRBM: the labels gate every interaction."""

    name = "factored"
    estimator = FactoredCRBM
    parameters = (
        "visible_factors_ hidden_factors_ past_visible_factors_ visible_from_factors_ "
        "past_hidden_factors_ hidden_from_factors_ label_features_ style_factors_ "
        "style_undirected_ style_hidden_ style_visible_ intercept_hidden_ "
        "intercept_visible_"
    ).split()


class Labelled(StyleModel):
    """(c) A CRBM with the labels as additive inputs to its dynamic biases."""

    name = "labelled"
    estimator = LabelledCRBM
    parameters = (*CRBM_PARAMETERS, "label_to_visible_", "label_to_hidden_")


CANDIDATES = {
    candidate.name: candidate
    for candidate in (Factored, Unlabelled, Separate, Labelled)
}


# ----------------------------------------------------------- measurements
def _draw_seed(rng):
    """An int seed from ``rng`` (the estimators take ints or RandomStates)."""
    return int(rng.integers(np.iinfo(np.int32).max))


def generated_ids(n_sequences, n_frames):
    return np.repeat(np.arange(n_sequences), n_frames)


def generate(candidate, split, weights, seed_style, args, rng):
    """Sequences following ``weights``, seeded with real frames of ``seed_style``."""
    width = candidate.history_length()
    history = split.seed_windows(seed_style, width, args.n_sequences, rng)
    return candidate.generate(weights, history, _draw_seed(rng))


def _blown_up(split, frames, n_sequences):
    """Sequences with a value beyond its channel's limit (or not finite)."""
    beyond = ~(np.abs(frames) <= split.limit)  # NaN counts as beyond
    return beyond.reshape(n_sequences, -1).any(axis=1)


def generate_judged(candidate, split, weights, seed_style, args, rng):
    """Generate, then judge: windows (kept, alive), last frames' pace, blow-ups."""
    frames = generate(candidate, split, weights, seed_style, args, rng)
    n_sequences, n_frames = args.n_sequences, len(weights)
    ids = generated_ids(n_sequences, n_frames)
    requested = np.asarray(split.styles, dtype=object)[np.argmax(weights, axis=1)]
    blown = _blown_up(split, frames, n_sequences)
    finite = np.where(np.isfinite(frames), frames, 0.0)
    verdict = split.judge.verdict(
        finite, np.tile(requested, n_sequences), sequence_ids=ids
    )
    last = np.arange(len(frames)).reshape(n_sequences, n_frames)[:, -LAST_FRAMES:]
    pace = split.pace.verdict(
        finite[last.ravel()],
        np.repeat(requested[-1], last.size),
        sequence_ids=generated_ids(n_sequences, LAST_FRAMES),
    )
    return verdict, pace, blown


def kept_cell(verdict, pace, blown, **more):
    """Windows kept (and alive) from JUDGED_FROM on, ``more``, pace and blow-ups."""
    judged = verdict.starts >= JUDGED_FROM
    return dict(
        kept=float(verdict.correct[judged].mean()),
        kept_alive=float(verdict.accepted[judged].mean()),
        **more,
        pace_ok=int(np.sum(pace.alive)),
        blown_up=int(blown.sum()),
    )


def style_kept(candidate, split, args, rng):
    """Per style: windows kept and alive, last-frame pace, blow-ups."""
    rows = {}
    seeds = [(NORMAL, "normal seeds")]
    if not candidate.controls_style:
        seeds.append((None, "own seeds"))
    for seed_style, label in seeds:
        for style in split.styles:
            weights = label_weights(split.styles, args.n_frames, style)
            verdict, pace, blown = generate_judged(
                candidate, split, weights, seed_style or style, args, rng
            )
            rows.setdefault(label, {})[style] = kept_cell(
                verdict,
                pace,
                blown,
                amplitude_ratio=pace.amplitude_ratio.tolist(),
                frequency_ratio=pace.frequency_ratio.tolist(),
            )
    return rows


def blends(candidate, split, args, rng):
    names = split.pre.get_feature_names_out()
    cells = {}
    for first, second in itertools.combinations(split.styles, 2):
        weights = label_weights(split.styles, args.n_frames, first, second, blend=0.5)
        if not candidate.can_generate(weights):
            return None
        verdict, frames, ids, blown = judged_blend(candidate, split, weights, args, rng)
        speed = forward_speed(frames, sequence_ids=ids, feature_names=names)
        frequency = step_frequency(
            frames, sequence_ids=ids, features=split.legs, frame_rate=FRAME_RATE
        )
        one_of_two = np.isin(verdict.predicted, [first, second]).mean()
        cells[f"{first}/{second}"] = dict(
            one_of_two=float(one_of_two),
            speed_between=_between(np.mean(speed), split.real_speed, first, second),
            frequency_between=_between(
                np.mean(frequency), split.real_frequency, first, second
            ),
            blown_up=int(blown.sum()),
        )
    return cells


def judged_blend(candidate, split, weights, args, rng):
    """Sequences following the label ``weights``, seeded with a normal walk:
    the judge's verdict of the windows from JUDGED_FROM on (each alive against
    the style it is judged as), the frames and sequence ids from JUDGED_FROM
    on, and which sequences blew up."""
    frames = generate(candidate, split, weights, NORMAL, args, rng)
    blown = _blown_up(split, frames, args.n_sequences)
    frames = np.where(np.isfinite(frames), frames, 0.0)
    ids = generated_ids(args.n_sequences, args.n_frames)
    verdict = split.judge.verdict(frames, sequence_ids=ids)
    judged = verdict.starts >= JUDGED_FROM
    verdict = Bunch(**{key: value[judged] for key, value in verdict.items()})
    later = np.tile(np.arange(args.n_frames) >= JUDGED_FROM, args.n_sequences)
    return verdict, frames[later], ids[later], blown


def _between(value, real, first, second, margin=0.1):
    """Whether ``value`` lies between the real values of two styles (or near)."""
    low, high = sorted((real[first], real[second]))
    return bool(low - margin * (high - low) <= value <= high + margin * (high - low))


def transitions(candidate, split, args, rng):
    cells = {}
    switch = args.n_frames // 2
    for first, second in itertools.permutations(split.styles, 2):
        weights = label_weights(
            split.styles, args.n_frames, first, second, switch=switch
        )
        if not candidate.can_generate(weights):
            return None
        verdict, _, blown = generate_judged(candidate, split, weights, first, args, rng)
        judged = verdict.starts >= switch + AFTER_SWITCH
        cells[f"{first}->{second}"] = dict(
            new_style=float(verdict.correct[judged].mean()),
            alive=float(verdict.alive[judged].mean()),
            new_alive=float(verdict.accepted[judged].mean()),
            blown_up=int(blown.sum()),
        )
    return cells


def likelihood(candidate, split, rows, seed):
    Z, styles, ids = split.frames(rows)
    estimate, error, lower = candidate.log_likelihood(Z, styles, ids, seed)
    scored = frames_with_history(ids, SCORED_FROM)
    return dict(
        mean=float(estimate[scored].mean()),
        standard_error=float(np.sqrt(np.sum(error[scored] ** 2)) / len(scored)),
        reverse_gap=float(np.mean(estimate[scored] - lower[scored])),
        n_frames=len(scored),
    )


def recognition(candidate, split, seed):
    Z, styles, ids = split.frames(split.test)
    first = np.concatenate(
        [np.flatnonzero(ids == k)[:RECOGNITION_FRAMES] for k in np.unique(ids)]
    )
    named = candidate.recognise(Z[first], ids[first], split.styles, seed)
    if named is None:
        return None
    truth = [styles[ids == k][0] for k in np.unique(ids)]
    return dict(
        correct=int(np.sum(named == np.asarray(truth, dtype=object))), of=len(truth)
    )


def fillin(candidate, split, seed):
    """Log ratio of the candidate's fill-in error to the best simple baseline's."""
    Z, _, ids = split.frames(split.train)
    baselines = [
        KNNImputer(n_neighbors=5).fit(Z),
        KNNImputer(n_neighbors=10).fit(Z),
        AutoregressiveImputer().fit(Z, sequence_ids=ids),
    ]
    walks = split.walks
    takes = np.unique(walks.sequence_ids[split.test])
    styles = walks.target_names[
        walks.target[np.searchsorted(walks.sequence_ids, takes)]
    ]
    held_out = {s: walks.sequence_names[k] for s, k in zip(styles, takes, strict=True)}
    cases = make_fillin_cases(
        walks,
        split.pre,
        trials=held_out,
        body_parts=paper_body_parts(walks.skeleton, **BODY_PARTS),
    )
    ratios, fillers = {}, {}
    for (style, part), case in cases.items():
        best = min(case.errors(b.transform(case.X_missing))[0] for b in baselines)
        if style not in fillers:
            fillers[style] = candidate.filler(style, Z, ids, seed)
        filled = fillers[style](case.X_missing)
        ratios[f"{style}/{part}"] = float(np.log(case.errors(filled)[0] / best))
    return ratios


def one_take(name, walks, args, seed, rng):
    """Per style: trained on its take 001 and the other styles' six takes."""
    cells = {}
    labels = walks.target_names[walks.target]
    takes = walks.takes[walks.sequence_ids]
    for style in args.one_take_styles or walks.target_names:
        train = (labels != style) | (takes == 1)
        split = Split(walks, train)
        Z, styles, ids = split.frames(train)
        candidate = CANDIDATES[name](args.params).fit(
            Z, styles, ids, seed=seed, n_iter=args.n_iter, only=[style]
        )
        weights = label_weights(split.styles, args.n_frames, style)
        seed_style = NORMAL if candidate.controls_style else style
        verdict, pace, blown = generate_judged(
            candidate, split, weights, seed_style, args, rng
        )
        log_likelihood = likelihood(candidate, split, ~train, seed)
        cells[style] = dict(
            kept_cell(verdict, pace, blown), log_likelihood=log_likelihood
        )
        print(
            f"    one take, {style}: {cells[style]['kept_alive']:.0%} kept and "
            f"alive, held-out LL {log_likelihood['mean']:.2f}",
            flush=True,
        )
    return cells


def speed(candidate, split, n_frames_trained, n_iter, fit_seconds, rng):
    """Training time per epoch; generation frames per second, 1 and 100 sequences."""
    weights = label_weights(split.styles, 300, NORMAL)
    rates = {}
    for n_sequences in (1, 100):
        history = split.seed_windows(
            NORMAL, candidate.history_length(), n_sequences, rng
        )
        run = partial(candidate.generate, weights, history, _draw_seed(rng))
        rates[n_sequences] = len(weights) * n_sequences / seconds(run)
    out = dict(
        seconds_per_epoch=fit_seconds / n_iter,
        training_frames_per_second=n_frames_trained * n_iter / fit_seconds,
        generation_fps_one=rates[1],
        generation_fps_per_sequence_of_100=rates[100] / 100,
    )
    if isinstance(candidate, StyleModel):
        out.update(epoch_against_products(candidate, split))
        out.update(generation_against_products(candidate, split, rng))
    return out


def _recorded_products(run):
    """The operand shapes and dtypes of every ``numpy.matmul`` that ``run()`` calls."""
    shapes, matmul = [], np.matmul

    def recording(a, b, *rest, **kwargs):
        shapes.append((a.shape, b.shape, np.result_type(a, b)))
        return matmul(a, b, *rest, **kwargs)

    np.matmul = recording
    try:
        run()
    finally:
        np.matmul = matmul
    return shapes


def _products_alone(shapes):
    """A function running products of ``shapes`` (random operands) alone."""
    rng = np.random.default_rng(0)
    operands = [
        (rng.random(a).astype(dtype), rng.random(b).astype(dtype))
        for a, b, dtype in shapes
    ]

    def products():
        for a, b in operands:
            np.matmul(a, b)

    return products


def generation_against_products(candidate, split, rng, n_sequences=100, n_frames=30):
    """Frames per second of ``n_sequences`` generated together against the
    bound set by the generation's matrix products alone (the issue's batch
    criterion: at least 0.6 of it)."""
    weights = label_weights(split.styles, n_frames, NORMAL)
    history = split.seed_windows(NORMAL, candidate.history_length(), n_sequences, rng)
    run = partial(candidate.generate, weights, history, _draw_seed(rng))
    shapes = _recorded_products(run)
    generation, alone = seconds(run), seconds(_products_alone(shapes))
    return dict(
        generation_seconds=generation,
        generation_products_seconds=alone,
        generation_of_products_bound=alone / generation,
    )


def epoch_against_products(candidate, split, repeats=3):
    """One training epoch's time against that of its matrix products alone.

    The epoch runs once with ``numpy.matmul`` recording the shapes of every
    product (the package's math calls it for all of them), then the same
    products run alone on arrays of those shapes; both are timed ``repeats``
    times (best of), one BLAS thread.
    """
    Z, styles, ids = split.frames(split.train)
    Z = Z.astype(np.float32)
    params = candidate.model.get_params()

    def one_epoch():
        model = candidate.estimator(**params)
        model.partial_fit(Z, styles, sequence_ids=ids)

    shapes = _recorded_products(one_epoch)
    products = _products_alone(shapes)
    epoch, alone = seconds(one_epoch, repeats), seconds(products, repeats)
    return dict(
        epoch_seconds=epoch,
        products_seconds=alone,
        epoch_over_products=epoch / alone,
        n_products=len(shapes),
    )


# ----------------------------------------------------------------- report
# The "Done when" in one table: one row per candidate (and seeding),
# each column a measure over the training seeds.  A part's result per seed
# is one cell (ONE_CELL_PARTS) or a dict of cells: per style (style,
# one-take), per pair (blends, transitions), per case (fill-in log ratios).
ONE_CELL_PARTS = ("likelihood", "recognition", "speed")


def _per_seed(per_seed, part, seeding=None):
    """``part``'s cells of every seed that has it: a list (one per seed) of lists."""
    rows = []
    for result in per_seed.values():
        found = result.get(part)
        if part == "style" and found is not None:
            found = found.get(seeding)
        if found is None:
            continue
        rows.append([found] if part in ONE_CELL_PARTS else list(found.values()))
    return rows


def _interval(rows, key, rng, percent=True):
    """Mean of ``key`` of the cells (None: the cells) over the seeds, with its
    95% bootstrap interval."""
    values = [[cell if key is None else cell[key] for cell in row] for row in rows]
    mean, low, high = bootstrap_mean(values, seed=rng)
    if percent:
        return f"{100 * mean:.0f}% [{100 * low:.0f}, {100 * high:.0f}]"
    return f"{mean:+.3f} [{low:+.3f}, {high:+.3f}]"


def _fillin(rows, rng):
    """Mean log ratio over styles, parts and seeds, its interval over the
    seed-cells (each a row of the bootstrap: one seed gives an interval too)."""
    return _interval([[ratio] for row in rows for ratio in row], None, rng, False)


def _lowest_style(per_seed, seeding):
    """The style whose mean share kept and alive over the seeds is lowest."""
    means = {}
    for result in per_seed.values():
        for style, cell in (result.get("style") or {}).get(seeding, {}).items():
            means.setdefault(style, []).append(cell["kept_alive"])
    style = min(means, key=lambda s: np.mean(means[s]))
    return f"{style} {100 * np.mean(means[style]):.0f}%"


def _pace(rows):
    cells = [cell for row in rows for cell in row]
    passed = sum(c["pace_ok"] for c in cells)
    total = sum(len(c["amplitude_ratio"]) for c in cells)
    return f"{passed}/{total}"


def _blown_up_total(rows):
    return str(sum(cell["blown_up"] for row in rows for cell in row))


def _blends(rows, rng):
    """Pairs (mean over seeds) with the speed between the two styles', pairs
    with at least 80% of windows judged one of the two (and the mean share of
    windows with its interval), pairs with the step frequency between."""
    n = len(rows[0])

    def pairs(passes):
        return f"{np.mean([sum(passes(c) for c in row) for row in rows]):.1f}/{n}"

    one_of_two = _interval(rows, "one_of_two", rng)
    return (
        f"{pairs(lambda c: c['speed_between'])}; "
        f"{pairs(lambda c: c['one_of_two'] >= 0.8)} ({one_of_two}); "
        f"freq {pairs(lambda c: c['frequency_between'])}"
    )


def _likelihood(rows):
    means = [row[0]["mean"] for row in rows]
    error = max(row[0]["standard_error"] for row in rows)
    gap = max(row[0]["reverse_gap"] for row in rows)
    span = f" ({min(means):.2f} to {max(means):.2f})" if len(means) > 1 else ""
    return f"{np.mean(means):.2f}{span}; SE {error:.1e}, gap {gap:.2f}"


def _recognition(rows):
    correct = [row[0]["correct"] for row in rows]
    return f"{min(correct)}-{max(correct)}/{rows[0][0]['of']}"


def _batch(rows):
    cells = [row[0] for row in rows if "generation_of_products_bound" in row[0]]
    if not cells:
        return "-"
    return f"{np.mean([c['generation_of_products_bound'] for c in cells]):.2f}"


def _one_take(rows):
    cells = [cell for row in rows for cell in row]
    alive = np.mean([c["kept_alive"] for c in cells])
    mean = np.mean([c["log_likelihood"]["mean"] for c in cells])
    return f"{100 * alive:.0f}%; LL {mean:.2f}"


def _epoch(rows):
    """Seconds per epoch, mean over the seeds that were trained in their run
    (a model loaded with ``--models`` has no training time)."""
    timed = [row[0]["seconds_per_epoch"] for row in rows]
    timed = [t for t in timed if np.isfinite(t)]
    return f"{np.mean(timed):.2f}" if timed else "-"


# (column, part, formatter of the per-seed rows of cells; ``rng`` for the
# bootstrap), for the table's columns in the order of the issue.
COLUMNS = [
    ("kept & alive [95%]", "style", lambda r, g: _interval(r, "kept_alive", g)),
    (
        "kept",
        "style",
        lambda r, g: f"{100 * np.mean([c['kept'] for x in r for c in x]):.0f}%",
    ),
    ("in pace", "style", lambda r, g: _pace(r)),
    ("blown up", "style", lambda r, g: _blown_up_total(r)),
    (
        "transitions: new & alive [95%]",
        "transitions",
        lambda r, g: _interval(r, "new_alive", g),
    ),
    (
        "blends: speed between; 1 of 2 >= 80% (windows [95%]); freq",
        "blends",
        _blends,
    ),
    ("held-out LL/frame", "likelihood", lambda r, g: _likelihood(r)),
    ("one take: kept & alive; LL", "one-take", lambda r, g: _one_take(r)),
    ("recognised", "recognition", lambda r, g: _recognition(r)),
    ("fill-in log ratio [95%]", "fillin", lambda r, g: _fillin(r, g)),
    ("100 together / products", "speed", lambda r, g: _batch(r)),
    ("s/epoch", "speed", lambda r, g: _epoch(r)),
]


def _seedings(per_seed):
    first = next(iter(per_seed.values()))
    return list(first.get("style") or {None: None})


def table(results, seed=0):
    """One row per candidate (and seeding): the issue's measures over the seeds
    (``seed``: of the bootstrap)."""
    rows = []
    for name, per_seed in results.items():
        for k, seeding in enumerate(_seedings(per_seed)):
            row = {
                "candidate": f"{name} ({seeding})" if seeding else name,
                "seeds": ",".join(str(seed) for seed in per_seed),
                "params": str(next(iter(per_seed.values())).get("n_parameters", "-")),
            }
            if k == 0 and seeding is not None:
                row["lowest style"] = _lowest_style(per_seed, seeding)
            for column, part, formatter in COLUMNS:
                cells = _per_seed(per_seed, part, seeding)
                shown = cells and (part == "style" or k == 0)
                # each column its own stream: its interval does not depend
                # on the columns before it
                fresh = np.random.default_rng(seed)
                row[column] = formatter(cells, fresh) if shown else "-"
            rows.append(row)
    headers = ["candidate", "seeds", "params", "lowest style"]
    headers += [column for column, _, _ in COLUMNS]
    print_table(
        [{h: row.get(h, "-") for h in headers} for row in rows],
        [(h, h, "s") for h in headers],
    )
    per_style_table(results)
    one_take_table(results)


def one_take_table(results):
    """The one-take split per style: windows kept and alive, and the held-out
    log-likelihood of the style's other takes, means over the seeds."""
    rows = []
    for name, per_seed in results.items():
        cells = {}
        for result in per_seed.values():
            for style, cell in (result.get("one-take") or {}).items():
                cells.setdefault(style, []).append(cell)
        if not cells:
            continue
        row = {"candidate": name}
        for style, found in sorted(cells.items()):
            alive = np.mean([c["kept_alive"] for c in found])
            mean = np.mean([c["log_likelihood"]["mean"] for c in found])
            row[style] = f"{100 * alive:.0f}%; {mean:.2f}"
        rows.append(row)
    if rows:
        styles = sorted({key for row in rows for key in row} - {"candidate"})
        print()
        print_table(
            [
                {key: row.get(key, "-") for key in ["candidate", *styles]}
                for row in rows
            ],
            [("candidate", "candidate", "s")] + [(s, s, "s") for s in styles],
            title="one take: kept & alive; held-out LL/frame of its other takes",
        )


def per_style_table(results):
    """Windows kept and alive per style, mean over the seeds."""
    rows = []
    for name, per_seed in results.items():
        for seeding in _seedings(per_seed):
            if seeding is None:
                continue
            means = {}
            for result in per_seed.values():
                for style, cell in result.get("style", {}).get(seeding, {}).items():
                    means.setdefault(style, []).append(cell["kept_alive"])
            row = {"candidate": f"{name} ({seeding})"}
            row.update({s: f"{100 * np.mean(v):.0f}%" for s, v in means.items()})
            rows.append(row)
    if rows:
        styles = [key for key in rows[0] if key != "candidate"]
        print()
        print_table(
            rows, [("candidate", "candidate", "s")] + [(s, s, "s") for s in styles]
        )


# ------------------------------------------------------------------- main
def _params_tag(args):
    """A file-name suffix that tells models of other ``--params`` apart."""
    if not args.params:
        return ""
    text = json.dumps(args.params, sort_keys=True).encode()
    return "_" + hashlib.sha1(text).hexdigest()[:8]


def fitted_candidate(name, split, args, seed):
    """``(candidate, training seconds)``, trained on the split's training frames,
    or loaded from ``args.models`` (NaN seconds) where an earlier run saved it."""
    candidate = CANDIDATES[name](args.params)
    saved = Path(args.models or "") / f"{name}_seed{seed}{_params_tag(args)}.joblib"
    if args.models and saved.exists():  # fitted by an earlier run
        vars(candidate).update(joblib.load(saved))
        print(f"  {name}, seed {seed}: loaded {saved}", flush=True)
        return candidate, float("nan")
    Z, styles, ids = split.frames(split.train)
    fit = partial(candidate.fit, Z, styles, ids, seed=seed, n_iter=args.n_iter)
    fit_seconds = seconds(fit)
    print(f"  {name}, seed {seed}: trained in {fit_seconds:.0f} s", flush=True)
    if args.models:  # to look at what it generates, or measure more parts
        saved.parent.mkdir(parents=True, exist_ok=True)
        joblib.dump(vars(candidate), saved)
    return candidate, fit_seconds


def run_candidate(name, walks, split, args, seed):
    Z, styles, ids = split.frames(split.train)
    rng = np.random.default_rng(seed)
    if set(args.parts) == {"one-take"}:  # its splits train their own models
        return {"one-take": one_take(name, walks, args, seed, rng)}
    candidate, fit_seconds = fitted_candidate(name, split, args, seed)
    n_iter = candidate.n_epochs()
    measures = {  # in this order: they draw from one random stream
        "style": lambda: style_kept(candidate, split, args, rng),
        "blends": lambda: blends(candidate, split, args, rng),
        "transitions": lambda: transitions(candidate, split, args, rng),
        "likelihood": lambda: likelihood(candidate, split, split.test, seed),
        "recognition": lambda: recognition(candidate, split, seed),
        "fillin": lambda: fillin(candidate, split, seed),
        "speed": lambda: speed(candidate, split, len(Z), n_iter, fit_seconds, rng),
        "one-take": lambda: one_take(name, walks, args, seed, rng),
    }
    out = {"n_parameters": int(candidate.n_parameters()), "fit_seconds": fit_seconds}
    for part, measure in measures.items():
        if part in args.parts:
            out[part] = measure()
    return out


def cached_cell(name, seed, args, walks, split):
    """``run_candidate``'s result, read from the cache when it is there.

    The key is the candidate, the seed, the options that change a result and
    the code of the package and of this script, so that runs of disjoint
    seeds in several processes, and a rerun after a crash, share the work.
    """
    key = hashlib.sha1()
    for path in sorted([*PACKAGE.rglob("*.py"), Path(__file__)]):
        key.update(path.read_bytes())
    options = (name, seed, args.n_iter, args.parts, args.n_frames, args.n_sequences)
    if args.params:
        options += tuple(sorted(args.params.items()))
    if args.one_take_styles:
        options += tuple(args.one_take_styles)
    key.update(repr(options).encode())
    path = CACHE / "styles" / f"{name}_seed{seed}_{key.hexdigest()[:16]}.json"
    if path.exists():
        return json.loads(path.read_text())
    result = run_candidate(name, walks, split, args, seed)
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(result))
    return result


def _merge(merged, parts):
    """Add one run's parts of a seed to ``merged``; the one-take split's styles
    run apart (``--one-take-styles``) merge too."""
    for part, cells in parts.items():
        if part == "one-take" and merged.get(part) and cells:
            merged[part].update(cells)
        else:
            merged[part] = cells


def tabulate(paths):
    """Print the tables of the results in earlier runs' JSON files, merged
    (seeds, and the parts of a seed)."""
    results = {}
    for path in paths:
        for name, per_seed in json.loads(Path(path).read_text())["results"].items():
            for seed, parts in per_seed.items():  # parts of one seed run apart merge
                _merge(results.setdefault(name, {}).setdefault(seed, {}), parts)
    print(f"\nBandai walks, 7 styles; from {', '.join(paths)}\n")
    table(results)
    return results


def main(argv=None):
    p = parser(__doc__)
    p.add_argument("--n-iter", type=int, help="epochs (default: the package's)")
    p.add_argument(
        "--candidates", nargs="+", default=list(CANDIDATES), choices=CANDIDATES
    )
    p.add_argument("--parts", nargs="+", default=list(PARTS), choices=PARTS)
    p.add_argument("--n-frames", type=int, default=1000)
    p.add_argument("--n-sequences", type=int, default=6)
    p.add_argument(
        "--one-take-styles",
        nargs="+",
        metavar="STYLE",
        help="the styles of the one-take split (default: all seven)",
    )
    p.add_argument(
        "--params",
        type=json.loads,
        metavar="JSON",
        help="estimator parameters other than the defaults, for every candidate's "
        "models, e.g. '{\"history_noise_fraction\": 0.5}'",
    )
    p.add_argument(
        "--models", help="folder to save fitted candidates in (and reuse them from)"
    )
    p.add_argument(
        "--tabulate",
        nargs="+",
        metavar="JSON",
        help="print the tables of earlier runs' JSON (merged) instead of running",
    )
    p.set_defaults(output=str(RESULTS / "styles.json"))
    args = p.parse_args(argv)
    if args.tabulate:
        return tabulate(args.tabulate)

    sklearn.set_config(enable_metadata_routing=True)
    walks = load_bandai_walks(args.data_home)
    split = Split(walks, walks.takes[walks.sequence_ids] <= 5)
    results = {}
    for name in args.candidates:
        results[name] = {
            seed: cached_cell(name, seed, args, walks, split) for seed in args.seeds
        }
    print(
        f"\nBandai walks, 7 styles; trained on takes 001-005, judged over "
        f"{args.n_sequences} x {args.n_frames} frames per style; seeds {args.seeds}, "
        f"n_iter {args.n_iter or 'default'}, parameters {args.params or 'default'}\n"
    )
    table(results)
    output = Path(args.output)
    output.parent.mkdir(parents=True, exist_ok=True)
    output.write_text(json.dumps({"args": vars(args), "results": results}, indent=1))
    print(f"\nwrote {output}")
    return results


if __name__ == "__main__":
    main()
