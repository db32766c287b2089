"""The parser alone: one table of good lines, one of bad lines, and hostile lines refused."""

from __future__ import annotations

import itertools
import math
import re
import subprocess
import sys

import pytest
from support import ROOT

from c2rviz.errors import BadArguments, LineError, UnknownCommand
from c2rviz.protocol.grammar import ForeignProtocol, parse_line
from c2rviz.protocol.registry import VERBS
from c2rviz.protocol.verbs.arm import (
    Ik,
    LinearSpeed,
    MotionMode,
    MoveL,
    MoveTo,
    RobotChoice,
    RobotsList,
    Speed,
    Status,
    Stop,
    Target,
    Tool,
    Wait,
)
from c2rviz.protocol.verbs.faults import Faults, FaultSpec, FaultVerb, Reset
from c2rviz.protocol.verbs.parts import (
    CameraEdit,
    CamerasQuery,
    GoalEdit,
    Grip,
    PartEdit,
    PartsQuery,
    Score,
)
from c2rviz.protocol.verbs.scene import (
    Collisions,
    Ghost,
    Guard,
    ObjectEdit,
    Objects,
    Plan,
    Record,
    Trail,
    Unwatch,
    Watch,
)
from c2rviz.protocol.verbs.seed import (
    Bye,
    Clear,
    Color,
    Help,
    Home,
    Joints,
    Limits,
    Mark,
    MarkerShape,
    Move,
    Names,
    Pose,
    Quit,
    Rand,
    Sleep,
    Units,
    Version,
    Where,
)

