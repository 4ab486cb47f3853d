"""The global band of notebook 16 (Q3; beyond the papers, whose Section 7 suggests one).

The window aligners apply it in their compiled steps; these functions call the same kernels.
"""

from __future__ import annotations

import numpy as np

from fpdtw.online.window import ForecastAligner, _clip_band, _mask_band

#: Half-width of ``band="1s"`` in seconds (times the input's frame rate): the aligners'.
BAND_SECONDS = ForecastAligner.BAND_SECONDS


def band_half_width(band: str, w: int, fps: float) -> int:
    """Half-width ``B`` in frames of a band option: ``"none"`` 0, ``"1s"`` ``round(fps)``,
    ``"half-w"`` ``floor(w / 2)``; both at least 1.

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    """
    if band == "none":
        return 0
    if band == "1s":
        return max(1, int(round(BAND_SECONDS * fps)))
    if band == "half-w":
        return max(1, int(w) // 2)
    raise ValueError(f"band must be 'none', '1s' or 'half-w', got {band!r}")


def band_rows(start: int, rows: int, q: int, band: int) -> np.ndarray:
    """Which rows ``r`` of a window (offsets from ``M_n = start``) lie inside the band,
    ``|start + r - q| <= band``: bool (rows,).

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    Notebook: 16_open_questions.ipynb
    """
    C = np.zeros((int(rows), 1))
    _mask_band(C, int(rows), 0, int(q), int(start), int(band))
    return np.isfinite(C[:, 0])


def band_window(start: int, w_i: int, q: int, band: int):
    """Offsets ``(first, last)`` of the rows of ``I_{start}..I_{start + w_i}`` inside the band,
    or None.

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    Notebook: 16_open_questions.ipynb
    """
    first, n = _clip_band(int(start), int(w_i) + 1, int(q), int(band))
    if abs(start + first - q) > band:  # no row inside: the kernel keeps the whole window
        return None
    return int(first), int(first + n - 1)


def band_cells(M, m: int, w: int, method: str, band: str = "half-w"):
    """The cells of eq. 1 a band aligner's windows compute, with and without its band.

    From its map ``M``: ``(q, full, banded)``, int64 each, the window steps' target frames
    and cells. A step at ``q`` has a window when ``n = q - 1 >= 2`` and ``M_n < m``: Method
    B, ``min(w, m - M_n) + 1`` rows by ``w + 1`` columns; Method C's square window,
    ``min(w - 1, m - M_n) + 1`` rows by ``w``. ``"half-w"`` computes only the rows of
    :func:`band_window`; ``"1s"`` masks, so computes all.

    Paper: FP-DTW Section 7 (conclusion: a global constraint).
    """
    M = np.asarray(M, dtype=np.int64)
    B = band_half_width(band, w, 0.0) if band == "half-w" else 0  # "1s" clips nothing
    reach, cols = (w, w + 1) if method == "B" else (w - 1, w)
    qs, full, banded = [], [], []
    for q in range(3, len(M)):  # n = q - 1 >= s = 2
        start = int(M[q - 1])
        if start >= m:
            continue
        w_i = min(reach, m - start)
        rows = w_i + 1
        if band == "half-w" and (r := band_window(start, w_i, q, B)) is not None:
            rows = r[1] - r[0] + 1
        qs.append(q)
        full.append((w_i + 1) * cols)
        banded.append(rows * cols)
    return tuple(np.array(x, dtype=np.int64) for x in (qs, full, banded))
