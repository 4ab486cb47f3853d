"""Figure code of the papers' figures, one module per figure or group, and the notebooks'
"paper | ours" rows, tables and facts. The package imports none of them, so that the claims
can read Table 2's timings and write tables without loading the figures.
"""