GOOD = [
    ("home", Home(), "home"),
    ("home\n", Home(), "newline"),
    ("home\r\n", Home(), "crlf"),
    ("  HOME\t", Home(), "case-and-whitespace"),
    ("HoMe # to zero", Home(), "trailing-comment"),
    ("", None, "empty"),
    ("   \t ", None, "whitespace-only"),
    ("# only a comment", None, "comment-only"),
    ("\r\n", None, "bare-crlf"),
    ("rand", Rand(), "rand"),
    ("degrees", Units(degrees=True), "degrees"),
    ("degree", Units(degrees=True), "degree"),
    ("RADIANS", Units(degrees=False), "radians"),
    ("radian", Units(degrees=False), "radian"),
    ("joints 1,2,3", Joints((1.0, 2.0, 3.0)), "joints"),
    ("j -1,+2.5,.5,1.,1e-3,2E+2", Joints((-1.0, 2.5, 0.5, 1.0, 1e-3, 200.0)), "number-forms"),
    ("joints 1 , 2 ,3", Joints((1.0, 2.0, 3.0)), "spaces-around-commas"),
    ("joints\t1,\t2", Joints((1.0, 2.0)), "tabs-around-commas"),
    ("joints 1e308", Joints((1e308,)), "largest-finite"),
    ("move 0 1", Move((0,), (1.0,)), "move-one"),
    ("move 0,1 90,-90", Move((0, 1), (90.0, -90.0)), "move-two"),
    ("move 0 , 1   0.1 , 0.2", Move((0, 1), (0.1, 0.2)), "move-spaced"),
    ("move 99 1", Move((99,), (1.0,)), "move-index-checked-later"),
    ("move 007 1", Move((7,), (1.0,)), "move-leading-zeros"),
    ("clear", Clear(), "clear"),
    ("mark", Mark(None), "mark-here"),
    ("mark 1,2,3,0,0,90", Mark((1.0, 2.0, 3.0, 0.0, 0.0, 90.0)), "mark-pose"),
    ("mark WORLD 1,2,3,0,0,90", Mark((1.0, 2.0, 3.0, 0.0, 0.0, 90.0), True), "mark-world"),
    ("robot", RobotChoice(None), "robot-ask"),
    ("robot right_arm", RobotChoice("right_arm"), "robot-choose"),
    ("robots", RobotsList(), "robots"),
    ("tool", Tool(None), "tool-ask"),
    ("tool 0,0,0.1,0,0,0", Tool((0, 0, 0.1, 0, 0, 0)), "tool"),
    ("ik 0.5,0,0.8,0,90,0", Ik((0.5, 0, 0.8, 0, 90, 0)), "ik"),
    ("ik 0.5,0,0.8", Ik((0.5, 0, 0.8)), "ik-point"),
    ("moveto 0.5,0,0.8", MoveTo((0.5, 0, 0.8)), "moveto-point"),
    ("movel 0.5 , 0 , 0.8", MoveL((0.5, 0, 0.8)), "movel-point"),
    ("moveto 0.5,0,0.8,0,90,0", MoveTo((0.5, 0, 0.8, 0, 90, 0)), "moveto"),
    ("moveto MARKER 3", MoveTo(None, 3), "moveto-marker"),
    ("movel 0.5,0,0.8,0,90,0", MoveL((0.5, 0, 0.8, 0, 90, 0)), "movel"),
    ("lspeed", LinearSpeed(None), "lspeed-ask"),
    ("lspeed 0.1", LinearSpeed(0.1), "lspeed"),
    (
        "object table box 1,0.6,0.05 0.6,0,-0.03,0,0,90",
        ObjectEdit("table", "box", (1.0, 0.6, 0.05), (0.6, 0.0, -0.03, 0.0, 0.0, 90.0)),
        "object-box",
    ),
    ("object b SPHERE .1 1,2,3", ObjectEdit("b", "sphere", (0.1,), (1, 2, 3, 0, 0, 0)), "sphere"),
    ("object t remove", ObjectEdit("t", "remove"), "object-remove"),
    ("objects", Objects(), "objects"),
    ("collisions", Collisions(), "collisions"),
    ("guard", Guard(None), "guard-ask"),
    ("guard ON", Guard(True), "guard-on"),
    ("guard off", Guard(False), "guard-off"),
    ("guard Plan", Guard(True, plan=True), "guard-plan"),
    ("plan", Plan("show"), "plan-show"),
    ("plan joints 1,2,-3", Plan("joints", (1.0, 2.0, -3.0)), "plan-joints"),
    ("PLAN Pose 0.5,0,1.2,0,90,0", Plan("pose", (0.5, 0, 1.2, 0, 90, 0)), "plan-pose"),
    ("plan pose 0.5,0,1.2", Plan("pose", (0.5, 0.0, 1.2)), "plan-point"),
    ("plan timeout", Plan("timeout"), "plan-timeout-ask"),
    ("plan timeout 0.25", Plan("timeout", (0.25,)), "plan-timeout"),
    ("plan resolution", Plan("resolution"), "plan-resolution-ask"),
    ("plan resolution 0.5,0.002", Plan("resolution", (0.5, 0.002)), "plan-resolution"),
    ("color 0,0.5,1", Color((0.0, 0.5, 1.0)), "color"),
    ("rgb 0,255,51", Color((0.0, 1.0, 0.2)), "rgb"),
    ("marker CUBE", MarkerShape("cube"), "marker"),
    ("where", Where(), "where"),
    ("pose", Pose(), "pose"),
    ("names", Names(), "names"),
    ("LIMITS", Limits(), "limits"),
    ("limits ALL", Limits(all=True), "limits-all"),
    ("motion", MotionMode(None), "motion-ask"),
    ("motion on", MotionMode("on"), "motion-on"),
    ("MOTION Follow", MotionMode("follow"), "motion-follow"),
    ("motion off", MotionMode("off"), "motion-off"),
    ("speed", Speed(None), "speed-ask"),
    ("speed 10", Speed(10.0), "speed"),
    ("speed 1", Speed(1.0), "speed-lowest"),
    ("speed 100", Speed(100.0), "speed-highest"),
    ("stop", Stop(), "stop"),
    ("wait", Wait(), "wait"),
    ("target", Target(), "target"),
    ("status", Status(), "status"),
    ("watch", Watch(None), "watch-default"),
    ("watch 20", Watch(20.0), "watch-hz"),
    ("WATCH 0.5", Watch(0.5), "watch-slow"),
    ("watch 1000", Watch(1000.0), "watch-highest"),
    ("unwatch", Unwatch(), "unwatch"),
    ("trail", Trail(None), "trail-ask"),
    ("trail on", Trail("on"), "trail-on"),
    ("trail OFF", Trail("off"), "trail-off"),
    ("trail clear", Trail("clear"), "trail-clear"),
    ("ghost", Ghost(None), "ghost-ask"),
    ("ghost off", Ghost(False), "ghost-off"),
    ("GHOST On", Ghost(True), "ghost-on"),
    ("record", Record(), "record-ask"),
    ("record demo_1", Record("demo_1"), "record"),
    ("record Take-2.v3 OVERWRITE", Record("Take-2.v3", overwrite=True), "record-overwrite"),
    ("record stop", Record(stop=True), "record-stop"),
    ("record cell all", Record("cell", every=True), "record-all"),
    ("record cell ALL overwrite", Record("cell", True, every=True), "record-all-overwrite"),
    ("help", Help(), "help"),
    ("help moveto", Help("moveto"), "help-verb"),
    ("HELP J", Help("joints"), "help-alias"),
    ("version", Version(), "version"),
    ("sleep 0", Sleep(0.0), "sleep-zero"),
    ("sleep 1e9", Sleep(1e9), "sleep-long-checked-by-server"),
    ("bye", Bye(), "bye"),
    ("quit", Quit(), "quit"),
    ("grip", Grip(None), "grip-ask"),
    ("grip 0", Grip(0.0), "grip-closed"),
    ("GRIP 1", Grip(1.0), "grip-open"),
    ("grip .25", Grip(0.25), "grip-quarter"),
    # faults (docs/faults.md)
    ("fault estop", FaultVerb(FaultSpec("estop")), "fault-estop"),
    ("FAULT Protective", FaultVerb(FaultSpec("protective")), "fault-protective"),
    ("fault stall joint_l", FaultVerb(FaultSpec("stall", "joint_l")), "fault-stall-name"),
    ("fault stall 1", FaultVerb(FaultSpec("stall", "1")), "fault-stall-index"),
    ("fault noise 0.01", FaultVerb(FaultSpec("noise", values=(0.01,))), "fault-noise"),
    ("fault latency 50", FaultVerb(FaultSpec("latency", values=(50.0, 0.0))), "fault-latency"),
    ("fault latency 50,10", FaultVerb(FaultSpec("latency", values=(50.0, 10.0))), "fault-jitter"),
    ("fault disconnect", FaultVerb(FaultSpec("disconnect")), "fault-disconnect"),
    ("fault at 2.5 estop", FaultVerb(FaultSpec("estop"), at_s=2.5), "fault-at"),
    ("fault after 0 protective", FaultVerb(FaultSpec("protective"), after_s=0.0), "fault-after"),
    ("fault clear", FaultVerb(clear="all"), "fault-clear"),
    ("fault clear estop", FaultVerb(clear="estop"), "fault-clear-kind"),
    ("fault clear ALL", FaultVerb(clear="all"), "fault-clear-all"),
    ("faults", Faults(), "faults"),
    ("reset", Reset(), "reset"),
    (
        "part p1 box 0.03,0.03,0.03 0.5,0,0.015,0,0,0 type=cube color=1,0,0",
        PartEdit("p1", "box", (0.03,) * 3, (0.5, 0, 0.015, 0, 0, 0), "cube", (1.0, 0.0, 0.0)),
        "part-box",
    ),
    (
        "part c cylinder 0.01,0.05 0.5,0.1,0.025,0,0,90",
        PartEdit("c", "cylinder", (0.01, 0.05), (0.5, 0.1, 0.025, 0, 0, 90)),
        "part-cylinder",
    ),
    (
        "part s sphere 0.02 0.4,0,0.02",
        PartEdit("s", "sphere", (0.02,), (0.4, 0, 0.02, 0, 0, 0)),
        "part-sphere",
    ),
    ("part p1", PartEdit("p1", ""), "part-ask"),
    ("part p1 remove", PartEdit("p1", "remove"), "part-remove"),
    ("part all remove", PartEdit("all", "remove"), "part-all-remove"),
    ("parts", PartsQuery(), "parts"),
    ("goal p1 0.5,0,0.015,0,0,0", GoalEdit("p1", False, (0.5, 0, 0.015, 0, 0, 0)), "goal"),
    (
        "goal type=cube 0.5,0,0.015,0,0,0 0.01,2",
        GoalEdit("type=cube", False, (0.5, 0, 0.015, 0, 0, 0), 0.01, 2.0),
        "goal-type-tol",
    ),
    ("goal all remove", GoalEdit("all", True), "goal-all-remove"),
    ("score", Score(), "score"),
    ("camera top 0,0,1,0,90,0", CameraEdit("top", "place", (0, 0, 1, 0, 90, 0)), "camera"),
    (
        "camera top 0,0,1,0,90,0 60,45,2",
        CameraEdit("top", "place", (0, 0, 1, 0, 90, 0), (60.0, 45.0, 2.0)),
        "camera-view",
    ),
    ("camera top", CameraEdit("top", "look"), "camera-look"),
    ("camera top remove", CameraEdit("top", "remove"), "camera-remove"),
    ("camera top rate 5", CameraEdit("top", "rate", values=(5.0,)), "camera-rate"),
    ("camera top noise 0.01,1", CameraEdit("top", "noise", values=(0.01, 1.0)), "camera-noise"),
    ("cameras", CamerasQuery(), "cameras"),
]


