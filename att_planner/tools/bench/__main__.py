"""``python -m att_planner.tools.bench`` = ``att-bench``."""
import sys

from att_planner.tools.bench import main

sys.exit(main())
