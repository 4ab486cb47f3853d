"""Read FBX motion files (the authors' dataset) into a :class:`~fpdtw.motion.Motion`.

Parsed by ufbx through **pufbx 0.1.0** (vendors ufbx 0.21.2), the one binding that exposes rotation
orders, node properties, keyframes and ufbx's animation baking (pyufbx 0.0.7 exposes none of these;
the tests use it to cross-check the frame rate). Its gaps, worked around: no ``Scene.settings``, so
the frame rate is the keyframe grid's (every joint is keyed at every 1/120 s; tested against
pyufbx's time mode); no link from a curve node to its property, so each joint's ``Lcl Rotation``
curves are the ones whose angles, with the joint's pre/post rotation, reproduce ufbx's own
evaluation (``bake_anim``) at every frame to 1e-6 rad (different curves that tie are an error);
``bake_anim`` leaks about 2 MB per read (read each file once).

Read: the bone nodes depth first from the one bone whose parent is not a bone, with their rotation
order, ``PreRotation`` and inverse ``PostRotation`` (ufbx's ``T * Rpre * R * Rpost^-1``); offsets =
the animated local translation as ufbx evaluates it (in 24 of 48 takes up to 0.28 cm from the static
``Lcl Translation``), the root's zero; frames: the take's range on the key grid (the authors' extra
key at t = 0 is not a frame); angles: the keyed ``Lcl Rotation`` values as stored, in degrees;
lengths in file units. Rejected (MotionFormatError): nodes above the skeleton that move, animated
scaling, several animation layers, spherical rotation orders, rotation curves not keyed at every
frame (unless constant), non-root bones whose translation varies.
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pufbx

from fpdtw import limits
from fpdtw.errors import MotionFormatError
from fpdtw.io._text import check_input_file
from fpdtw.motion.motion import Motion, Skeleton
from fpdtw.motion.rotations import euler_to_quat, quat_conj, quat_mul, quat_normalize, quat_slerp

#: ``ufbx_rotation_order`` values 0..5 as fpdtw order strings (axes in the order applied).
UFBX_ROTATION_ORDERS = ("XYZ", "XZY", "YZX", "YXZ", "ZXY", "ZYX")

#: Largest angle (radians) between a curve's rotation and ufbx's evaluation that
#: still counts as the same rotation when identifying curves.
ROTATION_TOL = 1e-6

#: Relative tolerance for "constant" translations and identity transforms.
TRANSLATION_RTOL = 1e-6

_IDENTITY = np.array([1.0, 0.0, 0.0, 0.0])
_BONE = 5  # ufbx_element_type UFBX_ELEMENT_BONE


def read_fbx(path, *, fps=None, name=None) -> Motion:
    """Read one FBX take (binary or ASCII) as a motion (``source="fbx"``, file units).

    ``fps`` is used only when no curve has two keys (else it must match the grid's); ``name``
    defaults to the file stem. MotionFormatError, naming the file, for a missing, empty, truncated
    or non-FBX file, no animation, no skeleton, or anything the module docstring rejects."""
    p = Path(path)
    if check_input_file(p) == 0:
        raise MotionFormatError(p, "empty file")
    try:
        scene = pufbx.load_fbx(str(p))
    except Exception as exc:  # pufbx.UFBXError and anything else from the C loader
        raise MotionFormatError(p, f"not a readable FBX file ({_msg(exc)})") from None
    try:
        return _read_scene(pufbx, scene, p, fps, name)
    except MotionFormatError:
        raise
    except Exception as exc:  # a binding error on content ufbx accepted
        what = f"{type(exc).__name__}: {_msg(exc)}"
        raise MotionFormatError(p, f"unexpected FBX content ({what})") from exc


def _msg(exc) -> str:
    return str(exc).strip() or type(exc).__name__


def _read_scene(pufbx, scene, p, fps, name) -> Motion:
    nodes, parents, above = _skeleton_nodes(scene, p)
    names = [n.name for n in nodes]
    orders, pre, post = zip(*(_node_rotation_setup(n, p) for n in nodes))
    pre, post = np.array(pre), np.array(post)

    stacks = scene.anim_stacks
    if len(stacks) == 0:
        raise MotionFormatError(p, "no animation (the file has no animation stack)")
    stack = stacks[0]
    layers = stack.layers
    if len(layers) != 1:
        what = "no animation layer" if len(layers) == 0 else f"{len(layers)} animation layers"
        raise MotionFormatError(p, f"{what} in take {stack.name!r}; exactly one is supported")
    values = list(layers[0].anim_values)
    if not values:
        raise MotionFormatError(p, f"no animation curves in take {stack.name!r}")
    curves = [[_keys(c) for c in v.curves] for v in values]
    defaults = [v.default_value.as_array() for v in values]

    fps = _frame_rate(curves, fps, p)
    t0, t1 = float(stack.time_begin), float(stack.time_end)
    if not t1 > t0:  # take range absent: use the keyed range
        times = np.concatenate([k[0] for vc in curves for k in vc if k is not None] or [[0.0]])
        t0, t1 = float(times.min()), float(times.max())
    span = (t1 - t0) * fps
    if not (np.isfinite(t0) and np.isfinite(span)):
        raise MotionFormatError(p, f"take {stack.name!r} has a non-finite time range")
    # bounded before anything of F frames is baked or allocated
    F = limits.check_file_frames(int(round(span)) + 1, p)

    baked = _bake(pufbx, scene, stack, fps, t0, F, p)
    local = {}
    for n in nodes + above:
        local[n.typed_id] = baked.get(n.typed_id) or _static_local(n, F)
        if np.max(np.abs(local[n.typed_id][2] - 1.0)) > TRANSLATION_RTOL:
            raise MotionFormatError(p, f"node {n.name!r} is scaled; scaling is not supported")
    T = np.stack([local[n.typed_id][0] for n in nodes], axis=1)  # (F, J, 3)
    Q = np.stack([local[n.typed_id][1] for n in nodes], axis=1)  # (F, J, 4)
    scale = max(float(np.max(np.linalg.norm(T[0], axis=-1))), 1e-12)
    for n in above:
        t_a, q_a, _ = local[n.typed_id]
        if np.max(np.abs(t_a)) > TRANSLATION_RTOL * scale or np.max(_angle(q_a, _IDENTITY)) > 1e-9:
            raise MotionFormatError(
                p,
                f"node {n.name!r} above the skeleton root {names[0]!r} moves or rotates; "
                "only an identity transform above the skeleton is supported",
            )
    drift = np.max(np.abs(T[:, 1:] - T[:1, 1:]), axis=(0, 2))
    if drift.size and drift.max() > TRANSLATION_RTOL * scale:
        j = int(np.argmax(drift)) + 1
        raise MotionFormatError(
            p,
            f"joint {names[j]!r} has an animated translation (varies by {drift.max():.3g} file "
            "units); fpdtw skeletons have fixed bone offsets",
        )

    sampled = [_sample_value(vc, d, t0, fps, F) for vc, d in zip(curves, defaults)]
    euler = _rotation_curves(nodes, orders, pre, post, Q, values, sampled, p)

    offsets = T[0].copy()
    offsets[0] = 0.0
    skeleton = Skeleton(
        joint_names=tuple(names),
        parents=np.asarray(parents),
        offsets=offsets,
        rotation_orders=tuple(orders),
        pre_rotations=pre,
        post_rotations=post,
        units="",
    )
    return Motion(
        name=name or p.stem,
        fps=fps,
        skeleton=skeleton,
        euler=euler,
        root_translation=T[:, 0].copy(),
        source="fbx",
        path=str(p),
    )


def _skeleton_nodes(scene, p):
    """Bone nodes depth first from the skeleton root, their parents, and the nodes above it."""
    bones = [n for n in scene.nodes if int(n.attrib_type) == _BONE]
    if not bones:
        raise MotionFormatError(p, "no skeleton (the file has no bone / LimbNode nodes)")
    roots = [n for n in bones if n.parent is None or int(n.parent.attrib_type) != _BONE]
    if len(roots) != 1:
        raise MotionFormatError(
            p, f"{len(roots)} separate skeletons ({', '.join(n.name for n in roots)}); one expected"
        )
    nodes, parents = [], []
    stack = [(roots[0], -1)]
    while stack:
        n, parent = stack.pop()
        nodes.append(n)
        parents.append(parent)
        here = len(nodes) - 1
        kids = [c for c in n.children if int(c.attrib_type) == _BONE]
        stack.extend((c, here) for c in reversed(kids))
    if len(nodes) != len(bones):
        raise MotionFormatError(p, "some bones hang below non-bone nodes inside the skeleton")
    if len({n.name for n in nodes}) != len(nodes):
        raise MotionFormatError(p, "two bones share a name")
    above = []
    a = roots[0].parent
    while a is not None and not a.is_root:
        above.append(a)
        a = a.parent
    return nodes, parents, above


def _prop_vec3(node, prop, default):
    """A node's vector property (its own value, else its template default)."""
    props = node.properties
    for source in (props, props.defaults):
        if source is None:
            continue
        for q in source:
            if q.name == prop:
                return np.array(q.value.as_list(), dtype=float)
    return np.array(default, dtype=float)


def _node_rotation_setup(node, p):
    """Rotation order, pre rotation and post rotation (quaternions) of a bone."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pufbx 0.1.0: Cython enum conversion warning
        code = int(node.rotation_order)
    if not 0 <= code < len(UFBX_ROTATION_ORDERS):
        raise MotionFormatError(
            p, f"joint {node.name!r} uses rotation order {code} (spherical); not supported"
        )
    pre = euler_to_quat(_prop_vec3(node, "PreRotation", (0, 0, 0)), "XYZ")
    post = quat_conj(euler_to_quat(_prop_vec3(node, "PostRotation", (0, 0, 0)), "XYZ"))
    return UFBX_ROTATION_ORDERS[code], pre, post


def _keys(curve):
    """(times, values, flat) of a curve; ``flat`` = constant between its keys."""
    if curve is None:
        return None
    k = curve.get_keyframes()
    if len(k) == 0:
        return None
    v = np.asarray(k["value"], dtype=float)
    slopes = np.concatenate([k["left"]["dy"], k["right"]["dy"]])
    flat = len(v) == 1 or bool(np.ptp(v) == 0.0 and not np.any(slopes))
    return np.asarray(k["time"], dtype=float), v, flat


def _frame_rate(curves, fps, p):
    """Frame rate of the keyframe grid, checked against ``fps``."""
    times = [k[0] for vc in curves for k in vc if k is not None and len(k[0]) > 1]
    grid = None
    if times:
        t = np.unique(np.concatenate(times))
        if not np.isfinite(t).all():
            raise MotionFormatError(p, "an animation key has a non-finite time")
        if t.size < 2:
            raise MotionFormatError(p, "animation curves have several keys at one time")
        dt = float(np.min(np.diff(t)))
        steps = (t - t[0]) / dt
        if dt <= 0 or np.max(np.abs(steps - np.rint(steps))) > 1e-3:
            raise MotionFormatError(p, "animation keys are not on a common frame grid")
        grid = 1.0 / dt
        if not np.isfinite(grid):  # keys closer than 1/inf s
            return limits.check_file_fps(grid, p, source=f"animation keys {dt:g} s apart")
        if abs(grid - round(grid)) < 1e-6 * grid:
            grid = float(round(grid))
    if grid is None:
        if fps is None:
            raise MotionFormatError(p, "no curve has two keys, so the frame rate is unknown")
        return limits.check_file_fps(fps, p, source=f"fps={fps}")
    if fps is not None and abs(float(fps) - grid) > 1e-6 * grid:
        raise MotionFormatError(p, f"fps={fps} given, but the file's keys are {grid:g} Hz")
    return limits.check_file_fps(grid, p, source=f"animation keys {1 / grid:g} s apart")


def _on_grid(times, t0, fps, F):
    """Frame index of each time and whether it falls on a frame of the take."""
    x = (np.asarray(times, dtype=float) - t0) * fps
    i = np.rint(x).astype(np.int64)
    return i, (np.abs(x - i) < 1e-3) & (i >= 0) & (i < F)


def _sample_curve(keys, default, t0, fps, F):
    """Values of one curve at the F frames, or None if not keyed at every frame."""
    if keys is None:
        return np.full(F, float(default))
    t, v, flat = keys
    if flat:
        return np.full(F, v[0])
    i, ok = _on_grid(t, t0, fps, F)
    out = np.full(F, np.nan)
    out[i[ok]] = v[ok]
    return None if np.isnan(out).any() else out


def _sample_value(curves3, default, t0, fps, F):
    """Curve node (x, y, z) at the F frames, shape (F, 3), or None."""
    cols = [_sample_curve(k, d, t0, fps, F) for k, d in zip(curves3, default)]
    return None if any(c is None for c in cols) else np.stack(cols, axis=1)


def _bake(pufbx, scene, stack, fps, t0, F, p):
    """ufbx's local (T (F, 3), Q (F, 4) wxyz, S (F, 3)) of every animated node, by typed id."""
    try:
        baked = pufbx.bake_anim(scene, stack.anim, resample_rate=float(fps))
    except Exception as exc:
        raise MotionFormatError(p, f"ufbx could not evaluate the animation ({_msg(exc)})") from None
    out = {}
    for bn in baked.modified_nodes:
        tk, rk, sk = bn.translation_keys, bn.rotation_keys, bn.scale_keys
        T = _fill(tk["time"], np.stack([tk["value"][c] for c in "xyz"], 1), t0, fps, F)
        Q = _fill(rk["time"], np.stack([rk["value"][c] for c in "wxyz"], 1), t0, fps, F, True)
        S = _fill(sk["time"], np.stack([sk["value"][c] for c in "xyz"], 1), t0, fps, F)
        out[bn.typed_id] = (T, quat_normalize(Q), S)
    return out


def _fill(times, vals, t0, fps, F, rotation=False):
    """Baked keys on the F frames; between keys linear (slerp for rotations), as ufbx means."""
    times = np.asarray(times, dtype=float)
    if len(times) == 1:
        return np.repeat(vals[:1], F, axis=0)
    i, ok = _on_grid(times, t0, fps, F)
    out = np.full((F, vals.shape[1]), np.nan)
    out[i[ok]] = vals[ok]
    gap = np.flatnonzero(np.isnan(out[:, 0]))
    if gap.size:
        t = np.clip(t0 + gap / fps, times[0], times[-1])
        i1 = np.clip(np.searchsorted(times, t), 1, len(times) - 1)
        i0 = i1 - 1
        a = (t - times[i0]) / (times[i1] - times[i0])
        if rotation:
            out[gap] = quat_slerp(vals[i0], vals[i1], a)
        else:
            out[gap] = (1 - a)[:, None] * vals[i0] + a[:, None] * vals[i1]
    return out


def _static_local(node, F):
    """Local transform of a node ufbx did not bake (not animated), repeated F times."""
    lt = node.local_transform
    t = np.array(lt.translation.as_list(), dtype=float)
    x, y, z, w = lt.rotation.as_list()
    s = np.array(lt.scale.as_list(), dtype=float)
    return (np.tile(t, (F, 1)), np.tile(quat_normalize([w, x, y, z]), (F, 1)), np.tile(s, (F, 1)))


def _angle(a, b):
    """Rotation angle (radians) between unit quaternions, broadcasting."""
    d = np.abs(np.sum(a * b, axis=-1))
    return 2.0 * np.arccos(np.clip(d, 0.0, 1.0))


def _rotation_curves(nodes, orders, pre, post, Q, values, sampled, p):
    """Euler angles (F, J, 3) of each joint's Lcl Rotation curve node: the one whose angles
    give ufbx's evaluated ``Q[:, j] = pre_j R(angles) post_j`` at every frame."""
    F, J = Q.shape[:2]
    cand = [i for i, s in enumerate(sampled) if s is not None]
    E = np.stack([sampled[i] for i in cand]) if cand else np.zeros((0, F, 3))
    quick = np.unique(np.linspace(0, F - 1, min(F, 9)).astype(np.int64))
    by_order = {o: euler_to_quat(E[:, quick], o) for o in set(orders)}
    euler = np.empty((F, J, 3))
    for j, n in enumerate(nodes):

        def matches(e, j=j):
            q = quat_mul(quat_mul(pre[j], euler_to_quat(e, orders[j])), post[j])
            return bool(np.all(_angle(q, Q[:, j]) < ROTATION_TOL))

        local = quat_mul(quat_mul(pre[j], by_order[orders[j]]), post[j])
        hits = np.flatnonzero(np.all(_angle(local, Q[quick, j]) < ROTATION_TOL, axis=1))
        # curve nodes named "R" (the FBX SDK's name for rotation curve nodes) first
        is_r = [values[cand[k]].name == "R" for k in hits]
        chosen = None
        for group in (
            [k for k, r in zip(hits, is_r) if r],
            [k for k, r in zip(hits, is_r) if not r],
        ):
            for k in group:
                if chosen is not None and np.array_equal(E[k], E[chosen]):
                    continue  # identical values: which one it is does not matter
                if matches(E[k]):
                    if chosen is not None:
                        raise MotionFormatError(
                            p,
                            f"joint {n.name!r}: several different rotation curves match "
                            "ufbx's evaluation of its rotation",
                        )
                    chosen = k
            if chosen is not None:
                break
        if chosen is not None:
            euler[:, j] = E[chosen]
            continue
        static = _prop_vec3(n, "Lcl Rotation", (0, 0, 0))
        if matches(np.broadcast_to(static, (F, 3))):
            euler[:, j] = static  # not animated: the node's own property value
            continue
        raise MotionFormatError(
            p,
            f"cannot find the Lcl Rotation curves of joint {n.name!r}: no curve node keyed "
            "at every frame of the take reproduces ufbx's evaluation of its rotation",
        )
    return euler
