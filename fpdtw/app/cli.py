"""The ``fpdtw`` command line: align two motion files, replay one live, manage the data.

::

    fpdtw align INPUT TARGET --method c --window 40 --out map.csv [--export-bvh aligned.bvh]
    fpdtw live  INPUT TARGET --method c --window 40 [--fast] [--animate side_by_side.gif]
    fpdtw serve INPUT --method c --window 40 --listen 127.0.0.1:7447 [--send osc.udp://...]
    fpdtw serve INPUT --source axis://HOST:7001 --header SKELETON.bvh [--once] [--out MAP.csv]
    fpdtw stream TAKE --to 127.0.0.1:7447 [--rate HZ] [--drop P] [--jitter-ms J] [--seed S]
    fpdtw stream TAKE [TAKE ...] --as axis [--listen 127.0.0.1:7001] [--fast]
    fpdtw serve INPUT --source vmc://0.0.0.0:39539 [--rate 60] [--once] [--out MAP.csv]
    fpdtw stream TAKE [TAKE ...] --as vmc [--to 127.0.0.1:39539] [--fast]
    fpdtw serve INPUT --source xsens://0.0.0.0:9763 [--rate 60] [--once] [--out MAP.csv]
    fpdtw stream TAKE [TAKE ...] --as xsens [--to 127.0.0.1:9763] [--fast]
    fpdtw serve INPUT --source axis+udp://0.0.0.0:7002 --header SKELETON.bvh [--once]
    fpdtw stream TAKE [TAKE ...] --as axis+udp [--to 127.0.0.1:7002] [--displacement] [--fast]
    fpdtw serve INPUT --source rokoko://0.0.0.0:14043 [--rate 60] [--once] [--out MAP.csv]
    fpdtw stream TAKE [TAKE ...] --as rokoko [--to 127.0.0.1:14043] [--fast]
    fpdtw serve INPUT --source natnet://MOTIVE_HOST:1510 [--rate 120] [--once] [--out MAP.csv]
    fpdtw stream TAKE [TAKE ...] --as natnet [--to 127.0.0.1:1510] [--fast]
    fpdtw data  fetch|verify|cite
    fpdtw experiments run [--smoke] [--results DIR] [--jobs N] [--scheduler ADDRESS]

Until the ``fpdtw`` script is installed, run ``python -m fpdtw.app.cli ...``.

Exit codes: 0 success; 2 bad usage (unknown option or method, ``--window 0``, an option
that does not apply to the method, ``--fps`` outside the plausible range, a window whose
matrices would pass the memory limit); 1 a problem with the data (missing, unreadable or
malformed file, a directory given as a file, skeletons without the joints the method
compares, a motion too short or too long for the limits of :mod:`fpdtw.limits`, an output
file that cannot be written, unavailable output format). Every error is one line,
``fpdtw: error: <file>: <what>``, naming the file(s) it is about; ``--debug`` shows the
full traceback instead.
"""

from __future__ import annotations

import argparse
import errno
import sys
import textwrap
from pathlib import Path

from fpdtw import registry
from fpdtw.app.argtypes import frame_number, positive_int

PROG = "fpdtw"

#: Methods by command-line name (from the registry, :data:`fpdtw.registry.ENTRIES`).
METHODS = {e.cli: e.about for e in registry.ENTRIES}
OFFLINE = tuple(e.cli for e in registry.ENTRIES if not e.online)
#: Default --window of the methods that take one (Methods B and C: the paper's 40).
WINDOW_DEFAULTS = {e.cli: e.default or 40 for e in registry.ENTRIES if e.param}
CONSTRAINED = tuple(e.cli for e in registry.ENTRIES if e.typev)

_DESCRIPTION = """\
Time a recorded motion (INPUT) to another performance of the same movement (TARGET).

The result is a MAP: for every frame of the TARGET, the frame of the INPUT to show at
that moment, so that a character animated with the INPUT moves in step with the TARGET.
Online methods compute each map entry from the target frames seen so far, as they would
for a live actor; offline ones see the whole target."""

_MOTION_HELP = """\
motion files: FBX (.fbx), Acclaim ASF/AMC (.amc; the .asf skeleton is found next to it
or in a parent folder, e.g. HDM_bd.asf for HDM_bd_..._120.amc, or given with
--skeleton / --target-skeleton) and BVH (.bvh), in any mix, in any Euler rotation order.

any format, any rig: the two motions may come from different capture systems. Both
need the 8 joints the FP-DTW cost compares (both hips, knees, shoulders and elbows;
OPW: 16 joints), found by a joint map: built in for the authors' FBX rig, Mixamo,
HDM05/CMU ASF/AMC and CMU BVH (ASF or MotionBuilder joint names); for another rig,
--joint-map FILE, a CSV 'joint,name' (our joint -> the rig's name; joints: center_hip,
left_hip, right_hip, left_knee, right_knee, left_ankle, right_ankle, middle_chest,
upper_chest, head, left_shoulder, right_shoulder, left_elbow, right_elbow, left_wrist,
right_wrist). Two motions of the same rig are compared by their local joint rotations,
as in the paper. Motions of different rigs (formats, rest orientations, joint names,
sizes) are compared by each joint's rotation away from its rig's REST POSE in
world-aligned axes: the same movement then gives the same map whatever the rig. The
rest pose is each rig's own by default: zero rotations (BVH: its offsets; ASF: its axis
frames; FBX: its pre/post rotations, the T-pose of the authors' rig). Limits: the two
rest poses must have the same shape and orientation (both T-poses, the same up axis
and facing); when they differ (an A-pose against a T-pose), give a frame of each motion
in which the performer stands in the same pose, --input-rest-frame K and
--target-rest-frame K. OPW compares joint positions: bodies whose sizes differ by more
than a factor 1.5 (different length units: cm, inches, m) are rescaled to the input's.

frame rates: if the two motions have different frame rates, the TARGET is resampled to
the INPUT's rate; --fps F resamples both to F Hz (rotations by slerp). Frame numbers in
the map refer to the resampled motions; times in seconds refer to the originals too.

limits (defaults of fpdtw.limits, each changed by its environment variable): frame
rates 1-10000 Hz (FPDTW_MIN_FPS, FPDTW_MAX_FPS), at most 1,000,000 frames per motion
(FPDTW_MAX_FRAMES), at least 2, and at most 2 GiB for the matrices of a method
(FPDTW_MAX_MATRIX_BYTES): dtw keeps two input x target matrices (two takes of about 96 s
at 120 Hz), oe-dtw one; the online methods a, b, c, oltw need memory proportional to
their window, not to the takes' length."""

_MAP_HELP = """\
map CSV (--out), one row per target frame, columns:
  target_frame   target frame number q
  target_time_s  q / target frame rate
  input_frame    M[q], the input frame shown at target frame q
  input_time_s   M[q] / input frame rate
  step_us        microseconds the online method took for this frame (empty for dtw, utw;
                 measured after an untimed warm-up over the first frames)
input_frame never decreases, except with --relocate: a jump back (a repeat, a restart) makes
it smaller than the row before."""

#: ``fpdtw live`` scores its map in ms against offline DTW's up to this many cells.
LIVE_DTW_CELLS = 25_000_000
#: ``fpdtw serve --listen`` by default: this machine only.
DEFAULT_LISTEN = "127.0.0.1:7447"

