"""A rosbridge client picks and places a part (lines on ``/c2rviz/command``) and follows
it on ``/tf`` as the frame ``parts/NAME``."""

from __future__ import annotations

from collections.abc import Iterator
from typing import Any

import pytest
import roslibpy
from roslibpy.ros import set_rosapi_timeout
from support import load_robot
from world_support import WAIT_S, WorldServer, ask, command_service, listen, until

PICK = "0,0.3,-0.3,0,-0.9707963,0"  # the fanuc pointing down at the part (test_part_verbs)
LIFT = "0,0,0,0,-1.5707963,0"
AWAY = "1.5707963,0,0,0,-1.5707963,0"


@pytest.fixture
def fanuc_ros() -> Iterator[roslibpy.Ros]:
    server = WorldServer({"fanuc_lrmate200id": load_robot("fanuc_lrmate200id")})
    set_rosapi_timeout(WAIT_S)
    client = roslibpy.Ros("127.0.0.1", server.port, transport="asyncio")
    try:
        client.run(timeout=WAIT_S)
        yield client
    finally:
        client.close()
        server.stop()


def _part(msg: dict[str, Any]) -> dict[str, Any] | None:
    return next((t for t in msg["transforms"] if t["child_frame_id"] == "parts/p1"), None)


def test_a_rosbridge_client_picks_and_places_a_part(fanuc_ros: roslibpy.Ros) -> None:
    service = command_service(fanuc_ros)
    tf = listen(fanuc_ros, "/tf", "tf2_msgs/msg/TFMessage")
    for line in (
        "grip 1",
        "object table box 0.4,0.6,0.05 0.45,0,0.154,0,0,0",
        "part p1 box 0.03,0.03,0.17 0.4438,0,0.264,0,0,0",
        f"joints {PICK}",
        "grip 0",
        f"joints {LIFT}",
        f"joints {AWAY}",
        "grip 1",
    ):
        reply = ask(service, line)
        assert reply["ok"], (line, reply)
    landed = until(
        tf, lambda m: (p := _part(m)) is not None and p["transform"]["translation"]["z"] < 0.0851
    )
    where = _part(landed)
    assert where is not None and where["header"]["frame_id"] == "base_link"
    assert where["transform"]["translation"]["y"] == pytest.approx(0.385, abs=0.01)  # beside
    assert ask(service, "part p1")["reply"].endswith(" resting on floor")
