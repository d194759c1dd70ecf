"""Benchmarks of the solver, the fitter, the design layer and the pipeline (``python -m benchmarks``)."""
