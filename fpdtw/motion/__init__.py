"""Motions: one motion type, skeletons, rotations, joint maps and per-frame features."""

from fpdtw.motion.features import Frame, MotionFeatures
from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS
from fpdtw.motion.motion import Motion, Skeleton

__all__ = ["OPW_JOINTS", "PAPER_JOINTS", "Frame", "Motion", "MotionFeatures", "Skeleton"]
