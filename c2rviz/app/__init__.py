"""The program: flags and ``cmdinterpreter.ini`` (``config``), the robots to serve
(``members``, with what the ini puts in their world: ``ini_world``), the doors beside the
text port (``doors``), the running program (``program``) and ``main`` (``cli``).
"""
