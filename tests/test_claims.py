"""Each claim of fpdtw.paper.claims says yes / no / partly correctly on made-up summaries."""

from __future__ import annotations

import json

import numpy as np
import pytest
from test_plots_results import paper_like_algos, paper_like_medians, write_fake_results

from fpdtw.paper import claims
from fpdtw.paper.claims import ClaimContext
from fpdtw.paper.numbers import FIG8_DEVIATIONS, FPDTW_NAMES


def ctx_paper_like(**kw):
    """A context whose medians mirror the paper: every score claim holds."""
    sim, dev = paper_like_medians()
    base = dict(
        mode="smoke",
        similarity=sim,
        deviation=dev,
        utw_median=sim["UTW"],
        table1=[
            dict(rate_hz=60, source="ours", best_w=20),
            dict(rate_hz=120, source="ours", best_w=40),
        ],
        timing=[
            dict(
                method=m,
                w=w,
                type_v=False,
                mean_us=t * (1 if m == "B" else 0.8),
                median_us=t * (0.9 if m == "B" else 0.7),
            )
            for m in ("B", "C")
            for w, t in ((10, 1000.0), (20, 2000.0), (40, 5000.0), (80, 17000.0))
        ],
        exhausted={"Mb w80": 0.01, "Mc w40": 0.05, "Mc w80": 0.3, "Mc w10": 0.0},
        oedtw_backward=dict(pairs=10, pairs_backward=7, fraction=0.7, jumps=30),
        fig8={"deviation": {"Mb w80": 8.0, "Mc w20": 177.0, "Mc w40": 62.0, "Mc w80": 6.0}},
        counts={"total": {"motions": 333, "movements": 44, "pairs": 3248}},
    )
    base.update(kw)
    return ClaimContext(**base)


def claim_row(cid, ctx):
    """The row of one claim of the table."""
    return next(c for c in claims.CLAIMS if c.id == cid).row(ctx)


def holds(ctx):
    return {r["id"]: r["holds"] for r in claims.build_claims(context=ctx)}


def test_every_claim_holds_on_paper_like_numbers():
    rows = claims.build_claims(context=ctx_paper_like())
    assert [r["id"] for r in rows] == [
        "1",
        "2",
        "3",
        "4",
        "4b",
        "4c",
        "5",
        "5b",
        "6",
        "7",
        "8",
        "9",
        "P1",
        "P2",
        "P3",
        "P4",
        "B1",
    ]
    # the FP-DTW paper's claims hold on paper-like numbers; the OPW rows have no facts here
    expected = {r["id"]: ("n/a" if r["id"][0] in "PB" else "yes") for r in rows}
    assert {r["id"]: r["holds"] for r in rows} == expected
    for r in rows:
        assert set(r) == set(claims.COLUMNS)
        assert r["stable"] == (r["id"] not in ("4", "4b"))
    by = {r["id"]: r for r in rows}
    assert by["1"]["ours"] == "pass either: Mc w40"
    assert by["2"]["ours"] == "pass both: Mc w40, Ma + Type V, Mc w80 + Type V"


def test_claim1_only_mc_w40():
    sim, dev = paper_like_medians()
    assert holds(ctx_paper_like())["1"] == "yes"
    dev2 = dict(dev, **{"Mb w80": 17.0})  # Mb w80 now passes the deviation benchmark too
    assert holds(ctx_paper_like(deviation=dev2))["1"] == "partly"
    sim3 = dict(sim, **{"Mc w40": 0.2})
    dev3 = dict(dev, **{"Mc w40": 30.0, "Mb w80": 17.0})  # Mc w40 fails, Mb w80 passes
    assert holds(ctx_paper_like(similarity=sim3, deviation=dev3))["1"] == "no"
    dev4 = dict(dev, **{"Mc w40": 30.0})
    row = claim_row("1", ctx_paper_like(similarity=sim3, deviation=dev4))
    assert row["holds"] == "no" and row["ours"] == "pass either: none"


