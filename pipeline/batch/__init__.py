"""The batch engine: tasks from inputs, the work on one record (:mod:`.record`), the workers and
executors that run it, the passes, pairs, sites and vertical motion, resuming and the job log.  It
writes through :mod:`pipeline.reports` and never imports :mod:`pipeline.commands`."""
