"""The truth simulation: what the flight software never sees.

The simulated spacecraft's state (:mod:`.simulation`), its imperfect actuators (:mod:`.actuators`)
and sensors with their errors and noise (:mod:`.sensors`), the dispersions of a Monte Carlo run
(:mod:`.dispersions`), the step on rows of runs — one simulation or a Monte Carlo batch
(:mod:`.batch`) — and the simulator node. The flight side (``att_planner`` but its tools) never imports this package: an
import-linter contract in ``pyproject.toml`` holds it to that.
"""
