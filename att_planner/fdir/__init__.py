"""Fault detection, isolation and recovery on the flight side (no ROS, pure cores).

:mod:`.table` declares the fault table (its pydantic schema, read by the suite's one loader);
:mod:`.status` the report of a fault; the detectors (:mod:`.wheels`, :mod:`.frozen`,
:mod:`.innovations`, :mod:`.bias`, :mod:`.outage`, :mod:`.watchdogs`) turn measurements into verdicts with
persistence counted in sim time; :mod:`.monitor` runs the table's detectors and keeps which faults
are active; the responses (:mod:`.allocation`, :mod:`.envelope`, :mod:`.safe_mode`) are pure
functions of that state (:mod:`.responses`); :mod:`.tap` feeds the monitor from what the in-process
closed loop publishes.
"""
