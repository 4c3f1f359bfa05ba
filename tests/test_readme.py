"""The README's example runs as written (with fewer epochs)."""

import re
from pathlib import Path

import numpy as np
import sklearn

README = Path(__file__).resolve().parents[1] / "README.md"


def test_readme_example_runs(data_home, monkeypatch):
    text = README.read_text()
    code = re.search(r"## Example\n\n```python\n(.*?)```", text, re.S).group(1)
    quick = code.replace("n_iter=1000", "n_iter=3").replace(
        "CRBMImputer(random_state=0)",
        "CRBMImputer(ConditionalRBM(20, n_iter=3), random_state=0)",
    )
    assert quick.count("n_iter=3") == 2, "the README example changed: update this test"
    monkeypatch.setenv("SKLEARN_CRBM_DATA", str(data_home))
    namespace = {}
    with sklearn.config_context():  # restores the config the example sets
        exec(compile(quick, str(README), "exec"), namespace)
    assert not sklearn.get_config()["enable_metadata_routing"]
    assert namespace["raw"].shape == (1200, 62)
    assert np.isfinite(namespace["raw"]).all()