def test_claim2_pass_both():
    sim, dev = paper_like_medians()
    dev2 = dict(dev, **{"Ma + Type V": 18.0})  # 18 is not BELOW 18
    row = claim_row("2", ctx_paper_like(deviation=dev2))
    assert row["holds"] == "partly" and "Ma + Type V" not in row["ours"]
    sim3 = {n: (0.0 if n not in ("DTW", "UTW") else v) for n, v in sim.items()}
    assert holds(ctx_paper_like(similarity=sim3))["2"] == "no"


@pytest.mark.parametrize(("b60", "b120", "want"), [(20, 40, "yes"), (20, 20, "partly"),
                         (10, 20, "partly"), (40, 40, "partly"), (80, 10, "no")])  # fmt: skip
def test_claim3_best_window(b60, b120, want):
    t1 = [
        dict(rate_hz=60, source="ours", best_w=b60),
        dict(rate_hz=120, source="ours", best_w=b120),
        dict(rate_hz=60, source="paper", best_w=20),
    ]
    assert holds(ctx_paper_like(table1=t1))["3"] == want
    assert holds(ctx_paper_like(table1=None))["3"] == "n/a"


def test_claim4_cost_growth():
    def rows(tb, tc):
        return [
            dict(method=m, w=w, type_v=False, median_us=t, mean_us=2 * t)
            for m, ts in (("B", tb), ("C", tc))
            for w, t in zip((10, 20, 40, 80), ts)
        ]

    steep = (10.0, 20.0, 40.0, 100.0)
    linear_ish = (10.0, 12.0, 15.0, 30.0)  # increasing, ratio 3
    flat_c = (10.0, 12.0, 11.0, 9.0)  # not monotonic, ratio 0.9
    assert holds(ctx_paper_like(timing=rows(steep, steep)))["4"] == "yes"
    assert holds(ctx_paper_like(timing=rows(steep, linear_ish)))["4"] == "partly"
    assert holds(ctx_paper_like(timing=rows(flat_c, flat_c)))["4"] == "no"
    row = claim_row("4", ctx_paper_like(timing=rows(steep, flat_c)))
    assert row["holds"] == "partly" and "not monotonic" in row["ours"]
    assert row["ours"] == (
        "w80/w10: Mb 10.0x, Mc 0.9x (not monotonic) (medians); means: Mb 10.0x, Mc 0.9x"
    )
    # the verdict reads the medians, not the means
    mean_steep = [dict(r, mean_us=100.0 * r["w"] ** 2) for r in rows(flat_c, flat_c)]
    assert holds(ctx_paper_like(timing=mean_steep))["4"] == "no"
    assert holds(ctx_paper_like(timing=None))["4"] == "n/a"


def test_claim4b_realtime_budget():
    def rows(b80, c80):
        return [dict(method="B", w=80, type_v=False, mean_us=b80, median_us=1.0),
                dict(method="C", w=80, type_v=False, mean_us=c80, median_us=1.0)]  # fmt: skip

    assert holds(ctx_paper_like(timing=rows(9000.0, 8400.0)))["4b"] == "yes"
    assert holds(ctx_paper_like(timing=rows(9000.0, 100.0)))["4b"] == "partly"
    assert holds(ctx_paper_like(timing=rows(80.0, 30.0)))["4b"] == "no"


def test_claim4c_mc_w80_runs_out():
    assert holds(ctx_paper_like())["4c"] == "yes"
    ex = {"Mb w80": 0.5, "Mc w40": 0.05, "Mc w80": 0.3}
    assert holds(ctx_paper_like(exhausted=ex))["4c"] == "no"
    assert holds(ctx_paper_like(exhausted={}))["4c"] == "n/a"


def test_claim5_ma_among_worst():
    sim, dev = paper_like_medians()
    row = claim_row("5", ctx_paper_like())
    assert row["holds"] == "yes" and "ranks 9 of 9 (similarity), 9 of 9" in row["ours"]
    # unconstrained similarity medians: Mc w40 0.3, Mc w20 0.2, Mc w80 0.14, Mb w80 0.12,
    # Mb w40 0.1, Mb w20 0.08, Mb w10 0.05, Mc w10 0.04 (and Ma)
    for ma, rank, want in ((0.045, 8, "yes"), (0.06, 7, "yes"), (0.09, 6, "partly"),
                           (0.11, 5, "partly")):  # fmt: skip
        row = claim_row("5", ctx_paper_like(similarity=dict(sim, Ma=ma)))
        assert f"ranks {rank} of 9 (similarity), 9 of 9 (deviation)" in row["ours"]
        assert row["holds"] == want
    # good in both tests
    both = ctx_paper_like(similarity=dict(sim, Ma=0.11), deviation=dict(dev, Ma=5.0))
    assert holds(both)["5"] == "no"


