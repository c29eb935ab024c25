"""Models shared by the flight software and the truth simulation.

Attitude kinematics (:mod:`.rotations`), rigid body and wheel dynamics with the spacecraft's
parameters (:mod:`.dynamics`), time, orbit, ephemeris, geomagnetic and atmosphere models, the
disturbance torques and the environment that composes them (:mod:`.world`), scenario files, and the
sensor and actuator datasheets. Nothing here draws a random number or knows a dispersed truth: the
flight software instantiates these models with the nominal spacecraft, the truth simulation
(:mod:`att_sim.truth`) with the dispersed one.
"""
