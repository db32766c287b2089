"""A brake along a straight joint-space move: every joint stops at one common fraction.

A move from rest to rest, phase-synchronized, is the segment ``q = start + u * s``
(``max |u_i| = 1``). ``line_brake`` takes the state of such a move (position,
velocity and acceleration, all along ``u``), reads ``s`` and its rates off the
joint that moves most, and brakes ``s`` with a one-joint ruckig profile (the
velocity interface) whose limits are the tightest of the joints' along ``u``:
``min v_i / |u_i|``, ``min a_i / |u_i|``, ``min j_i / |u_i|``. So every joint is
within its full limits and the arm stays on the segment. Pure: times are the
caller's.
"""

from __future__ import annotations

import numpy as np
from ruckig import ControlInterface, InputParameter, Ruckig, RuckigError, Trajectory

from .limits import MotionLimits

__all__ = ["LINE_TOLERANCE", "LineBrake", "State", "line_brake"]

State = tuple[tuple[float, ...], tuple[float, ...], tuple[float, ...]]
LINE_TOLERANCE = 1e-6  # relative: (q, v, a) this close to the segment lie on it


class LineBrake:
    """A brake along a straight move: ``q = start + u * s(t)``, ``s`` one ruckig profile.

    Plays as a ruckig ``Trajectory`` of all joints does (``at_time``, ``duration``).
    """

    def __init__(
        self, start: np.ndarray, u: np.ndarray, length: float, profile: Trajectory
    ) -> None:
        self.start = start
        self.u = u
        self.profile = profile
        self.duration = profile.duration
        s_end = profile.at_time(profile.duration)[0][0]
        self.beyond = s_end >= length  # it would pass the segment's end
        self.rest = tuple((start + u * min(s_end, length)).tolist())

    def at_time(self, t: float) -> tuple[list[float], list[float], list[float]]:
        (s,), (rate,), (acceleration,) = self.profile.at_time(min(t, self.duration))
        return (
            (self.start + self.u * s).tolist(),
            (self.u * rate).tolist(),
            (self.u * acceleration).tolist(),
        )


def line_brake(
    line: tuple[np.ndarray, np.ndarray], state: State, limits: MotionLimits
) -> LineBrake | None:
    """A brake of ``s`` along ``line`` (start, goal) from ``state`` at the full ``limits``,
    or None when the state is off the line."""
    start, goal = line
    delta = goal - start
    length = float(np.max(np.abs(delta)))
    if length == 0:
        return None
    u = delta / length
    k = int(np.argmax(np.abs(u)))
    q, v, a = (np.asarray(x, dtype=float) for x in state)
    s, rate, acceleration = (q[k] - start[k]) / u[k], v[k] / u[k], a[k] / u[k]
    for x, along in ((q - start, s), (v, rate), (a, acceleration)):
        scale = max(1.0, float(np.max(np.abs(x))))
        if float(np.max(np.abs(x - u * along))) > LINE_TOLERANCE * scale:
            return None
    moving = np.abs(u) > 0
    bounds = [
        float(np.min(np.asarray(per_joint)[moving] / np.abs(u[moving])))
        for per_joint in (limits.velocity, limits.acceleration, limits.jerk)
    ]
    inp = InputParameter(1)
    inp.control_interface = ControlInterface.Velocity
    inp.current_position, inp.current_velocity = [s], [rate]
    inp.current_acceleration = [min(max(acceleration, -bounds[1]), bounds[1])]
    inp.target_velocity = inp.target_acceleration = [0.0]
    inp.max_velocity, inp.max_acceleration, inp.max_jerk = ([b] for b in bounds)
    profile = Trajectory(1)
    try:
        Ruckig(1).calculate(inp, profile)
    except RuckigError:
        return None
    return LineBrake(start, u, length, profile)
