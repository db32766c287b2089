"""The browser view: viser, reached through one adapter, behind one door."""
