"""The rules that turn numbers into verdicts: checks, parts and claims (:data:`RULE`).

Chosen in f88f748 (2026-11-23) after the first full runs' claims tables; extended on
2026-11-24 (the second seed, the full rule text) after a reviewer's reading (docs/history.md).

Paper: FP-DTW Section 5 (the pass rule of the two benchmarks).
"""

from __future__ import annotations

import itertools
import math
import re
from dataclasses import dataclass

HOLDS = "holds"
CONTRADICTED = "contradicted"
INCONCLUSIVE = "inconclusive"
NOT_COMPARABLE = "not comparable"
ON_THRESHOLD = "on the threshold"

YES, NO, PARTLY, NA = "yes", "no", "partly", "n/a"
CLAIM_VERDICTS = (YES, PARTLY, NO, INCONCLUSIVE, NOT_COMPARABLE, NA)

#: The whole rule, printed under every claims table.
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
    """One number against one threshold: ``estimate > threshold`` (``above`` False: ``<``;
    ``strict`` False: ``>=``, ``<=``), decided on ``[low, high]`` or, ``interval`` False, on
    ``estimate`` alone. ``low_se``, ``high_se``: Monte Carlo errors of the ends (NaN: none)."""

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
    def verdict(self) -> str:
        """holds / contradicted / inconclusive (:data:`RULE`)."""
        lo, hi = map(float, (self.low, self.high) if self.interval else (self.estimate,) * 2)
        if not (math.isfinite(lo) and math.isfinite(hi) and math.isfinite(self.estimate)):
            return INCONCLUSIVE
        t = self.threshold
        if self.above:
            ok, bad = (lo > t, hi <= t) if self.strict else (lo >= t, hi < t)
        else:
            ok, bad = (hi < t, lo >= t) if self.strict else (hi <= t, lo > t)
        return HOLDS if ok else CONTRADICTED if bad else INCONCLUSIVE

    def mc_margin(self) -> float:
        """Monte Carlo standard errors from the nearer interval end to the threshold (or inf)."""
        ends = ((self.low, self.low_se), (self.high, self.high_se)) if self.interval else ()
        ok = [(e, se) for e, se in ends if math.isfinite(e) and math.isfinite(se) and se > 0]
        return min([float("inf"), *(abs(e - self.threshold) / se for e, se in ok)])

    def describe(self) -> str:
        """``"median deviation of Mc w20, frames 13.5 [12.1, 14.9] < 18"`` (or ``straddles``)."""
        v = self.verdict
        rel = ">" if (v == HOLDS) == self.above else "<"
        rel += "=" if (v == CONTRADICTED) == self.strict else ""
        rel = "straddles" if v == INCONCLUSIVE else rel
        return f"{self.quantity} {self.value_text()} {rel} {self.threshold:g}"

    def value_text(self) -> str:
        d, sg = self.digits, self.signed
        est = _fmt(self.estimate, d, sg)
        if not self.interval:
            return est
        return f"{est} [{_fmt(self.low, d, sg)}, {_fmt(self.high, d, sg)}]"


def point(quantity: str, value: float, threshold: float, **kw) -> Check:
    """A check of a value without resampling (timings, the OPW protocol)."""
    return Check(quantity, value, threshold=threshold, interval=False, **kw)


@dataclass(frozen=True, init=False)
class _Items:
    items: tuple

    def __init__(self, *items):
        object.__setattr__(self, "items", tuple(items))


@dataclass(frozen=True, init=False)
class AllOf(_Items):
    """Kleene's AND."""


@dataclass(frozen=True, init=False)
class AnyOf(_Items):
    """Kleene's OR."""


@dataclass(frozen=True)
class Not:
    """Kleene's NOT."""

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
    """The checks that decide a formula's verdict, in order."""
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
    return list(dict.fromkeys(c for x in chosen for c in evidence(x)))


def checks(node) -> list[Check]:
    """Every check of a formula, in order."""
    if isinstance(node, Check):
        return [node]
    if isinstance(node, Not):
        return checks(node.item)
    return [c for x in node.items for c in checks(x)]


def formula(node) -> str:
    """``formula(AllOf(a, Not(b)))`` -> ``"all(c1, not(c2))"`` (checks numbered as
    :func:`checks` lists them)."""
    count = itertools.count(1)

    def text(x):
        if isinstance(x, Check):
            return f"c{next(count)}"
        if isinstance(x, Not):
            return f"not({text(x.item)})"
        word = "all" if isinstance(x, AllOf) else "any"
        return f"{word}({', '.join(text(i) for i in x.items)})"

    return text(node)


def parse_formula(text: str, checks_by_number: dict):
    """The objects of a :func:`formula` text, given ``{check number: Check}`` (ValueError:
    not a formula, or a check number not given)."""
    tokens = iter(re.findall(r"all\(|any\(|not\(|c\d+|,|\)|\S", text))

    def take():
        if (tok := next(tokens, None)) is None:
            raise ValueError(f"formula {text!r} ends early")
        return tok

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
    if next(tokens, None) is not None:
        raise ValueError(f"formula {text!r}: text after the end")
    return out


@dataclass(frozen=True)
class Part:
    """One testable part of a claim: its text, a check or formula (None: not comparable), a note."""

    text: str
    test: object = None
    note: str = ""

    @property
    def verdict(self) -> str:
        return NOT_COMPARABLE if self.test is None else evaluate(self.test)

    def evidence(self) -> list[Check]:
        return [] if self.test is None else evidence(self.test)

    def decisive(self) -> Check | None:
        """The first check of the evidence (the part's row in the intervals table)."""
        return next(iter(self.evidence()), None)

    def explain(self) -> str:
        """``"<text>: <verdict> (<evidence>; <note>)"``, at most three checks named."""
        ev = self.evidence()
        said = [c.describe() for c in ev[:3]] + ([f"+{len(ev) - 3} more"] if len(ev) > 3 else [])
        said += [self.note] if self.note else []
        return f"{self.text}: {self.verdict}" + (f" ({'; '.join(said)})" if said else "")


def claim_verdict(verdicts) -> str:
    """A claim's verdict from its parts' (:data:`RULE`)."""
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
    """Which parts hold, and which do not and why (``contradiction`` first)."""
    head = f"{contradiction.rstrip('.')}. " if contradiction else ""
    vs = [p.verdict for p in parts]
    if vs and all(v == HOLDS for v in vs):
        if len(parts) == 1:
            return head + _sentence(parts[0].explain())
        weakest = "; ".join(p.decisive().describe() for p in parts if p.decisive() is not None)
        return head + f"All {len(parts)} parts hold ({weakest})"
    held = "; ".join(p.text for p in parts if p.verdict == HOLDS)
    failing = "; ".join(p.explain() for p in parts if p.verdict != HOLDS)
    return head + _sentence(failing) + (f". Holds: {held}" if held else "")


def _sentence(text: str) -> str:
    return text[:1].upper() + text[1:]


def part_label(claim_id: str, k: int) -> str:
    """``part_label("1", 0)`` -> ``"1(a)"``; ``part_label("5b", 1)`` -> ``"5b(b)"``."""
    return f"{claim_id}({chr(ord('a') + k)})"
