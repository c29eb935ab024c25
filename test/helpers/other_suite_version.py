"""A Dask worker preload (``dask worker ADDRESS --preload test/helpers/other_suite_version.py``): the
worker reports another suite version than its client, as one installed from another release would.
Importing it changes nothing; Dask calls :func:`dask_setup` in the worker it preloads."""
OTHER = "0.0.9+000000000000"


def dask_setup(worker) -> None:
    from att_planner.tools.monte_carlo import version

    version.suite_version = lambda: OTHER
