"""The engines the estimators run: private, no public names.

``_gibbs.py``: Gibbs sampling and mean-field steps of any layer;
``_online.py``: the one on-line loop behind generation and fill-in;
``_likelihood.py``: exact and annealed log-likelihoods;
``_training.py``: training any conditional layer by contrastive divergence.
"""
