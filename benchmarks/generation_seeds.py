"""Generation: do generated walks and jogs keep their style, for every seed?

Per training seed and encoding (``--encodings``: the paper's and the
default): ``ConditionalRBM(random_state=seed)`` (``--model``) on all 33
trials of CMU 35; 6 walk- and 6 jog-seeded sequences of 1000 frames
(``MotionPipeline.style_windows``); frames 200-299 and 900-999 judged
(``metrics.judge_generated_motion``: style kept, |z| <= 10, leg amplitude
and step frequency within 25% and 15% of the style's): windows passing,
240 for seeds 0-4 and both encodings.  From one seed, 4 sequences of 400
frames from the first walk and jog windows, frames 200-399:
``metrics.divergence`` (0: copies) and ``metrics.jitter`` over the real's.

Run from the repository root (fitted models are cached)::

    python benchmarks/generation_seeds.py
    python benchmarks/generation_seeds.py --seeds 0 --encodings paper
"""

import json

import _common as common
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.metrics import divergence, jitter

ENCODINGS = {"paper": common.PAPER_ENCODING, "default": {}}
STYLES = ("walk", "jog")
N_PER_STYLE = 6
WINDOWS = {"200-299": 300, "900-999": 1000}  # frames judged -> their end
AMPLITUDE_TOLERANCE, FREQUENCY_TOLERANCE = 0.25, 0.15
VERDICTS = ("style", "amplitude", "frequency", "blown")  # kept per sequence
N_FROM_ONE, ONE_SEED_FRAMES, ONE_SEED_JUDGED = 4, 400, slice(200, 400)


def passes(corpus, generated, n_frames, end, seed_styles):
    """Which sequences pass the window of 100 frames before ``end``."""
    n = len(seed_styles)
    window = generated.reshape(n, n_frames, -1)[:, :end].reshape(n * end, -1)
    ids = np.repeat(np.arange(n), end)
    verdict = corpus.judge(window, ids, seed_styles, last_frames=100)
    amplitude, frequency = (
        np.array([corpus.real[s][key] for s in seed_styles])
        for key in ("amplitude", "frequency")
    )
    lively = np.abs(verdict.amplitude / amplitude - 1) <= AMPLITUDE_TOLERANCE
    in_step = np.abs(verdict.frequency / frequency - 1) <= FREQUENCY_TOLERANCE
    return (verdict.style == seed_styles) & ~verdict.blown & lively & in_step, verdict


def _positions(corpus, Z, ids):
    with sklearn.config_context(enable_metadata_routing=True):
        raw = corpus.preprocessor.inverse_transform(Z, sequence_ids=ids)
    return corpus.data.skeleton.forward_kinematics(raw)


def real_jitter(corpus, style):
    """Mean jitter of the joint positions of the real trials of ``style``."""
    rows = np.isin(corpus.ids, np.flatnonzero(corpus.styles == style))
    positions = _positions(corpus, corpus.Z[rows], corpus.ids[rows])
    return float(np.mean(jitter(positions, sequence_ids=corpus.ids[rows])))


def from_one_seed(corpus, model, history, seed_styles, seed):
    """Divergence and relative jitter of sequences that share one seed window."""
    row = {}
    ids = np.repeat(np.arange(N_FROM_ONE), ONE_SEED_FRAMES)
    judged = np.tile(np.arange(ONE_SEED_FRAMES), N_FROM_ONE) >= ONE_SEED_JUDGED.start
    for style in STYLES:
        first = int(np.flatnonzero(seed_styles == style)[0])
        shared = np.repeat(history[first : first + 1], N_FROM_ONE, axis=0)
        Z = model.sample(ONE_SEED_FRAMES, history=shared, random_state=seed)
        row[f"{style} divergence"] = divergence(
            Z, sequence_ids=ids, frames=ONE_SEED_JUDGED
        )
        positions = _positions(corpus, Z, ids)[judged]
        row[f"{style} jitter"] = float(
            np.mean(jitter(positions, sequence_ids=ids[judged]))
        ) / real_jitter(corpus, style)
    return row


def generate_and_judge(corpus, seed, model_params):
    model = ConditionalRBM(random_state=seed, **model_params)
    model, _ = common.cached_fit(model, corpus.Z.astype(np.float32), corpus.ids)
    history, seed_styles = corpus.seed_windows(model, N_PER_STYLE, seed)
    n_frames = max(WINDOWS.values())
    generated = model.sample(n_frames, history=history, random_state=seed)
    row, details = {}, {}
    for window, end in WINDOWS.items():
        passed, verdict = passes(corpus, generated, n_frames, end, seed_styles)
        for style in STYLES:
            mine = seed_styles == style
            row[f"{style} {window}"] = int(passed[mine].sum())
            judged = {key: verdict[key][mine].tolist() for key in VERDICTS}
            details[f"{style} {window}"] = dict(passes=passed[mine].tolist(), **judged)
    row.update(from_one_seed(corpus, model, history, seed_styles, seed))
    return row, details


def main(argv=None):
    p = common.parser(__doc__)
    p.add_argument("--encodings", nargs="+", default=list(ENCODINGS), choices=ENCODINGS)
    p.add_argument("--model", default="{}", help="ConditionalRBM parameters, JSON")
    args = p.parse_args(argv)
    common.announce()
    model_params = json.loads(args.model)
    rows, details = [], {}
    for encoding in args.encodings:
        corpus = common.MotionCorpus(args.data_home, "cmu", ENCODINGS[encoding])
        for seed in args.seeds:
            row, details[f"{encoding} {seed}"] = generate_and_judge(
                corpus, seed, model_params
            )
            rows.append(dict(encoding=encoding, seed=seed, **row))
            print(f"  {encoding} seed {seed}: {row}", flush=True)
    cells = [f"{s} {w}" for w in WINDOWS for s in STYLES]
    total = sum(row[cell] for row in rows for cell in cells)
    passing = [(c, c.replace(" ", "s pass, frames "), "d") for c in cells]
    one_seed = [(f"{s} {k}", f"{s}: {k} from one seed", ".2f")
                for s in STYLES for k in ("divergence", "jitter")]  # fmt: skip
    windows = f"{total} of {len(rows) * len(cells) * N_PER_STYLE} windows"
    title = f"\nSequences passing (of {N_PER_STYLE} per cell): {windows}"
    columns = ["encoding", "seed", *passing, *one_seed]
    table = common.print_table(rows, columns, title=title)
    payload = dict(args=vars(args), rows=rows, passing=total, sequences=details)
    common.write_json("generation_seeds", args.output, **payload, table=table)
    return rows


if __name__ == "__main__":
    main()
