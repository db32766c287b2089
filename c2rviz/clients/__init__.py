"""The programs that talk to a server: the typed ``Client`` and ``AsyncClient`` a
controller uses (``from c2rviz import Client``), and the REPL behind ``c2rviz-cli``
and the player behind ``c2rviz-play``, which use ``Client`` too. They import only
``protocol`` (and the ini reader), never the server side.
"""
