"""``TestServer.stop`` after the server ended on its own (a client's ``quit``)."""

from __future__ import annotations

from support import Client

from c2rviz.testing import TestServer


def test_stop_after_a_quit_ended_the_server_does_not_raise(monkeypatch):
    server = TestServer({"clock": "real"}).start()
    client = Client("127.0.0.1", server.port)
    try:
        assert client.ask("quit") == "ok"
        assert server.quit_requested.wait(60)
        server._thread.join(60)  # its loop is closed now
        # The race a full run met: the thread still looked alive when stop() checked, and
        # its loop closed before stop() asked it to stop.
        monkeypatch.setattr(server._thread, "is_alive", lambda: True)
        server.stop()  # raised "RuntimeError: Event loop is closed"
    finally:
        client.close()
