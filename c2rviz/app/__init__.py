"""The program: flags and ``cmdinterpreter.ini`` (``config``), the robots to serve
(``cell``, ``robot_options``), the running program (``program``) and ``main`` (``cli``).
"""
