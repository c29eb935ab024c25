"""Record a run to an MCAP log in process, read it back with read_log and review it as att-review does."""
from pathlib import Path

import numpy as np

from att_msgs_py.log import read_log
from att_planner.tools.monte_carlo.log import write_run_log
from att_planner.tools.monte_carlo.run import checked, planned
from att_planner.tools.review import review
from att_sim.truth import dispersions

campaign = dispersions.load_campaign(Path(__file__).parents[1] / "campaigns" / "swift_demo.yaml")
path = Path("runs/review_example/run.mcap")           # every message the nodes would publish, in sim time
path.parent.mkdir(parents=True, exist_ok=True)
write_run_log(planned(checked(campaign)), dispersions.run_seed(campaign.seed, 0), path)
state = read_log(path)["/spacecraft/state"]           # {topic: TopicLog}: fields as numpy arrays
rates = np.linalg.norm(state["body_rate"], axis=1)
print(f"log: {len(state.log_time)} states over {state.log_time[-1]:.1f} s, peak rate {rates.max():.4f} rad/s")
result = review(path, scenario="swift_demo")          # figures, summary and a self-contained HTML page
print(f"reviewed: final attitude error {result.summary['final_attitude_error_deg']:.4f} deg, "
      f"estimation error rms {result.summary['estimation']['attitude_error_rms_arcsec']:.1f} arcsec")
print(f"review: {result.html} ({', '.join(result.figures)})")