_SERVE_HELP = """\
protocol (one TCP connection = one take, text lines):
  client -> server  the take's BVH header, HIERARCHY through 'Frame Time:' (a 'Frames:'
                    count is ignored), then one BVH motion line per captured frame,
                    optionally 't=<capture time s> ' first (else the arrival time counts)
  server -> client  one answer per motion line, before the next is read:
                      <frame index> <input frame> <input time s> <latency us>
                    frame index: the target frame on the INPUT's frame rate (the row of
                    'fpdtw align INPUT TAKE's map); input frame: the INPUT frame to show
                    (with --relocate it may go back: a jump to a repeat or a restart;
                    --send carries it as it is)
                    error: line <n>, frame <k>: <what>  (then the connection is closed)

dropped frames and rates: a gap of more than 1.5 frame periods between two frames is a
drop; its frames are filled (--gap: slerp between the frames around it, or the frame before
held) and keep their own indices. A target at another frame rate is resampled online to
the INPUT's rate (slerp between the two latest frames; at most one target period of delay).

limits (fpdtw.limits, each changed by its environment variable): a line 256 KiB
(FPDTW_MAX_LINE_BYTES), a header 1 MiB (FPDTW_MAX_HEADER_BYTES), 10,000 channels
(FPDTW_MAX_CHANNELS), a gap 10 s (FPDTW_MAX_GAP_S), 1,000,000 frames per take
(FPDTW_MAX_FRAMES); SIGINT or SIGTERM stop the server cleanly.

--source axis://HOST:PORT (a capture system's own stream instead; docs/live.md):
  fpdtw connects to Axis Neuron / Axis Studio's BVH string broadcast (Axis is the TCP
  server, port 7001 by default) and reads frames '<avatar index> <avatar name> v1 ... vN ||';
  the skeleton and rate come from --header FILE.bvh (same joints; with or without
  displacement, told apart by the value count). Each avatar index is a performer with its
  own aligner; --send adds '<avatar index> <avatar name>' to every answer. A take ends when
  Axis closes the connection; then fpdtw connects again (--once: exits). Unusable frames (a
  wrong value count, not a number, NaN/inf, cut, over 256 KiB without '||') are dropped,
  counted and reported; a dropped frame is a gap filled by --gap. --out MAP.csv writes each
  performer's map as MAP-take<T>-<avatar index>-<avatar name>.csv.

--source vmc://HOST:PORT: fpdtw listens for the VMC protocol (OSC over UDP, port 39539 by
  default): /VMC/Ext/Bone/Pos (Unity HumanBodyBones, local position and quaternion, left-
  handed Y-up), /VMC/Ext/Root/Pos, a frame ended by /VMC/Ext/T (its time). Each sender
  address is a performer (index in order of arrival, named HOST:PORT); its skeleton is the
  bones of its first frame. A take ends after --idle-timeout s of silence. Datagrams that are
  not OSC or over 32 KiB, bones that are not the skeleton's, NaN/inf, quaternions that are not
  rotations, duplicated and reordered frames and a flood are dropped and counted.

--source xsens://HOST:PORT: fpdtw listens for Xsens MVN's network streamer (UDP, port 9763 by
  default), type 02 ('MXTP02': each segment's global position and quaternion, Z up); other
  types are skipped. A sample is the datagrams of one sample counter (split ones joined); each
  character ID is a performer; its skeleton is the 23 body segments of its first complete
  sample; sample s counts at s / --rate. A take ends after --idle-timeout s of silence. Lost
  parts, duplicated and reordered datagrams, wrong ID strings or sizes, unknown segments,
  NaN/inf, quaternions that are not rotations and a flood are dropped and counted.

--source axis+udp://HOST:PORT: fpdtw listens for Axis' binary BVH broadcast (UDP, port 7002
  by default): a 64-byte header (0xDDFF, data count, with displacement, with reference, avatar
  index and name, frame index, 0xEEFF), then float32 values; the skeleton and rate come from
  --header FILE.bvh, as for axis://. Each avatar index is a performer; frame index f counts at
  f / rate. A take ends after --idle-timeout s of silence. Wrong tokens, sizes or value counts,
  duplicated and reordered frames, NaN/inf and a flood are dropped and counted.


--source rokoko://HOST:PORT: fpdtw listens for Rokoko Studio's custom streaming (JSON v3 over
  UDP, port 14043 by default; uncompressed: LZ4-compressed datagrams are counted, not read):
  each actor's body bones, world position and quaternion in Studio's Y-up left-handed axes.
  Each actor name is a performer; its skeleton is its first complete frame, Studio's T-pose
  the rest pose; frames are timed by scene.timestamp. A take ends after --idle-timeout s of
  silence. Datagrams that are not JSON v3 or over 64 KiB or nested too deep, unknown bones,
  NaN/inf, quaternions that are not rotations, duplicated and reordered frames and a flood
  are dropped and counted.


--source natnet://HOST:PORT: fpdtw is a NatNet 4.1 unicast client of OptiTrack Motive (3.1):
  PORT is Motive's command port (1510 by default). From a socket of its own it asks for the
  data descriptions (NAT_MODELDEF: each skeleton's bones, parents and offsets) and receives
  the frames (NAT_FRAMEOFDATA); set Motive to Unicast with skeletons in Local coordinates.
  Each skeleton ID is a performer; frame f counts at f / --rate (default 120). Packets that
  are not NatNet 4.1's or whose sizes disagree, unknown skeletons or bones, NaN/inf,
  quaternions that are not rotations, duplicated and reordered frames and a flood are dropped
  and counted."""

_METHODS_HELP = "methods:\n" + "\n".join(f"  {k:<7} {v}" for k, v in METHODS.items())


def _fill(text: str) -> str:
    return textwrap.fill(text, 88)


class UsageError(Exception):
    """A command-line combination argparse cannot check by itself (exit code 2)."""


class _Parser(argparse.ArgumentParser):
    """argparse with our program name in every sub-command's messages."""


def _frame_rate(text):
    from fpdtw import limits

    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {text!r}") from None
    if not v > 0 or v == float("inf"):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text!r}")
    try:
        why = limits.fps_problem(v)
    except ValueError as e:  # a malformed FPDTW_MIN_FPS / FPDTW_MAX_FPS
        raise argparse.ArgumentTypeError(str(e)) from None
    if why is not None:
        raise argparse.ArgumentTypeError(why)
    return v


def _number(text, what, lo, hi, lo_open=False):
    try:
        v = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}") from None
    if not (lo < v if lo_open else lo <= v) or not v < hi:
        raise argparse.ArgumentTypeError(f"must be {what}, got {text!r}")
    return v


def _seconds(text):
    return _number(text, "a number of seconds > 0 (below 1e6)", 0.0, 1e6, lo_open=True)


def _probability(text):
    return _number(text, "a probability in [0, 1)", 0.0, 1.0)


def _milliseconds(text):
    return _number(text, "a number of milliseconds >= 0 (below 1e6)", 0.0, 1e6)


def _add_pair_arguments(p, *, live: bool):
    p.add_argument("input", metavar="INPUT", help="the recorded motion to retime (.fbx/.amc/.bvh)")
    p.add_argument(
        "target",
        metavar="TARGET",
        help="the performance to follow" + (", replayed as if captured live" if live else ""),
    )
    _add_method_arguments(p, live=live)
    p.add_argument(
        "--fps",
        type=_frame_rate,
        metavar="F",
        help="resample both motions to F Hz first (1-10000 Hz, see limits below)",
    )
    p.add_argument("--skeleton", metavar="ASF", help="skeleton (.asf) of an .amc INPUT")
    p.add_argument("--target-skeleton", metavar="ASF", help="skeleton (.asf) of an .amc TARGET")
    _add_rig_arguments(p)
    p.add_argument(
        "--target-rest-frame",
        type=frame_number,
        metavar="K",
        help="take frame K of TARGET (in its own frame rate) as its rest pose (default: its "
        "rig's own rest pose)",
    )
    p.add_argument("--debug", action="store_true", help="show the traceback of an error")


