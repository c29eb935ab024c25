"""A small Monte Carlo campaign in process: the demo plan made once, flown on 8 dispersed truths as one batch."""
from pathlib import Path

import numpy as np

from att_planner.tools.monte_carlo.run import checked, fly_batch, planned
from att_sim.truth import dispersions

campaign = dispersions.load_campaign(Path(__file__).parents[1] / "campaigns" / "swift_demo.yaml")
runs = [(i, dispersions.run_seed(campaign.seed, i)) for i in range(8)]   # run i's seed: reproducible alone
setup = planned(checked(campaign, [seed for _, seed in runs]))          # the plan, on the nominal model
rows = fly_batch(setup, runs)                                           # each run converges, flies, settles
for row in rows:
    print(f"run {row['run']} seed {row['seed']}: success {row['success']}, "
          f"final error {row['final_error_deg'] * 3600:.1f} arcsec, min margin {row['min_margin_deg']:.2f} deg")
errors = np.array([row["final_error_deg"] for row in rows]) * 3600
print(f"{sum(r['success'] for r in rows)}/{len(rows)} successful; final error mean {errors.mean():.1f}, "
      f"max {errors.max():.1f} arcsec")
