"""Online aligners behind one streaming interface (see :mod:`fpdtw.online.base`)."""

from .base import OnlineAligner, run_online

__all__ = ["OnlineAligner", "run_online"]