def _world_axes(text):
    """``--up``/``--facing``: AXIS (both motions) or INPUT_AXIS,TARGET_AXIS; AXIS is x, -x,
    y, -y, z or -z."""
    from fpdtw.motion.rig import AXIS_NAMES

    names = [n.strip().lower() for n in text.split(",")]
    names = [n if n[:1] in "+-" else "+" + n for n in names]
    if len(names) > 2 or any(n not in AXIS_NAMES for n in names):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not an axis (x, -x, y, -y, z, -z) or two of them, INPUT,TARGET"
        )
    return tuple(AXIS_NAMES[n] for n in names * (3 - len(names)))[:2]


def _add_rig_arguments(p):
    """--joint-map, --input-rest-frame, --up and --facing."""
    p.add_argument(
        "--joint-map",
        action="append",
        default=[],
        metavar="FILE",
        help="joint map CSV 'joint,name' for a rig the built-in maps do not know; used for "
        "every motion whose skeleton has all its names (may be given several times)",
    )
    p.add_argument(
        "--input-rest-frame",
        type=frame_number,
        metavar="K",
        help="take frame K of INPUT (in its own frame rate) as its rest pose (default: its "
        "rig's own rest pose, zero rotations)",
    )
    for opt, what in (("--up", "up"), ("--facing", "the way the body faces")):
        p.add_argument(
            opt,
            type=_world_axes,
            metavar="AXIS[,AXIS]",
            help=f"the world axis that is {what} at rest, for both motions or INPUT,TARGET "
            "(x, -x, y, -y, z, -z; default: found from the rest pose, docs/align.md)",
        )


def _add_method_arguments(p, *, live: bool = True):
    """--method, --window, --constraint (online methods default to c)."""
    p.add_argument(
        "--method",
        "-m",
        choices=list(METHODS),
        default="c" if live else None,
        required=not live,
        metavar="METHOD",
        help="alignment method: " + ", ".join(METHODS) + (" (default c)" if live else ""),
    )
    p.add_argument(
        "--window",
        "-w",
        type=positive_int,
        metavar="W",
        help="window of methods a (default 2), b and c (default 40, the paper used 10, 20, "
        "40, 80), or OLTW's search width c in frames (default 120)",
    )
    p.add_argument(
        "--constraint",
        choices=["typeV"],
        help="restrict methods a, b, c to the paper's Type V local constraint",
    )
    p.add_argument(
        "--relocate",
        action="store_true",
        help="online methods: search the whole input beside the method and jump there when "
        "the performer skips, repeats or restarts (beyond the papers; the map may then go "
        "backwards)",
    )


