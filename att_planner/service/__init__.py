"""The planner service without ROS: request validation (:mod:`.requests`), solve-verify-fallback
(:mod:`.planning`) and budget-bounded child solves (:mod:`.worker`)."""
