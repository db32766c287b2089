"""NAME.html of a recorded pick and place embeds each part: its node, its columns, and
its poses per frame, NAME.csv's (the browser test plays it)."""

from __future__ import annotations

import base64
import gzip
import json
import re
from pathlib import Path

import numpy as np
import pytest
from support import Client

from tests.observers.test_record_parts import RUN, SETUP, _server


def _embedded(html: str) -> tuple[dict, np.ndarray]:
    meta = json.loads(re.search(r'id="c2rviz-recording">(.*?)</script>', html).group(1))
    blob = re.search(r'id="c2rviz-values">(.*?)</script>', html).group(1)
    values = np.frombuffer(gzip.decompress(base64.b64decode(blob)), dtype="<f4")
    return meta, values


def test_the_recorded_page_embeds_each_parts_shape_and_poses(tmp_path: Path) -> None:
    server = _server(tmp_path)
    client = Client(server.host, server.port)
    try:
        for line in SETUP:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record take").startswith("ok recording take")
        for line in RUN:
            assert client.ask(line).startswith("ok"), line
        assert client.ask("record stop").startswith("ok")
    finally:
        client.close()
        server.stop()
    html = (tmp_path / "take.html").read_text()
    meta, values = _embedded(html)
    assert meta["problems"] == []
    assert [p["name"] for p in meta["parts"]] == ["p1", "p2"]
    assert meta["parts"][0]["node"] == "/parts/robot/p1"
    width = len(meta["joints"]) + 6 + 12
    rows = values.reshape(meta["frames"], width)
    csv = np.genfromtxt(tmp_path / "take.csv", delimiter=",", skip_header=1)
    p1 = meta["parts"][0]["column"]
    np.testing.assert_allclose(rows[0, p1 : p1 + 6], csv[0, p1 + 1 : p1 + 7], atol=1e-6)
    np.testing.assert_allclose(rows[-1, p1 : p1 + 6], csv[-1, p1 + 1 : p1 + 7], atol=1e-6)
    assert rows[-1, p1 + 2] == pytest.approx(0.085, abs=1e-6)  # on the floor
    assert rows[:, p1 + 2].max() > 0.4  # carried up
    assert np.isnan(rows[-1, p1 + 6 : p1 + 12]).all()  # p2 was removed