@pytest.mark.parametrize(("line", "expected"), [g[:2] for g in GOOD], ids=[g[2] for g in GOOD])
def test_good_lines(line, expected):
    got = parse_line(line)
    assert got == expected
    if isinstance(got, Color):  # compare channels as numbers, not float bit patterns
        assert got.rgb == pytest.approx(expected.rgb)


EXAMPLES = [(line, verb.command) for verb in VERBS.values() for line in verb.examples]
"""Each verb's example lines, from its registry entry (``@verb(..., examples=...)``)."""


@pytest.mark.parametrize(("line", "command"), EXAMPLES, ids=[line for line, _ in EXAMPLES])
def test_each_verbs_examples_parse(line, command):
    assert type(parse_line(line)) is command


BAD = [
    ("joints", BadArguments, "joints: needs an argument", "joints-nothing"),
    ("joints 1 2", BadArguments, "joints: takes 1 argument, got 2", "joints-two-words"),
    ("joints nan", BadArguments, "bad number 'nan'", "nan"),
    ("joints 1,NaN", BadArguments, "bad number 'NaN'", "NaN"),
    ("joints inf", BadArguments, "bad number 'inf'", "inf"),
    ("joints -Infinity", BadArguments, "bad number '-Infinity'", "-Infinity"),
    ("joints 1e309", BadArguments, "value '1e309' is not a finite number", "overflow"),
    ("joints -1e309", BadArguments, "not a finite number", "negative-overflow"),
    ("joints 0x10", BadArguments, "bad number '0x10'", "hex"),
    ("joints 1.5abc", BadArguments, "bad number '1.5abc'", "trailing-letters"),
    ("joints 1,,2", BadArguments, "empty value in list", "double-comma"),
    ("joints 1,", BadArguments, "empty value in list", "trailing-comma"),
    ("joints ,1", BadArguments, "empty value in list", "leading-comma"),
    ("joints 1_0", BadArguments, "bad number '1_0'", "underscore"),
    ("joints .", BadArguments, "bad number '.'", "lone-dot"),
    ("joints 1e", BadArguments, "bad number '1e'", "bare-exponent"),
    ("joints --1", BadArguments, "bad number '--1'", "double-sign"),
    ("joints \u0661", LineError, "column 8 is not allowed", "arabic-indic-digit"),
    ("joints \uff11", LineError, "column 8 is not allowed", "fullwidth-digit"),
    ("home\x00x", LineError, "'\\x00' at column 5", "nul-inside"),
    ("home\x00", LineError, "'\\x00' at column 5", "nul-at-end"),
    ("ho\rme", LineError, "'\\r' at column 3", "cr-inside"),
    ("home\x1b[2J", LineError, "'\\x1b'", "escape-sequence"),
    ("home\u2028", LineError, "not allowed", "unicode-line-separator"),
    ("home\x0b", LineError, "'\\x0b'", "vertical-tab"),
    ("move 0,1 90", BadArguments, "2 indices but 1 values", "move-fewer-values"),
    ("move 0 1,2", BadArguments, "1 indices but 2 values", "move-more-values"),
    ("move 0,0 1,2", BadArguments, "joint 0 is given twice", "move-twice"),
    ("move -1 1", BadArguments, "bad joint index '-1'", "move-negative"),
    ("move x 1", BadArguments, "bad joint index 'x'", "move-letter"),
    ("move 1.5 1", BadArguments, "bad joint index '1.5'", "move-fraction"),
    ("move +1 1", BadArguments, "bad joint index '+1'", "move-plus"),
    ("move 0 nan", BadArguments, "bad number 'nan'", "move-nan"),
    ("move 1", BadArguments, "takes 2 arguments, got 1", "move-one-arg"),
    ("move 0, 1", BadArguments, "takes 2 arguments, got 1", "move-comma-glues"),
    ("move " + "9" * 5000 + " 1", BadArguments, "is too large", "move-5000-digits"),
    ("move 1234567890 1", BadArguments, "'1234567890' is too large", "move-10-digits"),
    ("mark 1,2,3", BadArguments, "mark: needs 6 values, got 3", "mark-three"),
    ("mark 1,2,3,4,5,6,7", BadArguments, "needs 6 values, got 7", "mark-seven"),
    ("mark 1,2,3,0,0,inf", BadArguments, "bad number 'inf'", "mark-inf"),
    ("mark world", BadArguments, "mark: world needs a pose", "mark-world-nothing"),
    ("mark 1e308,0,0,0,0,0", BadArguments, "x = 1e+308 m is outside -1000..1000 m", "mark-far"),
    ("ik 1,2", BadArguments, "needs 3 values (x,y,z) or 6 (x,y,z,roll,pitch,yaw), got 2", "ik-two"),
    ("tool 0,0,11,0,0,0", BadArguments, "tool: z = 11 m is outside -10..10 m", "tool-far"),
    ("lspeed 1e-320", BadArguments, "m/s is outside 0.001..5", "lspeed-tiny"),
    ("robot a/b", BadArguments, "robot: bad robot name 'a/b'", "robot-slash"),
    ("robot a b", BadArguments, "robot: takes 1 argument, got 2", "robot-two"),
    ("color 1,1", BadArguments, "color: needs 3 values, got 2", "color-two"),
    ("color 1,1,1,1", BadArguments, "needs 3 values, got 4", "color-four"),
    ("color 0,0,1.5", BadArguments, "channel 1.5 is outside 0..1", "color-over"),
    ("color -0.1,0,0", BadArguments, "channel -0.1 is outside 0..1", "color-negative"),
    ("rgb 0,0,256", BadArguments, "channel 256 is outside 0..255", "rgb-over"),
    ("rgb 1,2", BadArguments, "rgb: needs 3 values, got 2", "rgb-two"),
    ("marker cone", BadArguments, "unknown shape 'cone'", "marker-unknown"),
    ("marker", BadArguments, "marker: needs an argument", "marker-none"),
    ("sleep", BadArguments, "sleep: needs an argument", "sleep-none"),
    ("sleep -1", BadArguments, "seconds must be >= 0, got -1", "sleep-negative"),
    ("sleep nan", BadArguments, "bad number 'nan'", "sleep-nan"),
    ("sleep 1,2", BadArguments, "sleep: needs 1 values, got 2", "sleep-two"),
    ("grip 1.5", BadArguments, "grip: 1.5 is outside 0..1 (usage: grip [S])", "grip-over"),
    ("grip -0.1", BadArguments, "grip: -0.1 is outside 0..1", "grip-negative"),
    ("grip nan", BadArguments, "bad number 'nan'", "grip-nan"),
    ("grip 0.5 1", BadArguments, "grip: takes 1 argument, got 2", "grip-two"),
    ("part", BadArguments, "part: needs a name", "part-none"),
    ("part p1 cone 1 0,0,0", BadArguments, "unknown shape 'cone'", "part-cone"),
    (
        "part p1 box 1e308,1,1 0,0,0,0,0,0",
        BadArguments,
        "part size 1e+308 m is outside",
        "part-huge",
    ),
    ("part p1 box 0.1,0.1 0,0,0,0,0,0", BadArguments, "needs 3 values, got 2", "part-two-sizes"),
    ("part p1 box 0.1,0.1,0.1 0,0,0", BadArguments, "needs 6 values, got 3", "part-no-angles"),
    ("part p/1 box 0.1,0.1,0.1 0,0,0,0,0,0", BadArguments, "bad part name", "part-slash"),
    ("part all box 0.1,0.1,0.1 0,0,0,0,0,0", BadArguments, "'all' is not a part", "part-all"),
    ("part p1 sphere 0.1 0,0,0 hue=3", BadArguments, "not type=TYPE or color", "part-option"),
    ("part p1 sphere 0.1 0,0,0 color=2,0,0", BadArguments, "each in 0..1", "part-colour"),
    ("part p1 box 0.1,0.1,0.1 1e9,0,0,0,0,0", BadArguments, "outside -1000..1000", "part-far"),
    ("parts x", BadArguments, "parts: takes no arguments", "parts-arg"),
    ("goal", BadArguments, "needs a part name", "goal-none"),
    ("goal p1 0,0,0", BadArguments, "needs 6 values, got 3", "goal-short"),
    ("goal p1 0,0,0,0,0,0 0,1", BadArguments, "tolerances must be > 0", "goal-zero-tol"),
    ("score now", BadArguments, "score: takes no arguments", "score-arg"),
    ("home 1", BadArguments, "home: takes no arguments", "home-arg"),
    ("limits some", BadArguments, "limits: unknown argument 'some'", "limits-other"),
    ("motion fast", BadArguments, "unknown mode 'fast'; choose off, on or follow", "motion-fast"),
    ("motion on off", BadArguments, "takes 1 argument, got 2", "motion-two"),
    ("speed 0", BadArguments, "speed: 0 is outside 1..100", "speed-zero"),
    ("speed 101", BadArguments, "101 is outside 1..100", "speed-over"),
    ("speed nan", BadArguments, "bad number 'nan'", "speed-nan"),
    ("speed -5", BadArguments, "-5 is outside 1..100", "speed-negative"),
    ("stop now", BadArguments, "stop: takes no arguments", "stop-arg"),
    ("watch 0", BadArguments, "HZ must be above 0 and at most 1000, got 0", "watch-zero"),
    ("watch -1", BadArguments, "HZ must be above 0 and at most 1000, got -1", "watch-negative"),
    ("watch 1e9", BadArguments, "at most 1000, got 1e+09", "watch-huge"),
    ("watch fast", BadArguments, "bad number 'fast'", "watch-word"),
    ("watch 1 2", BadArguments, "watch: takes 1 argument, got 2", "watch-two"),
    ("unwatch now", BadArguments, "unwatch: takes no arguments", "unwatch-arg"),
    ("trail sideways", BadArguments, "unknown action 'sideways'; choose on, off", "trail-bad"),
    ("trail on off", BadArguments, "trail: takes 1 argument, got 2", "trail-two"),
    ("ghost maybe", BadArguments, "unknown action 'maybe'; choose on or off", "ghost-bad"),
    ("ghost on off", BadArguments, "ghost: takes 1 argument, got 2", "ghost-two"),
    ("record ../x", BadArguments, "bad name '../x'", "record-parent"),
    ("record a/b", BadArguments, "bad name 'a/b'", "record-folder"),
    ("record .hidden", BadArguments, "not starting with '.'", "record-dot"),
    ("record a\\b", BadArguments, "bad name", "record-backslash"),
    ("record " + "n" * 101, BadArguments, "bad name", "record-too-long"),
    ("record x now", BadArguments, "unknown option 'now'; only 'overwrite'", "record-option"),
    ("record stop overwrite", BadArguments, "'stop' takes no option", "record-stop-option"),
    ("record a b c d", BadArguments, "takes at most 3 arguments, got 4", "record-four"),
    ("record a all all", BadArguments, "'all' given twice", "record-all-twice"),
    ("guard maybe", BadArguments, "'maybe' is not on, off or plan", "guard-bad"),
    ("plan around", BadArguments, "'around' is not one of joints, pose, timeout", "plan-what"),
    ("plan joints", BadArguments, "plan: joints needs values", "plan-joints-none"),
    ("plan joints 1 2", BadArguments, "joints takes one list of values", "plan-two-words"),
    ("plan joints 1,nan", BadArguments, "bad number 'nan'", "plan-nan"),
    ("plan pose 1,2,3,4", BadArguments, "x,y,z or x,y,z,roll,pitch,yaw, not 4", "plan-pose-4"),
    ("plan timeout 1,2", BadArguments, "timeout takes one number of seconds", "plan-timeout-2"),
    ("plan timeout inf", BadArguments, "bad number 'inf'", "plan-timeout-inf"),
    ("plan resolution 1", BadArguments, "a joint step and a tool step", "plan-resolution-1"),
    ("degree 1", BadArguments, "(usage: degrees)", "alias-usage"),
    ("help movto", BadArguments, "help: no verb 'movto': did you mean 'moveto'?", "help-typo"),
    ("help fly", BadArguments, "no verb 'fly' (usage: help [VERB])", "help-unknown"),
    ("help joints move", BadArguments, "help: takes one verb at most", "help-two"),
    ("jump 1", UnknownCommand, "unknown command 'jump' (try 'help')", "unknown-verb"),
    ("jonts 1,2", UnknownCommand, "unknown command 'jonts' (did you mean 'joints'?)", "typo"),
    ("joints 0 0 0", BadArguments, "got 3 (separate values with commas: 1,2,3)", "spaces"),
    ("x" * 100, UnknownCommand, "'" + "x" * 40 + "...'", "unknown-long-verb-cut"),
    ("GET / HTTP/1.1", ForeignProtocol, "not HTTP", "http-get"),
    ("POST /api HTTP/1.0\r\n", ForeignProtocol, "not HTTP", "http-post"),
    ("Host: 127.0.0.1:31000", ForeignProtocol, "not HTTP", "http-host-header"),
    ("User-Agent: curl/8.0", ForeignProtocol, "not HTTP", "http-user-agent"),
    ("post / HTTP/1.1", ForeignProtocol, "not HTTP", "http-lowercase-method"),
    ("POST  /  HTTP/1.1", ForeignProtocol, "not HTTP", "http-double-space"),
    ("GET /", ForeignProtocol, "not HTTP", "http-0.9"),
    ("get\t/index.html", ForeignProtocol, "not HTTP", "http-0.9-tab-lowercase"),
    ("Delete /joints/3 HTTP/1.0", ForeignProtocol, "not HTTP", "http-delete"),
    ("OPTIONS * HTTP/1.1", ForeignProtocol, "not HTTP", "http-options-star"),
    ("CONNECT example.com:443 HTTP/1.1", ForeignProtocol, "not HTTP", "http-connect"),
    ("  head / HTTP/2.0  ", ForeignProtocol, "not HTTP", "http-padded"),
    ("BREW /pot HTTP/1.1", ForeignProtocol, "not HTTP", "http-unknown-method"),
    ("get where", UnknownCommand, "unknown command 'get'", "method-word-without-slash"),
    ("fly to HTTP/1.1x", UnknownCommand, "unknown command 'fly'", "http-not-at-the-end"),
    ("where:", UnknownCommand, "unknown command 'where:'", "typo-with-colon-is-not-http"),
    ("home: now", UnknownCommand, "unknown command 'home:'", "verb-colon-is-not-http"),
    ("fault", BadArguments, "fault: needs a fault: estop, protective, stall", "fault-none"),
    (
        "fault bogus",
        BadArguments,
        "unknown fault 'bogus'; faults: estop, protective",
        "fault-unknown",
    ),
    ("fault estop now", BadArguments, "estop takes no argument, got 'now'", "fault-estop-arg"),
    ("fault stall", BadArguments, "stall needs one joint", "fault-stall-none"),
    ("fault stall 1 2", BadArguments, "stall needs one joint", "fault-stall-two"),
    ("fault noise 0", BadArguments, "noise SIGMA 0 is outside (0, 100]", "fault-noise-zero"),
    ("fault noise -1", BadArguments, "noise SIGMA -1 is outside", "fault-noise-negative"),
    ("fault noise nan", BadArguments, "bad number 'nan'", "fault-noise-nan"),
    ("fault noise 1,2", BadArguments, "noise needs one SIGMA", "fault-noise-two"),
    ("fault latency -5", BadArguments, "latency MS -5 is outside 0..60000 ms", "fault-latency-neg"),
    ("fault latency 5,-1", BadArguments, "latency JITTER -1 is outside", "fault-jitter-neg"),
    ("fault latency 1,2,3", BadArguments, "latency needs MS[,JITTER]", "fault-latency-three"),
    (
        "fault after -1 estop",
        BadArguments,
        "S '-1' is not a time within 0..1e+06 s",
        "fault-after-neg",
    ),
    ("fault after 1e7 estop", BadArguments, "is not a time within", "fault-after-huge"),
    ("fault at x estop", BadArguments, "bad number 'x'", "fault-at-word"),
    ("fault at 1", BadArguments, "needs a fault", "fault-at-no-kind"),
    ("fault after", BadArguments, "after needs a time", "fault-after-no-time"),
    ("fault at 1 bogus", BadArguments, "unknown fault 'bogus'", "fault-at-unknown"),
    ("fault clear x", BadArguments, "cannot clear 'x'", "fault-clear-unknown"),
    ("fault clear a b", BadArguments, "clear takes at most one KIND", "fault-clear-two"),
    ("faults now", BadArguments, "faults: takes no arguments", "faults-arg"),
    ("reset all", BadArguments, "reset: takes no arguments", "reset-arg"),
]


