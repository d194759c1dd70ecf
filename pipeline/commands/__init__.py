"""The sub-commands of ``pipeline``, one module each (:mod:`pipeline.cli` loads them by name): each
parses its arguments into values and calls the batch engine (:mod:`pipeline.batch`), the public
batch API (:mod:`pipeline.api`) or the reports (:mod:`pipeline.reports`)."""
