"""Figure code of the papers' figures, one module per figure or group (:mod:`.oedtw` Fig. 1,
:mod:`.windows` Figs. 2 and 4, :mod:`.forecast` Fig. 3, :mod:`.scores` Figs. 5-6 and Table 1,
:mod:`.heatmaps` Figs. 7 and 10, :mod:`.walk_pair` Fig. 8, :mod:`.typev` Fig. 9,
:mod:`.timing` Table 2, :mod:`.opw` the OPW poster's Figs. 4-6), the notebooks' "paper |
ours" rows (:mod:`.paper_vs_ours`), tables (:mod:`.tables`) and facts (:mod:`.facts`).

Import a module by name: the package imports none of them, so that the claims can read
Table 2's timings and write tables without loading the figures that draw their evidence.
"""
