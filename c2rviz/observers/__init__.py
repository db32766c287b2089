"""Observers of the world that keep and share what happens: ``watch`` streams, the
tool's ``trail``, and recordings (``recorder`` writes one, ``recordings`` keeps them).
"""
