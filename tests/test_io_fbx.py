"""FBX reader (fpdtw.io.fbx) on the authors' 48 takes, cross-checked against ufbx.

Independent references used here:
* pyufbx (a second ufbx binding, run in a subprocess so that its copy of ufbx stays
  separate from pufbx's): frame rate / time mode, unit, take span, and the static
  (file-property) world position of every bone;
* pufbx's node properties and ufbx's baked animation, composed into world positions
  here, at a few frames of every take;
* the file's own layout (curve nodes stored as T, R, S triples in node order), for
  which curve is which joint's Lcl Rotation;
* hand-written ASCII FBX files with hand-computed answers.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
import sys
import textwrap
import warnings

import numpy as np
import pufbx
import pytest

from fpdtw.errors import MotionFormatError
from fpdtw.io.fbx import read_fbx
from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS
from fpdtw.motion.rotations import euler_to_quat, quat_rotate, quat_to_matrix

FBX_DIR = "mocap_single_person_actions/MoCapData"
KTIME = 46186158000  # FBX time ticks per second

#: The 48 takes of the authors' dataset held by the mirror (15 of the 63 are missing).
TAKES = """
    1_Punch_1_Kick_01 1_Punch_1_Kick_02 1_Punch_1_Kick_03 3_Jumps_01 3_Jumps_02_ 3_Jumps_03
    All_Fours_01 All_Fours_02 All_Fours_03 Dance_01 Dance_02 Dance_03 Highchair_Movement_01
    Highchair_Movement_02 Highchair_Movement_03 Highchair_Sit_Walk_01 Highchair_Sit_Walk_02
    Highchair_Sit_Walk_03 Highchair_Walk_Sit_01 Highchair_Walk_Sit_02 Highchair_Walk_Sit_03
    Long_Jump_01 Long_Jump_02 Long_Jump_03 Low_Chair_Movements_01 Low_Chair_Movements_02
    Low_Chair_Movements_03 One_Hand_Pickup_01 One_Hand_Pickup_02 One_Hand_Pickup_03
    Shelf_Stack_01 Shelf_Stack_02 Shelf_Stack_03 Sit_Walk_01 Sit_Walk_02 Sit_Walk_03 Twirls_02
    Twirls_03 Twirls_04 Two_Handed_Pickup_01 Two_Handed_Pickup_02 Two_Handed_Pickup_03 Walk_01
    Walk_02 Walk_03 Walk_Sit_01 Walk_Sit_02 Walk_Sit_03
