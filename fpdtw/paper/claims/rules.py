"""The one set of rules that turns numbers into verdicts: checks, parts and claims.

A claim of a paper is split into **parts**, each an atomic statement that can be tested
("Mc w40 passes a benchmark"; "no other unconstrained FP-DTW algorithm passes one"). A part
is a small logical formula of **checks**; a check is one number (with its 95 % interval)
against one threshold. The rules are :data:`RULE` (printed under every claims table). They
were chosen in f88f748 (2026-11-23), after the claims tables of the first full runs had been
committed, and extended on 2026-11-24 (the second seed, the rule text in full) after a
reviewer's reading of those tables; ``docs/history.md`` says which results had been seen:

* a :class:`Check` that says "estimate above threshold" **holds** when its whole interval
  lies above the threshold, is **contradicted** when its whole interval lies at or below
  it, and is **inconclusive** when the interval straddles it (and likewise for "below").
  A check without an interval (a timing, the OPW poster's deterministic protocol) is
  decided by its point value. A check whose value could not be computed is inconclusive.
* :class:`AllOf`, :class:`AnyOf` and :class:`Not` combine checks by Kleene's three-valued
  logic: holds = true, contradicted = false, inconclusive = unknown. ``AllOf`` holds when
  every item holds and is contradicted when any item is; ``AnyOf`` holds when any item
  holds and is contradicted when every item is; ``Not`` swaps holds and contradicted.
* a :class:`Part` may instead be **not comparable**: our data cannot test it (another
  sample than the paper's; a number that depends on data we do not have), with a note why.
* a part decided on resampled pairs is decided again with a second bootstrap seed; where
  the two seeds give different verdicts it is **on the threshold** (counted as
  inconclusive).
* a claim's verdict follows from its parts' verdicts (:func:`claim_verdict`): every part
  holds: **yes**; none holds and at least one is contradicted: **no**; none holds and none
  is contradicted: **inconclusive**; every part not comparable: **not comparable**;
  otherwise **partly**, and the reason names the parts that do not hold and the checks that
  make them fail (:func:`claim_reason`).

Paper: FP-DTW Section 5 (the pass rule of the two benchmarks).
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass, field

#: Verdicts of a check or a part.
HOLDS = "holds"
CONTRADICTED = "contradicted"
INCONCLUSIVE = "inconclusive"
NOT_COMPARABLE = "not comparable"

#: Verdicts of a claim ("n/a": not computed, or not a claim of the papers).
YES, NO, PARTLY, NA = "yes", "no", "partly", "n/a"
CLAIM_VERDICTS = (YES, PARTLY, NO, INCONCLUSIVE, NOT_COMPARABLE, NA)

ON_THRESHOLD = "on the threshold"
PART_VERDICTS = (HOLDS, CONTRADICTED, INCONCLUSIVE, NOT_COMPARABLE, ON_THRESHOLD)

#: The whole rule, printed under every claims table (README, ARTIFACT, book, figures/).
RULE = (
    "How a verdict is decided. A claim is split into parts: the statements its words make, "
    "no more. A part is a check, or checks joined by all-of, any-of and not (Kleene's "
    "three-valued logic). A check compares one estimate with one threshold. With a 95 % "
    "interval (a cluster bootstrap: movements resampled within each dataset, then motions "
    "within each movement; pairs sharing a motion move together) it holds when the whole "
    "interval clears the threshold, is contradicted when the whole interval fails it, and is "
    "inconclusive when the interval straddles it. A point check (timings, the OPW poster's "
    "deterministic protocol: no resampling) is decided by its value alone. Ties: a strict "
    "check ('above', 'below') counts a value equal to the threshold as failing; an 'at "
    "least' / 'at most' check counts it as clearing. A value that could not be computed is "
    "inconclusive. A part is not comparable when our data cannot test it (the reason is "
    "given). Every part decided on resampled pairs is decided again with a second seed; "
    "where the seeds disagree it is 'on the threshold', counted as inconclusive. A claim is "
    "yes when every part holds; no when none holds and at least one is contradicted; "
    "inconclusive when none holds and none is contradicted; not comparable when every part "
    "is; partly otherwise (some parts hold, others do not: the reason names them). Claims "
    "that could not be computed, and runs beyond the papers, are n/a."
)
#: Kept for the callers of the old name.
LEGEND = RULE

_FLIP = {HOLDS: CONTRADICTED, CONTRADICTED: HOLDS, INCONCLUSIVE: INCONCLUSIVE}


def _fmt(x: float, digits: int, sign: bool = False) -> str:
    if x is None or not math.isfinite(x):
        return "nan"
    return f"{x:+.{digits}f}" if sign else f"{x:.{digits}f}"


@dataclass(frozen=True)
class Check:
    """One number against one threshold: the atom of every verdict.

    Attributes
    ----------
    quantity : str
        What the estimate is, in words (``"median deviation of Mc w20, frames"``).
    estimate : float
        The value on the data (e.g. a median over the pairs).
    low, high : float
        Its 95 % interval (ignored when ``interval`` is False).
    threshold : float
    above : bool
        The statement: ``estimate > threshold`` (True) or ``estimate < threshold`` (False).
    interval : bool
        False for a value without resampling (timings, the OPW protocol): decided by the
        point value alone.
    digits : int
        Decimals shown.
    signed : bool
        Show a sign (differences).
    strict : bool
        True: "above" means ``> threshold``; False: ``>= threshold`` ("at least").
    low_se, high_se : float
        Monte Carlo standard errors of the interval ends (batch means over the bootstrap
        replicates; NaN when not estimated).
    """

    quantity: str
    estimate: float
    low: float = float("nan")
    high: float = float("nan")
    threshold: float = 0.0
    above: bool = True
    interval: bool = True
    digits: int = 3
    signed: bool = False
    strict: bool = True
    low_se: float = float("nan")
    high_se: float = float("nan")

    @property
    def bounds(self) -> tuple[float, float]:
        """The interval the verdict reads: ``(low, high)``, or the point value twice."""
        if self.interval:
            return float(self.low), float(self.high)
        return float(self.estimate), float(self.estimate)

    @property
    def verdict(self) -> str:
        """holds / contradicted / inconclusive, by the rule of the module docstring."""
        lo, hi = self.bounds
        if not (math.isfinite(lo) and math.isfinite(hi) and math.isfinite(self.estimate)):
            return INCONCLUSIVE
        t = self.threshold
        if self.above:
            ok, bad = (lo > t, hi <= t) if self.strict else (lo >= t, hi < t)
        else:
            ok, bad = (hi < t, lo >= t) if self.strict else (hi <= t, lo > t)
        return HOLDS if ok else CONTRADICTED if bad else INCONCLUSIVE

    def mc_margin(self) -> float:
        """How many Monte Carlo standard errors the nearer interval end lies from the
        threshold (inf without an interval or without an error estimate)."""
        if not self.interval:
            return float("inf")
        out = float("inf")
        for end, se in ((self.low, self.low_se), (self.high, self.high_se)):
            if math.isfinite(end) and math.isfinite(se) and se > 0:
                out = min(out, abs(end - self.threshold) / se)
        return out

    def describe(self) -> str:
        """``"median deviation of Mc w20, frames 13.5 [12.1, 14.9] < 18"``.

        The relation shown is what the numbers do: ``>``/``<`` where the check holds,
        ``<=``/``>=`` where it is contradicted, ``straddles`` where the interval crosses
        the threshold.
        """
        v = self.verdict
        if v == INCONCLUSIVE:
            rel = "straddles"
        elif (v == HOLDS) == self.above:
            rel = ">"
        else:
            rel = "<"
        if v != INCONCLUSIVE and (v == CONTRADICTED) == self.strict:
            rel += "="
        d = self.digits
        est = _fmt(self.estimate, d, self.signed)
        ci = f" [{_fmt(self.low, d, self.signed)}, {_fmt(self.high, d, self.signed)}]"
        thr = f"{self.threshold:g}"
        return f"{self.quantity} {est}{ci if self.interval else ''} {rel} {thr}"


@dataclass(frozen=True)
class AllOf:
    """Holds when every item holds; contradicted when any item is (Kleene's AND)."""

    items: tuple

    def __init__(self, *items):
        object.__setattr__(self, "items", tuple(items))


@dataclass(frozen=True)
class AnyOf:
    """Holds when any item holds; contradicted when every item is (Kleene's OR)."""

    items: tuple

    def __init__(self, *items):
        object.__setattr__(self, "items", tuple(items))


@dataclass(frozen=True)
class Not:
    """Holds when the item is contradicted, and the other way round."""

    item: object


def evaluate(node) -> str:
    """The verdict of a check or a formula of checks (holds / contradicted / inconclusive)."""
    if isinstance(node, Check):
        return node.verdict
    if isinstance(node, Not):
        return _FLIP[evaluate(node.item)]
    if isinstance(node, AllOf | AnyOf):
        vs = [evaluate(x) for x in node.items]
        win, lose = (CONTRADICTED, HOLDS) if isinstance(node, AllOf) else (HOLDS, CONTRADICTED)
        if win in vs:
            return win
        if vs and all(v == lose for v in vs):
            return lose
        return INCONCLUSIVE
    raise TypeError(f"not a check or a formula of checks: {node!r}")


def evidence(node) -> list[Check]:
    """The checks that decide a formula's verdict, in order.

    Holds: for ``AllOf`` every item's evidence, for ``AnyOf`` the holding items'.
    Contradicted: for ``AllOf`` the contradicted items', for ``AnyOf`` every item's.
    Inconclusive: the inconclusive items'. ``Not`` passes its item's evidence through.
    """
    if isinstance(node, Check):
        return [node]
    if isinstance(node, Not):
        return evidence(node.item)
    v = evaluate(node)
    items = node.items
    if v == INCONCLUSIVE:
        chosen = [x for x in items if evaluate(x) == INCONCLUSIVE]
    elif (v == HOLDS) == isinstance(node, AnyOf):
        chosen = [x for x in items if evaluate(x) == v]
    else:
        chosen = list(items)
    out = []
    for x in chosen:
        for c in evidence(x):
            if c not in out:
                out.append(c)
    return out


def checks(node) -> list[Check]:
    """Every check of a formula, in order."""
    if isinstance(node, Check):
        return [node]
    if isinstance(node, Not):
        return checks(node.item)
    return [c for x in node.items for c in checks(x)]


def formula(node) -> str:
    """The formula as text, its checks numbered in the order of :func:`checks` from 1.

    ``formula(AllOf(a, Not(b)))`` -> ``"all(c1, not(c2))"``; a single check -> ``"c1"``.
    :func:`parse_formula` reads it back.
    """
    count = iter(range(1, 1 << 30))

    def text(x):
        if isinstance(x, Check):
            return f"c{next(count)}"
        if isinstance(x, Not):
            return f"not({text(x.item)})"
        word = "all" if isinstance(x, AllOf) else "any"
        return f"{word}({', '.join(text(i) for i in x.items)})"

    return text(node)


def parse_formula(text: str, checks_by_number: dict):
    """The formula of :func:`formula` back as objects.

    Parameters
    ----------
    text : str
        ``"all(c1, not(c2))"``.
    checks_by_number : dict of int to Check

    Raises
    ------
    ValueError
        Text that is not a formula, or a check number not given.
    """

    tokens = re.findall(r"all\(|any\(|not\(|c\d+|,|\)|\S", text)
    pos = 0

    def take():
        nonlocal pos
        if pos >= len(tokens):
            raise ValueError(f"formula {text!r} ends early")
        pos += 1
        return tokens[pos - 1]

    def node():
        tok = take()
        if tok.startswith("c") and tok[1:].isdigit():
            k = int(tok[1:])
            if k not in checks_by_number:
                raise ValueError(f"formula {text!r} names check {k}, which is not given")
            return checks_by_number[k]
        if tok == "not(":
            inner = node()
            if take() != ")":
                raise ValueError(f"formula {text!r}: not(...) takes one item")
            return Not(inner)
        if tok in ("all(", "any("):
            items = [node()]
            while (sep := take()) == ",":
                items.append(node())
            if sep != ")":
                raise ValueError(f"formula {text!r}: expected ',' or ')', got {sep!r}")
            return AllOf(*items) if tok == "all(" else AnyOf(*items)
        raise ValueError(f"formula {text!r}: unexpected {tok!r}")

    out = node()
    if pos != len(tokens):
        raise ValueError(f"formula {text!r}: text after the end")
    return out


@dataclass(frozen=True)
class Part:
    """One atomic, testable part of a claim.

    Attributes
    ----------
    text : str
        The part in words ("Mc w40 passes a benchmark").
    test : Check or formula, optional
        What decides it; None for a part that is not comparable.
    note : str
        Why a part is not comparable, or a remark shown with its reason.
    """

    text: str
    test: object = None
    note: str = ""

    @property
    def verdict(self) -> str:
        return NOT_COMPARABLE if self.test is None else evaluate(self.test)

    def evidence(self) -> list[Check]:
        return [] if self.test is None else evidence(self.test)

    def decisive(self) -> Check | None:
        """The first check of the evidence: the row a part gets in the intervals table."""
        ev = self.evidence()
        return ev[0] if ev else None

    def explain(self, most: int = 3) -> str:
        """``"<text>: <verdict> (<evidence>)"``, at most ``most`` checks named."""
        v = self.verdict
        if self.test is None:
            return f"{self.text}: {v} ({self.note})" if self.note else f"{self.text}: {v}"
        ev = self.evidence()
        shown = "; ".join(c.describe() for c in ev[:most])
        more = f"; +{len(ev) - most} more" if len(ev) > most else ""
        note = f"; {self.note}" if self.note else ""
        return f"{self.text}: {v} ({shown}{more}{note})"


def claim_verdict(verdicts) -> str:
    """A claim's verdict from its parts' (rule in the module docstring)."""
    vs = list(verdicts)
    if not vs:
        return NA
    if all(v == NOT_COMPARABLE for v in vs):
        return NOT_COMPARABLE
    if all(v == HOLDS for v in vs):
        return YES
    if HOLDS in vs:
        return PARTLY
    return NO if CONTRADICTED in vs else INCONCLUSIVE


def claim_reason(parts, contradiction: str = "") -> str:
    """One or two sentences: which parts hold, and which do not and why.

    Parameters
    ----------
    parts : list of Part
    contradiction : str
        Where the paper's own text contradicts itself: said first.
    """
    head = f"{contradiction.rstrip('.')}. " if contradiction else ""
    vs = [p.verdict for p in parts]
    if vs and all(v == HOLDS for v in vs):
        if len(parts) == 1:
            return head + _sentence(parts[0].explain())
        weakest = "; ".join(p.decisive().describe() for p in parts if p.decisive() is not None)
        return head + f"All {len(parts)} parts hold ({weakest})"
    held = [p.text for p in parts if p.verdict == HOLDS]
    failing = [p.explain() for p in parts if p.verdict != HOLDS]
    out = head + _sentence("; ".join(failing))
    if held:
        out += ". Holds: " + "; ".join(held)
    return out


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:]


def part_label(claim_id: str, k: int) -> str:
    """``part_label("1", 0)`` -> ``"1(a)"``; ``part_label("5b", 1)`` -> ``"5b(b)"``."""
    return f"{claim_id}({chr(ord('a') + k)})"


@dataclass
class PartResult:
    """A part evaluated on every body of evidence a claims table shows."""

    label: str
    text: str
    verdict: str
    check: Check | None
    reason: str
    others: dict = field(default_factory=dict)


__all__ = [
    "CLAIM_VERDICTS",
    "CONTRADICTED",
    "HOLDS",
    "INCONCLUSIVE",
    "LEGEND",
    "NA",
    "NO",
    "NOT_COMPARABLE",
    "PARTLY",
    "PART_VERDICTS",
    "YES",
    "AllOf",
    "AnyOf",
    "Check",
    "Not",
    "Part",
    "PartResult",
    "ON_THRESHOLD",
    "RULE",
    "checks",
    "claim_reason",
    "claim_verdict",
    "evaluate",
    "evidence",
    "formula",
    "parse_formula",
    "part_label",
]
