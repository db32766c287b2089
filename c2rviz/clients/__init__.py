"""The programs that talk to a server: the line client, the REPL behind
``c2rviz-cli`` and the player behind ``c2rviz-play``. They import only ``protocol``
(and the ini reader), never the server side.
"""
