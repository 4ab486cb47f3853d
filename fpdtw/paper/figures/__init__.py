"""Figure code of the FP-DTW paper's figures, one module per figure (or group).

* :mod:`.oedtw` — Fig. 1 (OE-DTW end points jumping backwards);
* :mod:`.windows` — Figs. 2 and 4 (Method A/B/C windows drawn from the plain steps);
* :mod:`.forecast` — Fig. 3 (forecast error of smoothing levels vs frames ahead);
* :mod:`.walk_pair` — Fig. 8 (one walk pair: paths, right-hip curves, poses);
* :mod:`.typev` — Fig. 9 (the Type V constraint and its state table);
* :mod:`.scores` — Figs. 5 and 6 (similarity and deviation box plots) and Table 1;
* :mod:`.heatmaps` — Figs. 7 and 10 (aggregate heat maps of all paths);
* :mod:`.timing` — Table 2 (time per frame);
* :mod:`.opw` — OPW poster Figs. 4-6;
* :mod:`.facts` — the JSON of facts each figure notebook writes.

Plot functions take ``ax=None`` (or ``axes=None``) and return ``(fig, ax)``; figures are
saved with :func:`fpdtw.paper.figures.plotting.save_figure`. Import a module by name
(``from fpdtw.paper.figures import scores``): the package imports none of them, so that the
claims can read Table 2's timings (:mod:`.timing`) and write tables (:mod:`.tables`) without
loading the figures that draw the claims' evidence (:mod:`.scores`).
"""
