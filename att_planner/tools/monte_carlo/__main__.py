"""``python -m att_planner.tools.monte_carlo``: ``att-mc``."""
import sys

from att_planner.tools.monte_carlo import main

sys.exit(main())
