"""Train/test splits of CMU subject 35 for the fill-in and likelihood tables.

Each split holds out one walk and one jog; the preprocessing (exponential
maps, body-centred root, z-scores) is fitted on the training trials only.
``"paper"`` is the paper's §4.4 split (walk 35_29, jog 35_18); ``"second"``
holds out walk 35_05 and jog 35_22 (chosen for lengths like the paper's:
107 and 42 frames).  Not part of the package.
"""

import hashlib
import time
from pathlib import Path

import joblib
import numpy as np
import sklearn

from sklearn_crbm import ConditionalRBM
from sklearn_crbm.datasets import load_cmu35
from sklearn_crbm.model_selection import make_fillin_cases
from sklearn_crbm.preprocessing import make_motion_preprocessor

SPLITS = {"paper": ("35_29", "35_18"), "second": ("35_05", "35_22")}
CELLS = ("walk/leg", "walk/upper", "jog/leg", "jog/upper")


class Split:
    """One split: preprocessed training trials and the erased test cases.

    Attributes
    ----------
    preprocessor : Pipeline
        Fitted on the training trials.
    X_train, train_ids : ndarray
        Preprocessed training frames and their sequence ids.
    X_test, test_ids : ndarray
        The two held-out trials (walk first), preprocessed.
    cases : dict
        ``"walk/leg"`` ... ``"jog/upper"`` -> the case of
        :func:`~sklearn_crbm.model_selection.make_fillin_cases` (``X``,
        ``missing_mask``, ``X_missing``, ...): the left leg or the upper
        body erased from half-way to the end.
    """

    def __init__(self, data_home, name):
        cmu = load_cmu35(data_home)
        names = list(cmu.sequence_names)
        walk, jog = SPLITS[name]
        held_out = [names.index(walk), names.index(jog)]
        train = ~np.isin(cmu.sequence_ids, held_out)
        with sklearn.config_context(enable_metadata_routing=True):
            # the paper's encoding, in which the tables of the README were measured
            self.preprocessor = make_motion_preprocessor(
                cmu.skeleton, reference="rest", roll="taylor"
            )
            self.X_train = self.preprocessor.fit_transform(
                cmu.data[train], sequence_ids=cmu.sequence_ids[train]
            )
        self.name = name
        self.trials = SPLITS[name]
        self.train_ids = cmu.sequence_ids[train]
        cases = make_fillin_cases(
            cmu, self.preprocessor, trials={"walk": walk, "jog": jog}
        )
        parts = {"left leg": "leg", "upper body": "upper"}
        self.cases = {
            f"{motion}/{parts[part]}": case for (motion, part), case in cases.items()
        }
        self.X_test = np.concatenate(
            [self.cases["walk/leg"].X, self.cases["jog/leg"].X]
        )
        self.test_ids = np.repeat(
            np.arange(2), [len(self.cases["walk/leg"].X), len(self.cases["jog/leg"].X)]
        )


# ConditionalRBM's defaults just before average_fraction (the last epoch's
# parameters kept), and those before history_noise_fraction too (noise on
# every channel of the history): the earlier tables' models spell them out.
UNAVERAGED = dict(average_fraction=0.0)
EARLIER_DEFAULTS = dict(UNAVERAGED, history_noise=0.8, history_noise_fraction=1.0)

# What a trained model depends on: the cache key leaves out parameters that
# only affect inference (and any added later), so changes to inference reuse
# the fits.
_TRAINING_PARAMETERS = (
    "n_components order hidden_order visible_type visible_variance learning_rate "
    "momentum momentum_delay weight_decay cd_steps batch_size batching "
    "history_noise n_iter random_state"
).split()


# Training parameters added later, with the value the fits cached before had
# (the estimator's record of them, and init): in the key only when they
# differ from it.
_LATER_PARAMETERS = {"init": "random", **ConditionalRBM._added_parameters}

# The code a fit runs: a change to any of these (e.g. a new random stream)
# changes the fitted models, so their text is part of the key too.
PACKAGE = Path(__file__).resolve().parents[1] / "sklearn_crbm"
TRAINING_CODE = [
    PACKAGE / name
    for name in (
        "_base.py",
        "_crbm.py",
        "_crbm_math.py",
        "utils/_array_api.py",
        "utils/_autoregression.py",
        "utils/_random.py",
        "utils/_sequences.py",
        "utils/_windows.py",
    )
]


# All of the package's code: what a cached fill-in or generation result
# depends on besides the fit.
PACKAGE_CODE = sorted(PACKAGE.rglob("*.py"))


def hash_code(digest, sources):
    """``digest`` (a hashlib object) updated with the text of ``sources``."""
    for source in sources:
        digest.update(source.read_bytes())
    return digest


def code_digest(sources):
    """Eight hex digits naming the text of ``sources``.

    Part of a cache key, so that changed code is a new key.
    """
    return hash_code(hashlib.sha1(), sources).hexdigest()[:8]


def cached_model(cache_dir, model, X, sequence_ids):
    """``(fitted model, training seconds)``, from ``cache_dir`` when it is there."""
    params = {k: getattr(model, k) for k in _TRAINING_PARAMETERS if hasattr(model, k)}
    params.update(
        (k, getattr(model, k))
        for k, before in _LATER_PARAMETERS.items()
        if getattr(model, k, before) != before
    )
    digest = hashlib.sha1(repr(sorted(params.items())).encode())
    digest.update(np.ascontiguousarray(X).tobytes())
    digest.update(np.ascontiguousarray(sequence_ids).tobytes())
    hash_code(digest, TRAINING_CODE)
    path = Path(cache_dir) / f"{type(model).__name__}_{digest.hexdigest()[:20]}.joblib"
    if path.exists():
        return joblib.load(path)
    start = time.perf_counter()
    model.fit(X, sequence_ids=sequence_ids)
    result = (model, time.perf_counter() - start)
    path.parent.mkdir(parents=True, exist_ok=True)
    joblib.dump(result, path)
    return result
