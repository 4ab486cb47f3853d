"""Canonical joint names and how each data source names them.

The FP-DTW paper (Section 4) uses 8 joints for its cost and similarity metric:
both hips, knees, shoulders and elbows. The OPW poster (eq. 5) uses the positions
of 16 joints. Each source names its joints differently; a *joint map* resolves a
canonical name to the first candidate the skeleton actually has.

For rotations, the joint named here is the one whose local rotation moves the
limb: "left_hip" is the thigh joint (ASF ``lfemur``), "left_knee" the shin joint
(``ltibia``), "left_shoulder" the upper arm (``lhumerus``, not the clavicle),
"left_elbow" the forearm (``lradius``). For positions, a joint's position is the
origin of that joint, i.e. the anatomical hip, knee, shoulder, elbow.
"""

from __future__ import annotations

#: The FP-DTW paper's 8 joints (Section 4), in a fixed order.
PAPER_JOINTS = (
    "left_hip",
    "right_hip",
    "left_knee",
    "right_knee",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
)

#: The OPW poster's 16 joints (eq. 5), in the poster's order.
OPW_JOINTS = (
    "head",
    "center_hip",
    "right_hip",
    "left_hip",
    "middle_chest",
    "upper_chest",
    "left_shoulder",
    "right_shoulder",
    "left_elbow",
    "right_elbow",
    "left_wrist",
    "right_wrist",
    "left_knee",
    "right_knee",
    "left_ankle",
    "right_ankle",
)

#: ASF/AMC naming (HDM05, and CMU's BVH exports which keep the ASF bone names).
ASF_NAMES = {
    "center_hip": ("root", "hip"),
    "left_hip": ("lfemur",),
    "right_hip": ("rfemur",),
    "left_knee": ("ltibia",),
    "right_knee": ("rtibia",),
    "left_ankle": ("lfoot",),
    "right_ankle": ("rfoot",),
    "middle_chest": ("upperback",),
    "upper_chest": ("thorax",),
    "head": ("head",),
    "left_shoulder": ("lhumerus",),
    "right_shoulder": ("rhumerus",),
    "left_elbow": ("lradius",),
    "right_elbow": ("rradius",),
    "left_wrist": ("lwrist", "lhand"),
    "right_wrist": ("rwrist", "rhand"),
}

#: Naming of common FBX / MotionBuilder / Mixamo style rigs. The authors' rig
#: (matRandall/Mocap_SinglePersonActions) is covered by the first candidates;
#: see fpdtw.io.fbx for what its skeleton holds.
FBX_NAMES = {
    "center_hip": ("Hips", "Pelvis", "Root"),
    "left_hip": ("LeftUpLeg", "LeftThigh", "LeftHip", "L_Thigh"),
    "right_hip": ("RightUpLeg", "RightThigh", "RightHip", "R_Thigh"),
    "left_knee": ("LeftLeg", "LeftShin", "LeftKnee", "L_Calf"),
    "right_knee": ("RightLeg", "RightShin", "RightKnee", "R_Calf"),
    "left_ankle": ("LeftFoot", "LeftAnkle", "L_Foot"),
    "right_ankle": ("RightFoot", "RightAnkle", "R_Foot"),
    "middle_chest": ("Spine1", "Spine2", "Chest"),
    "upper_chest": ("Spine3", "Spine2", "UpperChest", "Chest"),
    "head": ("Head",),
    "left_shoulder": ("LeftArm", "LeftUpperArm", "LeftShoulder", "L_UpperArm"),
    "right_shoulder": ("RightArm", "RightUpperArm", "RightShoulder", "R_UpperArm"),
    "left_elbow": ("LeftForeArm", "LeftLowerArm", "LeftElbow", "L_Forearm"),
    "right_elbow": ("RightForeArm", "RightLowerArm", "RightElbow", "R_Forearm"),
    "left_wrist": ("LeftHand", "LeftWrist", "L_Hand"),
    "right_wrist": ("RightHand", "RightWrist", "R_Hand"),
}

NAMINGS = {"asf": ASF_NAMES, "bvh": ASF_NAMES, "fbx": FBX_NAMES}


def _strip_namespace(name: str) -> str:
    return name.rsplit(":", 1)[-1]


def resolve_joint_map(joint_names, naming):
    """Map canonical names to the skeleton's own joint names.

    Parameters
    ----------
    joint_names : sequence of str
        The skeleton's joint names (namespaces such as ``"mixamorig:"`` ignored).
    naming : dict of str to tuple of str, or str
        Candidates per canonical name, or a key of :data:`NAMINGS`.

    Returns
    -------
    joint_map : dict of str to str
        Canonical name -> skeleton joint name, for every canonical name found.
    """
    if isinstance(naming, str):
        naming = NAMINGS[naming]
    bare = {}
    for n in joint_names:
        bare.setdefault(_strip_namespace(n).lower(), n)
    out = {}
    for canon, candidates in naming.items():
        for cand in candidates:
            hit = bare.get(cand.lower())
            if hit is not None:
                out[canon] = hit
                break
    return out
