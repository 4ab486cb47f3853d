"""Forward Type V local continuity constraint as a state table (FP-DTW Section 6, Fig. 9).

Rabiner and Juang's Type V (dtw-python's ``rabinerJuangStepPattern(5, "c")``) has five
steps, each a diagonal move followed by up to two target-only or input-only moves. An
online map keeps ONE input frame per target frame; we keep the cell the path LEAVES the
target frame from (the highest, where the next window starts; the reading notes settle
this forward form; the lowest would give the time-reversed rule). Per target frame the
input then advances by 0..3, and a run of holds (0s) is at most 2 long and directly
follows an advance of exactly 1. As a state machine (Fig. 9 iii/iv; "-" not allowed)::

    state  meaning                                               0    1    2    3
    N      no hold: start, after an advance of 2/3 or two holds  -    A1   N    N
    A1     just advanced by exactly 1                            H1   A1   N    N
    H1     held once after an advance of 1                       N    A1   N    N

The start state is N whatever ``M_0`` (a Type V path leaves its start diagonally).
Advance 1 is always allowed, so a window of two rows always has a candidate; only once
the input is exhausted is a hold at ``m`` forced, which may break the constraint:
legality is asserted up to the first frame mapped to ``m`` (:func:`legal_prefix`).

Paper: FP-DTW Section 6, Fig. 9.
Notebook: 11_fig9_typev.ipynb
"""

from __future__ import annotations

import numpy as np

from fpdtw.errors import AlignmentError

#: Largest advance of the input index per target frame under Type V.
MAX_ADVANCE = 3


class TypeV:
    """The forward Type V constraint as a state table.

    ``states`` and ``meanings``; ``table[state, advance]`` (int64 (3, 4)): the next state,
    -1 if not allowed; ``start``; ``name``, the suffix in aligner names.

    Plain version: fpdtw.plain.type_v_allowed, fpdtw.plain.type_v_next.
    Paper: FP-DTW Section 6, Fig. 9 iv.
    """

    name = "Type V"
    states = ("N", "A1", "H1")
    meanings = (
        "no hold allowed (start, after an advance of 2 or 3, after the second hold)",
        "just advanced by exactly 1: may hold",
        "held once after an advance of 1: may hold once more",
    )
    start = 0

    def __init__(self):
        N, A1, H1 = 0, 1, 2
        self.table = np.array(
            [
                [-1, A1, N, N],  # N
                [H1, A1, N, N],  # A1
                [N, A1, N, N],  # H1
            ],
            dtype=np.int64,
        )
        self.table.setflags(write=False)

    def allowed(self, state: int) -> np.ndarray:
        """Allowed advances 0..3 in ``state``: bool array of shape (4,)."""
        return self.table[state] >= 0

    def next_state(self, state: int, advance: int) -> int:
        """State after ``advance``, or -1 if the advance is not allowed in ``state``."""
        if advance < 0 or advance > MAX_ADVANCE:
            return -1
        return int(self.table[state, advance])

    def as_table(self) -> list:
        """The table as rows of strings, header first: ``[["state", "0", ...], ["N", ...]]``."""
        rows = [["state"] + [str(a) for a in range(MAX_ADVANCE + 1)]]
        for s, name in enumerate(self.states):
            cells = [self.states[n] if n >= 0 else "-" for n in self.table[s]]
            rows.append([name] + cells)
        return rows

    def describe(self) -> str:
        """Plain-text rendering of the state table with the meaning of each state."""
        rows = self.as_table()
        width = max(len(c) for r in rows for c in r)
        lines = ["Forward Type V: advance of the input frame per target frame -> next state"]
        for r in rows:
            lines.append("  ".join(c.ljust(width) for c in r))
        lines.append(f"start state: {self.states[self.start]}; advances > {MAX_ADVANCE}: never")
        for name, meaning in zip(self.states, self.meanings):
            lines.append(f"{name}: {meaning}")
        return "\n".join(lines)

    def __repr__(self):
        return "TypeV()"


#: The one Type V instance the aligners share.
TYPE_V = TypeV()


def resolve_constraint(constraint):
    """A :class:`TypeV` or None from None, TypeV or "typeV" (any case); else AlignmentError."""
    if constraint is None:
        return None
    if isinstance(constraint, TypeV):
        return constraint
    if isinstance(constraint, str) and constraint.replace(" ", "").lower() == "typev":
        return TYPE_V
    raise AlignmentError(f"unknown constraint {constraint!r}; expected None or 'typeV'")


def legal_prefix(M, m=None) -> int:
    """Leading target frames over which legality is asserted: through the first mapped to ``m``."""
    M = np.asarray(M)
    if m is None:
        return M.shape[0]
    hit = np.flatnonzero(M >= m)
    return M.shape[0] if hit.size == 0 else int(hit[0]) + 1


def typev_violation(M, m=None):
    """First target frame (int) at which map ``M`` breaks forward Type V, or None.

    Only the frames up to the first mapped to ``m`` are checked; the path may start at any
    ``M_0``: only the advances count."""
    M = np.asarray(M, dtype=np.int64)
    if M.ndim != 1:
        raise ValueError(f"expected a 1-d map, got shape {M.shape}")
    state = TYPE_V.start
    for q in range(1, legal_prefix(M, m)):
        state = TYPE_V.next_state(state, int(M[q] - M[q - 1]))
        if state < 0:
            return q
    return None


def is_legal_typev(M, m=None) -> bool:
    """True if a map obeys the forward Type V constraint (:func:`typev_violation`).

    Paper: FP-DTW Section 6.
    Notebook: 11_fig9_typev.ipynb
    """
    return typev_violation(M, m) is None


def lowest_cells(M) -> np.ndarray:
    """Lowest input cell of each target row of the path read forward from ``M``.

    ``M_{t-1} + 1`` after an advance, ``M_t`` on a hold."""
    M = np.asarray(M, dtype=np.int64)
    L = M.copy()
    adv = np.diff(M) > 0
    L[1:][adv] = M[:-1][adv] + 1
    return L


def dtw_python_accepts(M) -> bool:
    """Ask dtw-python whether ``M`` is the forward reading of a Type V path.

    On ``[0..q] x [0..M_q]`` the :func:`lowest_cells` cost 0, the rest 1; accepted when the
    ``rabinerJuangStepPattern(5, "c")`` path costs 0 with ``M`` as its highest cell per row
    (sound: its paths are the pattern's steps; complete: lowest cells fix the highest).

    Paper: FP-DTW Section 6 (Type V, Rabiner and Juang's local continuity constraint).
    Notebook: 11_fig9_typev.ipynb
    """
    from dtw import dtw, rabinerJuangStepPattern

    M = np.asarray(M, dtype=np.int64)
    if M.ndim != 1 or M.size == 0 or M[0] < 0 or np.any(np.diff(M) < 0):
        return False
    M = M - M[0]  # a path from (0, M_0) is the path from (0, 0) shifted by M_0 input frames
    q = M.size - 1
    C = np.ones((q + 1, int(M[-1]) + 1))
    C[np.arange(q + 1), lowest_cells(M)] = 0.0
    try:
        al = dtw(C, step_pattern=rabinerJuangStepPattern(5, "c"))
    except ValueError:  # "No warping path found compatible with the local constraints"
        return False
    if al.distance != 0.0:
        return False
    highest = np.full(q + 1, -1, dtype=np.int64)
    np.maximum.at(highest, np.asarray(al.index1), np.asarray(al.index2))
    return bool(np.array_equal(highest, M))
