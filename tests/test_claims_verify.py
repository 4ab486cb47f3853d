"""Every verdict recomputes from the saved tables alone (python -m fpdtw.paper.claims verify).

A paper-like fake run (tests/test_claims.py) is decided and saved; the verifier reads only
the CSV files back. Changing one number in claims_checks.csv must change what it recomputes.
"""

import csv

import pytest
from test_claims import context, paper_like_run

from fpdtw.paper import claims
from fpdtw.paper.claims import rules as R
from fpdtw.paper.claims.verify import main, verify


@pytest.fixture(scope="module")
def saved(tmp_path_factory):
    folder = tmp_path_factory.mktemp("figures")
    results = tmp_path_factory.mktemp("results")
    with pytest.MonkeyPatch.context() as mp:
        mp.setenv("FPDTW_FIGURES_DIR", str(folder))
        mp.setenv("FPDTW_RESULTS_DIR", str(results))
        # Mc w20 near the deviation benchmark: some parts are not decided, others are
        run = paper_like_run({"Mc w20": (0.2, 17.0)}, spread={"Mc w20": 0.02})
        checks = []
        rows, parts = claims.evaluate_claims(
            claims.CLAIMS, claims.claim_contexts(context(run)), checks=checks
        )
        power = claims.power_rows(checks, movements=8)
        claims.save_claims(rows, "smoke", parts=parts, checks=checks, power=power)
    return folder, rows, parts, checks


def _rewrite(path, change):
    with path.open(newline="") as f:
        rows = list(csv.DictReader(f))
    fields = list(rows[0])
    change(rows)
    with path.open("w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, lineterminator="\n")
        w.writeheader()
        w.writerows(rows)


def test_every_verdict_recomputes_from_the_saved_files(saved, capsys):
    folder, rows, parts, checks = saved
    assert verify(folder) == []
    assert main(["verify", str(folder)]) == 0
    assert "every verdict recomputes" in capsys.readouterr().out
    # every body, and every check of a multi-check part (1(b): 8 others x 2 benchmarks)
    bodies = {c["body"] for c in checks}
    assert {"all", "seed2", "same_movements", "authors_fbx", "hdm05"} <= bodies
    one_b = [c for c in checks if c["body"] == "all" and c["part"] == "1(b)"]
    assert len(one_b) == 16 and one_b[0]["formula"].startswith("all(not(any(c1, c2))")
    short = (folder / "claims.md").read_text()
    assert short.splitlines()[0].count("|") - 1 == len(claims.SHORT_COLUMNS) <= 9
    assert R.RULE in short


def test_changing_one_check_changes_the_recomputed_verdict(saved, tmp_path):
    folder = saved[0]
    for name in ("claims.csv", "claims_intervals.csv", "claims_checks.csv"):
        (tmp_path / name).write_bytes((folder / name).read_bytes())

    def flip(rows):  # claim 5's part (a): Ma's rank interval moved below its threshold
        for r in rows:
            if r["part"] == "5(a)" and r["body"] == "all":
                r["low"], r["high"], r["estimate"] = "1", "2", "1"

    _rewrite(tmp_path / "claims_checks.csv", flip)
    problems = verify(tmp_path)
    assert "all claim 5: stored 'yes', recomputed 'partly'" in problems
    assert any(p.startswith("all 5(a) check 1: stored 'holds'") for p in problems)
    assert main(["verify", str(tmp_path)]) == 1


def test_a_part_on_the_threshold_between_seeds(saved, tmp_path):
    """The headline part is 'on the threshold' where the second seed's checks disagree."""
    folder = saved[0]
    for name in ("claims.csv", "claims_intervals.csv", "claims_checks.csv"):
        (tmp_path / name).write_bytes((folder / name).read_bytes())

    def straddle(rows):
        for r in rows:
            if r["part"] == "5(a)" and r["body"] == "seed2":
                r["low"], r["high"] = "6", "9"  # straddles 6.5 with the second seed

    _rewrite(tmp_path / "claims_checks.csv", straddle)
    problems = verify(tmp_path)
    assert "all 5(a): stored 'holds', recomputed 'on the threshold'" in problems
    assert "all claim 5: stored 'yes', recomputed 'partly'" in problems


def test_power_says_how_many_movements_would_decide(saved):
    rows = claims.power_rows(
        [dict(body="all", claim="1", part="1(a)", check=2, quantity="q", estimate=12.0,
              low=8.0, high=32.0, threshold=18.0, relation="<", verdict="inconclusive")],
        movements=27,
    )  # fmt: skip
    # below 18 at 12: the high end must fall under 18: 27 * (20 / 6) ** 2 = 300 movements
    assert rows[0]["movements_needed"] == 300 and rows[0]["to"] == "hold"


def test_the_committed_figures_recompute():
    """Every verdict in the repository's figures/ recomputes from its own CSV files."""
    from pathlib import Path

    folder = Path(__file__).resolve().parents[1] / "figures"
    assert verify(folder) == []
