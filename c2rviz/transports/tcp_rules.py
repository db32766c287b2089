"""What every TCP door (the text port, CRCL) keeps alike: a client's turn and the close.

A client's work runs ``TURN_S`` at a time, then the other clients go first, so one
client's flood delays the others by no more than that. A door that closes a
connection (a limit, ``bye``, a refusal, shutdown) sends what is queued, ends its side
and reads and drops what the client still sends for up to ``LINGER_S``
(``close_lingering``): closing with input unread would make the kernel reset the
connection, and a reset destroys replies not yet delivered.
"""

from __future__ import annotations

import asyncio
from typing import Final

__all__ = ["LINGER_S", "TURN_S", "close_lingering"]

TURN_S: Final = 0.002
"""Work per client per event-loop turn [s]: then the other clients go first."""
LINGER_S: Final = 2.0
"""After the close is decided, how long a client's input is read and dropped [s]."""


def close_lingering(transport: asyncio.Transport, eof: bool) -> asyncio.TimerHandle | None:
    """Send what is queued, then close without a reset.

    Unless the client has finished sending (``eof``), the door half-closes (FIN after
    the replies) and reads on; the caller drops what comes, and the connection closes
    when the client closes too, or is aborted ``LINGER_S`` after the close began.

    Args:
        transport: The connection's transport.
        eof: The client has sent all it will (nothing to linger for: it closes now).

    Returns:
        The timer that aborts the connection (cancel it once the client has closed), or
        None: the connection is closed or closing already.
    """
    if transport.is_closing():
        return None
    if eof:
        transport.close()  # nothing more will come: nothing to linger for
        return None
    try:
        transport.write_eof()
    except OSError:  # the client is already gone (ENOTCONN): nothing to deliver
        transport.abort()
        return None
    transport.resume_reading()
    return asyncio.get_running_loop().call_later(LINGER_S, transport.abort)