""".split()


# ----------------------------------------------------------------- fixtures
@pytest.fixture(scope="module")
def fbx_files(data_path):
    assert len(set(TAKES)) == 48
    return [data_path(f"{FBX_DIR}/{t}.fbx") for t in TAKES]


@pytest.fixture(scope="module")
def motions(fbx_files):
    return {p.name: read_fbx(p) for p in fbx_files}


_PROBE = textwrap.dedent(
    """
    import json, sys
    import ufbx  # pyufbx
    out = {}
    for f in sys.argv[1:]:
        with ufbx.load_file(f) as s:
            st = s.anim_stacks[0]
            world = {n.name: [float(x) for x in n.world_transform[3, :3]]
                     for n in s.nodes if n.bone is not None}
            out[f] = dict(fps=s.settings.frames_per_second, time_mode=int(s.settings.time_mode),
                          unit_meters=s.settings.unit_meters, t0=st.time_begin, t1=st.time_end,
                          world=world)
    print(json.dumps(out))
    """
)


@pytest.fixture(scope="module")
def pyufbx_ref(fbx_files):
    """What pyufbx reads from every take (separate process, separate ufbx copy)."""
    res = subprocess.run(
        [sys.executable, "-c", _PROBE, *map(str, fbx_files)],
        capture_output=True,
        text=True,
        check=True,
        timeout=300,
    )
    data = json.loads(res.stdout)
    return {p.name: data[str(p)] for p in fbx_files}


# ------------------------------------------------------------- the 48 takes
def test_every_take_loads(motions, pyufbx_ref):
    for fname, m in motions.items():
        ref = pyufbx_ref[fname]
        assert m.source == "fbx" and m.name == fname[:-4]
        assert m.fps == 120.0 == ref["fps"]
        assert ref["time_mode"] == 1  # UFBX_TIME_MODE_120_FPS
        assert ref["unit_meters"] == pytest.approx(0.01)  # centimetres
        # independent count: the take span read by pyufbx, sampled at its frame rate
        assert m.n_frames == round((ref["t1"] - ref["t0"]) * ref["fps"]) + 1 > 300
        assert m.skeleton.n_joints == 33
        assert np.isfinite(m.euler).all() and np.isfinite(m.root_translation).all()
        assert np.allclose(np.linalg.norm(m.quats, axis=-1), 1.0, atol=1e-12)
        assert m.joint_indices(PAPER_JOINTS).shape == (8,)
        assert m.joint_indices(OPW_JOINTS).shape == (16,)


def test_same_rig_in_every_take(motions):
    first = motions["Walk_01.fbx"].skeleton
    for m in motions.values():
        assert m.skeleton.same_topology(first)
        assert m.skeleton.rotation_orders == first.rotation_orders
        assert np.allclose(m.skeleton.pre_rotations, first.pre_rotations, atol=1e-12)


def test_rig_and_joint_map(motions):
    m = motions["Walk_01.fbx"]
    sk = m.skeleton
    assert sk.joint_names[0] == "Hips"
    assert m.joint_map == {
        "center_hip": "Hips",
        "left_hip": "LeftUpLeg",
        "right_hip": "RightUpLeg",
        "left_knee": "LeftLeg",
        "right_knee": "RightLeg",
        "left_ankle": "LeftFoot",
        "right_ankle": "RightFoot",
        "middle_chest": "Spine1",
        "upper_chest": "Spine3",
        "head": "Head",
        "left_shoulder": "LeftArm",
        "right_shoulder": "RightArm",
        "left_elbow": "LeftForeArm",
        "right_elbow": "RightForeArm",
        "left_wrist": "LeftHand",
        "right_wrist": "RightHand",
    }
    parent = {n: sk.joint_names[p] for n, p in zip(sk.joint_names, sk.parents) if p >= 0}
    assert parent["LeftUpLeg"] == "Hips" and parent["LeftLeg"] == "LeftUpLeg"
    assert parent["LeftArm"] == "LeftShoulder" and parent["LeftForeArm"] == "LeftArm"
    order = dict(zip(sk.joint_names, sk.rotation_orders))
    assert order["LeftShoulder"] == order["RightShoulder"] == "ZYX"
    assert order["LeftForeArm"] == order["RightForeArm"] == "YZX"
    assert order["LeftArm"] == order["LeftUpLeg"] == order["LeftLeg"] == "XYZ"
    # PreRotation read from the file: Spine has (-10, 0, 0) degrees (Euler XYZ)
    pre_spine = sk.pre_rotations[sk.index("Spine")]
    assert np.allclose(pre_spine, euler_to_quat([-10.000004285756797, 0, 0]), atol=1e-12)
    assert m.skeleton.offsets[0].tolist() == [0.0, 0.0, 0.0]


def test_degrees_of_freedom_match_the_paper(motions):
    """Paper: hips and shoulders 3 DOF, knees 1 DOF, elbows 2 DOF."""
    for m in motions.values():
        e = m.eulers(PAPER_JOINTS)  # (F, 8, 3) in order hips, knees, shoulders, elbows
        knees, elbows = e[:, 2:4], e[:, 6:8]
        assert np.abs(knees[..., 1:]).max() < 1e-9  # knee: only x (order XYZ)
        assert np.abs(elbows[..., 2]).max() < 1e-9  # elbow: x and y (order YZX), z fixed
    allm = np.concatenate([m.eulers(PAPER_JOINTS) for m in motions.values()])
    spread = np.ptp(allm, axis=0)  # (8, 3)
    assert (spread[[0, 1, 4, 5]] > 20).all()  # hips and shoulders move about all 3 axes
    assert (spread[2:4, 0] > 90).all() and (spread[6:8, :2] > 60).all()


def test_rotation_curves_are_the_files_own(fbx_files, motions):
    """Each joint's angles are the keys of its R curve node (association by file layout).

    In these files ufbx lists the curve nodes as (T, R, S) triples in node order; the
    reader finds them by value instead, so this is an independent check. Frame 0 of the
    curves (t = 0, a copy of frame 1) lies outside the take and is not a frame.
    """
    for path in fbx_files:
        m = motions[path.name]
        scene = pufbx.load_fbx(str(path))
        vals = list(scene.anim_stacks[0].layers[0].anim_values)
        nodes = sorted((n for n in scene.nodes if not n.is_root), key=lambda n: n.element_id)
        assert "".join(v.name for v in vals) == "TRS" * len(nodes)
        for i, n in enumerate(nodes):
            if n.name not in m.skeleton.joint_names:
                continue
            keys = [c.get_keyframes() for c in vals[3 * i + 1].curves]
            assert all(len(k) == m.n_frames + 1 for k in keys)
            assert all(k["value"][0] == k["value"][1] for k in keys)
            e = np.stack([k["value"][1:] for k in keys], axis=1)
            assert np.array_equal(m.euler[:, m.skeleton.index(n.name)], e), n.name
            if n.name == "Hips":
                t = np.stack(
                    [k["value"][1:] for k in (c.get_keyframes() for c in vals[3 * i].curves)], 1
                )
                assert np.array_equal(m.root_translation, t)


def test_hips_keeps_angles_beyond_180(motions):
    hips = np.concatenate([m.euler[:, 0] for m in motions.values()])
    assert np.abs(hips).max() > 179.0  # the animator's wrapped values, as stored


# ------------------------------------------------------ kinematic invariants
def test_bone_lengths_constant(motions):
    for m in motions.values():
        pos, _ = m.forward_kinematics()
        sk = m.skeleton
        lengths = np.linalg.norm(pos[:, 1:] - pos[:, sk.parents[1:]], axis=-1)  # (F, J-1)
        expect = np.linalg.norm(sk.offsets[1:], axis=-1)
        assert np.allclose(lengths, expect, rtol=1e-6, atol=1e-9)
        assert expect.max() > 20  # centimetres: the thigh is tens of cm


def test_quaternions_match_euler_per_joint(motions):
    m = motions["Dance_01.fbx"]
    for j, order in enumerate(m.skeleton.rotation_orders):
        assert np.allclose(m.quats[:, j], euler_to_quat(m.euler[:, j], order), atol=1e-12)
    # the convention by hand: order "ZYX" applies Z first, R = Rx @ Ry @ Rz
    j = m.skeleton.index("LeftShoulder")
    x, y, z = np.deg2rad(m.euler[10, j])
    Rx = np.array([[1, 0, 0], [0, np.cos(x), -np.sin(x)], [0, np.sin(x), np.cos(x)]])
    Ry = np.array([[np.cos(y), 0, np.sin(y)], [0, 1, 0], [-np.sin(y), 0, np.cos(y)]])
    Rz = np.array([[np.cos(z), -np.sin(z), 0], [np.sin(z), np.cos(z), 0], [0, 0, 1]])
    assert np.allclose(quat_to_matrix(m.quats[10, j]), Rx @ Ry @ Rz, atol=1e-12)


def _world_from_props(path, m):
    """FK positions of the file's static pose (node property values), shape (J, 3).

    The static pose is the rig's stored pose, with its own ``Lcl Translation`` values:
    in 24 of the 48 takes these differ (by up to 0.28 cm) from the animated, constant
    bone translations that the motion uses.
    """
    scene = pufbx.load_fbx(str(path))
    props = {}
    for n in scene.nodes:
        props[n.name] = {q.name: q.value for q in n.properties}
    euler = np.array([props[n]["Lcl Rotation"].as_list() for n in m.joint_names])
    trans = np.array([props[n]["Lcl Translation"].as_list() for n in m.joint_names])
    offsets = trans.copy()
    offsets[0] = 0.0
    skeleton = dataclasses.replace(m.skeleton, offsets=offsets)
    static = m.replace(skeleton=skeleton, euler=euler[None], root_translation=trans[:1], quats=None)
    return static.forward_kinematics()[0][0]


def test_static_pose_matches_pyufbx_world_positions(fbx_files, motions, pyufbx_ref):
    """Pre/post rotations and rotation orders reproduce ufbx's node world transforms."""
    for path in fbx_files:
        m = motions[path.name]
        pos = _world_from_props(path, m)
        ref = np.array([pyufbx_ref[path.name]["world"][n] for n in m.joint_names])
        assert np.abs(pos - ref).max() < 1e-6  # cm; the skeleton stands ~160 cm tall


