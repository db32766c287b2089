"""The robots' faults as ROS diagnostics: ``/diagnostics`` (``diagnostic_msgs/msg/
DiagnosticArray``), the ROS convention for a machine's health (pure).

One ``DiagnosticStatus`` per robot, named ``c2rviz/ROBOT`` with ``hardware_id`` ROBOT:

* level ``ERROR`` (2) while a stop holds the robot (``estop``, ``protective``, a released
  estop not yet ``reset``) or a joint is stalled; ``WARN`` (1) with only noise or latency;
  ``OK`` (0) without faults;
* ``message``: the stop's refusal (``emergency stop since t=...``), else the faults, else
  ``ok``;
* ``values``: one ``{key, value}`` per fault, active or scheduled (``estop`` ->
  ``since 1.500``, ``noise 0.01`` -> ``at 5.000``), as ``faults`` lists them (SI).

The level is sent as a JSON number (what roslibpy clients read; rosbridge_suite's own
encoding of a ``byte`` varies with its version).
"""

from __future__ import annotations

from collections.abc import Mapping

from ...ros.messages import Msg, header
from ...world.faults import RobotFaults

__all__ = ["DIAGNOSTICS_TOPIC", "DIAGNOSTIC_ARRAY", "ERROR", "OK", "WARN", "diagnostics"]

DIAGNOSTICS_TOPIC = "/diagnostics"
DIAGNOSTIC_ARRAY = "diagnostic_msgs/msg/DiagnosticArray"
OK, WARN, ERROR = 0, 1, 2


def status(robot: str, faults: RobotFaults, origin: float) -> Msg:
    """``robot``'s ``DiagnosticStatus`` (times from ``origin`` [s])."""
    listed = faults.listing(origin)
    texts = [fault.text(faults.joint_names) for fault, _ in listed]
    refusal = faults.refusal(origin)
    if refusal is not None or faults.held:
        level = ERROR
    elif faults.active:
        level = WARN
    else:
        level = OK
    if refusal is not None:
        message = str(refusal)
    else:
        active = [fault.text(faults.joint_names) for fault, _ in faults.active.values()]
        message = "faults: " + ", ".join(active) if active else "ok"
    return {
        "level": level,
        "name": f"c2rviz/{robot}",
        "message": message,
        "hardware_id": robot,
        "values": [{"key": text, "value": when} for text, (_, when) in zip(texts, listed)],
    }


def diagnostics(t: float, robots: Mapping[str, RobotFaults], origin: float) -> Msg:
    """``/diagnostics`` at time ``t`` [s]: every robot's status."""
    return {
        "header": header(t),
        "status": [status(name, faults, origin) for name, faults in robots.items()],
    }