@pytest.mark.parametrize(
    ("line", "error", "message"), [b[:3] for b in BAD], ids=[b[3] for b in BAD]
)
def test_bad_lines(line, error, message):
    with pytest.raises(error) as caught:
        parse_line(line)
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)  # a reply is always one line


# 8 KiB lines of the shapes that once made a regex backtrack quadratically (one held the
# event loop for 3 s). Their timing, and how it grows with length, is a figure:
# benchmarks/hostile_lines.py. Here: each is refused with our error, the right one.
HOSTILE = [
    ("joints " + "1" * 8000 + "x", BadArguments, "joints: bad number '111", "digits-x"),
    ("sleep " + "1" * 8000 + "e", BadArguments, "sleep: bad number '111", "digits-e"),
    ("move 0 " + "1" * 8000 + ".x", BadArguments, "move: bad number '111", "digits-dot-x"),
    ("joints " + "1." * 4000, BadArguments, "joints: bad number '1.1.1.", "dots"),
    (
        "move " + ",".join(map(str, range(1, 1500))) + ",1 " + ",".join(["0"] * 1500),
        BadArguments,
        "move: joint 1 is given twice",
        "late-duplicate",
    ),
    ("fly" + " a" * 4000, UnknownCommand, "unknown command 'fly'", "unknown-verb-spaced"),
    ("fly" + " " * 8000 + "HTTP/1.1x", UnknownCommand, "unknown command 'fly'", "almost-http"),
]


