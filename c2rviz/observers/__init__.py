"""Observers of the world that keep and share what happens: ``watch`` streams, the
tool's ``trail``, and recordings (``recorder`` writes a robot's NAME.txt and NAME.csv,
``bag_recorder`` the bag NAME/, ``recordings`` keeps them, one per robot, and finishes
them, and ``record_files`` puts their files in place whole).
"""
