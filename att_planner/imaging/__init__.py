"""Agile Earth observation: imaging sites with priorities, their access windows over a horizon,
the accessible bound and a greedy baseline (a planning estimate, not a flown day)."""
