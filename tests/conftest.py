import os

import matplotlib

matplotlib.use("Agg")

if os.environ.get("NGCONTACT_THREADS") == "1":
    # one thread as a run's (ngcontact.runner.threads): NGSolve's sparse Cholesky factorization would otherwise
    # sum on every core in an order that varies from call to call, for the tests that solve outside a run too
    import pyngcore

    pyngcore.SetNumThreads(1)