def test_claim5b_method_b_improves_with_w():
    sim, dev = paper_like_medians()
    assert holds(ctx_paper_like())["5b"] == "yes"
    assert holds(ctx_paper_like(similarity=dict(sim, **{"Mb w80": 0.09})))["5b"] == "partly"
    sim2 = dict(sim, **{"Mb w80": 0.09})
    dev2 = dict(dev, **{"Mb w20": 85.0})
    assert holds(ctx_paper_like(similarity=sim2, deviation=dev2))["5b"] == "no"


def test_claim6_type_v_improvements():
    sim, dev = paper_like_medians()
    assert holds(ctx_paper_like())["6"] == "yes"
    # Mc w10 + Type V also better in both tests: one algorithm too many -> partly
    sim2 = dict(sim, **{"Mc w10 + Type V": 0.3})
    dev2 = dict(dev, **{"Mc w10 + Type V": 1.0})
    row = claim_row("6", ctx_paper_like(similarity=sim2, deviation=dev2))
    assert row["holds"] == "partly" and "Mc w10" in row["ours"].split(";")[0]
    # better similarity only does not count as improved
    sim3 = {n: v for n, v in sim.items()}
    dev3 = {n: v for n, v in dev.items()}
    for n in FPDTW_NAMES:
        sim3[n + " + Type V"] = sim[n] - 0.01
        dev3[n + " + Type V"] = dev[n] - 1.0
    row = claim_row("6", ctx_paper_like(similarity=sim3, deviation=dev3))
    assert row["holds"] == "no" and row["ours"].startswith("improved: none; in one test only: Ma")


def test_claim7_oedtw_backward():
    assert holds(ctx_paper_like())["7"] == "yes"
    oe = dict(pairs=10, pairs_backward=0, fraction=0.0, jumps=0)
    assert holds(ctx_paper_like(oedtw_backward=oe))["7"] == "no"
    assert holds(ctx_paper_like(oedtw_backward=None))["7"] == "n/a"


def test_claim8_fig8_json_formats():
    assert holds(ctx_paper_like())["8"] == "yes"
    devs = {"Mb w80": 8.0, "Mc w20": 30.0, "Mc w40": 10.0, "Mc w80": 40.0}
    nested = {"algorithms": {n: {"deviation": v} for n, v in devs.items()}}
    assert holds(ctx_paper_like(fig8=nested))["8"] == "partly"  # below 18: Mb w80, Mc w40
    bad = {"deviations": {"Mb w80": 30.0, "Mc w20": 30.0, "Mc w40": 10.0, "Mc w80": 40.0}}
    assert holds(ctx_paper_like(fig8=bad))["8"] == "no"
    row = claim_row("8", ctx_paper_like(fig8=None))
    assert row["holds"] == "n/a" and "not computed" in row["ours"]
    assert holds(ctx_paper_like(fig8={"other": 1}))["8"] == "n/a"


def test_claim9_data():
    assert holds(ctx_paper_like())["9"] == "yes"
    counts = {
        "authors_fbx": {"motions": 48, "movements": 16, "pairs": 96},
        "total": {"motions": 335, "movements": 27, "pairs": 8610},
    }
    row = claim_row("9", ctx_paper_like(counts=counts))
    assert row["holds"] == "no" and "335 motions, 27 movements, 8610 pairs" in row["ours"]
    assert "authors_fbx: 48/16/96" in row["ours"]