def test_bone_offsets_shared_by_the_takes_of_a_movement(motions):
    """Two sets of bone lengths occur (two calibrations); the 3 takes of a movement share one."""
    by_movement = {}
    for fname, m in motions.items():
        by_movement.setdefault(fname.rsplit("_", 1)[0].rstrip("_0123456789"), []).append(m)
    assert len(by_movement) == 16
    variants = []
    for takes in by_movement.values():
        assert len(takes) == 3
        for m in takes[1:]:
            assert np.array_equal(m.skeleton.offsets, takes[0].skeleton.offsets)
        if not any(np.array_equal(takes[0].skeleton.offsets, v) for v in variants):
            variants.append(takes[0].skeleton.offsets)
    assert len(variants) == 2
    assert 0 < np.abs(variants[0] - variants[1]).max() < 0.5  # centimetres


def _baked_world(scene, times, names):
    """World positions (len(times), len(names), 3) composed from ufbx's baked locals."""
    baked = pufbx.bake_anim(scene, scene.anim_stacks[0].anim, resample_rate=120.0)
    local = {}
    for bn in baked.modified_nodes:
        loc = []
        for t in times:
            parts = []
            for keys, cols in (
                (bn.translation_keys, "xyz"),
                (bn.rotation_keys, "wxyz"),
                (bn.scale_keys, "xyz"),
            ):
                k = np.flatnonzero(np.abs(keys["time"] - t) < 1e-6)
                row = keys["value"][k[0] if len(k) else 0]  # constant channels: one key
                parts.append(np.array([row[c] for c in cols]))
            loc.append(parts)
        local[scene.nodes[bn.typed_id].name] = loc
    out = np.empty((len(times), len(names), 3))
    for i in range(len(times)):
        for j, name in enumerate(names):
            node = scene.find_node(name)
            chain = []
            while node is not None and not node.is_root:
                chain.append(node.name)
                node = node.parent
            p = np.zeros(3)
            for a in chain:  # from the node up to the scene root: p <- T + R (S p)
                t, q, s = local[a][i]
                p = t + quat_rotate(q, s * p)
            out[i, j] = p
    return out


