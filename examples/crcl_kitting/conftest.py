"""The c2rviz pytest plugin: an installed c2rviz loads it by itself (its ``pytest11`` entry
point); naming it here too runs these tests from a checkout that is not installed."""

pytest_plugins = ("c2rviz.testing.plugin",)
