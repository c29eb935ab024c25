"""Paper data only: the published cases, targets, initial conditions, gains and figures the
benchmarks and tests compare against. Planning and control code never imports this package."""
