"""Truth side: attitude dynamics, environment and the simulator node."""