def _command_group(sub, name: str, help: str, description: str, add_commands: str):
    """A command with ACTIONs (``fpdtw data fetch``, ``fpdtw experiments run``): the
    actions are added by ``add_commands`` ("module:function", imported only here, so that
    ``fpdtw align`` does not load the paper layer's modules until it is built)."""
    import importlib

    g = sub.add_parser(
        name,
        help=help,
        description=_fill(description),
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    actions = g.add_subparsers(dest=f"{name}_command", metavar="ACTION", parser_class=_Parser)
    actions.required = True
    module, _, function = add_commands.partition(":")
    getattr(importlib.import_module(module), function)(actions)
    return g


def build_parser() -> argparse.ArgumentParser:
    """The argument parser of the ``fpdtw`` command (align, live, serve, stream, data,
    experiments)."""
    fmt = argparse.RawDescriptionHelpFormatter
    ap = _Parser(
        prog=PROG,
        description=_DESCRIPTION,
        formatter_class=fmt,
        epilog=textwrap.dedent(
            """\
            examples:
              fpdtw align Walk_01.fbx Walk_02.fbx --method c --window 40 --out map.csv
              fpdtw align a.amc b.amc --method dtw --out map.csv --export-bvh a_aligned.bvh
              fpdtw live Walk_01.fbx Walk_02.fbx --method c --window 40 --animate walk.gif
              fpdtw serve Walk_01.fbx --method c --window 40 --send osc.udp://127.0.0.1:9000
              fpdtw stream Walk_02.bvh --to 127.0.0.1:7447 --drop 0.05
              fpdtw data cite
              fpdtw experiments run --smoke

            run "fpdtw COMMAND --help" for the options of a command."""
        ),
    )
    sub = ap.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    sub.required = True
    epilog = f"{_METHODS_HELP}\n\n{_MOTION_HELP}\n\n{_MAP_HELP}"

    a = sub.add_parser(
        "align",
        help="align INPUT to TARGET, write the map (and the retimed INPUT as BVH)",
        description=_fill(
            "Align INPUT (recorded) to TARGET and write the map as CSV; optionally "
            "write INPUT retimed by the map as a BVH file (opens in Blender)."
        ),
        formatter_class=fmt,
        epilog=epilog
        + "\n\nexample:\n  fpdtw align Walk_01.fbx Walk_02.fbx -m c -w 40 --out map.csv "
        "--export-bvh Walk_01_aligned.bvh",
    )
    _add_pair_arguments(a, live=False)
    a.add_argument("--out", "-o", required=True, metavar="MAP.csv", help="map CSV to write")
    a.add_argument(
        "--export-bvh",
        metavar="ALIGNED.bvh",
        help="also write INPUT retimed by the map (frame q = input frame M[q]; the "
        "TARGET's frame count and rate) as BVH",
    )
    a.add_argument(
        "--view",
        metavar="VIEW.html",
        help="also write a page that plays TARGET and the aligned INPUT with a time slider, "
        "the map and each joint's cost (one HTML file; opens offline)",
    )

    lv = sub.add_parser(
        "live",
        help="replay TARGET at its own frame rate as if captured, align it online, report "
        "the time per frame (and draw both skeletons side by side)",
        description=_fill(
            "Replay TARGET at its own frame rate as if it were being captured, feed "
            "it frame by frame to an online method, and report the time each frame took against "
            "the frame budget (1/fps) and the frames answered too late (DROPPED: the answer "
            "came after the next frame was due)."
        ),
        formatter_class=fmt,
        epilog=epilog
        + "\n\nexample:\n  fpdtw live Walk_01.fbx Walk_02.fbx -m c -w 40 --animate walk.gif",
    )
    _add_pair_arguments(lv, live=True)
    lv.add_argument(
        "--fast",
        "--no-realtime",
        dest="fast",
        action="store_true",
        help="do not wait for each frame's due time: run as fast as possible and compute "
        "the dropped frames on the simulated real-time schedule",
    )
    lv.add_argument("--out", "-o", metavar="MAP.csv", help="also write the map CSV")
    lv.add_argument(
        "--animate",
        metavar="OUT.gif|OUT.mp4",
        help="draw TARGET (left) and the aligned INPUT (right) as stick figures; .mp4 needs ffmpeg",
    )
    lv.add_argument(
        "--stride",
        type=positive_int,
        metavar="K",
        help="animation: draw every K-th target frame (default: about 20 per second)",
    )
    lv.add_argument(
        "--view",
        metavar="VIEW.html",
        help="also write a page that plays TARGET and the aligned INPUT with a time slider, "
        "the map and each joint's cost (one HTML file; opens offline)",
    )

    sv = sub.add_parser(
        "serve",
        help="align takes streamed over TCP (BVH header, then one motion line per frame) "
        "to INPUT, answering each frame at once",
        description=_fill(
            "Listen for live takes over TCP and align each, frame by frame, to the recorded "
            "INPUT with an online method. A client sends a BVH header (HIERARCHY through "
            "'Frame Time:') and then one BVH motion line per captured frame, optionally "
            "beginning with t=<capture time in s>; the server answers each line at once."
        ),
        formatter_class=fmt,
        epilog=f"{_SERVE_HELP}\n\n{_METHODS_HELP}\n\nexample:\n  fpdtw serve Walk_01.fbx -m c "
        "-w 40 --listen 127.0.0.1:7447 --send osc.udp://127.0.0.1:9000",
    )
    sv.add_argument("input", metavar="INPUT", help="the recorded motion (.fbx/.amc/.bvh)")
    _add_method_arguments(sv)
    sv.add_argument("--skeleton", metavar="ASF", help="skeleton (.asf) of an .amc INPUT")
    _add_rig_arguments(sv)
    sv.add_argument(
        "--listen",
        metavar="HOST:PORT",
        help=f"address to listen on (default {DEFAULT_LISTEN}: this machine only; "
        "0.0.0.0:PORT for every interface; port 0: any free port)",
    )
    sv.add_argument(
        "--max-clients",
        type=positive_int,
        default=8,
        metavar="N",
        help="takes aligned at once (default 8); one more gets an error line and is closed",
    )
    sv.add_argument(
        "--idle-timeout",
        type=_seconds,
        default=10.0,
        metavar="S",
        help="close a client silent for S seconds, with an error line (default 10)",
    )
    sv.add_argument(
        "--gap",
        choices=["slerp", "hold"],
        default="slerp",
        help="frames lost in a gap: interpolated by slerp between the frames around it "
        "(default) or the frame before it held",
    )
    sv.add_argument(
        "--view",
        nargs="?",
        const="127.0.0.1:7448",
        metavar="HOST:PORT",
        help="serve a page (default 127.0.0.1:7448) that shows each performer and the "
        "recorded take played by the map, the lag, the map and each joint's cost, as frames "
        "arrive; its address is printed",
    )
    sv.add_argument(
        "--send",
        action="append",
        default=[],
        metavar="URL",
        help="also send every answer to osc.udp://HOST:PORT (OSC message /fpdtw/frame) or "
        "udp://HOST:PORT (a text line); may be given several times",
    )
    sv.add_argument(
        "--source",
        metavar="URL",
        help="read takes from a capture system's own stream instead of listening: "
        "axis://HOST:PORT (Axis Neuron / Axis Studio BVH string broadcast, port 7001), "
        "vmc://HOST:PORT (listen for the VMC protocol, OSC over UDP, port 39539), "
        "xsens://HOST:PORT (listen for Xsens MVN's network streamer, UDP, port 9763), "
        "axis+udp://HOST:PORT (listen for Axis' binary BVH broadcast, UDP, port 7002), "
        "rokoko://HOST:PORT (listen for Rokoko Studio's custom streaming, JSON v3, UDP, "
        "port 14043), "
        "natnet://HOST:PORT (OptiTrack Motive's NatNet 4.1, unicast; its command port, 1510)",
    )
    sv.add_argument(
        "--header",
        metavar="SKELETON.bvh",
        help="--source axis|axis+udp: a BVH file of the streamed skeleton (its Frame Time is the "
        "stream's rate; its motion lines are ignored)",
    )
    sv.add_argument(
        "--rate",
        type=_frame_rate,
        metavar="HZ",
        help="--source vmc|xsens|rokoko|natnet: the senders' frame rate (default 60; rokoko: "
        "the stream's fps; natnet 120): the period a lost frame is measured in; VMC frames are "
        "timed by their /VMC/Ext/T, MVN samples by their sample counter, NatNet frames by their "
        "frame number",
    )
    sv.add_argument("--once", action="store_true", help="--source: exit after the first take")
    sv.add_argument(
        "--out",
        "-o",
        metavar="MAP.csv",
        help="--source: write each performer's map as MAP-take<T>-<index>-<name>.csv",
    )
    sv.add_argument("--debug", action="store_true", help="show the traceback of an error")

    st = sub.add_parser(
        "stream",
        help="play TAKE to a server as if it were being captured; print the latency",
        description=_fill(
            "Play TAKE to an 'fpdtw serve' server as a live capture: its BVH header, then one "
            "motion line per frame at its frame rate (or --rate), each with its capture time "
            "(t=), with simulated dropped frames and jitter; print the round-trip latency "
            "percentiles of the answers."
        ),
        formatter_class=fmt,
        epilog="example:\n  fpdtw stream Walk_02.bvh --to 127.0.0.1:7447 --drop 0.05 --seed 1",
    )
    st.add_argument("take", metavar="TAKE", nargs="+", help="the take to play (.bvh sent "
                    "verbatim; .fbx/.amc sent as BVH); with --as axis, one per avatar")  # fmt: skip
    st.add_argument("--to", metavar="HOST:PORT", help="the server (fpdtw's own protocol)")
    st.add_argument(
        "--as",
        dest="as_system",
        choices=list(_SYSTEMS),
        help="play TAKE as that capture system sends it: axis, as Axis Neuron's BVH string "
        "broadcast (a TCP server on --listen; avatars 0, 1, ... interleaved); vmc, as VMC "
        "protocol senders (OSC bundles over UDP to --to, default 127.0.0.1:39539; one sender "
        "per TAKE); xsens, as MVN's network streamer (MXTP02 datagrams over UDP to --to, "
        "default 127.0.0.1:9763; one character ID per TAKE); axis+udp, as Axis' binary BVH "
        "broadcast (datagrams over UDP to --to, default 127.0.0.1:7002; avatars 0, 1, ...); "
        "rokoko, as Rokoko Studio's "
        "custom streaming (JSON v3 datagrams over UDP to --to, default 127.0.0.1:14043; one "
        "actor per TAKE); "
        "natnet, as Motive's NatNet 4.1 "
        "unicast server (answers the client that asks on --to, default 127.0.0.1:1510, then "
        "streams to it; one skeleton per TAKE)",
    )
    st.add_argument(
        "--listen",
        metavar="HOST:PORT",
        help="--as axis: where to serve (default 127.0.0.1:7001; port 0: any free one)",
    )
    st.add_argument(
        "--displacement",
        action="store_true",
        help="--as axis|axis+udp: send every joint's position too (Axis' 'with displacement')",
    )
    st.add_argument(
        "--rate",
        type=_frame_rate,
        metavar="HZ",
        help="capture rate: send TAKE resampled to HZ (default: its own rate)",
    )
    st.add_argument(
        "--drop",
        type=_probability,
        default=0.0,
        metavar="P",
        help="drop each frame but the first with probability P (seeded)",
    )
    st.add_argument(
        "--jitter-ms",
        type=_milliseconds,
        default=0.0,
        metavar="J",
        help="send each line up to J ms late (uniform, seeded; t= stays the capture time)",
    )
    st.add_argument("--seed", type=int, default=0, metavar="S", help="seed of --drop and "
                    "--jitter-ms (default 0)")  # fmt: skip
    st.add_argument(
        "--streams",
        type=positive_int,
        default=1,
        metavar="N",
        help="play TAKE N times at once, one connection each (seeds S, S+1, ...); the "
        "latency is pooled",
    )
    st.add_argument(
        "--fast",
        action="store_true",
        help="send each line as soon as the previous answer is back (no pacing)",
    )
    st.add_argument(
        "--no-timestamps",
        action="store_true",
        help="send no t= (the server then times frames by their arrival)",
    )
    st.add_argument("--skeleton", metavar="ASF", help="skeleton (.asf) of an .amc TAKE")
    st.add_argument("--out", "-o", metavar="ANSWERS.csv", help="also write every answer as CSV")
    st.add_argument("--debug", action="store_true", help="show the traceback of an error")

    d = _command_group(
        sub,
        "data",
        "fetch, verify or cite the datasets the papers used",
        "The datasets listed in data_manifest/ (authors' FBX takes, HDM05, CMU): "
        "fetch them into the verified cache, re-check the cache, or print licences and "
        "citations. Set FPDTW_MIRROR to a folder or URL holding a copy to fetch offline.",
        "fpdtw.app.commands:add_data_commands",
    )
    e = _command_group(
        sub,
        "experiments",
        "run the papers' experiment grid (every pair, every algorithm), on this "
        "machine or on a Dask cluster",
        "The experiment grid behind the figures and tables: every ordered pair of takes "
        "of a movement, every algorithm, resumably, in worker processes here or as tasks "
        "on a Dask cluster (--scheduler). The notebook 05_run_experiments runs the same.",
        "fpdtw.app.commands:add_experiments_commands",
    )
    ap.commands = {
        "align": a, "live": lv, "serve": sv, "stream": st, "data": d, "experiments": e
    }  # fmt: skip
    return ap


# -- helpers ------------------------------------------------------------------------------


def _check_options(args):
    """Checks argparse cannot express; raise UsageError."""
    if args.command == "stream":
        return _check_stream_options(args)
    m = args.method
    if args.window is not None and m not in WINDOW_DEFAULTS:
        raise UsageError(f"--window does not apply to method {m!r} (only to a, b, c, oltw)")
    if m == "oltw" and args.window is not None and args.window < 2:
        raise UsageError("--window (OLTW's search width c) must be at least 2")
    if args.constraint and m not in CONSTRAINED:
        raise UsageError(f"--constraint applies to methods a, b, c, not {m!r}")
    if m == "c" and args.window is not None and args.window < 2:
        raise UsageError(
            "--window of method c must be at least 2 (with w = 1 its window is one input "
            "frame and the map stops moving)"
        )
    _check_window_size(m, args.window)
    pairs = [("--skeleton", args.input, args.skeleton)]
    if args.command != "serve":
        pairs.append(("--target-skeleton", args.target, args.target_skeleton))
    for opt, path, given in pairs:
        if given and Path(path).suffix.lower() != ".amc":
            raise UsageError(f"{opt} applies to an .amc motion, not {path}")
    if args.command in ("live", "serve") and m in OFFLINE:
        raise UsageError(f"{m!r} is offline (it needs the whole target); {args.command} needs "
                         "an online method: oe-dtw, a, b, c, opw, oltw")  # fmt: skip
    if getattr(args, "relocate", False) and m in OFFLINE:
        raise UsageError(f"--relocate: {m!r} is offline; --relocate wraps an online method")
    if args.command == "live" and args.stride is not None and not args.animate:
        raise UsageError("--stride applies only with --animate")
    if args.command == "serve":
        from fpdtw.app.serve import _Sender, parse_address
        from fpdtw.app.sources import parse_source

        try:
            parse_address(args.listen or DEFAULT_LISTEN)
            for url in args.send:
                _Sender(url).close()
            if args.source:
                parse_source(args.source)
        except (ValueError, OSError) as e:
            raise UsageError(f"{e}") from None
        _check_source_options(args)


def _check_source_options(args):
    """--source and the options that go with it."""
    if not args.source:
        for opt, given in (("--header", args.header), ("--once", args.once), ("--out", args.out),
                           ("--rate", args.rate)):  # fmt: skip
            if given:
                raise UsageError(f"{opt} applies only with --source")
        return
    if args.listen:
        raise UsageError("--listen does not apply with --source: fpdtw connects to the source")
    if args.source.startswith(("axis://", "axis+udp://")) and not args.header:
        raise UsageError(f"--source {args.source.split(':')[0]}:// needs --header SKELETON.bvh "
                         "(the stream carries no skeleton)")  # fmt: skip
    vmc = args.source.startswith(("vmc://", "xsens://", "rokoko://", "natnet://"))
    if vmc and args.header:
        raise UsageError(f"--header does not apply with --source {args.source.split(':')[0]}://"
                         ": the skeleton comes from the bones sent")  # fmt: skip
    if args.rate and not vmc:
        raise UsageError("--rate applies only with --source vmc://, xsens://, rokoko:// or "
                         "natnet://")  # fmt: skip


#: ``fpdtw stream --as``: the systems played (as ``fpdtw.app.sources.SOURCES``).
_SYSTEMS = ("axis", "axis+udp", "vmc", "xsens", "rokoko", "natnet")
#: ``fpdtw stream --as SYSTEM``'s default --to.
_AS_DEFAULT_TO = {"vmc": "127.0.0.1:39539", "xsens": "127.0.0.1:9763", "rokoko": "127.0.0.1:14043",
                  "axis+udp": "127.0.0.1:7002", "natnet": "127.0.0.1:1510"}  # fmt: skip


def _check_stream_options(args):
    from fpdtw.app.serve import parse_address

    if args.skeleton and Path(args.take[0]).suffix.lower() != ".amc":
        raise UsageError(f"--skeleton applies to an .amc motion, not {args.take[0]}")
    if args.as_system in ("vmc", "xsens", "axis+udp", "rokoko", "natnet"):
        disp = args.displacement and args.as_system != "axis+udp"
        given = [o for o, v in (("--listen", args.listen), ("--displacement", disp),
                 ("--drop", args.drop), ("--jitter-ms", args.jitter_ms), ("--streams",
                 args.streams != 1), ("--no-timestamps", args.no_timestamps), ("--out",
                 args.out)) if v]  # fmt: skip
        if given:
            raise UsageError(f"{given[0]} does not apply with --as {args.as_system}")
        default = _AS_DEFAULT_TO[args.as_system]
        try:
            if parse_address(args.to or default)[1] == 0:
                raise ValueError("port 0 is not a receiver's port")
        except ValueError as e:
            raise UsageError(f"--to: {e}") from None
        return
    if args.as_system:
        given = [o for o, v in (("--to", args.to), ("--drop", args.drop), ("--jitter-ms",
                 args.jitter_ms), ("--streams", args.streams != 1), ("--no-timestamps",
                 args.no_timestamps), ("--out", args.out)) if v]  # fmt: skip
        if given:
            raise UsageError(f"{given[0]} does not apply with --as {args.as_system}")
        try:
            parse_address(args.listen or "127.0.0.1:0")
        except ValueError as e:
            raise UsageError(f"--listen: {e}") from None
        return
    systems = "|".join(_SYSTEMS)
    if args.listen:
        raise UsageError("--listen applies only with --as axis")
    if args.displacement:
        raise UsageError("--displacement applies only with --as axis|axis+udp")
    if len(args.take) > 1:
        raise UsageError(f"several TAKEs (one per performer) apply only with --as {systems}")
    if args.to is None:
        raise UsageError(f"--to HOST:PORT is required (or --as {systems})")
    try:
        host, port = parse_address(args.to)
    except ValueError as e:
        raise UsageError(f"--to: {e}") from None
    if port == 0:
        raise UsageError("--to: port 0 is not a server's port")
    if args.fast and args.jitter_ms:
        raise UsageError("--jitter-ms needs real-time pacing: leave out --fast")


def _check_window_size(method, window):
    """A window whose matrices would pass fpdtw.limits.MAX_MATRIX_BYTES is a UsageError."""
    from fpdtw import limits
    from fpdtw.errors import LimitError

    if window is None or method not in WINDOW_DEFAULTS:
        return
    if method == "oltw":
        nbytes, what = limits.band_bytes(window), f"OLTW's c x c band ({window} x {window})"
    else:
        nbytes, what = limits.window_bytes(window), f"two {window + 1} x {window + 1} windows"
    try:
        limits.check_bytes(nbytes, None, f"--window {window} needs {what}", "use a smaller one")
    except LimitError as e:
        raise UsageError(str(e)) from None


def _check_output(path, option):
    """An output file can be written: not a folder, in a folder that exists (OSError)."""
    p = Path(path)
    if p.is_dir():
        raise OSError(errno.EISDIR, f"is a directory; {option} needs a file name", str(p))
    if not p.parent.is_dir():
        raise OSError(errno.ENOENT, f"cannot write it: no folder {p.parent}", str(p))


def _stage(args, *paths):
    """Say which file(s) the next step is about: an error then names them."""
    args.about = tuple(str(Path(p)) for p in paths if p)


def _joint_maps(args) -> list:
    """The --joint-map files, read (MotionFormatError naming a bad one)."""
    from fpdtw.motion.joints import read_joint_map

    maps = []
    for path in args.joint_map:
        _stage(args, path)
        maps.append(read_joint_map(path))
    return maps


def _load(args, path, skeleton):
    from fpdtw.io import load_motion

    maps = _joint_maps(args)
    _stage(args, path)
    kwargs = {"skeleton": skeleton} if skeleton else {}
    motion = load_motion(path, **kwargs)
    return motion.with_joint_map(*maps) if maps else motion


def _same_rate(a: float, b: float) -> bool:
    return abs(a - b) <= 1e-9 * max(a, b)


def _resample(args, motion, path, fps, log, role, to):
    """``motion`` at ``fps`` Hz (LimitError naming ``path`` if too long or too short)."""
    if _same_rate(motion.fps, fps):
        return motion
    _stage(args, path)
    log(f"resampling the {role} {motion.name} from {motion.fps:g} Hz to {to}")
    return motion.resample(fps)


def _prepare(args, log):
    """Load both motions, bring them to one frame rate, check lengths and joints.

    Returns the two motions and their rig transforms (:mod:`fpdtw.motion.rig`; taken on
    the motions as read, before resampling, with the rest frames asked for)."""
    from fpdtw import limits

    I = _load(args, args.input, args.skeleton)
    T = _load(args, args.target, args.target_skeleton)
    rigs = []
    for mo, path, rest in (
        (I, args.input, args.input_rest_frame),
        (T, args.target, args.target_rest_frame),
    ):
        _stage(args, path)
        _check_joints(args, mo, path)
        rigs.append(_rig(mo, rest, args, len(rigs)))
    if args.fps is not None:
        I = _resample(args, I, args.input, args.fps, log, "input", f"{args.fps:g} Hz")
        T = _resample(args, T, args.target, args.fps, log, "target", f"{args.fps:g} Hz")
    else:
        T = _resample(args, T, args.target, I.fps, log, "target", f"the input's {I.fps:g} Hz")
    for mo, path, role in ((I, args.input, "input"), (T, args.target, "target")):
        _stage(args, path)
        limits.check_min_frames(mo.n_frames, path, role)
    _check_sizes(args, I.n_frames, T.n_frames)
    _stage(args, args.input, args.target)
    return I, T, rigs


def _rig(motion, rest_frame, args, role=0):
    """The rig transform of the input (``role`` 0) or the target (1), with --up/--facing."""
    from fpdtw.motion.rig import rig_transform

    up, facing = (None if a is None else a[role] for a in (args.up, args.facing))
    return rig_transform(motion, rest_frame=rest_frame, up=up, facing=facing)


def _check_joints(args, mo, path):
    """The motion has the joints the method compares (MotionFormatError naming ``path``,
    the joints missing and the joints it has)."""
    from fpdtw.errors import MotionFormatError
    from fpdtw.motion.joints import OPW_JOINTS, PAPER_JOINTS

    joints = OPW_JOINTS if args.method == "opw" else PAPER_JOINTS
    what = "the 16 OPW joints" if args.method == "opw" else "the 8 joints FP-DTW compares"
    try:
        mo.require_joints(joints, what)
    except MotionFormatError as e:
        raise MotionFormatError(path, e.reason) from None


def _check_sizes(args, input_frames, target_frames):
    """The matrices of an offline or OE-DTW alignment fit the limits (LimitError)."""
    from fpdtw import limits

    files = (str(Path(args.input)), str(Path(args.target)))
    if args.method == "dtw":
        from fpdtw.dtw import check_dtw_size

        check_dtw_size(input_frames, target_frames, files)
    elif args.method == "oe-dtw":
        from fpdtw.online.oedtw import OEDTW

        limits.check_bytes(
            OEDTW.column_bytes(input_frames, target_frames),
            files,
            f"OE-DTW keeps every accumulated column: {target_frames} target x {input_frames} "
            "input frames of float64",
            limits.HINT_LONG,
        )


def _features(motion, method, rig=None):
    from fpdtw.motion.features import MotionFeatures
    from fpdtw.motion.joints import OPW_JOINTS

    return MotionFeatures.from_motion(
        motion, position_joints=OPW_JOINTS if method == "opw" else None, rig=rig
    )


def _pair_features(I, T, rigs, method, log):
    """The features of both motions (fpdtw.motion.features.pair_features): each with its
    rig, the target's positions (OPW) in the input's units when the two bodies' sizes say
    their units differ."""
    from fpdtw.motion.features import pair_features
    from fpdtw.motion.joints import OPW_JOINTS

    FI, FT = pair_features(I, T, position_joints=OPW_JOINTS if method == "opw" else None,
                           rigs=rigs)  # fmt: skip
    if not FI.rig.same_as(FT.rig):
        log("the two motions' rigs differ: comparing each joint's rotation away from its "
            "rig's rest pose, in its body's axes (up, facing)")  # fmt: skip
    if FT.body_size is not None:
        from fpdtw.motion.rig import body_size

        ratio = FT.body_size / body_size(T)
        if ratio != 1.0:
            log(f"the target's body is {1 / ratio:.3g} times the input's: its positions are "
                "rescaled to the input's size (different length units)")  # fmt: skip
    return FI, FT


def _algorithm_name(args) -> str:
    """The registry name of the method and options on the command line ("Mc w40 + Type V")."""
    entry = registry.by_cli(args.method)
    value = args.window or WINDOW_DEFAULTS.get(args.method)
    if entry.typev:
        name = registry.name(entry.key, value, bool(args.constraint))
    else:
        name = registry.name(entry.key, value if entry.param else None)
    if getattr(args, "relocate", False):  # online only (checked with the other options)
        name = registry.with_option(name, registry.RELOCATE)
    return name


def _factory(args):
    """``factory(I_features) -> OnlineAligner`` for an online method."""
    algorithm = registry.resolve(_algorithm_name(args))
    return algorithm.make


def _describe(mo) -> str:
    return f"{mo.name} ({mo.n_frames} frames at {mo.fps:g} Hz)"


# -- commands -----------------------------------------------------------------------------


def _cmd_align(args, log) -> int:
    import numpy as np

    from fpdtw.app.export import export_bvh, write_map_csv

    _check_output(args.out, "--out")
    if args.export_bvh:
        _check_output(args.export_bvh, "--export-bvh")
    if args.view:
        _check_output(args.view, "--view")
    I, T, rigs = _prepare(args, log)
    FI, FT = _pair_features(I, T, rigs, args.method, log)
    seconds = None
    if args.method in OFFLINE:
        M, _ = registry.align(_algorithm_name(args), FI, FT)
    else:
        from fpdtw.app.live import warm_up
        from fpdtw.online.base import run_online

        aligner = _factory(args)(FI)
        warm_up(aligner, FT)  # compile / load the numba kernels outside the timed run
        M, seconds = run_online(aligner, FT)
    M = np.asarray(M, dtype=np.int64)
    _stage(args, args.out)
    write_map_csv(args.out, M, T.fps, I.fps, seconds)
    print(f"aligned target {_describe(T)} to input {_describe(I)} with {_algorithm_name(args)}")
    print(f"map: {args.out} ({M.size} rows)")
    if seconds is not None:
        print(
            f"time per target frame: median {np.median(seconds) * 1e6:.1f} us, "
            f"max {seconds.max() * 1e6:.1f} us (budget {1e6 / T.fps:.0f} us)"
        )
    if args.export_bvh:
        _stage(args, args.export_bvh)
        export_bvh(I, M, T.fps, args.export_bvh)
        print(
            f"aligned input: {args.export_bvh} ({M.size} frames at {T.fps:g} Hz; frame q = "
            "input frame M[q])"
        )
    if args.view:
        _write_view(args, I, T, M, FI, FT)
    return 0


def _write_view(args, I, T, M, FI, FT) -> None:
    """``--view FILE.html``: the pair played by the map, in one page (fpdtw.app.view)."""
    from fpdtw.app.view import export_html, take_payload

    _stage(args, args.view)
    title = f"{_describe(T)} and {_describe(I)}, {_algorithm_name(args)}"
    payload = take_payload(I, T, M, FI, FT, title=title, name=Path(str(args.target)).name)
    print(f"view: {export_html(payload, args.view)} (open it in a browser)")


def _cmd_live(args, log) -> int:
    from fpdtw.app.export import write_map_csv
    from fpdtw.app.live import replay

    if args.out:
        _check_output(args.out, "--out")
    if args.view:
        _check_output(args.view, "--view")
    if args.animate:
        from fpdtw.app.animate import check_writer

        _check_output(args.animate, "--animate")
        check_writer(args.animate)  # fail before the replay, not after
    I, T, rigs = _prepare(args, log)
    FI, FT = _pair_features(I, T, rigs, args.method, log)
    mode = "as fast as possible" if args.fast else "in real time"
    log(f"replaying {_describe(T)} {mode}, aligning to {_describe(I)} with {_algorithm_name(args)}")
    report = replay(FI, FT, _factory(args), realtime=not args.fast)
    print(report.table())
    if FI.n_frames * FT.n_frames <= LIVE_DTW_CELLS:
        from fpdtw.dtw import dtw_pair
        from fpdtw.paper.edits import ms_table

        print("target frames within each tolerance of offline DTW's map (the papers' "
              "reference), on the input's clock:")  # fmt: skip
        print(ms_table({report.name: report.M}, dtw_pair(FI, FT).map, FI.fps))
    else:
        print(f"(no scores in ms: offline DTW's reference over {FI.n_frames} x {FT.n_frames} "
              f"frames is beyond {LIVE_DTW_CELLS:,} cells)")  # fmt: skip
    if args.out:
        _stage(args, args.out)
        write_map_csv(args.out, report.M, T.fps, I.fps, report.step_s)
        print(f"map: {args.out} ({report.n_frames} rows)")
    if args.animate:
        from fpdtw.app.animate import animate_alignment

        _stage(args, args.animate)
        out = animate_alignment(I, T, report.M, args.animate, stride=args.stride)
        print(f"animation: {out}")
    if args.view:
        _write_view(args, I, T, report.M, FI, FT)
    return 0


def _cmd_serve(args, log) -> int:
    from fpdtw import limits
    from fpdtw.app.live import warm_up
    from fpdtw.app.serve import Server, parse_address, run_server
    from fpdtw.motion.joints import OPW_JOINTS

    I = _load(args, args.input, args.skeleton)
    _stage(args, args.input)
    limits.check_min_frames(I.n_frames, args.input, "input")
    _check_joints(args, I, args.input)
    FI = _features(I, args.method, _rig(I, args.input_rest_frame, args))
    name = _algorithm_name(args)
    factory = _factory(args)
    warm_up(factory(FI), FI)  # compile / load the numba kernels before the first take
    host, port = parse_address(args.listen or DEFAULT_LISTEN)
    view = None
    if args.view:
        from fpdtw.app.view import Viewer

        _stage(args, args.view)
        view = Viewer(I, FI, *parse_address(args.view), title=f"{name}, input {_describe(I)}")
    server = Server(
        FI,
        factory,
        name,
        position_joints=OPW_JOINTS if args.method == "opw" else None,
        gap=args.gap,
        joint_maps=_joint_maps(args),
        axes=tuple(None if a is None else a[1] for a in (args.up, args.facing)),
        max_clients=args.max_clients,
        idle_timeout=args.idle_timeout,
        send=args.send,
        log=log,
        view=view,
    )
    server.warm_up(I)  # and the live target's kernels, on the input's own first frames
    if args.source:
        return _serve_source(args, log, FI, factory, name, server)
    sends = "".join(f"; answers also to {u}" for u in args.send)
    log(f"serving {name} against input {_describe(I)}; up to {args.max_clients} takes at "
        f"once; dropped frames: {args.gap}{sends}")  # fmt: skip
    _stage(args, args.listen or DEFAULT_LISTEN)
    return run_server(server, host, port)


def _serve_source(args, log, FI, factory, name, server) -> int:
    """``fpdtw serve --source URL``: takes read from a capture system (fpdtw.app.sources)."""
    from fpdtw.app.serve import _Sender
    from fpdtw.app.sources import Performers, parse_source, run_source

    if args.out:
        _check_output(args.out, "--out")
    module, host, port = parse_source(args.source)
    _stage(args, args.header)
    if args.source.startswith(("vmc://", "xsens://", "rokoko://", "natnet://")):
        source = module.Source(host, port, rate=args.rate)
        source.warm_up()  # its compiled kernels, before the first take
        skeleton = "from the bones sent"
    else:
        source, skeleton = module.Source(host, port, header=args.header), args.header
        for _, lines in source.header.counts.values():  # the input's joints are in the header
            s = server._session()
            for line in lines:
                s.feed(f"{line}\n".encode("latin-1"), 0.0)
    senders = [_Sender(u) for u in args.send]

    def performers(take):
        return Performers(
            FI, factory, take=take, max_performers=args.max_clients, senders=senders,
            record=bool(args.out), log=log, position_joints=server.position_joints,
            gap=args.gap, joint_maps=[*server.joint_maps, *getattr(module, "JOINT_MAPS", ())],
            axes=server.axes, view=server.view,
        )  # fmt: skip

    log(f"serving {name} against input {server.I.n_frames} frames at {FI.fps:g} Hz; reading "
        f"{source.describe()}, skeleton {skeleton}; dropped frames: {args.gap}")  # fmt: skip
    args.about = (args.source,)  # a URL, not a path (_stage would fold its '//')
    try:
        return run_source(source, performers, once=args.once, out=args.out,
                          idle_timeout=args.idle_timeout, log=log, view=server.view)  # fmt: skip
    finally:
        for s in senders:
            s.close()


def _cmd_stream(args, log) -> int:
    from fpdtw.app.stream import play_many, pooled_table, take_lines, write_answers_csv

    if args.as_system:
        return _stream_as(args, log)
    if args.out:
        _check_output(args.out, "--out")
    _stage(args, args.take[0])
    lines = take_lines(args.take[0], args.rate, skeleton=args.skeleton)
    _stage(args, args.to)
    reports = play_many(
        lines,
        args.to,
        args.streams,
        drop=args.drop,
        jitter_ms=args.jitter_ms,
        seed=args.seed,
        fast=args.fast,
        timestamps=not args.no_timestamps,
    )
    print(pooled_table(reports))
    if args.out:
        _stage(args, args.out)
        write_answers_csv(args.out, reports)
        print(f"answers: {args.out} ({sum(r.index.size for r in reports)} rows)")
    errors = [r.error for r in reports if r.error]
    if errors:
        print(f"{PROG}: error: {args.to}: the server answered {errors[0]!r}", file=sys.stderr)
        return 1
    return 0


def _stream_as(args, log) -> int:
    """``fpdtw stream TAKE ... --as axis|vmc|xsens|rokoko``: the takes as Axis' broadcast, to
    one client, as VMC senders, as MVN's network streamer or as Rokoko Studio."""
    from fpdtw.app.source_axis import play_as_axis
    from fpdtw.app.stream import take_lines

    if args.as_system == "axis+udp":
        from fpdtw.app.source_axis_udp import play_as_axis_udp

        takes = []
        for path in args.take:
            _stage(args, path)
            takes.append(take_lines(path, args.rate, skeleton=args.skeleton))
        to = args.to or _AS_DEFAULT_TO[args.as_system]
        _stage(args, to)
        mode = "one frame a millisecond" if args.fast else "in real time"
        log(f"playing {len(takes)} take(s) as Axis' binary BVH broadcast to {to} {mode}")
        play_as_axis_udp(takes, to, fast=args.fast, displacement=args.displacement,
                         out=sys.stdout)  # fmt: skip
        return 0
    if args.as_system in ("vmc", "xsens", "rokoko", "natnet"):
        from fpdtw.io import load_motion

        motions = []
        for path in args.take:
            _stage(args, path)
            m = load_motion(path, **({"skeleton": args.skeleton} if args.skeleton else {}))
            motions.append(m.resample(args.rate) if args.rate else m)
        vmc = args.as_system == "vmc"
        to = args.to or _AS_DEFAULT_TO[args.as_system]
        _stage(args, to)
        mode = "one frame a millisecond" if args.fast else "in real time"
        what = {"vmc": "VMC senders", "xsens": "MVN network streamer characters",
                "rokoko": "Rokoko Studio actors", "natnet": "Motive's NatNet skeletons"}[
                    args.as_system]  # fmt: skip
        where = f"on {to} (for the client that asks)" if args.as_system == "natnet" else f"to {to}"
        if args.as_system == "natnet":
            from fpdtw.app.source_natnet import play_as_natnet as play
        elif vmc:
            from fpdtw.app.source_vmc import play_as_vmc as play
        elif args.as_system == "rokoko":
            from fpdtw.app.source_rokoko import play_as_rokoko as play
        else:
            from fpdtw.app.source_xsens import play_as_xsens as play
        log(f"playing {len(motions)} take(s) as {what} {where} {mode}")
        play(motions, to, fast=args.fast, out=sys.stdout)
        return 0

    takes = []
    for path in args.take:
        _stage(args, path)
        takes.append(take_lines(path, args.rate, skeleton=args.skeleton))
    listen = args.listen or "127.0.0.1:7001"
    _stage(args, listen)
    mode = "as fast as read" if args.fast else "in real time"
    log(f"playing {len(takes)} take(s) as Axis' BVH broadcast {mode}; waiting for a client")
    play_as_axis(takes, listen, fast=args.fast, displacement=args.displacement)
    return 0


def _cmd_data(args) -> int:
    from fpdtw.app.commands import run_data_command

    return run_data_command(args, prog=PROG)


def _cmd_experiments(args) -> int:
    from fpdtw.app.commands import run_command

    return run_command(args, prog=f"{PROG} experiments {args.experiments_command}")


def main(argv=None) -> int:
    """Run the ``fpdtw`` command line; return the exit code (0, 1 or 2).

    Parameters
    ----------
    argv : list of str, optional
        Arguments without the program name (default ``sys.argv[1:]``).

    Returns
    -------
    code : int

    Paper: FP-DTW Sections 3-6 (the methods), OPW poster Algorithm 1, Dixon 2005.
    """
    ap = build_parser()
    try:
        args = ap.parse_args(argv)
    except SystemExit as e:  # --help (0) or a usage error (2)
        return e.code if isinstance(e.code, int) else 0
    if args.command == "data":
        return _cmd_data(args)
    if args.command == "experiments":
        return _cmd_experiments(args)
    sub = ap.commands[args.command]

    def log(msg):
        print(msg, file=sys.stderr)

    try:
        _check_options(args)
    except UsageError as e:
        sub.print_usage(sys.stderr)
        print(f"{PROG} {args.command}: error: {e}", file=sys.stderr)
        return 2
    args.about = ()
    commands = {"align": _cmd_align, "live": _cmd_live, "serve": _cmd_serve,
                "stream": _cmd_stream}  # fmt: skip
    try:
        return commands[args.command](args, log)
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return 130
    except Exception as e:
        if args.debug:
            raise
        print(_error_line(e, args.about), file=sys.stderr)
        return 1


def _error_line(exc: Exception, about: tuple) -> str:
    """The one line an error prints: ``fpdtw: error: <file>: <what>``.

    ``about`` names the file(s) of the step that failed; they are put in front of a
    message that names none of them (e.g. numpy's). Errors that are not fpdtw's, an
    OSError, a ValueError or a MemoryError are bugs: ``fpdtw: internal error: ...``.
    """
    from fpdtw import limits
    from fpdtw.errors import FpdtwError

    if isinstance(exc, OSError) and exc.filename is not None:
        msg = f"{exc.filename}: {exc.strerror or exc}"
    elif isinstance(exc, MemoryError):
        msg = (
            f"out of memory ({type(exc).__name__}: {exc}); lower the limits "
            f"(FPDTW_MAX_MATRIX_BYTES, FPDTW_MAX_FRAMES) or {limits.HINT_LONG}"
        )
    else:
        msg = str(exc) or type(exc).__name__
    known = isinstance(exc, FpdtwError | OSError | ValueError | MemoryError)
    if not known:
        msg = f"{type(exc).__name__}: {msg} (rerun with --debug for the traceback)"
    if about and not any(a in msg for a in about):
        msg = f"{', '.join(about)}: {msg}"
    msg = " ".join(msg.split())
    return f"{PROG}: {'error' if known else 'internal error'}: {msg}"


if __name__ == "__main__":
    sys.exit(main())
