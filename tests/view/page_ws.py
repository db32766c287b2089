"""A websocket stand-in for a tab (viser's wire format), for the page-process tests."""

from __future__ import annotations

import asyncio
from typing import Any


async def scene_messages(url: str, timeout_s: float = 120.0) -> list[dict[str, Any]]:
    """Every message a new tab gets until viser's end of replay (the whole scene)."""
    import msgspec
    import viser
    import websockets
    import zstandard

    decompress = zstandard.ZstdDecompressor().decompress
    out: list[dict[str, Any]] = []
    ws_url = url.replace("http://", "ws://", 1)
    base, _, query = ws_url.partition("?")
    ws_url = base.rstrip("/") + "/" + (f"?{query}" if query else "")
    async with websockets.connect(
        ws_url,
        subprotocols=[websockets.Subprotocol(f"viser-v{viser.__version__}")],
        max_size=None,
        compression=None,
        open_timeout=timeout_s,
    ) as ws:
        async with asyncio.timeout(timeout_s):
            async for raw in ws:
                assert isinstance(raw, bytes)
                size = int.from_bytes(raw[:8], "little")
                packed = int.from_bytes(raw[8:16], "little")
                body = msgspec.msgpack.decode(
                    decompress(raw[16 : 16 + packed], max_output_size=size)
                )
                out += body["messages"]
                if any(m.get("type") == "ReplayDoneMessage" for m in body["messages"]):
                    return out
    return out


def gui_values(
    messages: list[dict[str, Any]], kinds: tuple[str, ...] = ("GuiSliderMessage", "GuiTextMessage")
) -> dict[str, Any]:
    """Each labelled slider's and text's (``kinds``) value at the end of ``messages``."""
    labels: dict[str, str] = {}
    values: dict[str, Any] = {}
    for m in messages:
        if m.get("type") in kinds and isinstance(m["props"].get("label"), str):
            labels[m["uuid"]] = m["props"]["label"]
            values[m["props"]["label"]] = m["value"]
        elif m.get("uuid") in labels and "value" in m.get("updates", {}):
            values[labels[m["uuid"]]] = m["updates"]["value"]
    return values


def node_names(messages: list[dict[str, Any]]) -> set[str]:
    """Every scene node ``messages`` make."""
    return {m["name"] for m in messages if m.get("type", "").endswith("Message") and "name" in m}
