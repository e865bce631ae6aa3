"""Static identification: analytic friction laws fitted to steady-state samples by least squares.

* :mod:`.least_squares`: one analytic fit (the sum of squared errors, RWSAVSBAS paper eq. 11,
  minimised by any :mod:`fricid.optim` method), certified (:mod:`.convergence`), with
  standard errors and 95 % intervals (:mod:`.uncertainty`, :mod:`.profile`);
* :mod:`.varpro`: the exact optimum by variable projection;
* :mod:`.checks`: what the data can determine, before fitting;
* :mod:`.candidates`, :mod:`.select`: ``model="auto"``, the family chosen by held-out error.
"""
