"""The plugin's server opens the CRCL and rosbridge doors when a test asks, on free ports it
names (``c2rviz_server.crcl_port``, ``.rosbridge_port``), and they drive the same world as
the text port: a CRCL document over a plain socket, roslibpy over the websocket."""

from __future__ import annotations

import math
import queue
import socket
from typing import Any

import pytest
import roslibpy
from roslibpy.ros import set_rosapi_timeout

from c2rviz.transports.crcl import parse_status

WAIT_S = 60.0
INIT = b"""<?xml version="1.0" encoding="UTF-8"?>
<CRCLCommandInstance
  xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
  <CRCLCommand xsi:type="InitCanonType">
    <CommandID>1</CommandID>
  </CRCLCommand>
</CRCLCommandInstance>
"""
ACTUATE = b"""<?xml version="1.0" encoding="UTF-8"?>
<CRCLCommandInstance
  xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance">
  <CRCLCommand xsi:type="ActuateJointsType">
    <CommandID>7</CommandID>
    <ActuateJoint>
      <JointNumber>1</JointNumber>
      <JointPosition>0.5</JointPosition>
      <JointDetails xsi:type="JointSpeedAccelType"></JointDetails>
    </ActuateJoint>
  </CRCLCommand>
</CRCLCommandInstance>
"""
"""Joint 1 (CRCL numbers joints from 1) to 0.5 rad, as NIST's examples write it."""


def crcl_final_state(port: int, doc: bytes, command_id: int) -> str:
    """Send ``doc`` to the CRCL door; the state of the first final status of ``command_id``
    that it pushes (and its description, if any)."""
    with socket.create_connection(("127.0.0.1", port), timeout=WAIT_S) as sock:
        sock.sendall(doc)
        buffer, end = b"", b"</CRCLStatus>"
        while True:
            while end not in buffer:
                chunk = sock.recv(65536)
                assert chunk, "the CRCL door closed the connection"
                buffer += chunk
            cut = buffer.index(end) + len(end)
            status = parse_status(buffer[:cut]).command_status
            buffer = buffer[cut:]
            if status.command_id == command_id and status.state in ("CRCL_Done", "CRCL_Error"):
                return f"{status.state} {status.description or ''}".strip()


@pytest.mark.c2rviz(crcl=True, rosbridge=True)
@pytest.mark.parametrize(
    "c2rviz_server",
    [{"clock": "virtual"}, {"clock": "real"}],
    ids=["virtual", "real"],
    indirect=True,
)
def test_a_crcl_document_and_roslibpy_reach_the_test_server(c2rviz_server, c2rviz):
    assert c2rviz_server.crcl_port not in (0, c2rviz_server.port)
    assert c2rviz_server.rosbridge_port not in (None, 0, c2rviz_server.port)
    with c2rviz_server.idle_clients():  # the test's text client waits meanwhile
        assert crcl_final_state(c2rviz_server.crcl_port, INIT + ACTUATE, 7) == "CRCL_Done"
    assert c2rviz.where()[0] == pytest.approx(0.5)

    set_rosapi_timeout(WAIT_S)
    ros = roslibpy.Ros("127.0.0.1", c2rviz_server.rosbridge_port, transport="asyncio")
    with c2rviz_server.idle_clients():
        ros.run(timeout=WAIT_S)
        try:
            states: queue.Queue[dict[str, Any]] = queue.Queue()
            roslibpy.Topic(ros, "/joint_states", "sensor_msgs/msg/JointState").subscribe(states.put)
            first = states.get(timeout=WAIT_S)
            assert first["position"][0] == pytest.approx(0.5)
            service = roslibpy.Service(ros, "/c2rviz/command", "c2rviz_msgs/srv/Command")
            reply = service.call(
                roslibpy.ServiceRequest({"command": "joints 0.1,0.2,0,0,0,0,0"}), timeout=WAIT_S
            )
            assert reply["reply"] == "ok", reply
        finally:
            ros.close()
    assert c2rviz.where()[:2] == pytest.approx((0.1, 0.2))
    assert not math.isnan(c2rviz_server.now())


def test_no_door_is_opened_unless_asked(c2rviz_server):
    assert c2rviz_server.crcl_ports == {}
    assert c2rviz_server.rosbridge_port is None
    with pytest.raises(RuntimeError, match="crcl=True"):
        _ = c2rviz_server.crcl_port


@pytest.mark.c2rviz(crcl=True)
def test_crcl_alone_opens_no_rosbridge(c2rviz_server):
    assert c2rviz_server.crcl_port > 0
    assert c2rviz_server.rosbridge_port is None


def test_the_fixture_client_is_served_before_the_test_runs(c2rviz_server, c2rviz):
    """Else the test's first ``idle_clients()`` could miss it, and it would hold virtual
    time inside (a CRCL move stayed CRCL_Working so)."""
    assert c2rviz_server.text_clients() == 1