def test_the_claims_table_is_data():
    """Each claim is a row: unique id, the paper's value from fpdtw.paper.numbers, an
    extractor and a rule; a context without data gives "n/a" with the reason."""
    ids = [c.id for c in claims.CLAIMS]
    assert len(ids) == len(set(ids)) == 17
    assert (
        next(c for c in claims.CLAIMS if c.id == "4b").paper == "Mb w80 16945 us, Mc w80 10106 us"
    )
    empty = claims.ClaimContext()
    for c in claims.CLAIMS:
        row = c.row(empty)
        assert row["holds"] in ("n/a", "no", "yes", "partly")
        if row["holds"] == "n/a" and c.id != "B1":
            assert row["ours"].startswith("not computed (")
    rows = claims.build_claims(context=ctx_paper_like(), claims=claims.CLAIMS[:2])
    assert [r["id"] for r in rows] == ["1", "2"] and list(rows[0]) == list(claims.COLUMNS)


def test_build_claims_from_a_fake_results_folder(tmp_path, monkeypatch):
    """End to end: fake folder -> load_results -> context -> rows -> claims.json."""
    monkeypatch.setenv("FPDTW_RESULTS_DIR", str(tmp_path / "results"))
    monkeypatch.setenv("FPDTW_FIGURES_DIR", str(tmp_path / "figs"))
    sim, dev = paper_like_medians()
    algos = paper_like_algos(sim, dev)
    # OE-DTW: pair 0 jumps back once (5 -> 4), the others are monotonic
    oe = [np.round(np.arange(20) * 19 / 19).astype(np.int32) for _ in range(5)]
    oe[0] = oe[0].copy()
    oe[0][6] = 4
    algos["OE-DTW"]["maps"] = oe
    # Mc w80 runs out: reaches m = 19 at q = 10 in every pair
    algos["Mc w80"]["maps"] = [np.minimum(2 * np.arange(20), 19).astype(np.int32)] * 5
    # Method C's literal window: every Mc result of the paper-like run, except that Mc w40
    # (and Mc w40 at 60 Hz, i.e. Table 1's w20 best) fails everything
    for name in [n for n in algos if n.startswith("Mc w")]:
        lit = dict(algos[name])
        if name.startswith(("Mc w40", "Mc w20@")):
            lit["similarity"] = lit["similarity"] - 0.5
            lit["deviation"] = lit["deviation"] + 100.0
        base, rate = (name.split("@") + [""])[:2]
        w, _, tv = base[4:].partition(" + ")
        algos[
            f"Mc w{w} (literal window)" + (" + Type V" if tv else "") + (f"@{rate}" if rate else "")
        ] = lit
    write_fake_results(tmp_path / "results" / "smoke", algos)
    figs = tmp_path / "results" / "smoke" / "figs"
    figs.mkdir()
    devs = dict(FIG8_DEVIATIONS)
    devs.update(
        {k.replace("Mc w", "Mc w") + " (literal window)": 300.0 for k in devs if k.startswith("Mc")}
    )
    (figs / claims.FIG8_JSON).write_text(json.dumps({"deviation": devs}))
    bench = {
        "online": [
            dict(name=n, median_s=t * 1e-6, mean_s=t * 1e-6, p95_s=t * 1e-6, frames=9)
            for n, t in [(f"M{m} w{w}", 2.0 * w) for m in "bc" for w in (10, 20, 40, 80)]
            + [(f"Mc w{w} (literal window)", 1.0 * w) for w in (10, 20, 40, 80)]
        ]
    }
    (tmp_path / "results" / "bench.json").write_text(json.dumps(bench))
    rows = claims.build_claims("smoke")
    by = {r["id"]: r for r in rows}
    for cid in ("1", "2", "3", "5", "5b", "6", "7", "8"):
        assert by[cid]["holds"] == "yes", by[cid]
    # under the literal window the Mc w40 claims fail; the others are unchanged
    assert by["1"]["holds_literal"] == "no" and by["1"]["ours_literal"] == "pass either: none"
    assert by["2"]["holds_literal"] == "partly" and "Mc w40" not in by["2"]["ours_literal"]
    assert by["3"]["holds_literal"] == "partly"  # best w 40 at 120 Hz no more, still 20 at 60
    assert by["8"]["holds_literal"] == "partly"  # below 18: Mb w80 only
    assert "Mc w40 300.0" in by["8"]["ours_literal"]
    for cid in ("5b", "7", "9", "4b"):
        assert (by[cid]["ours"], by[cid]["holds"]) == (
            by[cid]["ours_literal"],
            by[cid]["holds_literal"],
        ) or cid == "4b"
    assert "Mc w80 80 us" in by["4b"]["ours_literal"] and "Mc w80 160 us" in by["4b"]["ours"]
    assert by["7"]["ours"].startswith("1 of 5 pairs (20%)")
    assert by["4c"]["holds"] == "yes" and "Mc w80 0.47" in by["4c"]["ours"]  # q = 11..19 of 19
    assert by["9"]["holds"] == "no"  # 5 fake pairs, not the paper's 3248
    assert by["4b"]["holds"] == "no"  # fake bench timings are microseconds
    paths = claims.save_claims(rows, "smoke")
    assert {p.name for p in paths} == {"claims.csv", "claims.md", "claims.json"}
    saved = json.loads((tmp_path / "results" / "smoke" / "claims.json").read_text())
    assert saved["mode"] == "smoke" and saved["claims"] == rows
    assert (tmp_path / "figs" / "claims.md").read_text().startswith("| id | claim |")


