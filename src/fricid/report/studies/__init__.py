"""Documents and text of the papers' studies, composed from what :mod:`fricid.experiments`
computes (studies compute; reports render).

* :mod:`.stribeck`: ``fricid bench stribeck`` ([R] Table 1, Fig. 6);
* :mod:`.rbfnn`: ``fricid bench rbfnn`` ([B] Tables 1, 3, 4, Fig. 9, 10);
* :mod:`.rwsavsbas`: ``fricid reproduce rwsavsbas``;
* :mod:`.bas_rbfnn` (with :mod:`.bas_rbfnn_networks`, :mod:`.bas_rbfnn_table4`):
  ``fricid reproduce bas-rbfnn``.

The submodules are imported on demand (each pulls in its study).
"""
