"""The README's fill-in example on a BVH corpus, as a user with BVH files runs it.

The README's example works on CMU subject 35 (``test_readme.py`` runs it as
written).  A user with a folder of BVH files writes the same lines with two
changes: the data read with :func:`~sklearn_crbm.datasets.read_bvh_folder`,
and the body part named as their skeleton names it.  This runs the README's
code with exactly those two changes, on the runs of Bandai Namco dataset-2
(``bandai_contents``: takes 001-009 to train, 010-012 held out) and the
left leg from ``UpperLeg_L``, whose descendants end in an end site without
channels.  As in ``test_readme.py``, ``n_iter`` is cut to a few epochs: the
test checks that the code runs, not how well the model fills in.

The user guide's own-data page, which reads, preprocesses and fills in a
BVH corpus in the same way, runs as doctests in ``test_docs.py``.
"""

import re
from pathlib import Path

import sklearn

README = Path(__file__).resolve().parents[1] / "README.md"
FEW_EPOCHS = 2

# the README's loader and body part, and what a user with BVH files puts there
SUBSTITUTIONS = {
    "from sklearn_crbm.datasets import load_cmu35\n": (
        "from sklearn_crbm.datasets import read_bvh_folder\n\n"
        "def load_cmu35(subset):\n"
        "    takes = {'train': '00?', 'test': '01?'}[subset]\n"
        "    return read_bvh_folder(\n"
        "        FOLDER, pattern=f'dataset-2_run_normal_{takes}.bvh'\n"
        "    )\n"
    ),
    'descendants("lfemur")': 'descendants("UpperLeg_L")',
}


def _example():
    text = README.read_text(encoding="utf-8")
    section = text.split("## Example\n", 1)[1].split("\n## ", 1)[0]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_readme_example_runs_on_a_bvh_corpus(data_home, capsys):
    code = _example()
    for old, new in SUBSTITUTIONS.items():
        assert code.count(old) == 1, f"the README example changed: update {old!r}"
        code = code.replace(old, new)
    assert code.count("n_iter=") == 1, "the README example changed: update this test"
    code = re.sub(r"\bn_iter=\d+", f"n_iter={FEW_EPOCHS}", code)
    namespace = {"FOLDER": data_home / "bandai_contents"}
    with sklearn.config_context():  # the example switches metadata routing on
        exec(compile(code, "README.md (Example, on BVH files)", "exec"), namespace)
    printed = dict(line.split() for line in capsys.readouterr().out.splitlines())
    assert set(printed) == {"CRBMImputer", "KNNImputer", "AutoregressiveImputer"}
    assert all(float(error) > 0 for error in printed.values())
    # the whole left leg was erased, and only it
    erased = namespace["names"][namespace["mask"].any(axis=0)]
    bones = {str(name).rsplit("_", 1)[0] for name in erased}
    assert bones == {"UpperLeg_L", "LowerLeg_L", "Foot_L", "Toes_L"}
