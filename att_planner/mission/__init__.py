"""Missions (issue 17): the target lists a day in orbit observes (:mod:`.targets`)."""
