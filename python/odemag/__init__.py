# odemag Python package (python/odemag): odemag.sweep runs sweeps on Dask (docs/sweeps.md).
