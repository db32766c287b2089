"""The version of c2rviz (the ``version`` verb and the package report it)."""

__version__ = "0.2.0"
