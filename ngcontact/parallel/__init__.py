"""Batches of independent solves on worker processes or a Dask cluster: the one room that starts a pool."""