@pytest.mark.parametrize(
    ("line", "error", "message"), [h[:3] for h in HOSTILE], ids=[h[3] for h in HOSTILE]
)
def test_hostile_lines_are_refused_with_our_error(line, error, message):
    with pytest.raises(error) as caught:
        parse_line(line)
    assert str(caught.value).startswith(message)
    assert len(str(caught.value)) < 200  # the line is cut in the reply, not echoed


def test_the_hostile_line_benchmark_runs():
    """benchmarks/hostile_lines.py cannot rot: it prints a row for each shape (figures only)."""
    done = subprocess.run(
        [sys.executable, str(ROOT / "benchmarks" / "hostile_lines.py"), "--quick"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    rows = [line.split("|")[1].strip() for line in done.stdout.splitlines()[2:]]
    assert rows == [h[3] for h in HOSTILE]


def test_every_short_spelling_from_number_characters_parses_as_the_grammar_says():
    """The parser lets float() judge lists spelled with [0-9.,eE+-] alone; it must agree
    with the grammar (sign, digits, fraction, exponent; finite) on every such string up to 6."""
    grammar = re.compile(r"[+-]?(?:[0-9]+(?:\.[0-9]*)?|\.[0-9]+)(?:[eE][+-]?[0-9]+)?")
    for length in range(1, 7):
        for chars in itertools.product("01+-.eE", repeat=length):
            text = "".join(chars)
            if grammar.fullmatch(text) and math.isfinite(float(text)):
                assert parse_line(f"joints {text}") == Joints((float(text),)), text
            else:
                with pytest.raises(BadArguments):
                    parse_line(f"joints {text}")