POSTER_LIKE_FIG4 = {
    "opw_mean_ms_range": [69.0, 79.0],
    "opw_max_ms": 121.0,
    "dtw_mean_ms_range": [20, 30],
}
POSTER_LIKE_FIG56 = {
    "removed_gamma5_mean_over_offsets": 0.70,
    "removed_gamma5_range_over_offsets": [0.6, 0.8],
    "removed_gamma5_at_offset": 0.7,
    "best_gamma": 0.15,
    "removed_best_gamma": 0.77,
    "largest_offset_max_below_150ms_s": 0.3,
    "largest_offset_mean_below_150ms_s": 0.5,
}


def _opw_rows(fig4, fig56):
    ctx = claims.ClaimContext(opw_fig4=fig4, opw_fig56=fig56)
    fns = [c for c in claims.CLAIMS if c.id.startswith("P")]
    return {r["id"]: r["holds"] for r in claims.build_claims(context=ctx, claims=fns)}


def test_opw_claims_hold_on_the_posters_numbers():
    assert _opw_rows(POSTER_LIKE_FIG4, POSTER_LIKE_FIG56) == dict.fromkeys(
        ["P1", "P2", "P3", "P4"], "yes"
    )


def test_opw_claims_fail_when_the_numbers_differ():
    fig4 = {**POSTER_LIKE_FIG4, "opw_mean_ms_range": [120.0, 160.0], "opw_max_ms": 300.0}
    fig56 = {
        **POSTER_LIKE_FIG56,
        "removed_gamma5_mean_over_offsets": 0.4,
        "best_gamma": 0.3,
        "removed_best_gamma": 0.5,
        "largest_offset_max_below_150ms_s": 0.1,
        "largest_offset_mean_below_150ms_s": 0.2,
    }
    assert _opw_rows(fig4, fig56) == dict.fromkeys(["P1", "P2", "P3", "P4"], "no")
    # below 150 ms but not the poster's numbers: partly
    fig4 = {**POSTER_LIKE_FIG4, "opw_mean_ms_range": [22.0, 36.0], "opw_max_ms": 84.0}
    assert _opw_rows(fig4, POSTER_LIKE_FIG56)["P1"] == "partly"


# -- the rows a notebook prints after its figure ---------------------------------------------


def test_claim_rows_picks_rows_in_the_order_asked():
    rows = claims.build_claims(context=ctx_paper_like())
    got = claims.claim_rows(["5b", "1"], rows=rows)
    assert [r["id"] for r in got] == ["5b", "1"]
    assert got[1] is next(r for r in rows if r["id"] == "1")
    with pytest.raises(KeyError, match="99"):
        claims.claim_rows(["99"], rows=rows)
    with pytest.raises(KeyError, match="99"):
        claims.claims_by_id(["1", "99"])
    with pytest.raises(ValueError, match="at most one"):
        claims.claim_rows(["1"], rows=rows, facts={})


