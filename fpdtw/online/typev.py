"""Forward Type V local continuity constraint as a state table (FP-DTW Section 6, Fig. 9).

Backward form
-------------
Rabiner and Juang's Type V local continuity constraint is dtw-python's
``rabinerJuangStepPattern(5, "c")``. With rows = target frames (the query, index i)
and columns = input frames (index j) its five steps are::

    g[i,j] = min( g[i-3,j-1] + d[i-2,j] + d[i-1,j] + d[i,j],   # target +3, input +1
                  g[i-2,j-1] + d[i-1,j] + d[i,j],              # target +2, input +1
                  g[i-1,j-1] + d[i,j],                         # diagonal
                  g[i-1,j-2] + d[i,j-1] + 0 d[i,j],            # target +1, input +2
                  g[i-1,j-3] + d[i,j-2] + 0 d[i,j-1] + 0 d[i,j] )  # target +1, input +3

Every step begins with a diagonal move; the target-only moves of the first two steps
(the same input frame for 2 or 3 target frames) and the input-only moves of the last two
(2 or 3 input frames within one target frame) follow it. The "c" weights charge exactly
one cell per target frame: the lowest input cell the path visits in that target row.

Forward form (what an online method can enforce)
------------------------------------------------
An online map gives ONE input frame per target frame, ``M_t``. A (1,2) or (1,3) step
visits two or three input frames within one target frame, so a one-cell-per-target-frame
map cannot list them all: it records the cell the path LEAVES the target frame from, the
highest input frame of the row, which is also where the next window starts
(``{I_{M_n}..}``). With this reading each backward step becomes, in advances
``a_t = M_t - M_{t-1}`` per target frame: ``1`` (diagonal), ``2`` and ``3`` (input +2,
+3), ``1, 0`` and ``1, 0, 0`` (target +2, +3). So, per new target frame, the input index
advances by 0..3, and a run of 0s (holds) is at most 2 long and directly follows an
advance of exactly 1 -- the forward form in the reading notes. (Recording the LOWEST
cell instead would give the time-reversed rule, holds that may follow any advance but
must be followed by an advance of exactly 1; the reading notes,
``notebooks/reading_notes.md``, settle the forward form above.)

That is a 3-state machine (the paper's Fig. 9 iii/iv), rows = states, columns = advance
0..3, cells = next state or "-" (not allowed); advances above 3 are never allowed::

    state  meaning                                           0    1    2    3
    N      no hold allowed: start, after an advance of 2/3,  -    A1   N    N
           after the second hold
    A1     just advanced by exactly 1                        H1   A1   N    N
    H1     held once after an advance of 1                   N    A1   N    N

(A state "held twice" would have the same row as N, so it is merged into N.) The start
state is N: the first target frame is mapped to input frame ``M_0`` (0, DTW's boundary
condition, the path starting at (0, 0); or another input frame with ``start="best"``, the
path then starting at (0, ``M_0``)), and the first step of a Type V path leaves its start
diagonally, so frame 1 cannot hold. Legality is the same from any ``M_0``: it depends on
the advances only. The warm-up of Methods B and C
(``M_1 = 1``, ``M_2 = 2``) goes N -> A1 -> A1: legal.

Advance 1 is allowed in every state, so whenever the input window has at least two
frames (``w_i >= 1``) an allowed candidate exists: a method never runs out of allowed
candidates inside a shrunken window. Only when the input is exhausted (``M_n = m``,
``w_i = 0``) is the one possible choice a hold at ``m``, which may break the constraint
(a third hold, or a hold after an advance of 2 or 3). The constraint cannot hold there;
legality is asserted up to the first target frame mapped to ``m`` (:func:`legal_prefix`).

Checking against dtw-python
---------------------------
:func:`dtw_python_accepts` asks dtw-python itself whether a map is the forward reading of
a Type V path, on the rectangle of target frames ``0..q`` x input frames ``0..M_q``:
each target row ``t`` gets a 0 at its lowest cell ``L_t`` (``M_{t-1} + 1`` after an
advance, ``M_t`` on a hold; ``L_0 = 0``), every other cell a 1, and the map is accepted
if the DTW path with ``rabinerJuangStepPattern(5, "c")`` has distance 0 and its highest
cell in every row equals ``M``. Sound: dtw-python only returns paths made of its
pattern's steps (it lists every sub-step cell), so acceptance exhibits a Type V path
whose forward reading is ``M``. Complete: for a legal ``M`` the implied path costs 0;
any zero-cost path has lowest cells ``L`` (each row is charged once, at its lowest cell),
and a row is entered either diagonally from the previous row's highest cell (then
``L_{t+1} > L_t``, highest ``= L_{t+1} - 1``) or by a hold from a one-cell row
(``L_{t+1} = L_t``, highest ``= L_t``), so ``L`` and the end cell fix every row's
highest cell, which for a legal ``M`` (holds only after an advance of 1, where
``L_t = M_t``) is ``M`` itself.

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

    Attributes
    ----------
    states : tuple of str
        State names, index = state number.
    meanings : tuple of str
        One-line meaning of each state.
    table : ndarray of int64, shape (3, 4)
        ``table[state, advance]`` = next state, or -1 if the advance is not allowed.
    start : int
        State before target frame 1 (after ``M_0``, whatever it is).
    name : str
        Suffix used in aligner names ("Type V").

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
        """The table as rows of strings, header first (for drawing Fig. 9 iv).

        Returns
        -------
        rows : list of list of str
            ``[["state", "0", "1", "2", "3"], ["N", "-", "A1", "N", "N"], ...]``.
        """
        rows = [["state"] + [str(a) for a in range(MAX_ADVANCE + 1)]]
        for s, name in enumerate(self.states):
            cells = [self.states[n] if n >= 0 else "-" for n in self.table[s]]
            rows.append([name] + cells)
        return rows

    def describe(self) -> str:
        """Plain-text rendering of the state table with the meaning of each state."""
        rows = self.as_table()
        width = max(len(c) for r in rows for c in r)
        lines = [
            "Forward Type V: advance of the input frame per target frame -> next state",
        ]
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
    """Turn an aligner's ``constraint`` argument into a :class:`TypeV` or None.

    Parameters
    ----------
    constraint : None, "typeV" (any case, with or without a space) or TypeV

    Raises
    ------
    AlignmentError
        Anything else.
    """
    if constraint is None:
        return None
    if isinstance(constraint, TypeV):
        return constraint
    if isinstance(constraint, str) and constraint.replace(" ", "").lower() == "typev":
        return TYPE_V
    raise AlignmentError(f"unknown constraint {constraint!r}; expected None or 'typeV'")


def legal_prefix(M, m=None) -> int:
    """Number of leading target frames over which Type V legality is asserted.

    Up to and including the first frame mapped to ``m`` (the last input frame), or the
    whole map if ``m`` is None or never reached.
    """
    M = np.asarray(M)
    if m is None:
        return M.shape[0]
    hit = np.flatnonzero(M >= m)
    return M.shape[0] if hit.size == 0 else int(hit[0]) + 1


def typev_violation(M, m=None, tv: TypeV = TYPE_V):
    """First target frame at which a map breaks the forward Type V constraint.

    Parameters
    ----------
    M : array_like of int, shape (n,)
        Map target frame -> input frame.
    m : int, optional
        Index of the last input frame: only the frames up to the first one mapped to
        ``m`` are checked (the constraint cannot hold once the input is exhausted).
    tv : TypeV

    Returns
    -------
    q : int or None
        The first offending target frame, None if legal. The path may start at any input
        frame ``M_0`` (``start="best"`` of the window methods): only the advances count.
    """
    M = np.asarray(M, dtype=np.int64)
    if M.ndim != 1:
        raise ValueError(f"expected a 1-d map, got shape {M.shape}")
    n = legal_prefix(M, m)
    if n == 0:
        return None
    state = tv.start
    for q in range(1, n):
        state = tv.next_state(state, int(M[q] - M[q - 1]))
        if state < 0:
            return q
    return None


def is_legal_typev(M, m=None) -> bool:
    """True if a map obeys the forward Type V constraint (see :func:`typev_violation`).

    Paper: FP-DTW Section 6.
    Notebook: 11_fig9_typev.ipynb
    """
    return typev_violation(M, m) is None


def lowest_cells(M) -> np.ndarray:
    """Lowest input cell of each target row of the Type V path read forward from ``M``.

    ``L_0 = M_0``; ``L_t = M_{t-1} + 1`` after an advance, ``M_t`` on a hold.
    """
    M = np.asarray(M, dtype=np.int64)
    L = M.copy()
    adv = np.diff(M) > 0
    L[1:][adv] = M[:-1][adv] + 1
    return L


def dtw_python_accepts(M) -> bool:
    """Ask dtw-python whether ``M`` is the forward reading of a Type V path.

    Builds the 0/1 cost matrix described in the module docstring on the rectangle
    ``[0..q] x [0..M_q]`` and runs ``dtw(C, step_pattern=rabinerJuangStepPattern(5,
    "c"))`` (rows = target = query). Accepts if the distance is 0 and the path's highest
    input cell in every target row equals ``M``. Needs the ``dtw-python`` package (a
    test dependency).

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


__all__ = [
    "MAX_ADVANCE",
    "TYPE_V",
    "TypeV",
    "dtw_python_accepts",
    "is_legal_typev",
    "legal_prefix",
    "lowest_cells",
    "resolve_constraint",
    "typev_violation",
]
