"""Imported first by the studies that run side by side: one BLAS, OpenMP and numba thread per
process unless the caller set otherwise. It must come before numpy and numba load (they read
these only then): two constriction runs with two threads each ran 2.5x slower per step on two
cores than with one each."""

import os

for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_var, "1")
