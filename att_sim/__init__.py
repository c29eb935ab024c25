"""Truth and shared models: the simulated spacecraft, its environment and the models flight software shares."""
