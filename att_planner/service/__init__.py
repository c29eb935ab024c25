"""The planner service without ROS: request validation (:mod:`.requests`, with the closed-sky test
of :mod:`.sky`), solve-verify-fallback (:mod:`.planning`) and budget-bounded child solves
(:mod:`.worker`)."""
