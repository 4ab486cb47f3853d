"""fpdtw: online alignment of human motion (FP-DTW, Randall et al. 2023, and OPW)."""

from .errors import AlignmentError, DataFetchError, FpdtwError, ManifestError, MotionFormatError
from .features import Frame, MotionFeatures
from .joints import OPW_JOINTS, PAPER_JOINTS
from .motion import Motion, Skeleton

__version__ = "0.1.0"

__all__ = [
    "AlignmentError",
    "DataFetchError",
    "FpdtwError",
    "Frame",
    "ManifestError",
    "Motion",
    "MotionFeatures",
    "MotionFormatError",
    "OPW_JOINTS",
    "PAPER_JOINTS",
    "Skeleton",
]
