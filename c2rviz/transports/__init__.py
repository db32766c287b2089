"""The doors: each turns bytes from its clients into lines or commands on a ``Session``
and its replies back into bytes. ``tcp_text`` is the seed's text port.
"""
