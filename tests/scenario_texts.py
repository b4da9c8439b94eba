"""Scenario texts shared by the tests (imported by name: pytest puts tests/ on sys.path)."""

#: A box spinning near its middle axis for one second, five samples: the smallest valid run.
BOX_SCENARIO = """name = "t"
[body]
type = "box"
mass = 1.0
size = [1.0, 2.0, 3.0]
[initial]
omega = [0.0, 1.0, 0.1]
[time]
span = [0.0, 1.0]
samples = 5
"""
