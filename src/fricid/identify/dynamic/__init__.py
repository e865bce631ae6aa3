"""Dynamic identification: friction, inertia and gravity from any trajectory log.

* :mod:`.trajectory`: ``fit_trajectory`` (LuGre, Dahl, or a static law with J and gravity);
* :mod:`._data`: uniform series, derivative filters, cluster-robust covariance;
* :mod:`._routes`, :mod:`._filtered`: the identification routes (simulation error, the
  parallel-filtered equation error); :mod:`._rate`: the log rate's bias, by simulation.
"""
