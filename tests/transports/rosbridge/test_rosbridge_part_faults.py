"""rosbridge's /diagnostics lists the part faults as it lists the others: ``slip P`` a
warning while on, a scheduled ``drop`` among the values (published with the next
change, as every scheduled fault is) until it comes due."""

from __future__ import annotations

import roslibpy
from world_support import WAIT_S, WorldServer, ask, command_service, listen, until


def test_diagnostics_list_slip_and_a_scheduled_drop(
    world_server: WorldServer, ros_world: roslibpy.Ros
) -> None:
    diagnostics = listen(ros_world, "/diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
    assert diagnostics.get(timeout=WAIT_S)["status"][0]["level"] == 0
    service = command_service(ros_world)
    assert ask(service, "fault after 1000 drop p1")["ok"]  # told with the next change
    assert ask(service, "fault slip 0.25")["ok"]
    slipping = until(diagnostics, lambda m: m["status"][0]["level"] == 1)["status"][0]
    assert slipping["message"] == "faults: slip 0.25"
    assert [v["key"] for v in slipping["values"]] == ["slip 0.25", "drop p1"]
    assert slipping["values"][1]["value"].startswith("at ")
    assert ask(service, "fault clear")["ok"]
    assert until(diagnostics, lambda m: m["status"][0]["level"] == 0)["status"][0]["values"] == []
