"""The command language beyond the seed's verbs, one module per concern.

Each module declares its verbs with ``registry.verb`` on frozen command classes
and parses with the grammar pieces of ``commands``. Pure: no I/O, nothing heavy
imported (the clients parse with it). ``commands`` imports every module here, so
``parse_line`` and ``help`` know all verbs.
"""

__all__: list[str] = []
