"""Missions: the target lists a day in orbit observes (:mod:`.targets`)."""
