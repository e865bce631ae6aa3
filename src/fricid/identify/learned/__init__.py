"""Learned identification: models that keep a stored state instead of named parameters.

* :mod:`.rbf`: the RBF network (BAS-RBFNN paper, eq. 14-19; plain, BAS-RBFNN, GA-RBFNN) and
  its scikit-learn estimator (:mod:`._rbf_estimator`, its parameters checked by
  :mod:`._rbf_params`: public scikit-learn API only), its structure chosen by
  cross-validation (:mod:`._rbf_select`, :mod:`._rbf_folds`, :mod:`._rbf_search`);
* :mod:`.hybrid`: an analytic backbone plus an RBF residual;
* :mod:`.gp`: a Gaussian process with its posterior standard deviation;
* :mod:`.train`: ``fit`` for these three; :mod:`._trust`: what their model files record
  about trust (convergence, effective degrees of freedom, cross-validation).

Nothing here is imported by ``import fricid.identify``: scikit-learn loads on first use.
"""
