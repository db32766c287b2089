"""One table of every door's limits (``protocol.limits``): each door's object is built from it."""

from __future__ import annotations

import dataclasses

import pytest
from support import ROOT

from c2rviz.app import config
from c2rviz.protocol.limits import DOORS, LIMITS, below_floor, bounds, rows
from c2rviz.session.services import ServerLimits
from c2rviz.transports.crcl.documents import MAX_DOCUMENT_BYTES
from c2rviz.transports.crcl.server import CrclLimits
from c2rviz.transports.rosbridge.policy import PolicyError, RosbridgePolicy
from c2rviz.view.door_rules import DoorPolicy, DoorPolicyError

OBJECTS = {
    "text": ServerLimits,
    "crcl": CrclLimits,
    "rosbridge": RosbridgePolicy,
    "page": DoorPolicy,
}
NOT_LIMITS = {"extra_origins", "token", "compression"}  # who may come in, not what they may cost


@pytest.mark.parametrize("door", DOORS)
def test_each_doors_object_is_its_rows(door: str) -> None:
    fields = {f.name: f.default for f in dataclasses.fields(OBJECTS[door])}
    table = {row.name: row.default for row in rows(door)}
    assert {k: v for k, v in fields.items() if k not in NOT_LIMITS} == table


def test_every_row_is_one_doors_and_named_once() -> None:
    keys = [(row.door, row.name) for row in LIMITS]
    assert len(keys) == len(set(keys))
    assert {door for door, _ in keys} == set(DOORS)
    for row in LIMITS:
        assert row.low is None or row.high is None or row.low <= row.default <= row.high


def test_the_crcl_parser_caps_documents_at_the_doors_limit() -> None:
    assert MAX_DOCUMENT_BYTES == CrclLimits().max_document_bytes == 1 << 20


def test_the_ini_and_flags_bound_the_text_limits_by_the_table() -> None:
    for key, (field, _kind, low, high) in config._OPTIONS.items():
        door = "page" if key == "max_viewers" else "text"
        name = "max_clients" if key == "max_viewers" else field
        if door == "page" or field in {f.name for f in dataclasses.fields(ServerLimits)}:
            assert (low, high) == bounds(door, name)
    assert config.Settings().max_viewers == DoorPolicy().max_clients


@pytest.mark.parametrize(
    ("make", "error", "text"),
    [
        (
            lambda: DoorPolicy(max_clients=0),
            DoorPolicyError,
            "viewer max clients '0' is not at least 1",
        ),
        (
            lambda: DoorPolicy(max_clients=0, max_queued_frames=0),
            DoorPolicyError,
            "viewer max clients '0' is not at least 1",
        ),
        (lambda: DoorPolicy(max_queued_frames=0), DoorPolicyError, "viewer max queued frames '0'"),
        (
            lambda: RosbridgePolicy(max_read_ahead=0, max_queue_length=-1),
            PolicyError,
            "rosbridge max read ahead '0' is not at least 1",
        ),
        (
            lambda: RosbridgePolicy(max_queue_length=-1),
            PolicyError,
            "rosbridge max queue length '-1' is not at least 0",
        ),
    ],
    ids=["page-one", "page-first-named", "page-frames", "rosbridge-order", "rosbridge-zero-floor"],
)
def test_a_value_below_its_floor_is_named(make, error, text: str) -> None:  # type: ignore[no-untyped-def]
    with pytest.raises(error) as caught:
        make()
    assert text in str(caught.value)


def test_floors_allow_the_lowest() -> None:
    assert below_floor("rosbridge", RosbridgePolicy(max_queue_length=0, max_read_ahead=1)) is None
    assert below_floor("page", DoorPolicy(max_clients=1)) is None


def test_the_docs_show_the_defaults() -> None:
    text = (ROOT / "docs" / "limits.md").read_text()
    crcl, bridge, page = CrclLimits(), RosbridgePolicy(), DoorPolicy()
    assert f"| {crcl.max_document_bytes}; {crcl.max_connections} |" in text
    assert f"| {bridge.max_frame_bytes}; {bridge.max_connections} |" in text
    assert f"| viewer tabs at once; one more is closed | {page.max_clients} |" in text
    assert f"| largest frame a page may send (bytes) | {page.max_frame_bytes} |" in text