def test_claim_rows_from_a_notebooks_own_facts():
    """Notebook 10 checks claim 8 from its JSON alone, under both readings of Method C."""
    fig8 = {
        "deviation": {
            **FIG8_DEVIATIONS,
            "Mc w20 (literal window)": 150.0,
            "Mc w40 (literal window)": 3.0,
            "Mc w80 (literal window)": 300.0,
        }
    }
    (row,) = claims.claim_rows(["8"], "smoke", facts={"fig8": fig8})
    assert row["holds"] == "yes"  # the paper's numbers: below 18 are Mb w80 and Mc w80
    assert row["holds_literal"] == "partly"  # literal: Mb w80 and Mc w40 below 18
    assert "Mc w40 3.0" in row["ours_literal"]
    assert fig8["deviation"]["Mc w40"] == FIG8_DEVIATIONS["Mc w40"]  # facts not changed
    # a claim that needs the experiment results is not computed from facts
    (row,) = claims.claim_rows(["1"], "smoke", facts={"fig8": fig8})
    assert row["holds"] == "n/a" and row["ours"].startswith("not computed")
    (row,) = claims.claim_rows(["P1"], facts={"opw_fig4": POSTER_LIKE_FIG4})
    assert row["holds"] == "yes"
    with pytest.raises(TypeError, match="unknown facts"):
        claims.ClaimContext.from_facts(similarity={"Ma": 0.1})


def test_format_claims_prints_paper_ours_holds_and_the_literal_window_where_it_differs():
    rows = claims.build_claims(context=ctx_paper_like())
    for r in rows:  # make one row differ under the literal window
        if r["id"] == "1":
            r["ours_literal"], r["holds_literal"] = "pass either: none", "no"
    text = claims.format_claims(claims.claim_rows(["1", "5b"], rows=rows))
    lines = text.splitlines()
    assert lines[0].startswith("[1] Without a constraint, Mc w40")
    assert "    paper: Mc w40" in lines
    assert "    ours:  pass either: Mc w40" in lines
    assert "    holds? yes" in lines
    assert sum("literal window" in x for x in lines) == 1  # only for claim 1
    assert "pass either: none; holds? no" in text
    assert max(len(x) for x in lines) <= 96
    assert claims.format_claims(rows, stable=False).startswith("[4]")
    assert "[4]" not in claims.format_claims(rows, stable=True)
    assert claims.format_claims([]) == "(no claims)"
    assert claims.format_claims(rows) == claims.format_claims(rows)  # deterministic


def test_claims_summary_counts_each_verdict_per_reading():
    rows = [
        dict(holds="yes", holds_literal="no"),
        dict(holds="yes", holds_literal="partly"),
        dict(holds="n/a", holds_literal="n/a"),
    ]
    assert claims.claims_summary(rows).splitlines() == [
        "square window: yes 2, partly 0, no 0, n/a 1 (of 3 claims)",
        "literal window: yes 0, partly 1, no 1, n/a 1 (of 3 claims)",
    ]


def test_timing_claims_from_a_notebooks_own_rows():
    """Notebook 09 checks claims 4 and 4b from its bench rows; the literal window's rows stand
    for Method C under that reading."""
    rows = [
        dict(algorithm=f"M{m.lower()} w{w}{sfx}", method=m, w=w, type_v=False,
             mean_us=t * k, median_us=t * k)
        for m in ("B", "C")
        for w, t in ((10, 1000.0), (20, 2000.0), (40, 5000.0), (80, 17000.0))
        for sfx, k in (("", 1.0), (" (literal window)", 0.1 if w == 80 else 1.0))
        if not (m == "B" and sfx)
    ]  # fmt: skip
    got = {r["id"]: r for r in claims.claim_rows(["4", "4b"], facts={"timing": rows})}
    assert got["4"]["holds"] == "yes" and got["4b"]["holds"] == "yes"
    assert "Mc w80 17000 us" in got["4b"]["ours"]
    assert "Mc w80 1700 us" in got["4b"]["ours_literal"]  # the literal rows, as Mc's
    assert got["4b"]["holds_literal"] == "partly"  # only Mb w80 over the budget
    assert got["4"]["holds_literal"] == "partly"  # Mc: 1700 / 1000, not 8-fold