def test_fk_matches_ufbx_evaluation(fbx_files, motions):
    """Our FK equals ufbx's own evaluation of the animation at a few frames."""
    for path in fbx_files:
        m = motions[path.name]
        frames = [0, m.n_frames // 3, m.n_frames - 1]
        times = [(1 + k) / 120.0 for k in frames]  # the take starts at frame 1 (t = 1/120)
        scene = pufbx.load_fbx(str(path))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ref = _baked_world(scene, times, m.joint_names)
        pos, _ = m.forward_kinematics()
        assert np.abs(pos[frames] - ref).max() < 1e-6, path.name  # cm


# ------------------------------------------------------- hand-written files
def _ascii_fbx(joints, frames=None, keys=None, bone=True, layers=1, root_scale=None):
    """A minimal ASCII FBX 7.4 file (120 Hz, take = frames 1..frames).

    joints: dicts with name, parent (None for the root), t (offset), optional order
    (ufbx rotation order code), pre (PreRotation), rot (static Lcl Rotation), euler
    (F, 3) and trans (F, 3) curves, keys (frame indices with keys, default: ``keys``,
    which defaults to all frames).
    """
    objs, conns, ids = [], [], {}

    def vec(v):
        return ",".join(repr(float(x)) for x in v)

    for i, j in enumerate(joints):
        nid = 1000 + 10 * i
        ids[j["name"]] = nid
        kind = "LimbNode" if bone else "Null"
        props = [f'P: "Lcl Translation", "Lcl Translation", "", "A",{vec(j["t"])}']
        if "order" in j:
            props.append(f'P: "RotationOrder", "enum", "", "",{j["order"]}')
        if "pre" in j:
            props.append(f'P: "PreRotation", "Vector3D", "Vector", "",{vec(j["pre"])}')
        if "rot" in j:
            props.append(f'P: "Lcl Rotation", "Lcl Rotation", "", "A",{vec(j["rot"])}')
        if root_scale is not None and j["parent"] is None:
            props.append(f'P: "Lcl Scaling", "Lcl Scaling", "", "A",{vec([root_scale] * 3)}')
        body = "".join(f"\t\t\t{x}\n" for x in props)
        objs.append(
            f'Model: {nid}, "Model::{j["name"]}", "{kind}" {{\n\t\tVersion: 232\n'
            f"\t\tProperties70:  {{\n{body}\t\t}}\n\t}}"
        )
        objs.append(f'NodeAttribute: {nid + 1}, "NodeAttribute::{j["name"]}", "{kind}" {{\n\t}}')
        conns.append(f'C: "OO",{nid + 1},{nid}')
        conns.append(f'C: "OO",{nid},{ids[j["parent"]] if j["parent"] else 0}')
    if frames:
        keys = list(range(frames)) if keys is None else keys
        start, stop = KTIME // 120, frames * KTIME // 120
        objs.append(
            'AnimationStack: 900, "AnimStack::Take 001", "" {\n\t\tProperties70:  {\n'
            f'\t\t\tP: "LocalStart", "KTime", "Time", "",{start}\n'
            f'\t\t\tP: "LocalStop", "KTime", "Time", "",{stop}\n\t\t}}\n\t}}'
        )
        for L in range(layers):
            objs.append(f'AnimationLayer: {901 + L}, "AnimLayer::Layer{L}", "" {{\n\t}}')
            conns.append(f'C: "OO",{901 + L},900')
        cid = 5000
        for j in joints:
            for prop, field, short in (
                ("Lcl Rotation", "euler", "R"),
                ("Lcl Translation", "trans", "T"),
            ):
                if field not in j:
                    continue
                jk = j.get("keys", keys)
                kt = [(1 + k) * KTIME // 120 for k in jk]
                v = np.asarray(j[field], dtype=float)[jk]
                cid += 10
                objs.append(f'AnimationCurveNode: {cid}, "AnimCurveNode::{short}", "" {{\n\t}}')
                conns.append(f'C: "OO",{cid},901')
                conns.append(f'C: "OP",{cid},{ids[j["name"]]}, "{prop}"')
                for a in range(3):
                    objs.append(
                        f'AnimationCurve: {cid + 1 + a}, "AnimCurve::", "" {{\n\t\tKeyVer: 4009\n'
                        f"\t\tKeyTime: *{len(kt)} {{\n\t\t\ta: {','.join(map(str, kt))}\n\t\t}}\n"
                        f"\t\tKeyValueFloat: *{len(kt)} {{\n\t\t\ta: {vec(v[:, a])}\n\t\t}}\n"
                        "\t\tKeyAttrFlags: *1 {\n\t\t\ta: 260\n\t\t}\n"
                        "\t\tKeyAttrDataFloat: *4 {\n\t\t\ta: 0,0,0,0\n\t\t}\n"
                        f"\t\tKeyAttrRefCount: *1 {{\n\t\t\ta: {len(kt)}\n\t\t}}\n\t}}"
                    )
                    conns.append(f'C: "OP",{cid + 1 + a},{cid}, "d|{"XYZ"[a]}"')
    return (
        "; FBX 7.4.0 project file\n"
        "FBXHeaderExtension:  {\n\tFBXHeaderVersion: 1003\n\tFBXVersion: 7400\n}\n"
        "Objects:  {\n" + "".join(f"\t{o}\n" for o in objs) + "}\n"
        "Connections:  {\n" + "".join(f"\t{c}\n" for c in conns) + "}\n"
    )


EULER = np.array([[0, 0, 90], [10, 20, 30], [200, -190, 45.5], [360, 0, -720]], dtype=float)
TRANS = np.array([[0, 90, 0], [1, 90, 0], [2, 91, 0], [3, 92, 1]], dtype=float)


def _three_joints(**root):
    return [
        dict(name="Hips", parent=None, t=(0, 0, 0), euler=EULER, trans=TRANS, **root),
        dict(
            name="LeftUpLeg",
            parent="Hips",
            t=(0, 10, 0),
            order=5,
            pre=(0, 0, 90),
            euler=EULER[::-1],
        ),
        dict(name="LeftLeg", parent="LeftUpLeg", t=(0, -40, 0), rot=(5, 0, 0)),
    ]


def _sparse_leg():
    joints = _three_joints()
    joints[1]["keys"] = [0, 3]  # keys on frames 0 and 3 only, values changing between
    return joints


def test_known_answer_file(tmp_path):
    path = tmp_path / "three.fbx"
    path.write_text(_ascii_fbx(_three_joints(), frames=4))
    m = read_fbx(path, name="tiny")
    assert m.name == "tiny" and m.fps == 120.0 and m.n_frames == 4
    assert m.joint_names == ("Hips", "LeftUpLeg", "LeftLeg")
    assert m.skeleton.parents.tolist() == [-1, 0, 1]
    assert m.skeleton.rotation_orders == ("XYZ", "ZYX", "XYZ")
    assert m.skeleton.offsets.tolist() == [[0, 0, 0], [0, 10, 0], [0, -40, 0]]
    # angles exactly as keyed, including 200, -190, 360 and -720 degrees
    assert np.array_equal(m.euler[:, 0], EULER)
    assert np.array_equal(m.euler[:, 1], EULER[::-1])
    assert np.array_equal(m.euler[:, 2], np.tile([5.0, 0, 0], (4, 1)))  # static property
    assert np.array_equal(m.root_translation, TRANS)
    pos, _ = m.forward_kinematics()
    # frame 0: Hips at (0, 90, 0) turned 90 deg about z, so the child offset (0, 10, 0)
    # points along -x; LeftUpLeg's pre rotation (90 about z) and its angles (360, 0, -720)
    # = identity add another 90: the shin (0, -40, 0) turned 180 about z points up.
    assert np.allclose(pos[0], [[0, 90, 0], [-10, 90, 0], [-10, 130, 0]], atol=1e-9)
    # frame 3: Hips angles (360, 0, -720) = identity, at (3, 92, 1)
    assert np.allclose(pos[3, :2], [[3, 92, 1], [3, 102, 1]], atol=1e-9)


def test_fps_argument(tmp_path):
    path = tmp_path / "static.fbx"
    joints = [dict(name="Hips", parent=None, t=(0, 0, 0), euler=EULER, trans=TRANS)]
    path.write_text(_ascii_fbx(joints, frames=4, keys=[0]))  # one key: no frame grid
    with pytest.raises(MotionFormatError, match=r"static\.fbx.*frame rate"):
        read_fbx(path)
    m = read_fbx(path, fps=120)
    assert m.n_frames == 4 and m.fps == 120.0
    assert np.array_equal(m.euler[:, 0], np.tile(EULER[0], (4, 1)))
    keyed = tmp_path / "keyed.fbx"
    keyed.write_text(_ascii_fbx(joints, frames=4))
    assert read_fbx(keyed, fps=120.0).fps == 120.0
    with pytest.raises(MotionFormatError, match=r"keyed\.fbx.*fps=30"):
        read_fbx(keyed, fps=30)


# ------------------------------------------------------------- bad inputs
@pytest.fixture(scope="module")
def walk_bytes(data_path):
    return data_path(f"{FBX_DIR}/Walk_01.fbx").read_bytes()


@pytest.mark.parametrize(
    "fname, content, reason",
    [
        ("missing.fbx", None, "no such file"),
        ("empty.fbx", b"", "empty file"),
        ("garbage.fbx", bytes(range(256)) * 20, "not a readable FBX"),
        ("text.fbx", b"hello, not an FBX file\n", "not a readable FBX"),
        ("half.fbx", "half", "not a readable FBX"),
    ],
)
def test_unreadable_files(tmp_path, walk_bytes, fname, content, reason):
    path = tmp_path / fname
    if content == "half":
        content = walk_bytes[: len(walk_bytes) // 2]
    if content is not None:
        path.write_bytes(content)
    with pytest.raises(MotionFormatError, match=reason) as err:
        read_fbx(path)
    assert fname in str(err.value) and err.value.path == str(path)


@pytest.mark.parametrize(
    "kwargs, reason",
    [
        (dict(joints=_three_joints(), frames=None), "no animation"),
        (dict(joints=_three_joints(), frames=4, bone=False), "no skeleton"),
        (dict(joints=_three_joints(), frames=4, layers=2), "2 animation layers"),
        (dict(joints=_three_joints(), frames=4, root_scale=2.0), "'Hips' is scaled"),
        (dict(joints=_sparse_leg(), frames=4), "Lcl Rotation curves of joint 'LeftUpLeg'"),
    ],
    ids=["no-animation", "no-skeleton", "two-layers", "scaled", "sparse-keys"],
)
def test_unsupported_content(tmp_path, kwargs, reason):
    path = tmp_path / "bad.fbx"
    path.write_text(_ascii_fbx(**kwargs))
    with pytest.raises(MotionFormatError, match=reason) as err:
        read_fbx(path)
    assert "bad.fbx" in str(err.value)


def test_animated_bone_translation_rejected(tmp_path):
    joints = _three_joints()
    joints[1]["trans"] = TRANS  # LeftUpLeg slides
    path = tmp_path / "slide.fbx"
    path.write_text(_ascii_fbx(joints, frames=4))
    with pytest.raises(
        MotionFormatError, match=r"slide\.fbx.*'LeftUpLeg' has an animated translation"
    ):
        read_fbx(path)


def test_moving_node_above_skeleton_rejected(tmp_path):
    joints = [dict(name="char1", parent=None, t=(0, 0, 0), trans=TRANS)] + _three_joints()
    joints[1]["parent"] = "char1"
    text = _ascii_fbx(joints, frames=4)
    # char1 is a plain Null, not a bone
    text = text.replace('"Model::char1", "LimbNode"', '"Model::char1", "Null"').replace(
        '"NodeAttribute::char1", "LimbNode"', '"NodeAttribute::char1", "Null"'
    )
    path = tmp_path / "above.fbx"
    path.write_text(text)
    with pytest.raises(MotionFormatError, match=r"above\.fbx.*'char1' above the skeleton root"):
        read_fbx(path)
